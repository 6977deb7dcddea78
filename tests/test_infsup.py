"""The discrete inf-sup constant of the PEERS triple (ngdual.verification.infsup, Lemma 3.28).

On Example 3.46 clamped all round (no boundary multipliers), b + s maps X_h with the H(div)
norm to M_h x S_h with L^2:

* its largest singular value is sqrt(2) exactly: |b(v, tau) + s(xi, tau)| is at most
  ||(v, xi)|| ||(div tau, as tau)|| and |as tau|^2 = (tau_12 - tau_21)^2 <= 2 |tau|^2;
* its smallest (beta_h) stays away from zero under refinement, and without the Curl
  bubbles X_h = RT_0^2 leaves a two-dimensional kernel (modes no stress sees).
"""

import numpy as np
import pytest

import ngdual as nd
from ngdual.forms import assemble
from ngdual.mesh import build_mesh
from ngdual.verification.infsup import (
    gram_matrix,
    largest_singular_value,
    smallest_singular_values,
)


@pytest.fixture(scope="module")
def problems():
    clamped = nd.load_scene("thesis-3.46-frictionless",
                            ["boundary.dirichlet=['left', 'right', 'bottom', 'top']",
                             "boundary.neumann=[]", "boundary.contact=[]"])
    return [assemble(clamped, build_mesh(clamped.geometry, level)) for level in (1, 2)]


def test_the_continuity_constant_of_b_plus_s_in_the_h_div_norm_is_sqrt_2(problems):
    for problem in problems:
        G = gram_matrix(problem)
        s, m = problem.sigma, problem.mult
        largest = largest_singular_value(G[s][:, s], problem.block(s, m), G[m][:, m])
        assert largest == pytest.approx(np.sqrt(2.0), abs=1e-10)


def test_the_peers_inf_sup_constant_stays_while_rt0_alone_has_a_two_dimensional_kernel(problems):
    betas, thirds = [], []
    for problem in problems:
        G = gram_matrix(problem)
        s, rt0, m = problem.sigma, problem.index("r1", "r2"), problem.mult
        Y = G[m][:, m]
        betas.append(smallest_singular_values(G[s][:, s], problem.block(s, m), Y)[0])
        bare = smallest_singular_values(G[rt0][:, rt0], problem.block(rt0, m), Y)
        assert np.all(bare[:2] < 1e-6)
        thirds.append(bare[2])
    assert 0.38 < betas[1] <= betas[0] < 0.4
    assert betas[1] / betas[0] > 0.99
    assert thirds[1] / thirds[0] == pytest.approx(0.5, abs=0.05)   # decays like h
