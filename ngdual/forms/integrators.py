"""How NGSolve runs an assembly: in its task manager where a core would otherwise idle or
from a mesh size on, and with the element matrices of its symbolic integrators from the
derivatives of the integrand."""

from __future__ import annotations

import contextlib
import os
import time

import ngsolve as ngs

# NGSolve's task manager wakes and synchronises its threads in every parallel loop: on a
# 2-core machine with the other core busy a loop waits up to ~0.1 s for the descheduled
# worker whatever its size (d.Assemble of hertz-cylinder, 28 000 unknowns: 0.11 s in the
# task manager, 0.003 s without). Where another core idles, it halves an assembly of any
# size (the condensed PEERS_1 form of hertz-cylinder's last tolerance step, 1 685
# triangles: 0.070 -> 0.036 s; with the other core busy 0.06-0.14 s). So a volume
# assembly runs in the task manager when the machine had at least IDLE_CORES idle cores
# since the last decision (psutil's CPU times, measured over at least IDLE_WINDOW seconds;
# a shorter window keeps the last decision), and from PARALLEL_ELEMENTS triangles on
# (level 5 of Example 3.46) whatever the load; the boundary forms are always assembled in
# one thread. Both assemble the same matrices bit for bit (tests/test_assembly_threads.py).
PARALLEL_ELEMENTS = 8192
IDLE_CORES = 0.5
IDLE_WINDOW = 0.2


class _IdleCores:
    """Whether the machine has had :data:`IDLE_CORES` idle cores since the last decision
    (the first: since ngdual was imported); never on one core."""

    def __init__(self):
        self.cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") \
            else (os.cpu_count() or 1)
        self.last, self.idle = self._sample(), False

    @staticmethod
    def _sample() -> tuple[float, float]:
        """(wall time, the machine's idle CPU seconds)."""
        import psutil

        return time.monotonic(), psutil.cpu_times().idle

    def __call__(self) -> bool:
        if self.cores < 2:
            return False
        now = self._sample()
        wall = now[0] - self.last[0]
        if wall >= IDLE_WINDOW:
            self.idle = (now[1] - self.last[1]) / wall >= IDLE_CORES
            self.last = now
        return self.idle


idle_cores = _IdleCores()


def parallel_tasks(mesh: ngs.Mesh):
    """NGSolve's task manager for a volume assembly on ``mesh`` where a core idles
    (:data:`IDLE_CORES`) or from :data:`PARALLEL_ELEMENTS` triangles on, else a context that
    does nothing."""
    if mesh.ne >= PARALLEL_ELEMENTS or idle_cores():
        return ngs.TaskManager()
    return contextlib.nullcontext()


@contextlib.contextmanager
def differentiated_integrands():
    """NGSolve's symbolic integrators added to a form and assembled inside (both: an integrator
    made inside and assembled outside gives another matrix) take their element matrices from
    the derivatives of the integrand with respect to the test functions
    (``ngsglobals.symbolic_integrator_uses_diff``) rather than by evaluating the integrand
    once per pair of trial and test function components. The broken PEERS block
    (:func:`~ngdual.forms.peers_block.broken_peers`) of hertz-cylinder, level 5, assembles
    in 1.2 s this way and in 1.6 s the other (one thread), to the same bits (every shipped
    scene at k = 0, hertz-cylinder at k = 1)."""
    default = ngs.ngsglobals.symbolic_integrator_uses_diff
    ngs.ngsglobals.symbolic_integrator_uses_diff = True
    try:
        yield
    finally:
        ngs.ngsglobals.symbolic_integrator_uses_diff = default
