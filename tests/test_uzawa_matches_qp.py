"""Algorithm 3.38 (Uzawa) and an independent convex QP solve of (3.103) give the same solution.

Example 3.46 without friction on levels 1-4: the Uzawa iteration (eps = 1e-10)
and Clarabel's interior-point solution of
min 1/2 sigma^T A sigma - g^T sigma s.t. B^T sigma = b, C_n^T sigma <= 0
share no code beyond the assembled matrices, so their agreement checks both.
"""

from functools import cache

import numpy as np
import pytest

from ngdual import peers, post
from ngdual.forms import assemble
from ngdual.mesh import build_mesh
from ngdual.quantities import norms
from ngdual.scene import load_scene
from ngdual.solvers.qp import solve_qp
from ngdual.solvers.settings import Model, UzawaSettings
from ngdual.solvers.uzawa import uzawa

LEVELS = [1, 2, 3, pytest.param(4, marks=pytest.mark.slow)]
RTOL = 1e-6
NORMS = ("sigma_X", "u", "eta", "phi", "lam_t", "lam_n")


@cache
def problem(level):
    scene = load_scene("thesis-3.46-frictionless")
    return assemble(scene, build_mesh(scene.geometry, level))


@cache
def solutions(level):
    """(Uzawa in the h12 metric, reference QP) on ``level``, computed once per session."""
    pb = problem(level)
    return (uzawa(pb, UzawaSettings.from_scene(pb.scene, eps=1e-10, metric="h12")),
            solve_qp(pb, Model.of(pb.scene)))


def relative_difference(a, b):
    return abs(a - b) / max(abs(a), abs(b), np.finfo(float).tiny)


def vector_difference(a, b):
    return np.linalg.norm(a - b) / max(np.linalg.norm(b), np.finfo(float).tiny)


def assert_norms_agree(first, second):
    n1, n2 = norms(first), norms(second)
    diffs = {k: relative_difference(n1[k], n2[k]) for k in NORMS}
    assert all(n2[k] > 0 for k in NORMS), n2
    assert max(diffs.values()) <= RTOL, diffs


@pytest.mark.parametrize("level", LEVELS)
def test_uzawa_and_qp_norms_agree(level):
    u_sol, qp_sol = solutions(level)
    assert u_sol.converged and qp_sol.converged
    assert_norms_agree(u_sol, qp_sol)


@pytest.mark.parametrize("level", LEVELS)
def test_uzawa_and_qp_coefficients_of_sigma_and_lambda_n_agree(level):
    u_sol, qp_sol = solutions(level)
    for names in (peers.STRESS, ("lam_n",)):
        assert vector_difference(u_sol.part(*names), qp_sol.part(*names)) <= RTOL, names


@pytest.mark.parametrize("which", [0, 1], ids=["uzawa", "qp"])
@pytest.mark.parametrize("level", LEVELS)
def test_solution_satisfies_the_contact_conditions_of_3_103(level, which):
    """lambda_n >= 0, C_n^T sigma <= 0 and lambda_n^T C_n^T sigma = 0, up to 1e-8 relative."""
    pb = problem(level)
    sol = solutions(level)[which]
    lam = sol.part("lam_n")
    traction = pb.block(pb.sigma, pb.lam_n).T @ sol.part(*peers.STRESS)
    assert lam.min() >= 0.0
    assert traction.max() <= 1e-8 * np.max(np.abs(traction))
    assert abs(lam @ traction) <= 1e-8 * np.linalg.norm(lam) * np.linalg.norm(traction)


@pytest.mark.parametrize("level", LEVELS)
def test_qp_multipliers_satisfy_stationarity(level):
    """A sigma + B y + C_n lambda_n = g: the dual values of the QP are the unknowns of (3.103)."""
    pb = problem(level)
    x = solutions(level)[1].x
    s, y, lam = pb.sigma, pb.mult, pb.lam_n
    a_sigma = pb.block(s, s) @ x[s]
    residual = a_sigma + pb.block(s, y) @ x[y] + pb.block(s, lam) @ x[lam] - pb.rhs[s]
    assert np.linalg.norm(residual) <= 1e-10 * (np.linalg.norm(pb.rhs[s]) + np.linalg.norm(a_sigma))


@pytest.mark.parametrize("level", LEVELS)
def test_uzawa_and_qp_find_the_same_contact_nodes(level):
    u_sol, qp_sol = solutions(level)
    count = post.contact_summary(u_sol)["nodes_in_contact"]
    assert 0 < count < len(problem(level).lam_n)     # the contact set is a genuine unknown
    assert post.contact_summary(qp_sol)["nodes_in_contact"] == count


def test_euclidean_metric_gives_the_same_solution_as_h12():
    h12, _ = solutions(3)
    pb = problem(3)
    euclidean = uzawa(pb, UzawaSettings.from_scene(pb.scene, eps=1e-10, metric="euclidean"))
    assert euclidean.converged
    assert_norms_agree(euclidean, h12)
