"""The assembly of (3.62) and of the hybridised system gives the same matrices whether
NGSolve's task manager runs it in parallel or one thread does (forms.parallel_tasks); a
core that idles gets the task manager at every size, a busy one only from PARALLEL_ELEMENTS
triangles on."""

import contextlib

import ngsolve as ngs
import numpy as np
import pytest

from ngdual import forms
from ngdual.mesh import build_mesh
from ngdual.scene import load_scene
from ngdual.solvers import condensation
from ngdual.solvers.hybrid import HybridSystem


def assembled(scene, mesh):
    problem = forms.assemble(scene, mesh)
    hybrid = HybridSystem(problem, friction=scene.has_friction)
    return problem.K, problem.rhs, hybrid.H, hybrid.rhs(problem.rhs)


def test_parallel_and_serial_assembly_agree_bit_for_bit(monkeypatch):
    scene = load_scene("thesis-3.46-frictionless")
    mesh = build_mesh(scene.geometry, 5)
    assert mesh.ne >= forms.PARALLEL_ELEMENTS
    parallel = assembled(scene, mesh)
    for module in (forms.peers_block, condensation):
        monkeypatch.setattr(module, "parallel_tasks", lambda mesh: contextlib.nullcontext())
    serial = assembled(scene, mesh)
    for p, s in zip(parallel, serial):
        if hasattr(p, "tocsr"):
            assert np.array_equal(p.indptr, s.indptr) and np.array_equal(p.indices, s.indices)
            p, s = p.data, s.data
        assert np.array_equal(p, s)


@pytest.mark.parametrize("idle, parallel", [(0.9, True), (0.05, False)])
def test_the_task_manager_runs_where_a_core_idles(monkeypatch, idle, parallel):
    """A small mesh is assembled in NGSolve's task manager exactly when the machine had
    IDLE_CORES idle cores over the last window; a large one always."""
    cores = forms.integrators.idle_cores
    mesh = build_mesh(load_scene("hertz-cylinder").geometry, 1)
    assert mesh.ne < forms.PARALLEL_ELEMENTS
    now = (100.0, 50.0)   # (wall time, idle CPU seconds) of the machine
    monkeypatch.setattr(cores, "cores", 2)
    monkeypatch.setattr(cores, "last", (now[0] - 1.0, now[1] - idle))
    monkeypatch.setattr(cores, "_sample", lambda: now)
    assert isinstance(forms.parallel_tasks(mesh), ngs.TaskManager) is parallel
    monkeypatch.setattr(forms.integrators, "PARALLEL_ELEMENTS", mesh.ne)
    assert isinstance(forms.parallel_tasks(mesh), ngs.TaskManager)
