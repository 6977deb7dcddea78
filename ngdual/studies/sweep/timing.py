"""How a sweep task is timed: the median of repeated runs (:func:`repeated`,
:func:`median_steps`), the rounds of a paired timing, and one thread per task
(:func:`one_thread`)."""

from __future__ import annotations

import contextlib
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
