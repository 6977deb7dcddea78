"""The PEERS block assembled with NGSolve's differentiated integrands
(forms.differentiated_integrands) is the one of its default integrators, to the bit: the
matrices of (3.62) and of the hybridised system do not depend on how NGSolve forms the
element matrices."""

import contextlib

import numpy as np
import pytest

from ngdual import forms, peers
from ngdual.mesh import build_mesh
from ngdual.scene import load_scene
from ngdual.solvers.hybrid import HybridSystem


def _assert_same_bits(first, second):
    for a, b in zip(first, second):
        if hasattr(a, "tocsr"):
            assert np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)
            a, b = a.data, b.data
        assert np.array_equal(a, b)


@pytest.mark.parametrize("name", ["hertz-cylinder", "thesis-3.46-coulomb"])
def test_differentiated_integrands_give_the_matrices_of_3_62_to_the_bit(name, monkeypatch):
    scene = load_scene(name)
    mesh = build_mesh(scene.geometry, 2)

    def assembled():
        problem = forms.assemble(scene, mesh)
        return problem, HybridSystem(problem, friction=scene.has_friction)

    def matrices(problem, hybrid):  # broken.matrix lives as long as its problem
        return problem.K, problem.rhs, problem.broken.matrix, hybrid.H, hybrid.rhs(problem.rhs)

    differentiated = assembled()
    monkeypatch.setattr(forms.peers_block, "differentiated_integrands", contextlib.nullcontext)
    default = assembled()
    _assert_same_bits(matrices(*differentiated), matrices(*default))


def test_differentiated_integrands_give_the_peers_block_of_order_1_to_the_bit(monkeypatch):
    scene = load_scene("hertz-cylinder", ["discretisation.order=1",
                                          "discretisation.multipliers=facet"])
    spaces = forms.Spaces.build(scene, build_mesh(scene.geometry, 1))
    lame = scene.material.lame
    size = sum(spaces.components[name].ndof for name in peers.PEERS)
    differentiated = forms.broken_peers(spaces, lame)
    conforming = forms.conforming_peers(spaces, lame, size)
    monkeypatch.setattr(forms.peers_block, "differentiated_integrands", contextlib.nullcontext)
    default = forms.broken_peers(spaces, lame)
    _assert_same_bits((differentiated.matrix, conforming),
                      (default.matrix, forms.conforming_peers(spaces, lame, size)))
