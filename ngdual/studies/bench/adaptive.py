"""What the steps of an adaptive run cost, per order, against their solves (``ngdual bench
adaptive``).

Runs :func:`ngdual.afem.adapt` at every order k of ``orders`` (a tolerance run by default:
the pressure goal to 1 %, with the loop's marking, theta and least growth per step) and
records, per step, the unknowns and their ``growth`` over the step before, and the wall time
of every phase read from the step's record and solution (``on_step``): the refinement that
made the mesh, the assembly of (3.62), the hybridisation (the edge multipliers' coupling
and the static condensation, :class:`~ngdual.solvers.hybrid.HybridSystem`), the Cholesky
factorisation, the contact iterations (from the first substitution to the recovered
unknowns), the physics checks, the estimate (4.50), the goal's indicators and the marking.
The step's total is its wall time, from the end of the previous step's marking to the end
of its own (the refinement included); ``other`` is what no phase accounts for (meshing,
the formula checks, the spaces of the next mesh).

``solve_s`` is the factorisation and the contact iterations (``timings["factorize"]`` and
``timings["solve"]``), the part of a step that grows with its unknowns as a sparse direct
solve does; ``fixed_s`` is the rest of the step (assembly, spaces, checks, estimate, goal,
marking, refinement), and ``fixed_ratio`` = fixed_s / solve_s.

The unit of ``ratio`` is one linear solve of the mesh's own system as the active-set solver
does it, from its formulas: the assembly of (3.62), the factorisation (the static
condensation and the Cholesky factorisation) and one forward and one backward substitution
(``timings["substitute"]``); ``ratio`` = step total / unit is what the adaptive loop pays
on a mesh beyond solving it once. ``ratio_factorize`` counts the assembly as a fixed cost of
the step (unit: factorisation and substitution), ``ratio_cholesky`` the condensation too
(unit: Cholesky factorisation and substitution). Where the solver does not time a phase
(the active-set method of order k >= 1 has no ``substitute``) its column is empty.
"""

from __future__ import annotations

import time
import warnings

from .measure import header, warning_messages

# the table ngdual bench adaptive prints: (title, key of a record, format)
COLUMNS = (("k", "order", "1d"), ("step", "step", "4d"), ("unknowns", "ndof", "9d"),
           ("growth", "growth", "6.2f"), ("marked", "marked", "6d"),
           ("refine", "seconds.refine", "6.3f"), ("assemble", "seconds.assemble", "8.3f"),
           ("hybridise", "seconds.hybridize", "9.3f"), ("cholesky", "seconds.cholesky", "8.3f"),
           ("iter", "iterations.inner", "4d"), ("contact", "seconds.contact", "7.3f"),
           ("checks", "seconds.checks", "6.3f"), ("estimate", "seconds.estimate", "8.3f"),
           ("goal", "seconds.goal", "6.3f"), ("mark", "seconds.mark", "6.3f"),
           ("other", "seconds.other", "6.3f"), ("step", "seconds.step", "6.3f"),
           ("solve", "solve_s", "6.3f"), ("fixed", "fixed_s", "6.3f"),
           ("fixed/solve", "fixed_ratio", "11.2f"), ("ratio", "ratio", "6.2f"),
           ("relative", "relative_estimate", "9.2e"))

# the phases of a step, each read from the solution's timings (or the step record's)
SOLVER_PHASES = {"assemble": "assemble", "hybridize": "hybridize", "cholesky": "cholesky",
                 "contact": "solve", "checks": "checks"}
LOOP_PHASES = ("estimate", "goal", "mark")


def step_seconds(record: dict, timings: dict, refine: float, wall: float) -> dict:
    """The phases of one step (s): the solver's ``timings``, the estimate, the goal's
    indicators and the marking of the step ``record``, the ``refine`` that made its mesh and
    its ``wall`` time; with the units of the ratios (``unit``, ``unit_factorize``,
    ``unit_cholesky``) where the solver times them."""
    seconds = {"refine": refine,
               **{phase: timings.get(key) for phase, key in SOLVER_PHASES.items()},
               **{phase: record["timings_s"].get(phase) for phase in LOOP_PHASES}}
    seconds["other"] = wall - sum(s for s in seconds.values() if s is not None)
    seconds["step"] = wall
    solved = "substitute" in timings
    seconds["unit_factorize"] = timings["factorize"] + timings["substitute"] if solved else None
    seconds["unit"] = timings["assemble"] + seconds["unit_factorize"] if solved else None
    seconds["unit_cholesky"] = timings["cholesky"] + timings["substitute"] if solved else None
    return seconds


def solve_seconds(timings: dict) -> float | None:
    """The factorisation and the contact iterations of a solve (s), None where the solver
    does not time them apart."""
    if "factorize" not in timings or "solve" not in timings:
        return None
    return timings["factorize"] + timings["solve"]


def run(scene: str, overrides=(), orders=(0, 1, 2), goal: str = "pressure",
        tol: float | None = 0.01, level: int | None = None, steps: int | None = None,
        theta: float | None = None, growth: float | None = None, allow_large: bool = False,
        on_record=None) -> dict:
    """The per-step records of an adaptive run of ``scene`` (name or path, with
    ``overrides``) at every order of ``orders``, aiming at ``goal`` with ``tol`` (or
    ``steps`` steps without one); ``level``, ``steps``, ``theta``, ``growth`` and
    ``allow_large`` as for :func:`ngdual.afem.adapt` (None: its defaults). Calls
    ``on_record(study)`` after each step."""
    from ...afem import AdaptWarning, adapt, growth_default, loop_defaults
    from ...scene import load_scene
    from ...solution import PhysicsWarning

    theta, steps, level = loop_defaults(tol, theta, steps, level)
    growth = growth_default(tol, growth)
    study = header("adaptive", scene=scene, overrides=list(overrides), orders=list(orders),
                   goal=goal, tol=tol, level=level, steps=steps, marking="dorfler",
                   theta=theta, growth=growth)
    records = study["records"]

    for order in orders:
        previous: list[dict] = []   # the last step's record, whose refine follows on_step
        clock = [time.perf_counter()]

        def on_step(record, solution, estimated, marked, order=order, previous=previous,
                    clock=clock) -> None:
            now = time.perf_counter()
            refine = previous[-1]["timings_s"]["refine"] if previous else 0.0
            seconds = step_seconds(record, solution.timings, refine, now - clock[0])
            units = {key: seconds[f"unit{suffix}"] for key, suffix in
                     (("ratio", ""), ("ratio_factorize", "_factorize"),
                      ("ratio_cholesky", "_cholesky"))}
            solve = solve_seconds(solution.timings)
            fixed = None if solve is None else seconds["step"] - solve
            ndof = record["dofs"]["total"]
            records.append({"scene": scene, "order": order, "step": record["step"],
                            "ndof": ndof, "elements": record["elements"],
                            "growth": ndof / previous[-1]["dofs"]["total"] if previous
                            else None,
                            "marked": record.get("marked"), "converged": record["converged"],
                            "iterations": record["iterations"],
                            "estimator": record["estimator"],
                            "relative_estimate": record["relative_estimate"],
                            "stopped_by": record.get("stopped_by"),
                            "seconds": seconds, "timings_s": dict(solution.timings),
                            "solve_s": solve, "fixed_s": fixed,
                            "fixed_ratio": fixed / solve if solve else None,
                            **{key: seconds["step"] / unit if unit else None
                               for key, unit in units.items()},
                            "warnings": warning_messages(solution)})
            previous[:] = [record]
            if on_record:
                on_record(study)
            clock[0] = time.perf_counter()

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PhysicsWarning)
            warnings.simplefilter("ignore", AdaptWarning)   # the records say: stopped_by
            adapt(load_scene(scene, list(overrides)), marking="dorfler", theta=theta,
                  steps=steps, level=level, on_step=on_step, allow_large=allow_large,
                  goal=goal, tol=tol, order=order, growth=growth)
    return study
