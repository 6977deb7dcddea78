"""What one adaptive step costs against one linear solve of its mesh (``ngdual bench
adaptive``).

Runs :func:`ngdual.afem.adapt` with Dörfler marking and records, per step, the wall time of
every phase read from the step's record and solution (``on_step``): the refinement that
made the mesh, the assembly of (3.62), the hybridisation (the edge multipliers' coupling
and the static condensation, :class:`~ngdual.solvers.hybrid.HybridSystem`), the Cholesky
factorisation, the contact iterations (from the first substitution to the recovered
unknowns), the physics checks, the estimate (4.50) and the marking. The step's total is
its wall time, from the end of the previous step's marking to the end of its own (the
refinement included); ``other`` is what no phase accounts for (meshing, the formula
checks, the spaces of the next mesh).

The unit is one linear solve of the mesh's own system as the active-set solver does it,
from its formulas: the assembly of (3.62) (the PEERS element matrices once, for the
hybridisation and for K where a solver forms it, :class:`~ngdual.forms.BrokenPeers`), the
factorisation (``timings["factorize"]``: the static condensation and the Cholesky
factorisation) and one forward and one backward substitution (``timings["substitute"]``);
``ratio`` = step total / unit is what the adaptive loop pays on a mesh beyond solving it
once. ``ratio_factorize`` counts the assembly as a fixed cost of the step (unit:
factorisation and substitution), ``ratio_cholesky`` the condensation too (unit: Cholesky
factorisation and substitution).
"""

from __future__ import annotations

import time
import warnings

from .measure import header, warning_messages

# the table ngdual bench adaptive prints: (title, key of a record, format)
COLUMNS = (("step", "step", "4d"), ("unknowns", "ndof", "9d"),
           ("refine", "seconds.refine", "7.3f"), ("assemble", "seconds.assemble", "8.3f"),
           ("hybridise", "seconds.hybridize", "9.3f"), ("cholesky", "seconds.cholesky", "8.3f"),
           ("iter", "iterations.inner", "4d"), ("contact", "seconds.contact", "7.3f"),
           ("checks", "seconds.checks", "6.3f"), ("estimate", "seconds.estimate", "8.3f"),
           ("mark", "seconds.mark", "6.3f"), ("other", "seconds.other", "6.3f"),
           ("step", "seconds.step", "7.3f"), ("unit", "seconds.unit", "6.3f"),
           ("ratio", "ratio", "6.2f"), ("ratio fact", "ratio_factorize", "10.2f"),
           ("ratio chol", "ratio_cholesky", "10.2f"))

# the phases of a step, each read from the solution's timings (or the step record's)
SOLVER_PHASES = {"assemble": "assemble", "hybridize": "hybridize", "cholesky": "cholesky",
                 "contact": "solve", "checks": "checks"}


def step_seconds(record: dict, timings: dict, refine: float, wall: float) -> dict:
    """The phases of one step (s): the solver's ``timings``, the estimate and the marking of
    the step ``record``, the ``refine`` that made its mesh and its ``wall`` time."""
    seconds = {"refine": refine,
               **{phase: timings.get(key) for phase, key in SOLVER_PHASES.items()},
               "estimate": record["timings_s"]["estimate"], "mark": record["timings_s"]["mark"]}
    seconds["other"] = wall - sum(s for s in seconds.values() if s is not None)
    seconds["step"] = wall
    solved = "substitute" in timings
    seconds["unit_factorize"] = timings["factorize"] + timings["substitute"] if solved else None
    seconds["unit"] = timings["assemble"] + seconds["unit_factorize"] if solved else None
    seconds["unit_cholesky"] = timings["cholesky"] + timings["substitute"] if solved else None
    return seconds


def run(scene: str, overrides=(), level: int | None = None, steps: int = 8,
        theta: float = 0.5, allow_large: bool = False, on_record=None) -> dict:
    """The per-step records of ``steps`` Dörfler steps (``theta``) on ``scene`` (name or
    path, with ``overrides``) from its mesh on ``level``; ``on_record(study)`` after each.
    ``allow_large`` as for :func:`ngdual.afem.adapt`."""
    from ...afem import adapt
    from ...scene import load_scene
    from ...solution import PhysicsWarning

    study = header("adaptive", scene=scene, overrides=list(overrides), level=level,
                   steps=steps, marking="dorfler", theta=theta)
    records = study["records"]
    previous: list[dict] = []   # the last step's adapt record, whose refine follows on_step
    clock = [time.perf_counter()]

    def on_step(record, solution, estimated, marked) -> None:
        now = time.perf_counter()
        refine = previous[-1]["timings_s"]["refine"] if previous else 0.0
        seconds = step_seconds(record, solution.timings, refine, now - clock[0])
        units = {key: seconds[f"unit{suffix}"] for key, suffix in
                 (("ratio", ""), ("ratio_factorize", "_factorize"),
                  ("ratio_cholesky", "_cholesky"))}
        records.append({"scene": scene, "step": record["step"],
                        "ndof": record["dofs"]["total"], "elements": record["elements"],
                        "marked": record["marked"], "converged": record["converged"],
                        "iterations": record["iterations"], "estimator": record["estimator"],
                        "seconds": seconds, "timings_s": dict(solution.timings),
                        **{key: seconds["step"] / unit if unit else None
                           for key, unit in units.items()},
                        "warnings": warning_messages(solution)})
        previous[:] = [record]
        if on_record:
            on_record(study)
        clock[0] = time.perf_counter()

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        adapt(load_scene(scene, list(overrides)), marking="dorfler", theta=theta, steps=steps,
              level=level, on_step=on_step, allow_large=allow_large)
    return study
