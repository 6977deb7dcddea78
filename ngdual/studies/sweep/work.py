"""The work of a sweep task: the functions of :data:`TASKS`, each returning a record and arrays.

``solve`` (one scene on one level, with the estimator and optionally the field arrays or
the solution samples of the true-error studies), ``dofs`` (Table 3.1), ``adapt`` (an
adaptive run with the extras of Section 4.2), ``peer`` (the primal peer,
:mod:`ngdual.studies.primal_peer`), ``manufactured`` (exact errors and the estimator) and
``paired`` (a uniform solve and an adaptive run timed in turn).
:func:`execute` runs one task and adds the header every record carries; writing it is
:mod:`~ngdual.studies.sweep.records`' business, scheduling :mod:`~ngdual.studies.sweep.runner`'s.
"""

from __future__ import annotations

import contextlib
import os
import platform
import socket
import time
import traceback
import warnings
from collections.abc import Callable

import numpy as np

from ...io import versions
from .fields import field_arrays
from .records import Task

# The true-error tasks time ``repeat`` runs and record the median: a wall time of a fraction
# of a second varies by about 10 % from run to run with the machine's load, enough to decide
# which of two methods reaches an accuracy first (the work-precision study's verdicts). The
# runs after the first are made only while a run takes less than REPEAT_BELOW_S: longer ones
# vary less and cost more.
REPEAT_BELOW_S = 5.0
# The work-precision study times its close verdicts again, uniform and adaptive in turn
# (:func:`paired_task`): this many runs of each.
PAIRED_ROUNDS = 7


def repeated(first: float, again: Callable[[], float], repeat: int) -> list[float]:
    """``first`` and the wall times of further runs ``again()``, up to ``repeat`` in all,
    while the last one took less than :data:`REPEAT_BELOW_S`.

    >>> repeated(0.3, lambda: 0.2, 3), repeated(6.0, lambda: 0.2, 3)
    ([0.3, 0.2, 0.2], [6.0])
    """
    times = [float(first)]
    while len(times) < repeat and times[-1] < REPEAT_BELOW_S:
        times.append(float(again()))
    return times


def load_scene_with(scene: str, overrides):
    """The shipped scene ``scene`` with ``overrides`` (a sweep parameter: a list)."""
    from ...scene import load_scene

    return load_scene(scene, list(overrides))


def _status_of(solution) -> str:
    return "ok" if solution.converged else "not-converged"


def _solve_quietly(scene, level: int):
    from ...solution import PhysicsWarning
    from ...solvers import solve_scene

    with warnings.catch_warnings():  # recorded under "warnings", not printed by a worker
        warnings.simplefilter("ignore", PhysicsWarning)
        return solve_scene(scene, level)


def solve_task(scene: str, level: int, overrides: list[str] = (), fields: bool = False,
               samples: bool = False, repeat: int = 1) -> tuple[dict, dict]:
    """Solve one scene on one level: the result record of ``ngdual solve`` (and field arrays).

    The record keeps the failed physics checks under ``warnings``, as ``result.json`` does.

    The record also holds the a posteriori estimate (4.50) of the solution under the keys of
    an adaptive step (:func:`ngdual.afem.step_record`): ``estimator`` = (sum_T eta_T^2)^(1/2),
    ``estimator_sum`` = sum_T eta_T, and ``estimator_seconds``, the time it took (not part
    of ``timings_s``, which times the solve as in ``result.json``). With ``fields=True`` the
    arrays hold what the figures of Section 3.4 plot (:func:`field_arrays`); with
    ``samples=True`` the solution as the arrays of
    :func:`ngdual.verification.overkill.solution_samples` (true errors). ``time_s`` is the
    median of ``timings_s["total"]`` over ``repeat`` solves (:func:`repeated`; the runs in
    ``time_runs_s``).
    """
    from ...estimator import estimate
    from ...post import result_record

    sc = load_scene_with(scene, overrides)
    solution = _solve_quietly(sc, level)
    record = result_record(solution)
    runs = repeated(solution.timings["total"],
                    lambda: _solve_quietly(sc, level).timings["total"], repeat)
    record.update(time_s=float(np.median(runs)), time_runs_s=runs)
    record["status"] = _status_of(solution)
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


# the keyword arguments of ngdual.afem.adapt that an adaptive task carries
LOOP_KEYS = ("marking", "theta", "steps", "level", "goal", "tol", "window")


def loop_arguments(params: dict) -> dict:
    """The keyword arguments of :func:`ngdual.afem.adapt` in an adaptive task's
    parameters (:data:`LOOP_KEYS`; the window, a list in JSON, as a tuple)."""
    loop = {k: params[k] for k in LOOP_KEYS}
    if loop["window"] is not None:
        loop["window"] = tuple(loop["window"])
    return loop


class _Budget(Exception):
    """An adaptive run reached its element budget."""


def adapt_task(scene: str, marking: str, theta: float, steps: int, level: int,
               overrides: list[str] = (), snapshots: list[int] = (), samples: bool = False,
               max_elements: int | None = None, goal: str = "stress",
               tol: float | None = None, window: list[float] | None = None,
               reference_order: int | None = None, reference_dofs: int = 0,
               repeat: int = 1) -> tuple[dict, dict]:
    """An adaptive run (:func:`ngdual.afem.adapt` with its ``goal``, ``tol`` and ``window``):
    its history, with extras for Section 4.2.

    Every step record of :func:`ngdual.afem.step_record` gets ``eta_as`` (the
    largest eta_{as,T} with as(sigma_h) in L^2 and in H(div), and the share
    q_as of triangles with eta_{as,T} >= 0.1 max, Table 4.2) and ``cumulative_s``, the
    wall time to this step's solution (the step's ``solved_s``: every SOLVE, ESTIMATE, MARK
    and REFINE before it and its SOLVE; not the extras of ``on_step``). A uniform solve's
    time (:func:`solve_task`) is that of its SOLVE, without the estimate: the estimate and
    marks on the step's mesh, which only decide whether to go on, are left out here alike
    (loading the scene from its TOML is left out of both). The
    meshes of the steps in ``snapshots`` are kept as arrays ``points_<k>``,
    ``triangles_<k>`` and ``marked_<k>``. A ConvergenceError keeps the steps done.
    With ``samples=True`` every step's solution is kept as the arrays of
    :func:`ngdual.verification.overkill.solution_samples`, prefixed ``s<k>_``; the run stops
    after the first step whose mesh has at least ``max_elements`` triangles. With
    ``reference_order`` k, every step of at most ``reference_dofs`` unknowns is solved again
    by PEERS_k on its mesh (:func:`order_samples`, arrays ``s<k>_order_<name>``; not in
    ``cumulative_s``): references for sigma; the first that fails ends them
    (``reference_order_failed``).

    With ``repeat`` > 1 the loop alone (no samples, no extras) runs up to ``repeat - 1``
    times more, each to the first step past :data:`REPEAT_BELOW_S` (:func:`_loop_times`);
    ``cumulative_runs_s`` holds every run's time to the step, and ``cumulative_s`` is the
    sum of the steps' median times (a step's time is its cumulative time less the step
    before's), so it grows with the steps as one run's does.
    """
    from ...afem import adapt
    from ...estimator import estimate
    from ...mesh import mesh_arrays
    from ...solution import ConvergenceError

    history, arrays = [], {}
    run = {"scene": scene, "marking": marking, "theta": theta, "steps": steps, "level": level,
           "overrides": list(overrides), "goal": goal, "tol": tol, "window": window,
           "reference_order": reference_order}

    def on_step(record, solution, indicators, marked):
        record["cumulative_s"] = record["solved_s"]
        hdiv = estimate(solution, "hdiv")
        record["eta_as"] = {}
        for norm, est in (("l2", indicators), ("hdiv", hdiv)):
            eta_as = np.sqrt(est.terms["asymmetry"])
            record["eta_as"][norm] = {"max": float(eta_as.max()),
                                      "q": float(np.mean(eta_as >= 0.1 * eta_as.max()))}
        k = record["step"]
        if k in snapshots:
            mesh = solution.problem.fes.mesh
            arrays[f"points_{k}"], arrays[f"triangles_{k}"] = mesh_arrays(mesh)
            arrays[f"marked_{k}"] = (np.zeros(mesh.ne, bool) if marked is None
                                     else np.asarray(marked, bool))
        if samples:
            from ...verification.overkill import solution_samples

            arrays.update({f"s{k}_{n}": v for n, v in solution_samples(solution).items()})
            if (reference_order and record["dofs"]["total"] <= reference_dofs
                    and "reference_order_failed" not in run):
                try:
                    arrays.update({f"s{k}_order_{n}": v for n, v
                                   in order_samples(solution, reference_order).items()})
                except ConvergenceError as err:   # no reference from here on; k = 0 stays
                    run["reference_order_failed"] = f"step {k}: {err}"
        history.append(dict(record))
        if max_elements is not None and record["elements"] >= max_elements:
            raise _Budget

    loop = loop_arguments({"marking": marking, "theta": theta, "steps": steps, "level": level,
                           "goal": goal, "tol": tol, "window": window})
    try:
        with _tolerance_kept_quiet():
            adapt(load_scene_with(scene, overrides), on_step=on_step, **loop)
        status = "ok" if all(r["converged"] for r in history) else "not-converged"
    except ConvergenceError as err:
        run.update(message=str(err))
        status = "failed"
    except _Budget:
        status = "ok" if all(r["converged"] for r in history) else "not-converged"
    runs = [[r["cumulative_s"] for r in history]]
    # (a rerun may keep no step: one whose first mesh differs, or that fails)
    while len(runs) < repeat and history and runs[0][0] < REPEAT_BELOW_S:
        runs.append(_loop_times(scene, overrides, loop, [r["dofs"]["total"] for r in history],
                                max_elements))
    for r, cumulative in zip(history, median_steps(runs)):
        r["cumulative_runs_s"] = [t[r["step"]] for t in runs if len(t) > r["step"]]
        r["cumulative_s"] = cumulative
    run.update(status=status, history=history)
    return run, arrays


def median_steps(runs: list[list[float]]) -> list[float]:
    """The cumulative times of a loop whose steps take the median of their times in
    ``runs`` (each run's cumulative time per step; a run may stop early): nondecreasing as
    every run's are.

    >>> median_steps([[1.0, 3.0, 7.0], [2.0, 3.0], [1.0, 4.0]])
    [1.0, 3.0, 7.0]
    """
    steps = [np.diff(t, prepend=0.0) for t in runs]
    return np.cumsum([np.median([d[j] for d in steps if len(d) > j])
                      for j in range(len(runs[0]))]).tolist()


def _loop_times(scene: str, overrides, loop: dict, unknowns: list[int],
                max_elements: int | None) -> list[float]:
    """The wall time from the start to every step's solution of the adaptive run ``loop``
    on ``scene`` (``solved_s``, as :func:`adapt_task` times it), up to the step of the
    last of ``unknowns``, the first step past :data:`REPEAT_BELOW_S` or the first of
    ``max_elements`` triangles; the steps from the first whose unknowns differ from
    ``unknowns`` (another mesh: a tie in the marking broken otherwise) are left out."""
    from ...afem import adapt
    from ...solution import ConvergenceError

    times = []

    def on_step(record, solution, indicators, marked):
        times.append(record["solved_s"])
        step = record["step"]
        if step >= len(unknowns) or record["dofs"]["total"] != unknowns[step]:
            times.pop()
            raise _Budget
        if (step == len(unknowns) - 1 or times[-1] >= REPEAT_BELOW_S
                or (max_elements is not None and record["elements"] >= max_elements)):
            raise _Budget

    try:
        with _tolerance_kept_quiet():
            adapt(load_scene_with(scene, overrides), on_step=on_step, **loop)
    except (ConvergenceError, _Budget):
        pass
    return times


@contextlib.contextmanager
def _tolerance_kept_quiet():
    """A run that stops short of its tol, or reaches it with an estimate known to be too
    small, says so in its last record (``stopped_by``, ``stop_message``); a worker does not
    print it as well (:class:`ngdual.afem.ToleranceWarning`)."""
    from ...afem import ToleranceWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ToleranceWarning)
        yield


def paired_task(uniform: dict, adaptive: dict, unknowns: list[int],
                rounds: int = PAIRED_ROUNDS) -> tuple[dict, dict]:
    """A uniform solve and an adaptive run to the solution of one of its steps, timed in
    turn: after one run of each (not counted), ``rounds`` rounds of one run each, uniform
    first in the odd rounds and adaptive first in the even ones, so that a slow period of
    the machine falls on both alike (the repeats of a true-error task, back to back, fall
    on one method).

    ``uniform``: the solve's ``scene``, ``level`` and ``overrides`` (timed as
    :func:`solve_task` times it); ``adaptive``: the run's ``scene``, ``overrides`` and the
    keyword arguments of :func:`ngdual.afem.adapt` (timed as :func:`adapt_task` times it,
    to the solution of the step of the last of ``unknowns``, its steps' unknowns: a run
    whose meshes differ, or that takes :data:`REPEAT_BELOW_S` or longer, is not counted).
    The record holds every run (``uniform_runs_s``, ``adaptive_runs_s``) and the medians
    ``uniform_s`` and ``adaptive_s``.
    """
    sc = load_scene_with(uniform["scene"], uniform["overrides"])
    loop = loop_arguments(adaptive)

    def time_adaptive() -> float | None:
        times = _loop_times(adaptive["scene"], adaptive["overrides"], loop, unknowns, None)
        return times[-1] if len(times) == len(unknowns) else None

    # one run of each first, not counted: the first solve of a process pays its one-time
    # costs (imports, NGSolve's first assembly: 1.5 s against 0.9 s on hertz-cylinder)
    _solve_quietly(sc, uniform["level"])
    time_adaptive()
    runs: dict[str, list] = {"uniform": [], "adaptive": []}
    for r in range(rounds):
        for which in ("uniform", "adaptive") if r % 2 == 0 else ("adaptive", "uniform"):
            runs[which].append(_solve_quietly(sc, uniform["level"]).timings["total"]
                               if which == "uniform" else time_adaptive())
    counted = [t for t in runs["adaptive"] if t is not None]
    if not counted:
        return {"status": "failed", "message": "no adaptive run reached the step's mesh "
                "below the repeat limit"}, {}
    return {"status": "ok", "uniform_runs_s": runs["uniform"], "adaptive_runs_s": runs["adaptive"],
            "uniform_s": float(np.median(runs["uniform"])),
            "adaptive_s": float(np.median(counted))}, {}


def order_samples(solution, order: int) -> dict:
    """sigma, u and eta of PEERS_``order`` on the mesh of ``solution`` (a discrete solution
    of its scene), as the element samples of
    :func:`ngdual.verification.overkill.element_samples`, and ``ndof``, its unknowns."""
    from ...quantities import fields
    from ...solvers.dispatch import solve_on_mesh, with_discretisation
    from ...verification.overkill import element_samples

    pb = solution.problem
    finer = solve_on_mesh(with_discretisation(pb.scene, order=order), pb.fes.mesh)
    f = fields(finer)
    out = element_samples(pb.fes.mesh, {"sigma": f.sigma, "u": f.u, "eta": f.eta})
    return {"sigma": out["sigma"], "u": out["u"], "eta": out["eta"],
            "ndof": np.array(finer.problem.fes.ndof)}


def peer_task(scene: str, level: int, order: int, overrides: list[str] = (),
              subdivisions: int = 1, repeat: int = 1) -> tuple[dict, dict]:
    """The scene solved by the primal peer (:mod:`ngdual.studies.primal_peer`: P``order``
    displacements, Nitsche contact, semismooth Newton) on the scene's mesh of ``level``:
    DOFs, Newton steps, wall time (meshing included) and the arrays of
    :func:`~ngdual.studies.primal_peer.primal_samples` (pressure samples on Gamma_C edges
    split into ``subdivisions`` parts); ``time_s`` the median over ``repeat`` solves
    (:func:`repeated`, the runs in ``time_runs_s``)."""
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


TASKS: dict[str, Callable[..., tuple[dict, dict]]] = {
    "solve": solve_task, "dofs": dofs_task, "adapt": adapt_task, "peer": peer_task,
    "manufactured": manufactured_task, "paired": paired_task}


def _ngsolve_threads() -> int:
    """The threads of NGSolve's task manager (``ngsolve.GetNumThreads`` counts them only
    inside one)."""
    import ngsolve as ngs

    with ngs.TaskManager():
        return ngs.GetNumThreads()


@contextlib.contextmanager
def one_thread():
    """NGSolve's task manager and every BLAS on one thread inside (restored on exit); yields
    the threads NGSolve's task manager then has.

    One task per core, so that the wall times of the methods compare: with NGSolve's
    default (every core) the PEERS assembly of a mesh of 8 192 triangles or more
    (:data:`ngdual.forms.PARALLEL_ELEMENTS`) took the second core of a one-worker study,
    while the primal peer and the small meshes of an adaptive run assemble on one; BLAS on
    one thread for the reason of :data:`ngdual.tolerances.BLAS_THREADS`.
    """
    import ngsolve as ngs
    from threadpoolctl import threadpool_limits

    from ...tolerances import BLAS_THREADS

    before = _ngsolve_threads()
    ngs.SetNumThreads(1)
    try:
        with threadpool_limits(limits=BLAS_THREADS):
            yield _ngsolve_threads()
    finally:
        ngs.SetNumThreads(before)


def execute(task: Task) -> tuple[dict, dict]:
    """Compute ``task`` (no files) on one thread (:func:`one_thread`): its record and
    arrays, failures included; the record's ``threads`` are NGSolve's during the task."""
    from ...solution import ConvergenceError

    started = time.time()
    start = time.perf_counter()
    arrays: dict = {}
    threads = None
    try:
        with one_thread() as threads:
            record, arrays = TASKS[task.kind](**task.params)
    except ConvergenceError as err:
        record = {"status": "failed", "message": str(err), "history_length": len(err.history)}
    except Exception as err:  # noqa: BLE001 - a sweep never dies of one task
        record = {"status": "error", "message": f"{type(err).__name__}: {err}",
                  "traceback": traceback.format_exc()}
    header = {"id": task.id, "kind": task.kind, "params": task.params, "label": task.label,
              "started": started, "wall_s": time.perf_counter() - start,
              "host": socket.gethostname(), "pid": os.getpid(), "threads": threads,
              "load_average": list(os.getloadavg()),  # at the end: wall times depend on it
              "python": platform.python_version(), "arrays": sorted(arrays),
              "versions": versions()}
    return {**header, **record, "status": record.get("status", "ok")}, arrays
