"""How a sweep task is timed: the median of repeated runs (:func:`repeated`,
:func:`median_steps`), the rounds of a paired timing, one thread per task
(:func:`one_thread`) and the wall time a task may spend (:class:`Share`)."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable

import numpy as np

# The true-error tasks time ``repeat`` runs and record the median: a wall time of a fraction
# of a second varies by about 10 % from run to run with the machine's load, enough to decide
# which of two methods reaches an accuracy first (the work-precision study's verdicts). The
# runs after the first are made only while a run takes less than REPEAT_BELOW_S: longer ones
# vary less and cost more.
REPEAT_BELOW_S = 5.0
# The work-precision study times its close verdicts again, uniform and adaptive in turn
# (:func:`ngdual.studies.sweep.adaptive_tasks.paired_task`): this many runs of each.
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
    (:data:`ngdual.forms.PARALLEL_ELEMENTS`) would take the second core of a one-worker
    study, while the primal peer and the small meshes of an adaptive run assemble on one;
    BLAS on one thread for the reason of :data:`ngdual.tolerances.BLAS_THREADS`.
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


class Share:
    """The wall time a task of steps (the levels of uniform refinement, an adaptive run) may
    spend, from its creation: :meth:`next_fits` after each step says whether the next one
    ends within it, predicted as the last step's wall time times its growth (the larger of
    the growth of the unknowns and of the step's time; ``growth`` before the second step).
    A step may still overrun it by what the prediction misses.

    >>> share = Share(0.0)
    >>> share.next_fits(100, 4.0)
    False
    """

    def __init__(self, seconds: float):
        self.seconds = float(seconds)
        self.start = self.last = time.perf_counter()
        self.steps: list[tuple[int, float]] = []

    def next_fits(self, unknowns: int, growth: float) -> bool:
        now = time.perf_counter()
        step = now - self.last
        if self.steps:
            before_n, before_s = self.steps[-1]
            growth = max(unknowns / before_n, step / before_s if before_s > 0 else 1.0, 1.0)
        self.steps.append((unknowns, step))
        self.last = now
        return now - self.start + step * growth <= self.seconds
