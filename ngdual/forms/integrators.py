"""How NGSolve runs an assembly: in its task manager from a mesh size on, and with the
element matrices of its symbolic integrators from the derivatives of the integrand."""

from __future__ import annotations

import contextlib

import ngsolve as ngs

# NGSolve's task manager wakes and synchronises its threads in every parallel loop: on a
# 2-core machine with the other core busy a loop waits up to ~0.1 s for the descheduled
# worker whatever its size (d.Assemble of hertz-cylinder, 28 000 unknowns: 0.11 s in the
# task manager, 0.003 s without). It pays only for the volume forms from this many elements
# on (level 5 of Example 3.46, twice as fast on an idle machine); the boundary forms are
# always assembled in one thread. Both assemble the same matrices bit for bit.
PARALLEL_ELEMENTS = 8192


def parallel_tasks(mesh: ngs.Mesh):
    """NGSolve's task manager for a volume assembly on ``mesh`` from
    :data:`PARALLEL_ELEMENTS` triangles on, else a context that does nothing."""
    return ngs.TaskManager() if mesh.ne >= PARALLEL_ELEMENTS else contextlib.nullcontext()


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
