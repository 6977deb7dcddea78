"""Nested Uzawa (Algorithm 3.41, Remark 3.45): Tresca and Coulomb on coarse levels, and
the variants (loop order, metrics, step, condensed iteration) reach the same solution."""

import dataclasses
import functools

import numpy as np
import pytest

from ngdual import post, trace
from ngdual.forms import assemble
from ngdual.friction import build_friction_forms
from ngdual.mesh import build_mesh
from ngdual.scene import SceneError, SceneTypeError, load_scene
from ngdual.solvers import solve_scene
from ngdual.solvers.nested import box_projection, box_projection_qp, nested_uzawa
from ngdual.solvers.projections import NonnegativeProjection, metric_matrix
from ngdual.solvers.settings import NestedUzawaSettings, UzawaSettings
from ngdual.solvers.uzawa import uzawa


def test_box_projection_qp_equals_closed_form():
    rng = np.random.default_rng(0)
    mass = rng.uniform(0.5, 2.0, 12)
    c = rng.normal(scale=2.0, size=12)
    np.testing.assert_allclose(box_projection_qp(c, mass), box_projection(c, mass), atol=1e-7)


@functools.cache
def _solve(name):
    scene = load_scene(name, ["solver.method=uzawa", "solver.eps2=1e-8"])
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


@functools.cache
def _coulomb_problem(level=2):
    return assemble(load_scene("thesis-3.46-coulomb"), build_mesh(load_scene(
        "thesis-3.46-coulomb").geometry, level))


def _nested(**options):
    pb = _coulomb_problem()
    settings = NestedUzawaSettings.from_scene(pb.scene, eps1=1e-11, eps2=1e-10, **options)
    return nested_uzawa(pb, settings)


@pytest.mark.parametrize("variant", [{"loop_order": "contact-outer"},
                                     {"friction_metric": "mass"}, {"rho2": 0.5},
                                     {"metric": "euclidean"}])
def test_loop_orders_metrics_and_steps_reach_the_same_solution(variant):
    base, other = _nested(), _nested(**variant)
    assert base.converged and other.converged
    assert np.linalg.norm(other.x - base.x) <= 1e-7 * np.linalg.norm(base.x)


def test_condensed_iteration_repeats_the_sparse_solves_exactly():
    """Same iterates, so the same iteration counts and the same solution."""
    condensed, full = _nested(condensed=True), _nested(condensed=False)
    assert condensed.iterations == full.iterations
    assert np.linalg.norm(condensed.x - full.x) <= 1e-10 * np.linalg.norm(full.x)


def test_frictionless_uzawa_condensed_equals_sparse():
    problem = assemble(load_scene("thesis-3.46-frictionless"),
                       build_mesh(load_scene("thesis-3.46-frictionless").geometry, 3))
    settings = UzawaSettings.from_scene(problem.scene, eps=1e-10)
    a = uzawa(problem, settings)
    b = uzawa(problem, dataclasses.replace(settings, condensed=True))
    assert a.iterations == b.iterations and a.history == pytest.approx(b.history, rel=1e-6)
    assert np.linalg.norm(a.x - b.x) <= 1e-10 * np.linalg.norm(a.x)


def test_projection_by_nnls_equals_the_cvxpy_qp():
    problem = _coulomb_problem()
    W = metric_matrix(problem.spaces.contact, 1.0, "h12")
    rng = np.random.default_rng(1)
    nnls, qp = NonnegativeProjection(W), NonnegativeProjection(W, solver="cvxpy")
    active = 0
    for _ in range(10):
        c = rng.normal(size=W.shape[0])
        chi = nnls(c)
        assert chi.min() >= 0
        active += int((chi == 0).sum())
        np.testing.assert_allclose(chi, qp(c), atol=1e-8 * np.abs(chi).max())
    assert active > 0


def test_stick_slip_diagnostics_are_consistent(solved):
    _, sol = solved
    diag = trace.friction_diagnostics(sol)
    assert set(diag.edge_status) <= {"free", "stick", "slip"}
    assert np.all(np.abs(diag.nu[diag.edge_status == "slip"]) >= 1 - 1e-6)
    assert np.all(np.abs(diag.nu[diag.edge_status == "stick"]) < 1)
    separated = diag.node_status == "separation"
    assert np.all(diag.lam_n[separated] > 0) and np.all(diag.lam_n[~separated] >= 0)
    summary = post.contact_summary(sol)
    assert summary["stick_nodes"] + summary["slip_nodes"] == summary["nodes_in_contact"] > 0


def test_condensed_has_one_default_resolved_per_algorithm_and_is_validated():
    """``solver.condensed = "auto"`` (the scene's default) is the Gamma_C response for nested
    Uzawa and sparse solves for Algorithm 3.38 (solvers.settings.CONDENSED_AUTO); a given
    value applies to both; anything else is refused naming the field."""
    coulomb = load_scene("thesis-3.46-coulomb")
    assert coulomb.solver.condensed == "auto"
    assert NestedUzawaSettings.from_scene(coulomb).condensed is True
    assert UzawaSettings.from_scene(coulomb).condensed is False
    forced = load_scene("thesis-3.46-coulomb", ["solver.method='uzawa'", "solver.condensed=false"])
    assert NestedUzawaSettings.from_scene(forced).condensed is False
    with pytest.raises(SceneError) as bad:
        load_scene("thesis-3.46-coulomb", ["solver.method='uzawa'", "solver.condensed='yes'"])
    assert bad.value.field == "solver.condensed"
    with pytest.raises(SceneTypeError) as bad:
        UzawaSettings.from_scene(coulomb, condensed=1)
    assert bad.value.field == "solver.condensed"
    with pytest.raises(SceneError, match="does nothing"):
        load_scene("hertz-cylinder", ["solver.condensed=true"])
