"""The adaptive loop SOLVE -> ESTIMATE -> MARK -> REFINE of Section 4.2.

:func:`adapt` solves the scene on its initial mesh (:func:`ngdual.solvers.solve_on_mesh`),
computes the indicators eta_{tot,T} of (4.50) (:mod:`ngdual.estimator`), marks with one of
the strategies of :mod:`ngdual.marking`, refines the marked triangles with netgen's
bisection (plus its conforming closure) and carries the coarse boundary meshes h~, h^ over
to the new mesh, nested and with h~ ~ 2h locally
(:meth:`ngdual.boundary.BoundaryMeshes.follow`). Each step adds one plain record to the
returned history (:func:`step_record`): DOFs, the estimate and its terms, the norms of
Tables 3.2/3.3, iterations and the wall time of every phase; given the norms of the exact
solution (e.g. Aitken-extrapolated from uniform levels, :func:`reference_norms`), also the
total error (3.124) and the effectivity index estimate / e_tot (Table 4.4). Uniform
refinement is ``marking="max", theta=0``.

The loop aims at a goal (:data:`GOALS`): ``"stress"``, the thesis' (4.50), or
``"pressure"``, the contact pressure on Gamma_C (:mod:`ngdual.goal`). It runs at the order k
of the scene's ``[discretisation]``: the indicators are those of (4.50) at order k, and the
pressure goal's p_h is the trace of sigma_h with the facet multipliers. Given a tolerance
``tol`` it stops as soon as the goal's relative estimate (:func:`relative_estimate`) is
below it, ``steps`` being then only a bound; a run whose estimate stalls
(:data:`STALL_STEPS`) or whose marking reaches the smallest triangle it refines
(:data:`RESOLUTION`) stops there and says so (``stopped_by``, :class:`ToleranceWarning`).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict

import ngsolve as ngs
import numpy as np

from . import budget
from .boundary import BoundaryMeshes, nearest_vertex
from .checks import thesis_ends_outside_l2
from .estimator import ASYMMETRY_NORMS, Estimate, estimate
from .geometry import length_scale
from .goal import GOALS, goal_estimate, in_window, singular_free_ends
from .marking import STRATEGIES, mark
from .mesh import build_mesh, element_diameters, mesh_arrays
from .quantities import norms
from .rates import extrapolated_norms, total_error
from .scene import Scene, SceneError, SceneTypeError, check_level, contact_junctions, ensure_valid
from .solvers import solve_on_mesh, solve_scene
from .solvers.active_set import ContactStart
from .solvers.dispatch import with_discretisation
from .solvers.result import Solution

StepCallback = Callable[[dict, Solution, Estimate, np.ndarray | None], None]

# The thesis' marking (Section 4.2, Tables 4.1-4.4): Doerfler with theta = 0.5.
MARKING, THETA = "dorfler", 0.5
# Doerfler's theta of a tolerance-driven run. With growth g per step the loop's time to a
# target is about g / ln g times one solve of the mesh the target needs (all steps, and the
# overshoot of the last), least at g = e. theta = 0.9 grows the unknowns faster than 0.8 on
# every problem and order measured (mean growth per step 1.08-2.75 against 1.07-2.36; the
# goals whose estimate sits on a few triangles grow by 1.1-1.3x at either;
# docs/theory/estimator.md, "A goal and a tolerance").
THETA_TOL = 0.9
# The number of solves: the thesis' runs take 5; a tolerance-driven run stops by its
# tolerance (or the memory budget), and STEPS_TOL only bounds a tolerance it cannot reach.
STEPS, STEPS_TOL = 5, 30
# The initial level of a tolerance-driven run: the coarsest. On a finer start mesh the first
# steps refine a band around the singularities or Gamma_C inside a mesh already fine
# elsewhere and grow the unknowns by 1.01-1.2x (hertz-cylinder --goal pressure --tol 0.01:
# 4.6 s from level 1, 12.5 s from level 2, 11.7 s from its level 3; docs/theory/estimator.md).
LEVEL_TOL = 1
# A tolerance run stops as stalled when its goal's relative estimate has not fallen below
# its best for this many steps: the estimate is then held by triangles that refining does
# not improve (the work-precision study's runs never went more than two steps without a
# new best; the wedge's pressure goal at order 1 and 2 reaches 7.8e-4 and 6.5e-4 with
# Gamma_C edges of 2e-6 at the apex, and then rises while only the apex is refined:
# docs/theory/estimator.md, "A goal and a tolerance").
STALL_STEPS = 3
# The smallest triangle the loop refines, as a share of the scene's length scale L
# (:func:`ngdual.geometry.length_scale`): a thousand times the geometry's round-off
# (:data:`ngdual.geometry.ROUND_OFF`, below which two positions are one point), and far
# below what the studies' solutions need (their finest triangles: 1.2e-6 L, at the flat
# punch's edges). A marking that reaches below it stops the loop.
RESOLUTION = 1e-7


def loop_defaults(tol: float | None, theta: float | None, steps: int | None,
                  level: int | None = None) -> tuple[float, int, int | None]:
    """(theta, steps, level) of :func:`adapt`, the ones not given taking their defaults:
    THETA, STEPS and the scene's level (None), or with a ``tol`` THETA_TOL, STEPS_TOL and
    LEVEL_TOL."""
    theta = (THETA if tol is None else THETA_TOL) if theta is None else theta
    steps = (STEPS if tol is None else STEPS_TOL) if steps is None else steps
    level = (None if tol is None else LEVEL_TOL) if level is None else level
    return theta, steps, level


def refine(mesh: ngs.Mesh, marked: np.ndarray) -> ngs.Mesh:
    """A copy of ``mesh`` with the marked triangles refined (netgen bisection + closure).

    The copy keeps the vertex numbers (new vertices are appended), which the
    coarse boundary meshes rely on; refining a copy leaves the spaces built on
    ``mesh`` valid (NGSolve cannot update compressed spaces in place).
    """
    marked = np.asarray(marked, dtype=bool)
    if len(marked) != mesh.ne:
        raise ValueError(f"{len(marked)} marks for a mesh of {mesh.ne} elements")
    fine = ngs.Mesh(mesh.ngmesh.Copy())
    for el in fine.Elements(ngs.VOL):
        fine.SetRefinementFlag(el, bool(marked[el.nr]))
    fine.Refine()
    return fine


def refine_with_boundary(scene: Scene, mesh: ngs.Mesh, coarse: BoundaryMeshes,
                         marked: np.ndarray) -> tuple[ngs.Mesh, BoundaryMeshes]:
    """REFINE: the marked triangles of ``mesh`` refined (:func:`refine`) and the coarse
    boundary meshes h~, h^ carried over to the new mesh."""
    fine = refine(mesh, marked)
    return fine, coarse.follow(scene, fine)


def refine_towards(scene: Scene, mesh: ngs.Mesh, point, times: int
                   ) -> tuple[ngs.Mesh, BoundaryMeshes]:
    """``times`` refinements of the triangles touching the vertex nearest to ``point``, with
    the coarse boundary meshes following: a mesh graded towards ``point`` (h ratio about
    2^times). A grading that would refine a triangle smaller than :data:`RESOLUTION` times
    the scene's length scale is refused (ValueError), as the adaptive loop stops there."""
    coarse = BoundaryMeshes.for_scene(scene, mesh)
    for done in range(times):
        # the nearest vertex, not every vertex within a fixed distance of point: the graded
        # mesh's vertices come closer to it than any fixed distance
        points, triangles = mesh_arrays(mesh)
        touching = (triangles == nearest_vertex(dict(enumerate(points)), point)).any(axis=1)
        small = _below_resolution(scene, element_diameters(mesh), touching)
        if small:
            raise ValueError(f"times: refinement {done + 1} of {times} would refine triangles "
                             f"at {tuple(point)} {small}")
        mesh, coarse = refine_with_boundary(scene, mesh, coarse, touching)
    return mesh, coarse


def _below_resolution(scene: Scene, h: np.ndarray, marked: np.ndarray) -> str | None:
    """"of diameter ..., below the smallest the loop refines, ..." when a ``marked`` triangle's
    diameter ``h`` is below :data:`RESOLUTION` times the scene's length scale (else None)."""
    floor = RESOLUTION * length_scale(scene.geometry.curves())
    small = marked & (h < floor)
    if not small.any():
        return None
    return (f"of diameter {h[small].min():.2g}, below the smallest the loop refines, "
            f"{floor:.2g} ({RESOLUTION:g} of the scene's length scale)")


def adapt(scene: Scene, marking: str | None = None, theta: float | None = None,
          steps: int | None = None, level: int | None = None, asymmetry: str = "l2",
          reference: dict | None = None, on_step: StepCallback | None = None,
          allow_large: bool = False, goal: str = "stress", tol: float | None = None,
          window: tuple[float, float] | None = None, order: int | None = None,
          multipliers: str | None = None) -> list[dict]:
    """Run ``steps`` adaptive steps on ``scene`` from its mesh on ``level``, or fewer when
    the goal's relative estimate falls below ``tol``.

    Parameters
    ----------
    scene : Scene
    marking : {"max", "fraction", "dorfler"}, optional
        Marking strategy (:func:`ngdual.marking.mark`) with parameter ``theta``; default
        Doerfler.
    theta : float, optional
        Marking parameter in [0, 1]; default :data:`THETA` = 0.5 (the thesis'), with a
        ``tol`` :data:`THETA_TOL` (faster growth of the unknowns).
    steps : int, optional
        Number of SOLVE-ESTIMATE steps (``steps - 1`` refinements); default :data:`STEPS`
        = 5; with ``tol`` the largest number of steps, default :data:`STEPS_TOL` = 30.
    level : int, optional
        Level of the initial mesh; default the scene's, with ``tol`` :data:`LEVEL_TOL` = 1
        (the coarsest: the first steps are not spent on a mesh fine everywhere).
    asymmetry : {"hdiv", "l2"}
        Norm of as(sigma_h) in the estimator (see :func:`ngdual.estimator.estimate`).
    reference : dict, optional
        Norms of the exact solution (keys of :func:`ngdual.quantities.norms`); adds
        the errors of (3.124) and the effectivity index to every record.
    on_step : callable, optional
        ``on_step(record, solution, estimated, marked)`` after MARK (``estimated`` the
        :class:`~ngdual.estimator.Estimate`, ``marked`` None on the last step), before the
        mesh is refined: for output files.
    allow_large : bool
        Refine even when the next mesh's estimated memory exceeds what the machine has
        available (:mod:`ngdual.budget`; refused with a SceneError otherwise).
    goal : {"stress", "pressure"}
        What the indicators that drive MARK estimate (:data:`GOALS`): ``"stress"`` the
        error of (3.124) by (4.50), ``"pressure"`` ||p - p_h||_{L2(Gamma_C)}
        (:func:`ngdual.goal.goal_estimate`).
    tol : float, optional
        Stop after the first step whose ``relative_estimate`` (:func:`relative_estimate`)
        is at most ``tol``.
    window : (float, float), optional
        With ``goal="pressure"``: the pressure's error is that on the part of Gamma_C whose
        x lies in [lo, hi] (:func:`ngdual.goal.goal_estimate`), e.g. the core |x| < a/2 of
        a flat punch, whose pressure is not in L2 at its edges. Default: all of Gamma_C.
    order, multipliers : int, str, optional
        The order k of PEERS_k and the multiplier family in place of the scene's
        ``[discretisation]`` entries, as for :func:`ngdual.solve`
        (:func:`ngdual.solvers.dispatch.with_discretisation`).

    Returns
    -------
    list of dict
        One record per step (see :func:`step_record`), with the physics checks its
        solution fails under ``warnings`` (recorded, not issued as Python warnings), and
        ``goal``, ``goal_estimate``, ``relative_estimate`` and ``elapsed_s``, the wall time
        of SOLVE, ESTIMATE, MARK and REFINE from the start of ``adapt`` to the end of the
        step (without the time spent in ``on_step``; before ``on_step`` it holds the time
        up to MARK), and ``solved_s``, the wall time from the start to the step's solution:
        the steps before in full and this step's SOLVE (as ``timings["total"]`` of
        :func:`~ngdual.solvers.solve_scene` times one solve, from the checks of the
        arguments on, meshing included). The last record's ``stopped_by`` is ``"tol"``,
        ``"steps"``, ``"stall"`` (with ``tol``: the relative estimate has not fallen below
        its best for :data:`STALL_STEPS` steps), ``"resolution"`` (the marking reached a
        triangle smaller than :data:`RESOLUTION` times the scene's length scale) or
        ``"singular"`` (with ``tol``: the goal's error has no finite value, where p is not
        in L2 at an end of Gamma_C that the contact zone reaches or the thesis' ends leave
        sigma outside L2 (:func:`_infinite_error`), on a solve whose relative estimate is
        at most ``tol``, which then measures no error, or on :data:`STALL_STEPS` successive
        solves), the last three with a ``stop_message``; so is ``"tol"`` where the goal's
        estimate is known to be too small (the pressure goal at a kink of Gamma_C,
        :func:`_reached`), and ``"steps"`` where the goal's error is not finite (the
        message of ``"resolution"`` then says so too).

    Warns
    -----
    ToleranceWarning
        With ``tol``, when the run stops without reaching it (``"singular"`` included), or
        reaches it with an estimate known to be too small.
    """
    start = time.perf_counter()   # as solve_scene's timings["total"]: checks and mesh too
    scene = with_discretisation(scene, order, multipliers)
    _check_adapt_arguments(scene, marking, theta, steps, level, asymmetry, reference, on_step,
                           allow_large, goal, tol, window)
    marking = MARKING if marking is None else marking
    theta, steps, level = loop_defaults(tol, theta, steps, level)
    budget.check_scene(scene, level, "level", allow_large)
    mesh = build_mesh(scene.geometry, level)
    coarse = BoundaryMeshes.for_scene(scene, mesh)
    history, warm, unbounded = [], None, 0
    for step in range(steps):
        # SOLVE
        solution = solve_on_mesh(scene, mesh, coarse, start=warm)
        solved = time.perf_counter() - start
        # ESTIMATE
        estimated = estimate(solution, asymmetry)
        record = step_record(step, solution, estimated, reference)
        record["solved_s"] = solved
        indicators = _goal_indicators(record, solution, estimated, goal, window)
        history.append(record)
        infinite = _infinite_error(solution, goal, window)   # why the goal's error is not finite
        unbounded = unbounded + 1 if infinite else 0         # on so many successive solves
        # a dict with the record's stopped_by (and stop_message) once the loop ends
        stop = _tolerance_stop(scene, history, tol, goal, window, infinite, unbounded)
        # MARK
        marked = None
        if stop is None and step < steps - 1:
            with _timed(record, "mark"):
                marked = mark(indicators, theta, marking)
            stop = _unresolved(scene, solution, estimated, marked)
            if stop is None:
                record["marked"] = int(marked.sum())
            else:
                marked = None
        record["elapsed_s"] = time.perf_counter() - start
        last = marked is None
        if last:
            stop = stop or {"stopped_by": "steps"}
            if infinite and stop["stopped_by"] in ("steps", "resolution"):
                stop = {**stop, "stop_message": ": ".join(
                    filter(None, (stop.get("stop_message"), infinite)))}
            record.update(stop)
            # not reached, or reached with an estimate known to be too small (a kink)
            if tol is not None and (stop["stopped_by"] != "tol" or "stop_message" in stop):
                below = record["relative_estimate"] <= tol   # "singular", or the kink's "tol"
                warnings.warn(f"adapt: the goal's relative estimate "
                              f"{record['relative_estimate']:.3g} is "
                              + (f"below tol = {tol:g}, but " if below
                                 else f"above tol = {tol:g}: ")
                              + stop.get("stop_message", f"the {steps} steps are spent"),
                              ToleranceWarning, stacklevel=2)
        if on_step is not None:
            called = time.perf_counter()
            on_step(record, solution, estimated, marked)
            start += time.perf_counter() - called   # output files are not the loop's cost
        if last:
            break
        # REFINE
        _check_refinement_size(scene, solution, marked, allow_large)
        with _timed(record, "refine"):
            mesh, coarse = refine_with_boundary(scene, mesh, coarse, marked)
            warm = _warm_start(solution)
        record["elapsed_s"] = time.perf_counter() - start
    return history


class ToleranceWarning(UserWarning):
    """An adaptive run given a ``tol`` stopped without reaching it (its last record's
    ``stopped_by`` is ``"steps"``, ``"stall"``, ``"resolution"`` or ``"singular"``: the
    goal's error is not finite, and an estimate below tol measures none), or reached it with an
    estimate known to be too small there (``"tol"`` with a ``stop_message``:
    :func:`_reached`)."""


# The pressure goal's effectivity on the wedge, whose pressure is log-singular at the kink of
# Gamma_C: its estimate / the true error over the work-precision study's steps at orders 0-2
# (README; docs/theory/estimator.md, "A kink of Gamma_C").
KINK_EFFECTIVITY = (0.11, 0.65)


def _tolerance_stop(scene: Scene, history: list[dict], tol: float | None, goal: str,
                    window: tuple[float, float] | None, infinite: str | None,
                    unbounded: int) -> dict | None:
    """The stop of a tolerance run after the solve of ``history[-1]`` (None while it goes
    on, and without ``tol``).

    ``"singular"`` where the goal's error has no finite value (``infinite`` says why,
    :func:`_infinite_error`) on this solve and its relative estimate is at most ``tol``
    (the estimate measures no error, so no tol is reached), or on the last
    :data:`STALL_STEPS` solves (``unbounded``; refining does not make it finite, while the
    estimate may creep down for a dozen solves); ``"tol"`` at an estimate at most ``tol``
    (:func:`_reached`); ``"stall"`` (:func:`_stalled`)."""
    if tol is None:
        return None
    if infinite and (history[-1]["relative_estimate"] <= tol or unbounded >= STALL_STEPS):
        return {"stopped_by": "singular", "stop_message": infinite}
    if history[-1]["relative_estimate"] <= tol:
        return _reached(scene, goal, window)
    return _stalled(history, tol, infinite)


def _reached(scene: Scene, goal: str, window: tuple[float, float] | None) -> dict:
    """The stop of a run whose relative estimate is at most its ``tol``; with the pressure
    goal on a Gamma_C (or a ``window`` of it) that has a kink, where the estimate is too
    small by a constant (:data:`KINK_EFFECTIVITY`), with a ``stop_message`` that says so."""
    if goal != "pressure":
        return {"stopped_by": "tol"}
    kinks = np.array([point for point, kind, _ in contact_junctions(scene) if kind == "kink"],
                     dtype=float).reshape(-1, 2)
    kinks = kinks[in_window(kinks[:, 0], window)]
    if not len(kinks):
        return {"stopped_by": "tol"}
    where = _points(kinks)
    low, high = KINK_EFFECTIVITY
    return {"stopped_by": "tol",
            "stop_message": f"Gamma_C has a kink at {where}, where the pressure goal's "
                            f"estimate is too small by a constant ({low:g}-{high:g} of the "
                            f"true error on the wedge; docs/theory/estimator.md, 'A kink of "
                            f"Gamma_C'): the pressure error may be several times tol"}


def _stalled(history: list[dict], tol: float | None, reason: str | None = None
             ) -> dict | None:
    """The stop of a tolerance run whose relative estimate has not fallen below its best
    for :data:`STALL_STEPS` steps (None while it falls, and without ``tol``), with the
    ``reason`` its message gives (default: refining does not reduce it)."""
    if tol is None or len(history) <= STALL_STEPS:
        return None
    estimates = [r["relative_estimate"] for r in history]
    best = int(np.argmin(estimates[:-STALL_STEPS]))
    if min(estimates[-STALL_STEPS:]) < estimates[best]:
        return None
    if estimates[best] == float("inf"):   # the goal's size is 0 on every mesh so far
        pressure = history[-1].get("goal") == "pressure"
        size, why = (("||p_h||", "no contact where the goal measures the pressure; a window "
                                 "inside the contact zone can be measured") if pressure
                     else ("||sigma_h||", "no load"))
        return {"stopped_by": "stall",
                "stop_message": f"{size} is 0 at every step, so the estimate relative to it "
                                f"is undefined and no tol can be reached ({why})"}
    since = ", ".join(f"{e:.3g}" for e in estimates[-STALL_STEPS:])
    return {"stopped_by": "stall",
            "stop_message": f"the estimate has not fallen below its best, "
                            f"{estimates[best]:.3g} at step {best}, for {STALL_STEPS} "
                            f"steps ({since}): "
                            f"{reason or 'refining the marked triangles does not reduce it'}"}


def _infinite_error(solution: Solution, goal: str,
                    window: tuple[float, float] | None) -> str | None:
    """Why the ``goal``'s error has no finite value on the solution's scene, None where it
    has one: with the pressure goal, the contact zone reaches an end of Gamma_C where p is
    not in L2 (:func:`ngdual.goal.singular_free_ends`); with either goal, the thesis' ends
    leave sigma (and p) outside L2 at a clamped end of Gamma_C
    (:func:`ngdual.checks.thesis_ends_outside_l2`; for the pressure goal an end in its
    ``window``)."""
    if goal == "pressure":
        ends = singular_free_ends(solution, window)
        if len(ends):
            return _not_in_l2(ends)
    clamped = thesis_ends_outside_l2(solution)
    if goal == "pressure":
        clamped = clamped[in_window(clamped[:, 0], window)]
    if not len(clamped):
        return None
    ends = "end" if len(clamped) == 1 else "ends"
    return (f'contact.ends = "thesis" sets lambda = 0 at the clamped {ends} {_points(clamped)} '
            f"of Gamma_C against g - u_D.n != 0 there, so sigma is not in L2 there: the "
            f"goal's error is infinite and its estimate measures none; use contact.ends = "
            f'"consistent"' + (f" or a window away from the {ends}" if goal == "pressure"
                               else ""))


def _not_in_l2(ends: np.ndarray) -> str:
    """Why the pressure goal's error is infinite where p is not in L2 at ``ends`` of Gamma_C
    (:func:`ngdual.goal.singular_free_ends`)."""
    one = len(ends) == 1
    return (f"the contact zone reaches Gamma_C's {'end' if one else 'ends'} at {_points(ends)}, "
            f"where a free side begins, and the pressure is singular there (like d^(-1/2) at a "
            f"flat punch's edge, d the distance to the end), not in L2: its L2 error on "
            f"Gamma_C is infinite and the goal's estimate measures none; a window away from "
            f"the {'end' if one else 'ends'} has a finite one (window=(lo, hi), ngdual adapt "
            f"--window)")


def _points(points) -> str:
    """``points`` (x, y) for a stop message: "(x1, y1), (x2, y2)"."""
    return ", ".join(f"({x:.4g}, {y:.4g})" for x, y in points)


def _unresolved(scene: Scene, solution: Solution, estimated: Estimate,
                marked: np.ndarray) -> dict | None:
    """The stop of a loop whose marking reaches a triangle of diameter below
    :data:`RESOLUTION` times the scene's length scale (None otherwise)."""
    small = _below_resolution(scene, estimated.h, marked)
    if small is None:
        return None
    points, triangles = mesh_arrays(solution.problem.fes.mesh)
    smallest = np.flatnonzero(marked)[np.argmin(estimated.h[marked])]
    where = points[triangles[smallest]].mean(axis=0)
    return {"stopped_by": "resolution",
            "stop_message": f"the marking reaches triangles near {_points([where])} {small}"}


def _warm_start(solution: Solution) -> ContactStart | None:
    """The contact multipliers the next step's active-set iteration starts from (None
    without contact or for the thesis' Uzawa algorithms, which start from zero)."""
    if solution.method.startswith("active-set"):
        return ContactStart.of(solution)
    return None


def relative_estimate(record: dict) -> float:
    """The goal's estimate relative to the size of the solution it measures.

    ``"stress"``: the estimate (sum_T eta_{tot,T}^2)^{1/2} of (4.50) over ||sigma_h||_{H(div)}
    (``norms["sigma_X"]``), the leading part of the total error (3.124) that (4.50) bounds.
    ``"pressure"``: the estimate of ||p - p_h||_{L2(Gamma_C)} over ||p_h||_{L2(Gamma_C)}
    (:func:`ngdual.goal.goal_estimate`).
    A zero size gives infinity (no tol is reached: :func:`_stalled` says why), unless the
    estimate is zero too (a solution that is zero everywhere the goal measures, and
    estimated to be exact there).
    """
    size, total = record["goal_size"], record["goal_estimate"]
    if size > 0:
        return total / size
    return 0.0 if total == 0 else float("inf")


def _goal_indicators(record: dict, solution: Solution, estimated: Estimate,
                     goal: str, window: tuple[float, float] | None) -> np.ndarray:
    """The element indicators of ``goal``; adds ``goal``, ``goal_estimate``, ``goal_size``
    and ``relative_estimate`` to the step's record."""
    if goal == "stress":
        indicators, total, size = (estimated.indicators, estimated.total,
                                   record["norms"]["sigma_X"])
    else:
        with _timed(record, "goal"):
            pressure = goal_estimate(solution, estimated, window)
        indicators, total, size = pressure.indicators, pressure.total, pressure.size
        record["goal_terms"] = pressure.summed()
    record.update(goal=goal, goal_estimate=float(total), goal_size=float(size))
    record["relative_estimate"] = relative_estimate(record)
    return indicators


@contextmanager
def _timed(record: dict, phase: str) -> Iterator[None]:
    """Record the wall time of the block as ``record["timings_s"][phase]``."""
    start = time.perf_counter()
    yield
    record["timings_s"][phase] = time.perf_counter() - start


def _check_adapt_arguments(scene, marking, theta, steps, level, asymmetry, reference, on_step,
                           allow_large, goal, tol, window) -> None:
    """A SceneError (SceneTypeError for a wrong type) naming the first bad argument."""
    ensure_valid(scene)
    check_level(level, "level", optional=True)
    if not isinstance(goal, str):
        raise SceneTypeError("goal", f"must be one of {', '.join(GOALS)}, got "
                                     f"{type(goal).__name__}")
    if goal not in GOALS:
        raise SceneError("goal", f"unknown goal {goal!r}; use one of " + ", ".join(GOALS))
    if goal == "pressure" and not scene.labels("contact"):
        raise SceneError("goal", f"scene {scene.name!r} has no contact boundary: no pressure "
                                 "to aim at")
    if window is not None:
        if goal != "pressure":
            raise SceneError("window", "a window selects part of Gamma_C for the pressure "
                                       "goal; use it with goal='pressure'")
        if (not isinstance(window, (tuple, list)) or len(window) != 2
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in window)):
            raise SceneTypeError("window", f"must be two numbers (lo, hi), got {window!r}")
        if not -float("inf") < window[0] < window[1] < float("inf"):
            raise SceneError("window", f"must be finite with lo < hi, got {tuple(window)}")
    if tol is not None:
        if isinstance(tol, bool) or not isinstance(tol, (int, float)):
            raise SceneTypeError("tol", f"must be a number > 0, got {tol!r}")
        if not 0 < tol < float("inf"):
            raise SceneError("tol", f"must be a finite number > 0, got {tol!r}")
    if marking is not None and marking not in STRATEGIES:
        raise SceneError("marking", f"unknown marking {marking!r}; use one of "
                                    + ", ".join(STRATEGIES))
    if theta is not None and (isinstance(theta, bool) or not isinstance(theta, (int, float))):
        raise SceneTypeError("theta", f"must be a number in [0, 1], got {theta!r}")
    if theta is not None and not 0 <= theta <= 1:
        raise SceneError("theta", f"must lie in [0, 1], got {theta!r}")
    if steps is not None and (isinstance(steps, bool)
                              or not isinstance(steps, (int, np.integer))):
        raise SceneTypeError("steps", f"must be an integer >= 1, got {steps!r}")
    if steps is not None and steps < 1:
        raise SceneError("steps", f"must be >= 1, got {steps}")
    if asymmetry not in ASYMMETRY_NORMS:
        raise SceneError("asymmetry", f"unknown norm {asymmetry!r}; use one of "
                                      + ", ".join(ASYMMETRY_NORMS))
    if reference is not None and not isinstance(reference, dict):
        raise SceneTypeError("reference", f"must be a dict of norms, got "
                                          f"{type(reference).__name__}")
    if on_step is not None and not callable(on_step):
        raise SceneTypeError("on_step", f"must be callable, got {type(on_step).__name__}")
    if not isinstance(allow_large, bool):
        raise SceneTypeError("allow_large", f"must be True or False, got {allow_large!r}")


def _check_refinement_size(scene: Scene, solution: Solution, marked: np.ndarray,
                           allow_large: bool) -> None:
    """Refuse a refinement of the solution's mesh whose solve would not fit in memory at the
    scene's order k (bisection of the marked triangles and their closure: at most about 4
    new triangles per marked one)."""
    elements = solution.problem.fes.mesh.ne + 4.0 * int(np.sum(marked))
    disc = scene.discretisation
    need = budget.solve_memory(elements, scene.solver.method, disc.order, disc.family)
    have = budget.available_memory()
    if need > have and not allow_large:
        raise SceneError("steps", f"the next refinement would have about {elements:.3g} "
                                  f"triangles and need about {need / 2**30:.3g} GiB, more than "
                                  f"the {have / 2**30:.3g} GiB available; use fewer steps or "
                                  "pass --allow-large (allow_large=True)")


def step_record(step: int, solution: Solution, estimated: Estimate,
                reference: dict | None = None) -> dict:
    """The history entry of one adaptive step (plain JSON-serialisable data).

    ``estimator`` is the estimate (sum_T eta_{tot,T}^2)^{1/2} of (4.50);
    ``estimator_terms[k]`` is (sum_T term_k,T)^{1/2}, so ``estimator``^2 is the sum of their
    squares; ``estimator_sum`` is sum_T eta_{tot,T} (the eta_tot of Table 4.4) and
    ``estimator_max`` the largest indicator. ``norms`` are those of Tables 3.2/3.3, where
    ``eta`` is the rotation. ``warnings`` lists the physics checks the step's solution
    fails (:mod:`ngdual.checks`). With ``reference`` (the norms of the exact solution):
    ``errors``, ``e_tot`` of (3.124) and the effectivity indices ``estimator`` / e_tot and
    ``estimator_sum`` / e_tot.
    """
    pb = solution.problem
    mesh = pb.fes.mesh
    dofs = pb.spaces.dofs()
    timings = solution.timings
    record = {
        "step": step,
        "elements": mesh.ne,
        "h_min": float(estimated.h.min()),
        "h_max": float(estimated.h.max()),
        "dofs": {**dofs, "total": int(sum(dofs.values()))},
        "converged": bool(solution.converged),
        "iterations": {k: int(v) for k, v in solution.iterations.items()},
        "estimator": estimated.total,
        "estimator_sum": estimated.total_sum,
        "estimator_max": float(estimated.indicators.max()),
        "estimator_terms": {k: float(np.sqrt(v)) for k, v in estimated.summed().items()},
        "asymmetry_norm": estimated.asymmetry,
        "norms": norms(solution),
        "warnings": [asdict(w) for w in solution.warnings],
        "marked": 0,
        "timings_s": {"assemble": float(timings.get("assemble", pb.assemble_seconds)),
                      "solve": float(timings.get("factorize", 0.0) + timings.get("condense", 0.0)
                                       + timings.get("solve", 0.0)),
                      "estimate": estimated.seconds, "mark": 0.0, "refine": 0.0},
    }
    if reference is not None:
        errors, e_tot = total_error(record["norms"], reference)
        record.update(errors=errors, e_tot=e_tot,
                      effectivity=estimated.total / e_tot if e_tot > 0 else None,
                      effectivity_sum=estimated.total_sum / e_tot if e_tot > 0 else None)
    return record


def reference_norms(scene: Scene, levels: list[int]) -> dict:
    """Norms of the exact solution, Aitken-extrapolated from uniform levels (Section 3.4).

    Uses the last three of ``levels`` (at least three, consecutive uniform
    refinements); see :func:`ngdual.rates.aitken_extrapolate` for its safeguard.
    """
    ensure_valid(scene)
    if not isinstance(levels, (list, tuple)):
        raise SceneTypeError("levels", f"must be a list of levels, got {levels!r}")
    for level in levels:
        check_level(level, "levels")
    if len(levels) < 3:
        raise SceneError("levels", f"Aitken extrapolation needs at least three levels, got "
                                   f"{list(levels)}")
    return extrapolated_norms([norms(solve_scene(scene, level)) for level in levels[-3:]])
