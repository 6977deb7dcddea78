"""Nested Uzawa (Algorithm 3.41, Remark 3.45): Tresca and Coulomb on coarse levels."""

import functools

import numpy as np
import pytest

from ngdual.friction import build_friction_forms
from ngdual.scene import load_scene
from ngdual.solve import solve_scene
from ngdual.solvers.nested import box_projection, box_projection_qp


def test_box_projection_qp_equals_closed_form():
    rng = np.random.default_rng(0)
    mass = rng.uniform(0.5, 2.0, 12)
    c = rng.normal(scale=2.0, size=12)
    np.testing.assert_allclose(box_projection_qp(c, mass), box_projection(c, mass), atol=1e-7)


@functools.cache
def _solve(name):
    scene = load_scene(name, ["solver.eps2=1e-8"])
    return scene, solve_scene(scene, 2)


@pytest.fixture(params=["thesis-3.46-tresca", "thesis-3.46-coulomb"])
def solved(request):
    return _solve(request.param)


def test_nested_uzawa_converges_and_satisfies_the_contact_conditions(solved):
    _, sol = solved
    assert sol.converged
    r = sol.residuals
    assert r["lambda_n_negative"] == 0.0
    assert r["sigma_n_positive"] < 1e-7 and r["complementarity"] < 1e-7
    assert r["nu_bound"] == 0.0 and np.abs(sol.nu).max() <= 1.0


def test_nu_is_the_sign_of_lambda_t_where_q_lambda_t_is_not_small(solved):
    """(3.62)_7: q(kappa - nu, lambda_t) <= 0 for all |kappa| <= 1."""
    _, sol = solved
    forms = build_friction_forms(sol.problem)
    qlt = forms.q_matrix(sol.friction_bound) @ sol.part("lam_t")
    big = np.abs(qlt) > 1e-3 * np.abs(qlt).max()
    assert big.any()
    np.testing.assert_allclose(sol.nu[big], np.sign(qlt[big]), atol=1e-4)
    assert sol.residuals["nu_sign"] < 1e-4


def test_tangential_equation_holds_with_the_final_nu(solved):
    """(3.62)_5: C_t^T sigma = Q_F^T nu, checked on the assembled matrices."""
    _, sol = solved
    pb = sol.problem
    forms = build_friction_forms(pb)
    C_t = pb.block(pb.sigma, pb.index("lam_t"))
    lhs = C_t.T @ sol.x[pb.sigma]
    rhs = forms.q_matrix(sol.friction_bound).T @ sol.nu
    assert np.abs(lhs - rhs).max() <= 1e-8 * (np.abs(rhs).max() + 1e-300)


def test_coulomb_bound_is_mu_times_the_normal_stress():
    scene, sol = _solve("thesis-3.46-coulomb")
    forms = build_friction_forms(sol.problem)
    F = forms.coulomb_bound(sol.x, scene.friction.mu)
    np.testing.assert_allclose(F, sol.friction_bound, rtol=1e-5, atol=1e-8 * F.max())
