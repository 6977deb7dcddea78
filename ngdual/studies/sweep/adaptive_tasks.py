"""The sweep tasks of an adaptive run: ``adapt`` (a run of :func:`ngdual.afem.adapt` with the
extras of Section 4.2, :func:`adapt_task`), ``peer_adapt`` (the primal peer adapting,
:func:`peer_adapt_task`) and ``paired`` (a uniform solve and an adaptive run timed in turn,
:func:`paired_task`), each returning a record and arrays."""

from __future__ import annotations

import contextlib
import warnings

import numpy as np

from .solve_tasks import load_scene_with, solve_quietly
from .timing import PAIRED_ROUNDS, REPEAT_BELOW_S, Share, median_steps

# the keyword arguments of ngdual.afem.adapt that an adaptive task carries
LOOP_KEYS = ("marking", "theta", "steps", "level", "goal", "tol", "window")
# the growth of an adaptive run's first step, before a second one measures it
ADAPTIVE_GROWTH = 2.0


def loop_arguments(params: dict) -> dict:
    """The keyword arguments of :func:`ngdual.afem.adapt` in an adaptive task's
    parameters (:data:`LOOP_KEYS`; the window, a list in JSON, as a tuple)."""
    loop = {k: params[k] for k in LOOP_KEYS}
    if "growth" in params:  # the least growth per step (ngdual.afem.adapt); else its default
        loop["growth"] = params["growth"]
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
               repeat: int = 1, share_s: float | None = None,
               growth: float | None = None) -> tuple[dict, dict]:
    """An adaptive run (:func:`ngdual.afem.adapt` with its ``goal``, ``tol`` and ``window``):
    its history, with extras for Section 4.2.

    Every step record of :func:`ngdual.afem.step_record` gets ``eta_as`` (the largest eta_{as,T}
    with as(sigma_h) in L^2 and in H(div), and the share q_as of triangles with eta_{as,T} >= 0.1
    max, Table 4.2) and ``cumulative_s``, the wall time to this step's solution (the step's
    ``solved_s``: every SOLVE, ESTIMATE, MARK and REFINE before it and its SOLVE; not the extras of
    ``on_step``). A uniform solve's time (:func:`~ngdual.studies.sweep.solve_tasks.solve_task`) is
    that of its SOLVE, without the estimate: the estimate and marks on the step's mesh, which only
    decide whether to go on, are left out here alike (loading the scene from its TOML is left out of
    both). The meshes of the steps in ``snapshots`` are kept as arrays ``points_<k>``,
    ``triangles_<k>`` and ``marked_<k>``. A ConvergenceError keeps the steps done. With
    ``samples=True`` every step's solution is kept as the arrays of
    :func:`ngdual.verification.overkill.solution_samples`, prefixed ``s<k>_``; the run stops after
    the first step whose mesh has at least ``max_elements`` triangles. With ``reference_order`` k,
    every step of at most ``reference_dofs`` unknowns is solved again by PEERS_k on its mesh
    (:func:`order_samples`, arrays ``s<k>_order_<name>``; not in ``cumulative_s``): references for
    sigma; the first that fails ends them (``reference_order_failed``).

    With ``repeat`` > 1 the loop alone (no samples, no extras) runs up to ``repeat - 1`` times more,
    each to the first step past :data:`~ngdual.studies.sweep.timing.REPEAT_BELOW_S`
    (:func:`_loop_times`); ``cumulative_runs_s`` holds every run's time to the step, and
    ``cumulative_s`` is the sum of the steps' median times (a step's time is its cumulative time
    less the step before's), so it grows with the steps as one run's does.

    With ``share_s`` the run also stops after the first step whose successor would end past
    ``share_s`` seconds of the task's wall time (:class:`~ngdual.studies.sweep.timing.Share`).
    """
    from ...afem import adapt
    from ...estimator import estimate
    from ...mesh import mesh_arrays
    from ...solution import ConvergenceError

    history, arrays = [], {}
    share = None if share_s is None else Share(share_s)
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
        if share is not None and not share.next_fits(record["dofs"]["total"], ADAPTIVE_GROWTH):
            raise _Budget

    loop = loop_arguments({"marking": marking, "theta": theta, "steps": steps, "level": level,
                           "goal": goal, "tol": tol, "window": window,
                           **({} if growth is None else {"growth": growth})})
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


def _loop_times(scene: str, overrides, loop: dict, unknowns: list[int],
                max_elements: int | None) -> list[float]:
    """The wall time from the start to every step's solution of the adaptive run ``loop``
    on ``scene`` (``solved_s``, as :func:`adapt_task` times it), up to the step of the last of
    ``unknowns``, the first step past :data:`~ngdual.studies.sweep.timing.REPEAT_BELOW_S` or the
    first of ``max_elements`` triangles; the steps from the first whose unknowns differ from
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


def peer_adapt_task(scene: str, order: int, share_s: float | None = None,
                    overrides: list[str] = (), subdivisions: int = 1,
                    max_elements: int | None = None, repeat: int = 1) -> tuple[dict, dict]:
    """The primal peer of degree ``order`` adapting on ``scene``
    (:func:`~ngdual.studies.primal_peer.adapt_primal`: Kelly's indicator, Dörfler marking,
    netgen's bisection, as a tolerance run of :func:`ngdual.adapt`) until the next step would
    end past ``share_s`` seconds of wall time (:class:`~ngdual.studies.sweep.timing.Share`),
    after the first step of ``max_elements`` triangles, or when Newton fails
    (``stopped_by``). The record's ``history`` holds per step the records of
    :func:`~ngdual.studies.primal_peer.adapt_primal` and ``cumulative_s``, its
    ``solved_s``; the arrays every step's :func:`~ngdual.studies.primal_peer.primal_samples`
    (the edges of Gamma_C split into ``subdivisions`` parts), prefixed ``s<step>_``. With
    ``repeat`` > 1 the loop alone runs again as :func:`adapt_task`'s does, and
    ``cumulative_s`` is the sum of the steps' median times."""
    from ..primal_peer import primal_samples

    sc = load_scene_with(scene, overrides)
    share = None if share_s is None else Share(share_s)
    history, arrays = [], {}

    def on_step(record, result):
        record["cumulative_s"] = record["solved_s"]
        arrays.update({f"s{record['step']}_{k}": v
                       for k, v in primal_samples(sc, result, subdivisions).items()})
        history.append(dict(record))
        if max_elements is not None and record["elements"] >= max_elements:
            raise _Budget
        if share is not None and not share.next_fits(record["ndof"], ADAPTIVE_GROWTH):
            raise _Budget

    stopped = _peer_loop(sc, order, on_step)
    if not history:
        return {"status": "failed", "message": stopped}, {}
    runs = [[r["cumulative_s"] for r in history]]
    while len(runs) < repeat and runs[0][0] < REPEAT_BELOW_S:
        runs.append(_peer_loop_times(sc, order, [r["ndof"] for r in history]))
    for r, cumulative in zip(history, median_steps(runs)):
        r["cumulative_runs_s"] = [t[r["step"]] for t in runs if len(t) > r["step"]]
        r["cumulative_s"] = cumulative
    return {"status": "ok", "scene": scene, "order": order, "history": history,
            "stopped_by": stopped}, arrays


def _peer_loop(scene, order: int, on_step) -> str:
    """Run :func:`~ngdual.studies.primal_peer.adapt_primal` with ``on_step``; what stopped
    it: "steps", "budget" (``on_step`` raised :class:`_Budget`) or Newton's failure."""
    from ..primal_peer import NewtonError, adapt_primal

    try:
        adapt_primal(scene, order, on_step=on_step)
    except _Budget:
        return "budget"
    except NewtonError as err:
        return f"Newton failed: {err}"
    return "steps"


def _peer_loop_times(scene, order: int, unknowns: list[int]) -> list[float]:
    """The wall time to every step's solution of the adaptive peer (``solved_s``) up to the
    step of the last of ``unknowns`` or the first past
    :data:`~ngdual.studies.sweep.timing.REPEAT_BELOW_S`; the steps from the first whose
    unknowns differ are left out."""
    times = []

    def on_step(record, result):
        if record["step"] >= len(unknowns) or record["ndof"] != unknowns[record["step"]]:
            raise _Budget
        times.append(record["solved_s"])
        if record["step"] == len(unknowns) - 1 or times[-1] >= REPEAT_BELOW_S:
            raise _Budget

    _peer_loop(scene, order, on_step)
    return times


def paired_task(uniform: dict, adaptive: dict, unknowns: list[int],
                rounds: int = PAIRED_ROUNDS) -> tuple[dict, dict]:
    """A uniform solve and an adaptive run to the solution of one of its steps, timed in
    turn: after one run of each (not counted), ``rounds`` rounds of one run each, uniform
    first in the odd rounds and adaptive first in the even ones, so that a slow period of
    the machine falls on both alike (the repeats of a true-error task, back to back, fall
    on one method).

    ``uniform``: the solve's ``scene``, ``level`` and ``overrides`` (timed as
    :func:`~ngdual.studies.sweep.solve_tasks.solve_task` times it); ``adaptive``: the run's
    ``scene``, ``overrides`` and the keyword arguments of :func:`ngdual.afem.adapt` (timed as
    :func:`adapt_task` times it, to the solution of the step of the last of ``unknowns``, its steps'
    unknowns: a run whose meshes differ, or that takes
    :data:`~ngdual.studies.sweep.timing.REPEAT_BELOW_S` or longer, is not counted). The record holds
    every run (``uniform_runs_s``, ``adaptive_runs_s``) and the medians ``uniform_s`` and
    ``adaptive_s``.
    """
    sc = load_scene_with(uniform["scene"], uniform["overrides"])
    loop = loop_arguments(adaptive)

    def time_adaptive() -> float | None:
        times = _loop_times(adaptive["scene"], adaptive["overrides"], loop, unknowns, None)
        return times[-1] if len(times) == len(unknowns) else None

    # one run of each first, not counted: the first solve of a process pays its one-time
    # costs (imports, NGSolve's first assembly: 1.5 s against 0.9 s on hertz-cylinder)
    solve_quietly(sc, uniform["level"])
    time_adaptive()
    runs: dict[str, list] = {"uniform": [], "adaptive": []}
    for r in range(rounds):
        for which in ("uniform", "adaptive") if r % 2 == 0 else ("adaptive", "uniform"):
            runs[which].append(solve_quietly(sc, uniform["level"]).timings["total"]
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
