"""The studies of ``ngdual figures``: named lists of sweep tasks derived from a :class:`Plan`.

A figure script declares the studies it reads (``STUDIES``); :func:`studies` lists every
one. The tasks are :class:`~ngdual.studies.sweep.Task` of the kinds of
:mod:`ngdual.studies.sweep.work`; the same solve has the same id wherever it is asked
for, so the tables and the figures share it.
"""

from __future__ import annotations

from ..cost.methods import order_method, order_overrides
from ..sweep import Task
from ..sweep.adaptive_tasks import LOOP_KEYS
from ..sweep.timing import PAIRED_ROUNDS
from ..variants import UZAWA, setting
from .plan import (
    ADAPT_STEPS,
    ADAPTIVE_RUNS,
    COARSE_ORDER_PROBLEMS,
    COARSE_ORDERS,
    GAP_CASES,
    MANUFACTURED_CASES,
    ORDERS,
    PEER_ORDERS,
    REFERENCE_ORDER,
    REFERENCE_ORDER_DOFS,
    SCENES,
    TRUTH_GOALS,
    TRUTH_PROBLEMS,
    Plan,
)

# the least growth per step of the study's adaptive runs: 1, the Doerfler sets the study was
# measured with (a tolerance run's default is ngdual.loop_defaults.GROWTH_TOL)
STUDY_GROWTH = 1.0


def _cost(level: int, friction: bool) -> float:
    return (4.0 if friction else 1.5) ** level / 50


def solve(plan: Plan, problem_or_scene: str, level: int, overrides=(), fields: bool | None = None
          ) -> Task:
    """The task solving a scene (a problem key of :data:`SCENES` or a scene name) on ``level``.

    Without overrides, the solve on :attr:`Plan.field_level` keeps the field arrays,
    so that the tables and the figures share one solve.
    """
    scene = SCENES.get(problem_or_scene, problem_or_scene)
    overrides = list(overrides)
    if fields is None:
        fields = not overrides and level == plan.field_level
    label = f"{scene} L{level}" + (" " + " ".join(overrides) if overrides else "")
    return Task("solve", {"scene": scene, "level": level, "overrides": overrides,
                          "fields": bool(fields)}, label,
                _cost(level, "frictionless" not in scene))


def _uzawa(**steps: float) -> list[str]:
    """The thesis' Uzawa iterations with the steps (rho, rho1, rho2) that differ from 1."""
    return [UZAWA, *(setting(f"solver.{k}", v) for k, v in steps.items() if v != 1.0)]


def rho_tasks(plan: Plan) -> dict[str, dict]:
    """The rho searches of the Uzawa algorithms: ``frictionless[(level, rho)]`` and
    ``coulomb[(level, rho1, rho2)]``."""
    fl = {(lv, r): solve(plan, "frictionless", lv, _uzawa(rho=r))
          for lv in plan.levels for r in plan.rho_grid}
    co = {}
    for lv in plan.levels:
        pairs = ([(r1, r2) for r1 in plan.rho1_grid for r2 in plan.rho2_grid]
                 if lv <= plan.rho_level else [(1.0, 1.0), *plan.rho_cross])
        for r1, r2 in pairs:
            co[(lv, r1, r2)] = solve(plan, "coulomb", lv, _uzawa(rho1=r1, rho2=r2))
    return {"frictionless": fl, "coulomb": co}


def gap_tasks(plan: Plan) -> dict[str, Task]:
    """Figs. 3.24-3.28: every case of :data:`GAP_CASES` with both solvers, and
    ``uzawa-gap0-eps8``: nested Uzawa with eps_2 = 1e-8 (Fig. 3.25)."""
    out = {}
    for key, (scene, overrides) in GAP_CASES.items():
        out[key] = solve(plan, scene, plan.gap_level, overrides, fields=True)
        out[f"uzawa-{key}"] = solve(plan, scene, plan.uzawa_gap_level, [UZAWA, *overrides],
                                    fields=True)
    out["uzawa-gap0-eps8"] = solve(plan, "thesis-3.46-coulomb-gap0", plan.uzawa_gap_level,
                                   [UZAWA, setting("solver.eps2", 1e-8)], fields=True)
    return out


def adaptive_task(plan: Plan, problem: str, strategy: str) -> Task:
    """An adaptive run of Section 4.2 (:data:`ADAPTIVE_RUNS`) with its snapshots."""
    marking, theta, level = ADAPTIVE_RUNS[strategy]
    refinements = {"max": plan.max_marking_refinements, "fraction": plan.fraction_refinements,
                   "dorfler": plan.dorfler_refinements}[strategy]
    snapshots = {"max": plan.max_marking_snapshots,
                 "fraction": plan.fraction_snapshots}.get(strategy, [])
    scene = SCENES[problem]
    return Task("adapt", {"scene": scene, "marking": marking, "theta": theta,
                          "steps": refinements + 1, "level": level, "overrides": [],
                          "snapshots": list(snapshots)},
                f"{scene} {marking} theta={theta}", 4.0 * refinements)


def _repeats(plan: Plan) -> dict:
    """The timed runs of a true-error task, as its parameter (none when one: the ids of
    the smoke runs' tasks stay)."""
    return {"repeat": plan.timing_repeats} if plan.timing_repeats > 1 else {}


def truth_solve(plan: Plan, problem: str, level: int, order: int = 0,
                family: str = "facet") -> Task:
    """A uniform solve of a :data:`TRUTH_PROBLEMS` scene that keeps its sample arrays, by
    PEERS_``order`` with the multipliers ``family`` (:func:`~.plan.order_overrides`)."""
    tp = TRUTH_PROBLEMS[problem]
    return Task("solve", {"scene": tp.scene, "level": level,
                          "overrides": [*tp.overrides, *order_overrides(order, family)],
                          "fields": False, "samples": True, **_repeats(plan)},
                f"{tp.scene} L{level} samples"
                + (f" k={order}" if order else "") + (" coarse" if family == "coarse" else ""),
                _cost(level + 1 + order, problem == "coulomb"))


def truth_adapt(plan: Plan, problem: str, goal: str, order: int = 0) -> Task:
    """The adaptive run of a :data:`TRUTH_PROBLEMS` scene aiming at ``goal``
    (:data:`TRUTH_GOALS`; the pressure goal on the problem's ``pressure_window``), keeping
    every step's samples: a tolerance run of :func:`ngdual.afem.adapt` (its theta and
    initial level) of PEERS_``order`` to the problem's ``reference_tol`` or the budget
    :meth:`Plan.reference_elements` (:meth:`Plan.order_elements` at order k), at most
    :data:`ADAPT_STEPS` solves; below order :data:`REFERENCE_ORDER` the stress goal's steps
    of at most :data:`REFERENCE_ORDER_DOFS` unknowns also by PEERS_k, k =
    :data:`REFERENCE_ORDER`."""
    from ...afem import THETA_TOL

    tp = TRUTH_PROBLEMS[problem]
    window = tp.pressure_window
    return Task("adapt", {"scene": tp.scene, "marking": "dorfler", "theta": THETA_TOL,
                          "steps": ADAPT_STEPS, "level": None,
                          "overrides": [*tp.overrides, *order_overrides(order)],
                          "snapshots": [], "samples": True,
                          "max_elements": (plan.order_elements(problem, order) if order
                                           else plan.reference_elements(problem)),
                          "goal": goal, "tol": tp.reference_tol,
                          "window": (list(window) if window and goal == "pressure"
                                     else None),
                          # Doerfler's own sets, as the study's runs and references were
                          # measured (session 11); a part of the task's id
                          "growth": STUDY_GROWTH,
                          **({"reference_order": REFERENCE_ORDER,
                              "reference_dofs": REFERENCE_ORDER_DOFS}
                             if goal == "stress" and order < REFERENCE_ORDER else {}),
                          **_repeats(plan)},
                f"{tp.scene} {goal} goal samples" + (f" k={order}" if order else ""),
                2.0 * plan.truth_levels(problem)[-1])


def peer_solve(plan: Plan, problem: str, level: int, order: int) -> Task:
    """The primal peer on a :data:`TRUTH_PROBLEMS` scene, its pressure samples on Gamma_C
    edges split as finely as the edges of the finest uniform level."""
    tp = TRUTH_PROBLEMS[problem]
    finest = plan.truth_levels(problem)[-1]
    return Task("peer", {"scene": tp.scene, "level": level, "order": order,
                         "overrides": list(tp.overrides),
                         "subdivisions": 2 ** max(finest - level, 0), **_repeats(plan)},
                f"{tp.scene} L{level} peer P{order}", _cost(level, False))


def peer_adapt(plan: Plan, problem: str, order: int) -> Task:
    """The primal peer of degree ``order`` adapting on a :data:`TRUTH_PROBLEMS` scene
    (Kelly's indicator, :func:`~ngdual.studies.sweep.adaptive_tasks.peer_adapt_task`) to the
    budget :meth:`Plan.reference_elements` of ngdual's adaptive runs at order 0."""
    tp = TRUTH_PROBLEMS[problem]
    return Task("peer_adapt", {"scene": tp.scene, "order": order,
                               "overrides": list(tp.overrides), "subdivisions": 4,
                               "max_elements": plan.reference_elements(problem),
                               **_repeats(plan)},
                f"{tp.scene} peer P{order} adaptive", 2.0 * plan.truth_levels(problem)[-1])


def paired_timing(plan: Plan, uniform: Task, adaptive: Task, unknowns: list[int]) -> Task:
    """The uniform solve ``uniform`` and the adaptive run ``adaptive`` to the solution of
    its step of ``unknowns[-1]`` unknowns (``unknowns``: its steps' up to that one), timed
    in turn (:func:`ngdual.studies.sweep.adaptive_tasks.paired_task`): PAIRED_ROUNDS runs of each
    where the plan times its tasks more than once, else one."""
    u, a = uniform.params, adaptive.params
    return Task("paired", {"uniform": {k: u[k] for k in ("scene", "level", "overrides")},
                           "adaptive": {"scene": a["scene"], "overrides": a["overrides"],
                                        **{k: a[k] for k in (*LOOP_KEYS, "growth")
                                           if k in a}},
                           "unknowns": [int(n) for n in unknowns],
                           "rounds": PAIRED_ROUNDS if plan.timing_repeats > 1 else 1},
                f"{u['scene']} paired: {uniform.label} / {adaptive.label} to {unknowns[-1]}",
                10.0)


def truth_tasks(plan: Plan, problem: str) -> dict[str, list[Task]]:
    """Every task of the true-error study of one problem, by method: uniform refinement
    (active set), one adaptive run per goal, at the orders :data:`~.plan.ORDERS` uniform
    refinement and both goals' runs, on the frictionless problems
    :data:`~.plan.COARSE_ORDER_PROBLEMS` uniform refinement at the orders
    :data:`~.plan.COARSE_ORDERS` with the coarse multipliers, the primal peers on the
    uniform levels and adapting (:func:`peer_adapt`)."""
    levels = plan.truth_levels(problem)
    out = {"uniform": [truth_solve(plan, problem, lv) for lv in levels]}
    for goal in TRUTH_GOALS:
        out[f"adaptive, {goal} goal"] = [truth_adapt(plan, problem, goal)]
    for order in ORDERS:
        out[order_method("uniform", order)] = [truth_solve(plan, problem, lv, order)
                                               for lv in plan.order_levels(problem, order)]
        for goal in TRUTH_GOALS:
            out[order_method(f"adaptive, {goal} goal", order)] = [
                truth_adapt(plan, problem, goal, order)]
    for order in COARSE_ORDERS if problem in COARSE_ORDER_PROBLEMS else ():
        out[order_method("uniform", order, "coarse")] = [
            truth_solve(plan, problem, lv, order, "coarse")
            for lv in plan.order_levels(problem, order)]
    for order in PEER_ORDERS:
        out[f"primal P{order}"] = [peer_solve(plan, problem, lv, order) for lv in levels]
        out[f"primal P{order}, adaptive"] = [peer_adapt(plan, problem, order)]
    return out


def manufactured_tasks(plan: Plan) -> dict[str, Task]:
    """Manufactured cases (exact errors) on uniform levels 1..K-1 and Doerfler theta = 0.5
    from level 1 (2K steps): the estimator against the truth."""
    levels = list(range(1, plan.max_level))
    out = {f"{case}, uniform L{lv}": Task("manufactured", {"case": case, "level": lv},
                                           f"manufactured {case} L{lv}", 1.5 ** lv / 20)
           for case in MANUFACTURED_CASES for lv in levels}
    for case in MANUFACTURED_CASES:
        out[f"{case}, adaptive"] = Task(
            "manufactured", {"case": case, "level": 1, "marking": "dorfler", "theta": 0.5,
                             "steps": 2 * plan.max_level}, f"manufactured {case} dorfler", 5.0)
    return out


def studies(plan: Plan) -> dict[str, list[Task]]:
    """Every study a script may declare in ``STUDIES``, as lists of tasks."""
    rho = rho_tasks(plan)
    out = {
        "dofs": [Task("dofs", {"scene": SCENES["coulomb"], "level": lv}, f"dofs L{lv}", 0.1)
                 for lv in plan.levels],
        "rho-frictionless": list(rho["frictionless"].values()),
        "rho-coulomb": list(rho["coulomb"].values()),
        "gaps": list(gap_tasks(plan).values()),
        "adaptive": [adaptive_task(plan, p, s) for p in SCENES for s in ADAPTIVE_RUNS],
    }
    for problem in SCENES:
        out[f"uniform-{problem}"] = [solve(plan, problem, lv) for lv in plan.levels]
    out["manufactured"] = list(manufactured_tasks(plan).values())
    out["truth"] = [t for problem in TRUTH_PROBLEMS
                    for ts in truth_tasks(plan, problem).values() for t in ts]
    return out
