"""The assembly of (3.62) and of the hybridised system gives the same matrices whether
NGSolve's task manager runs it in parallel or one thread does (forms.parallel_tasks)."""

import contextlib

import numpy as np

from ngdual import forms
from ngdual.mesh import build_mesh
from ngdual.scene import load_scene
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
    monkeypatch.setattr(forms.peers_block, "parallel_tasks", lambda mesh: contextlib.nullcontext())
    serial = assembled(scene, mesh)
    for p, s in zip(parallel, serial):
        if hasattr(p, "tocsr"):
            assert np.array_equal(p.indptr, s.indptr) and np.array_equal(p.indices, s.indices)
            p, s = p.data, s.data
        assert np.array_equal(p, s)
