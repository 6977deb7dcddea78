"""The adaptive loop SOLVE -> ESTIMATE -> MARK -> REFINE of Section 4.2: :func:`adapt`.

The loop's body is the four steps; :class:`_Run` keeps its history, its clock and its stop
rules (:class:`~ngdual.afem.stops.StopRules`), and calls ``on_step``.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import ngsolve as ngs
import numpy as np

from .. import budget
from ..boundary import BoundaryMeshes
from ..estimator import Estimate, estimate
from ..goal import Goal, goal_for
from ..loop_defaults import (
    GROWTH,
    GROWTH_TOL,
    LEVEL_TOL,
    MARKING,
    STEPS,
    STEPS_TOL,
    THETA,
    THETA_TOL,
)
from ..marking import mark
from ..mesh import build_mesh
from ..scene import Scene
from ..solution import Solution
from ..solvers import solve_on_mesh
from ..solvers.dispatch import with_discretisation
from ..solvers.start import ContactStart
from .arguments import check_adapt_arguments
from .records import relative_estimate, step_record
from .refinement import refine_with_boundary
from .stops import Stop, StopRules, out_of_memory

StepCallback = Callable[[dict, Solution, Estimate, np.ndarray | None], None]

def loop_defaults(tol: float | None, theta: float | None, steps: int | None,
                  level: int | None = None) -> tuple[float, int, int | None]:
    """(theta, steps, level) of :func:`adapt`, the ones not given taking their defaults:
    THETA, STEPS and the scene's level (None), or with a ``tol`` THETA_TOL, STEPS_TOL and
    LEVEL_TOL."""
    theta = (THETA if tol is None else THETA_TOL) if theta is None else theta
    steps = (STEPS if tol is None else STEPS_TOL) if steps is None else steps
    level = (None if tol is None else LEVEL_TOL) if level is None else level
    return theta, steps, level


def growth_default(tol: float | None, growth: float | None) -> float:
    """The least growth of the unknowns per step of :func:`adapt`, ``growth`` unless None:
    GROWTH (none, the thesis' runs) or with a ``tol`` GROWTH_TOL."""
    if growth is not None:
        return growth
    return GROWTH if tol is None else GROWTH_TOL


def adapt(scene: Scene, marking: str | None = None, theta: float | None = None,
          steps: int | None = None, level: int | None = None, asymmetry: str = "l2",
          reference: dict | None = None, on_step: StepCallback | None = None,
          allow_large: bool = False, goal: str = "stress", tol: float | None = None,
          window: tuple[float, float] | None = None, order: int | None = None,
          multipliers: str | None = None, growth: float | None = None) -> list[dict]:
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
    growth : float, optional
        The least factor in [1, 4] by which REFINE multiplies the triangles (and about the
        unknowns): above 1 it refines the marked triangles, then the triangles at the peaks
        of their estimate, once and again until the mesh has grown by ``growth``
        (:func:`ngdual.afem.refinement.refine_graded`). Default :data:`GROWTH` = 1 (the
        marked triangles alone, as in the thesis), with a ``tol`` :data:`GROWTH_TOL` = 1.5
        (a step that grows the unknowns little costs almost as much as one that grows them
        much).
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
        available (:mod:`ngdual.budget`; otherwise the loop stops before that refinement,
        ``stopped_by = "memory"``).
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
        arguments on, meshing included). The last record's ``stopped_by`` names the stop
        rule that ended the loop (:mod:`ngdual.afem.stops`): ``"tol"``, ``"steps"``,
        ``"stall"`` (with ``tol``: the relative estimate has not fallen below its best for
        :data:`~ngdual.afem.stops.STALL_STEPS` steps), ``"resolution"`` (the marking
        reached a triangle smaller than :data:`~ngdual.afem.refinement.RESOLUTION` times
        the scene's length scale), ``"singular"`` (with ``tol``: the goal's error has no
        finite value, where p is not in L2 at an end of Gamma_C that the contact zone
        reaches or the thesis' ends leave sigma outside L2
        (:meth:`ngdual.goal.Goal.infinite_error`), on a solve whose relative estimate is at
        most ``tol``, which then measures no error, or on STALL_STEPS successive solves),
        ``"no_contact"`` (the pressure goal's window holds no contact, on the first solve)
        or ``"memory"`` (the next refinement would not fit in memory, or a solve ran out of
        it), all but the first two with a ``stop_message``; so is ``"tol"`` where the
        goal's estimate is known to be too small (the pressure goal at a kink of Gamma_C,
        :meth:`ngdual.goal.Goal.caution`), and ``"steps"`` where the goal's error is not
        finite (the messages of ``"resolution"`` and ``"memory"`` then say so too).

    Raises
    ------
    MemoryError
        When the solve on the initial mesh runs out of memory (a later solve that does ends
        the loop, ``stopped_by = "memory"``).

    Warns
    -----
    ToleranceWarning
        With ``tol``, when the run stops without reaching it (``"singular"`` included), or
        reaches it with an estimate known to be too small.
    AdaptWarning
        Without ``tol``, when a window without contact or the memory ends the run before
        its steps are spent.
    """
    start = time.perf_counter()   # as solve_scene's timings["total"]: checks and mesh too
    scene = with_discretisation(scene, order, multipliers)
    check_adapt_arguments(scene, marking, theta, steps, level, asymmetry, reference, on_step,
                          allow_large, goal, tol, window, growth)
    marking = MARKING if marking is None else marking
    theta, steps, level = loop_defaults(tol, theta, steps, level)
    growth = growth_default(tol, growth)
    budget.check_scene(scene, level, "level", allow_large)
    run = _Run(StopRules(scene, goal_for(goal, window), tol, steps, allow_large, growth), tol,
               steps, reference, on_step, start)
    mesh = build_mesh(scene.geometry, level)
    coarse, warm = BoundaryMeshes.for_scene(scene, mesh), None
    for _ in range(steps):
        # SOLVE
        try:
            solution = solve_on_mesh(scene, mesh, coarse, start=warm)
        except MemoryError:
            run.out_of_memory(mesh)   # the last record says so (raised on the first solve)
            break
        solved = run.elapsed()
        # ESTIMATE
        estimated = estimate(solution, asymmetry)
        indicators = run.measure(solution, estimated, solved)
        # MARK, unless a stop rule ends the loop (the last record then says why)
        marked = run.mark(indicators, theta, marking)
        if marked is None:
            break
        # REFINE
        with run.timed("refine"):
            mesh, coarse = refine_with_boundary(scene, mesh, coarse, marked, indicators,
                                                growth)
            warm = _warm_start(solution)
    return run.history


class AdaptWarning(UserWarning):
    """An adaptive run ended before its steps were spent for a reason its caller should
    hear of: a pressure goal's window without contact (``"no_contact"``) or the memory
    (``"memory"``)."""


class ToleranceWarning(AdaptWarning):
    """An adaptive run given a ``tol`` stopped without reaching it (its last record's
    ``stopped_by`` is neither ``"tol"`` nor, without a message, anything else: ``"steps"``,
    ``"stall"``, ``"resolution"``, ``"memory"``, ``"no_contact"`` or ``"singular"``, where
    the goal's error is not finite and an estimate below tol measures none), or reached it
    with an estimate known to be too small there (``"tol"`` with a ``stop_message``:
    :meth:`ngdual.goal.Goal.caution`)."""


class _Run:
    """The bookkeeping of one run of :func:`adapt`: its history, its clock (the wall time
    from ``start``, less the time spent in ``on_step``: output files are not the loop's
    cost), its stop rules and the warnings of its end."""

    def __init__(self, rules: StopRules, tol: float | None, steps: int,
                 reference: dict | None, on_step: StepCallback | None, start: float):
        self.rules, self.tol, self.steps = rules, tol, steps
        self.reference, self.on_step, self.start = reference, on_step, start
        self.history: list[dict] = []

    @property
    def goal(self) -> Goal:
        return self.rules.goal

    def elapsed(self) -> float:
        return time.perf_counter() - self.start

    def measure(self, solution: Solution, estimated: Estimate, solved: float) -> np.ndarray:
        """The step's record (:func:`~ngdual.afem.records.step_record`, with ``solved_s``,
        ``goal``, ``goal_estimate``, ``goal_size``, ``relative_estimate`` and the goal's
        ``goal_terms``) appended to the history; returns the goal's indicators."""
        record = step_record(len(self.history), solution, estimated, self.reference)
        record["solved_s"] = solved
        measured = self.goal.measure(solution, estimated, record["norms"])
        if measured.seconds is not None:   # the goal's own indicators
            record["timings_s"]["goal"] = measured.seconds
            record["goal_terms"] = measured.terms
        record.update(goal=self.goal.name, goal_estimate=float(measured.total),
                      goal_size=float(measured.size))
        record["relative_estimate"] = relative_estimate(record)
        self.history.append(record)
        self.step, self.stop = self.rules.after_estimate(self.history, solution, estimated,
                                                        measured)
        return measured.indicators

    def mark(self, indicators: np.ndarray, theta: float, marking: str) -> np.ndarray | None:
        """MARK (:func:`ngdual.mark`) unless a stop rule ends the loop before or after it
        (then None, and the last record says why); ``on_step`` sees the marks."""
        record, stop, marked = self.history[-1], self.stop, None
        if stop is None:
            with _timed(record, "mark"):
                marked = mark(indicators, theta, marking)
            stop = self.rules.after_mark(self.step, marked)
            if stop is None:
                record["marked"] = int(marked.sum())
            else:
                marked = None
        record["elapsed_s"] = self.elapsed()
        if stop is not None:
            self._end(StopRules.finish(stop, self.step))
        if self.on_step is not None:
            called = time.perf_counter()
            self.on_step(record, self.step.solution, self.step.estimated, marked)
            self.start += time.perf_counter() - called
        return marked

    def out_of_memory(self, mesh: ngs.Mesh) -> None:
        """End the loop whose solve on ``mesh`` ran out of memory: the last record says so
        (:func:`~ngdual.afem.stops.out_of_memory`); on the first solve, raise it again."""
        if not self.history:
            raise   # the MemoryError that adapt's handler caught
        self._end(out_of_memory(self.history, mesh.ne, self.tol, self.steps))

    @contextmanager
    def timed(self, phase: str) -> Iterator[None]:
        """Time the block into the last record's ``timings_s[phase]`` and ``elapsed_s``."""
        with _timed(self.history[-1], phase):
            yield
        self.history[-1]["elapsed_s"] = self.elapsed()

    def _end(self, stop: Stop) -> None:
        """The last record's ``stopped_by`` (and ``stop_message``), and the warning a run
        with a tol it did not reach, or one ended early, gives."""
        record = self.history[-1]
        record.update(stop.record())
        relative, tol = record["relative_estimate"], self.tol
        if tol is not None and (stop.stopped_by != "tol" or stop.message):
            warnings.warn(f"adapt: the goal's relative estimate {relative:.3g} is "
                          + (f"below tol = {tol:g}, but " if relative <= tol
                             else f"above tol = {tol:g}: ")
                          + (stop.message or f"the {self.steps} steps are spent"),
                          ToleranceWarning, stacklevel=4)
        elif tol is None and stop.early:
            warnings.warn(f"adapt: {stop.message}", AdaptWarning, stacklevel=4)


def _warm_start(solution: Solution) -> ContactStart | None:
    """The contact multipliers the next step's active-set iteration starts from (None
    without contact or for the thesis' Uzawa algorithms, which start from zero)."""
    if solution.method.startswith("active-set"):
        return ContactStart.of(solution)
    return None


@contextmanager
def _timed(record: dict, phase: str) -> Iterator[None]:
    """Record the wall time of the block as ``record["timings_s"][phase]``."""
    start = time.perf_counter()
    yield
    record["timings_s"][phase] = time.perf_counter() - start
