"""The stop rules of the adaptive loop: each ends it for one reason and says which.

The loop asks its :class:`StopRules` after ESTIMATE and after MARK; the first rule that
answers ends the loop, and its :class:`Stop` becomes the last record's ``stopped_by`` and
``stop_message``:

============== ==========================================================================
``no_contact``  the pressure goal's window holds no contact (:class:`NoContact`)
``singular``    with a tol: the goal's error has no finite value (:class:`Singular`)
``tol``         the goal's relative estimate is at most tol (:class:`Reached`)
``stall``       with a tol: no new best for :data:`STALL_STEPS` steps (:class:`Stalled`)
``steps``       the steps are spent (:class:`StepsSpent`)
``resolution``  the marking reaches the smallest triangle the loop refines (:class:`Resolution`)
``memory``      the next refinement would not fit in memory (:class:`MemoryBudget`), or a
                solve ran out of it (:func:`out_of_memory`)
============== ==========================================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import budget
from ..estimator import Estimate
from ..forms.spaces import variant_of
from ..goal import Goal, Measure
from ..goal.base import points_text
from ..mesh import mesh_arrays
from ..scene import Scene
from ..solution import Solution
from .refinement import below_resolution

# A tolerance run stops as stalled when its goal's relative estimate has not fallen below
# its best for this many steps: the estimate is then held by triangles that refining does
# not improve (the work-precision study's runs never went more than two steps without a
# new best; the wedge's pressure goal at order 1 and 2 reaches 7.8e-4 and 6.5e-4 with
# Gamma_C edges of 2e-6 at the apex, and then rises while only the apex is refined:
# docs/theory/estimator.md, "A goal and a tolerance").
STALL_STEPS = 3
# the stops after which the reason why the goal's error is not finite is added to the message
UNFINISHED = ("steps", "resolution", "memory")


@dataclass(frozen=True)
class Stop:
    """Why the loop ended: ``stopped_by`` and, where there is more to say, ``message``;
    ``early`` where the run ended before its steps for a reason its caller hears of even
    without a tol (:class:`ngdual.afem.AdaptWarning`)."""

    stopped_by: str
    message: str | None = None
    early: bool = False

    def record(self) -> dict:
        """The last record's ``stopped_by`` and ``stop_message``."""
        return {"stopped_by": self.stopped_by,
                **({} if self.message is None else {"stop_message": self.message})}


@dataclass
class Step:
    """What the rules read after a step's ESTIMATE (and MARK): the ``history`` so far (its
    last record this step's), the step's ``solution``, its ``estimated`` indicators of (4.50)
    and its goal's ``measured``, why the goal's error is not finite on it (``infinite``,
    :meth:`ngdual.goal.Goal.infinite_error`) and the ``marked`` triangles."""

    history: list[dict]
    solution: Solution | None = None
    estimated: Estimate | None = None
    measured: Measure | None = None
    infinite: str | None = None
    marked: np.ndarray | None = None

    @property
    def relative(self) -> float:
        return self.history[-1]["relative_estimate"]


class NoContact:
    """The pressure goal's window (or Gamma_C) holds no contact: nothing to aim at, known on
    the first solve (:meth:`ngdual.goal.Goal.nothing_to_measure`)."""

    def __init__(self, goal: Goal):
        self.goal = goal

    def __call__(self, step: Step) -> Stop | None:
        why = self.goal.nothing_to_measure(step.solution, step.measured)
        return None if why is None else Stop("no_contact", why, early=True)


class Singular:
    """With a tol: the goal's error has no finite value, on a solve whose relative estimate
    is at most tol (it measures no error) or on :data:`STALL_STEPS` successive solves
    (refining does not make it finite, while the estimate may creep down for a dozen)."""

    def __init__(self, tol: float | None):
        self.tol, self.unbounded = tol, 0   # successive solves with an infinite error

    def __call__(self, step: Step) -> Stop | None:
        self.unbounded = self.unbounded + 1 if step.infinite else 0
        if self.tol is None or not step.infinite:
            return None
        if step.relative <= self.tol or self.unbounded >= STALL_STEPS:
            return Stop("singular", step.infinite)
        return None


class Reached:
    """The relative estimate is at most tol; with the goal's caution where its estimate is
    known to be too small (the pressure goal at a kink of Gamma_C)."""

    def __init__(self, tol: float | None, goal: Goal, scene: Scene):
        self.tol, self.goal, self.scene = tol, goal, scene

    def __call__(self, step: Step) -> Stop | None:
        if self.tol is None or step.relative > self.tol:
            return None
        return Stop("tol", self.goal.caution(self.scene))


class Stalled:
    """With a tol: the relative estimate has not fallen below its best for
    :data:`STALL_STEPS` steps, for the step's reason (its ``infinite``) or because refining
    the marked triangles does not reduce it."""

    def __init__(self, tol: float | None, goal: Goal):
        self.tol, self.goal = tol, goal

    def __call__(self, step: Step) -> Stop | None:
        history = step.history
        if self.tol is None or len(history) <= STALL_STEPS:
            return None
        estimates = [r["relative_estimate"] for r in history]
        best = int(np.argmin(estimates[:-STALL_STEPS]))
        if min(estimates[-STALL_STEPS:]) < estimates[best]:
            return None
        if estimates[best] == float("inf"):   # the goal's size is 0 on every mesh so far
            return Stop("stall", f"{self.goal.size_name} is 0 at every step, so the estimate "
                                 f"relative to it is undefined and no tol can be reached "
                                 f"({self.goal.zero_size_reason})")
        since = ", ".join(f"{e:.3g}" for e in estimates[-STALL_STEPS:])
        reason = step.infinite or "refining the marked triangles does not reduce it"
        return Stop("stall", f"the estimate has not fallen below its best, {estimates[best]:.3g} "
                             f"at step {best}, for {STALL_STEPS} steps ({since}): {reason}")


class StepsSpent:
    """The loop has solved ``steps`` times."""

    def __init__(self, steps: int):
        self.steps = steps

    def __call__(self, step: Step) -> Stop | None:
        return Stop("steps") if len(step.history) >= self.steps else None


class Resolution:
    """The marking reaches a triangle of diameter below
    :data:`ngdual.afem.refinement.RESOLUTION` times the scene's length scale."""

    def __init__(self, scene: Scene):
        self.scene = scene

    def __call__(self, step: Step) -> Stop | None:
        marked, h = step.marked, step.estimated.h
        small = below_resolution(self.scene, h, marked)
        if small is None:
            return None
        points, triangles = mesh_arrays(step.solution.problem.fes.mesh)
        smallest = np.flatnonzero(marked)[np.argmin(h[marked])]
        where = points[triangles[smallest]].mean(axis=0)
        return Stop("resolution", f"the marking reaches triangles near {points_text([where])} "
                                  f"{small}")


class MemoryBudget:
    """The solve after the next refinement would need more memory than this process may use
    (:func:`ngdual.budget.solve_memory` against :func:`ngdual.budget.available_memory`; the
    bisection of the marked triangles and its closure make at most about 4 new triangles per
    marked one, and a least ``growth`` grows the triangles by about that factor,
    :func:`~ngdual.afem.refinement.refine_graded`), unless ``allow_large``: the loop stops
    before that refinement."""

    def __init__(self, scene: Scene, tol: float | None, steps: int, allow_large: bool,
                 growth: float):
        self.scene, self.tol, self.steps, self.allow_large = scene, tol, steps, allow_large
        self.growth = growth

    def __call__(self, step: Step) -> Stop | None:
        ne = step.solution.problem.fes.mesh.ne
        elements = max(ne + 4.0 * int(np.sum(step.marked)), self.growth * ne)
        variant = variant_of(self.scene)
        need = budget.solve_memory(elements, self.scene.solver.method, variant.order,
                                   variant.family)
        have = budget.available_memory()
        if need <= have or self.allow_large:
            return None
        return Stop("memory", f"the next refinement would have about {elements:.3g} triangles "
                              f"and its solve need about {need / 2**30:.3g} GiB, more than "
                              f"{budget.describe_available(have)}: "
                              + remedy(step.history, self.tol, self.steps), early=True)


def out_of_memory(history: list[dict], triangles: int, tol: float | None, steps: int) -> Stop:
    """The stop of a loop whose solve on a refined mesh of ``triangles`` ran out of memory
    (a MemoryError, though :class:`MemoryBudget` let the refinement through)."""
    return Stop("memory", f"the solve of step {len(history)}, on {triangles} triangles, ran out "
                          f"of memory (MemoryError) within {budget.describe_available()}: "
                          + remedy(history, tol, steps), early=True)


def remedy(history: list[dict], tol: float | None, steps: int) -> str:
    """Where a run stopped by the memory budget got to, and what gets it further."""
    done = f"stopped after {len(history)} of at most {steps} steps"
    if tol is None:
        return f"{done}; use fewer steps, or allow_large=True (--allow-large) to refine anyway"
    relative = history[-1]["relative_estimate"]
    return (f"{done}, at a relative estimate of {relative:.3g}, {relative / tol:.3g} times "
            f"tol = {tol:g}; a looser tol, a higher order (discretisation.order) or "
            f"allow_large=True (--allow-large) to refine anyway")


class StopRules:
    """The rules of one run of the loop, in the order they are asked."""

    def __init__(self, scene: Scene, goal: Goal, tol: float | None, steps: int,
                 allow_large: bool, growth: float):
        self.goal = goal
        self.after_estimate_rules = (NoContact(goal), Singular(tol), Reached(tol, goal, scene),
                                     Stalled(tol, goal), StepsSpent(steps))
        self.after_mark_rules = (Resolution(scene), MemoryBudget(scene, tol, steps, allow_large,
                                                                   growth))

    def after_estimate(self, history: list[dict], solution: Solution, estimated: Estimate,
                       measured: Measure) -> tuple[Step, Stop | None]:
        """The step just estimated, and the first stop of the rules asked before MARK."""
        step = Step(history, solution, estimated, measured, self.goal.infinite_error(solution))
        return step, _first(self.after_estimate_rules, step)

    def after_mark(self, step: Step, marked: np.ndarray) -> Stop | None:
        """The first stop of the rules asked before REFINE, once ``marked`` is known."""
        step.marked = marked
        return _first(self.after_mark_rules, step)

    @staticmethod
    def finish(stop: Stop, step: Step) -> Stop:
        """``stop``, with the reason why the goal's error is not finite after a stop that
        does not give it (:data:`UNFINISHED`)."""
        if step.infinite and stop.stopped_by in UNFINISHED:
            return Stop(stop.stopped_by, ": ".join(filter(None, (stop.message, step.infinite))),
                        stop.early)
        return stop


def _first(rules, step: Step) -> Stop | None:
    return next((stop for stop in (rule(step) for rule in rules) if stop is not None), None)
