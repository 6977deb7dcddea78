"""The sweep tasks of one solve: ``solve`` (one scene on one level, with the estimator and
optionally the field arrays or the solution samples of the true-error studies), ``dofs``
(Table 3.1), ``peer`` (the primal peer, :mod:`ngdual.studies.primal_peer`),
``manufactured`` (exact errors and the estimator) and ``uniform`` (the levels of uniform
refinement within a wall-time share), each returning a record and arrays."""

from __future__ import annotations

import warnings

import numpy as np

from .fields import field_arrays
from .timing import Share, repeated

# a uniform refinement multiplies the unknowns by about four, and the time by at least that
UNIFORM_GROWTH = 4.0
# the peer's pressure samples on a level L split every Gamma_C edge into 2^(K - L) parts,
# K = SUBDIVIDED_LEVEL (as :func:`peer_task` does with the finest level of the study)
SUBDIVIDED_LEVEL = 5


def load_scene_with(scene: str, overrides):
    """The shipped scene ``scene`` with ``overrides`` (a sweep parameter: a list)."""
    from ...scene import load_scene

    return load_scene(scene, list(overrides))


def status_of(solution) -> str:
    return "ok" if solution.converged else "not-converged"


def solve_quietly(scene, level: int):
    from ...solution import PhysicsWarning
    from ...solvers import solve_scene

    with warnings.catch_warnings():  # recorded under "warnings", not printed by a worker
        warnings.simplefilter("ignore", PhysicsWarning)
        return solve_scene(scene, level)


def solve_task(scene: str, level: int, overrides: list[str] = (), fields: bool = False,
               samples: bool = False, repeat: int = 1) -> tuple[dict, dict]:
    """Solve one scene on one level: the result record of ``ngdual solve`` (and field arrays).

    The record keeps the failed physics checks under ``warnings``, as ``result.json`` does.

    The record also holds the a posteriori estimate (4.50) of the solution under the keys of an
    adaptive step (:func:`ngdual.afem.step_record`): ``estimator`` = (sum_T eta_T^2)^(1/2),
    ``estimator_sum`` = sum_T eta_T, and ``estimator_seconds``, the time it took (not part of
    ``timings_s``, which times the solve as in ``result.json``). With ``fields=True`` the arrays
    hold what the figures of Section 3.4 plot (:func:`~ngdual.studies.sweep.fields.field_arrays`);
    with ``samples=True`` the solution as the arrays of
    :func:`ngdual.verification.overkill.solution_samples` (true errors). ``time_s`` is the median of
    ``timings_s["total"]`` over ``repeat`` solves (:func:`~ngdual.studies.sweep.timing.repeated`;
    the runs in ``time_runs_s``).
    """
    from ...estimator import estimate
    from ...post import result_record

    sc = load_scene_with(scene, overrides)
    solution = solve_quietly(sc, level)
    record = result_record(solution)
    runs = repeated(solution.timings["total"],
                    lambda: solve_quietly(sc, level).timings["total"], repeat)
    record.update(time_s=float(np.median(runs)), time_runs_s=runs)
    record["status"] = status_of(solution)
    record["ndof"] = int(sum(record["dofs"].values()))
    indicators = estimate(solution)
    record.update(estimator=indicators.total, estimator_sum=indicators.total_sum,
                  estimator_seconds=indicators.seconds)
    arrays = field_arrays(solution) if fields else {}
    if samples:
        from ...verification.overkill import solution_samples

        arrays.update(solution_samples(solution))
    return record, arrays


def dofs_task(scene: str, level: int, overrides: list[str] = ()) -> tuple[dict, dict]:
    """The DOF counts of Table 3.1 and the mesh size h on one level (no assembly)."""
    from ...forms import Spaces
    from ...mesh import build_mesh, mesh_size

    sc = load_scene_with(scene, overrides)
    mesh = build_mesh(sc.geometry, level)
    dofs = Spaces.build(sc, mesh).dofs()
    return {"status": "ok", "scene": scene, "level": level, "dofs": dofs,
            "ndof": int(sum(dofs.values())), "h": mesh_size(mesh), "elements": mesh.ne}, {}


def peer_task(scene: str, level: int, order: int, overrides: list[str] = (),
              subdivisions: int = 1, repeat: int = 1) -> tuple[dict, dict]:
    """The scene solved by the primal peer (:mod:`ngdual.studies.primal_peer`: P``order``
    displacements, Nitsche contact, semismooth Newton) on the scene's mesh of ``level``:
    DOFs, Newton steps, wall time (meshing included) and the arrays of
    :func:`~ngdual.studies.primal_peer.primal_samples` (pressure samples on Gamma_C edges
    split into ``subdivisions`` parts); ``time_s`` the median over ``repeat`` solves
    (:func:`~ngdual.studies.sweep.timing.repeated`, the runs in ``time_runs_s``)."""
    from ..primal_peer import NewtonError, primal_samples, solve_scene_primal

    sc = load_scene_with(scene, overrides)
    try:
        result, seconds = solve_scene_primal(sc, level, order)
    except NewtonError as err:
        return {"status": "failed", "message": str(err)}, {}
    record = {"status": "ok", "scene": scene, "level": level, "order": order,
              "ndof": int(result.ndof), "newton_iterations": result.newton_iterations,
              "timings_s": {**{k: float(v) for k, v in result.times.items()},
                            "total": seconds}}
    runs = repeated(seconds, lambda: solve_scene_primal(sc, level, order)[1], repeat)
    record.update(time_s=float(np.median(runs)), time_runs_s=runs)
    return record, primal_samples(sc, result, subdivisions)


def uniform_task(scene: str, share_s: float, overrides: list[str] = (),
                 peer_order: int | None = None) -> tuple[dict, dict]:
    """Uniform refinement of ``scene`` within ``share_s`` seconds of wall time: its levels
    1, 2, ... solved by ngdual (by the primal peer of degree ``peer_order``), each timed as
    :func:`solve_task` (:func:`peer_task`) times one solve, until the next level would end
    past the share (:class:`~ngdual.studies.sweep.timing.Share`), would not fit in memory
    (:func:`ngdual.budget.check_scene`) or a solve fails (``stopped_by`` of the record:
    ``"share"``, ``"memory"`` or the failure).

    The record's ``history`` holds per level ``level``, ``ndof``, ``elements`` and
    ``time_s``; the arrays every level's samples (:func:`ngdual.verification.overkill.
    solution_samples`, :func:`~ngdual.studies.primal_peer.primal_samples` with the edges of
    Gamma_C split as finely as those of level :data:`SUBDIVIDED_LEVEL`), prefixed
    ``s<level>_``."""
    from ...budget import check_scene
    from ...scene import SceneError
    from ...solution import ConvergenceError
    from ...verification.overkill import solution_samples
    from ..primal_peer import NewtonError, primal_samples, solve_scene_primal

    sc = load_scene_with(scene, overrides)
    share = Share(share_s)
    history, arrays, stopped = [], {}, "share"
    for level in range(1, 100):
        try:
            if peer_order is None:
                solution = solve_quietly(sc, level)
                seconds, mesh = solution.timings["total"], solution.problem.fes.mesh
                ndof = int(sum(solution.problem.spaces.dofs().values()))
                samples = solution_samples(solution)
            else:
                result, seconds = solve_scene_primal(sc, level, peer_order)
                mesh, ndof = result.u.space.mesh, int(result.ndof)
                samples = primal_samples(sc, result, 2 ** max(SUBDIVIDED_LEVEL - level, 0))
        except (ConvergenceError, NewtonError) as err:
            stopped = f"failed on level {level}: {err}"
            break
        history.append({"level": level, "ndof": ndof, "elements": mesh.ne, "time_s": seconds})
        arrays.update({f"s{level}_{k}": v for k, v in samples.items()})
        if not share.next_fits(ndof, UNIFORM_GROWTH):
            break
        try:
            check_scene(sc, level + 1)
        except SceneError:
            stopped = "memory"
            break
    if not history:
        return {"status": "failed", "message": stopped}, {}
    return {"status": "ok", "scene": scene, "peer_order": peer_order, "history": history,
            "stopped_by": stopped}, arrays


def manufactured_task(case: str, level: int, marking: str | None = None, theta: float = 0.5,
                      steps: int = 1) -> tuple[dict, dict]:
    """A manufactured case (:mod:`ngdual.verification.manufactured`) on uniform ``level``
    (``marking=None``) or adaptively from it: per step the DOFs, the estimator of (4.50)
    and the exact errors (:func:`~ngdual.verification.manufactured_errors.volume_errors`)."""
    from ...afem import adapt
    from ...verification.manufactured import manufactured_case
    from ...verification.manufactured_errors import volume_errors

    mc = manufactured_case(case)
    history = []

    def on_step(record, solution, indicators, marked):
        history.append({"step": record["step"], "ndof": record["dofs"]["total"],
                        "elements": record["elements"], "estimator": record["estimator"],
                        "converged": record["converged"], "warnings": record["warnings"],
                        "errors": volume_errors(mc, solution)})

    adapt(mc.scene(), marking or "max", theta if marking else 0.0,
          steps if marking else 1, level, on_step=on_step)
    return {"status": "ok" if all(r["converged"] for r in history) else "not-converged",
            "case": case, "history": history}, {}
