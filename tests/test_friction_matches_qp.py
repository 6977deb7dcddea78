"""Nested Uzawa (Remark 3.45) and an independent solver agree on the Coulomb problem (3.62).

The reference fixes F, solves the discrete problem as ONE convex QP in (sigma, nu)
with Clarabel (interior point, no metric, no factorisation) and iterates on
F = mu_f |sigma_n| (3.123) by successive substitution. Example 3.46 with mu_f = 0.5,
g = 0.01 and g = 0 (h^ = 2h~), levels 1-4.
"""

from functools import cache

import numpy as np
import pytest

from ngdual.forms import assemble
from ngdual.friction import build_friction_forms
from ngdual.mesh import build_mesh
from ngdual.quantities import norms
from ngdual.scene import load_scene
from ngdual.solvers import solve_problem
from ngdual.solvers.qp import solve_qp_friction
from ngdual.solvers.settings import Model

RTOL = 1e-5
CASES = [(name, level) if level <= 2 else pytest.param(name, level, marks=pytest.mark.slow)
         for name in ("thesis-3.46-coulomb", "thesis-3.46-coulomb-gap0") for level in (1, 2, 3, 4)]


@cache
def solutions(name, level):
    scene = load_scene(name, ["solver.method=uzawa", "solver.eps1=1e-11", "solver.eps2=1e-10"])
    problem = assemble(scene, build_mesh(scene.geometry, level))
    return (scene, solve_problem(problem),
            solve_qp_friction(problem, Model.of(scene)))


@pytest.mark.parametrize(("name", "level"), CASES)
def test_norms_agree(name, level):
    _, uzawa, qp = solutions(name, level)
    assert uzawa.converged and qp.converged
    a, b = norms(uzawa), norms(qp)
    # lambda_n vanishes up to round-off in full contact (g = 0): measure it against the
    # displacement scale on Gamma_C, max(||lambda_n||, ||lambda_t||)
    scale = {k: abs(b[k]) for k in ("sigma_X", "lam_t")}
    scale["lam_n"] = max(b["lam_n"], b["lam_t"])
    for key, ref in scale.items():
        assert abs(a[key] - b[key]) <= RTOL * ref, (key, a[key], b[key])


@pytest.mark.parametrize(("name", "level"), CASES)
def test_nu_and_F_agree_where_F_is_not_negligible(name, level):
    _, uzawa, qp = solutions(name, level)
    forms = build_friction_forms(uzawa.problem)
    F_hat = forms.per_hat_edge(qp.friction_bound)
    relevant = F_hat > 1e-3 * F_hat.max()
    assert relevant.sum() >= 2
    assert np.abs(uzawa.nu - qp.nu)[relevant].max() <= RTOL
    np.testing.assert_allclose(uzawa.friction_bound, qp.friction_bound,
                               atol=RTOL * qp.friction_bound.max())


@pytest.mark.parametrize(("name", "level"), CASES)
def test_discrete_coulomb_conditions(name, level):
    """sigma_n <= 0, |sigma_t| <= F tested with the h~ hats (Prop. 3.25); |sigma_t|/|sigma_n|
    <= mu_f; nu = sign(Q lambda_t) where Q lambda_t does not vanish ((3.62)_7)."""
    scene, sol, _ = solutions(name, level)
    pb, mu_f = sol.problem, scene.friction.mu
    forms = build_friction_forms(pb)
    r = sol.residuals
    assert r["sigma_n_positive"] <= 1e-8 and r["lambda_n_negative"] == 0.0
    assert r["sigma_t_bound"] <= 1e-12 and r["tangential"] <= 1e-10 and r["nu_bound"] == 0.0
    # Coulomb: int |sigma_t| mu_i <= mu_f int |sigma_n|_h^ mu_i for every hat mu_i
    sigma = sol.x[pb.sigma]
    tangential = pb.block(pb.sigma, pb.index("lam_t")).T @ sigma
    mean_normal = forms.coulomb_bound(sol.x, 1.0)  # the h^ mean of |sigma_n|
    q_normal = forms.q_matrix(mean_normal).T @ np.ones(forms.n_nu)
    assert q_normal.max() > 0
    assert np.all(np.abs(tangential) <= mu_f * q_normal * (1 + 1e-6) + 1e-12 * q_normal.max())
    Q, lam_t = forms.q_matrix(sol.friction_bound), sol.part("lam_t")
    qlt = Q @ lam_t
    F_hat = forms.per_hat_edge(sol.friction_bound)
    slipping = np.abs(qlt) > 1e-4 * (Q @ np.abs(lam_t))  # stick: Q lambda_t = 0
    slipping &= F_hat > 1e-6 * F_hat.max()  # nu is arbitrary where F vanishes
    np.testing.assert_array_equal(sol.nu[slipping], np.sign(qlt[slipping]))
    assert r["nu_sign"] <= 1e-6
