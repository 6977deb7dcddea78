"""The hybridised active-set solver at every order (issues 27, 48): the same discrete solution
as the conforming one.

Truth: :func:`ngdual.solvers.conforming.conforming_active_set`, which solves (3.62) on the
assembled conforming K with one sparse LU and shares neither the broken spaces, the edge
multipliers, the static condensation nor the Cholesky factorisation with
:func:`ngdual.solvers.active_set.active_set_solve`. Fast: Example 3.46 (consistent ends)
at k = 0 (facet), 1, 2 without friction and with Tresca and Coulomb friction, Hertz at k = 1;
slow: Hertz at k = 2 and level 2 of Example 3.46 with Coulomb friction at k = 2.
"""

import ngsolve as ngs
import numpy as np
import pytest
import scipy.sparse as sp

from ngdual.forms import assemble, broken_peers, conforming_peers
from ngdual.mesh import build_mesh
from ngdual.scene import load_scene
from ngdual.solvers import condensation, solve_scene
from ngdual.solvers.active_set import active_set_solve
from ngdual.solvers.condensation import element_schur
from ngdual.solvers.conforming import conforming_active_set
from ngdual.solvers.convergence import TOLERANCE
from ngdual.solvers.hybrid import HybridSystem
from ngdual.solvers.linear import solve_linear
from ngdual.solvers.settings import solver_settings
from ngdual.sparse import to_scipy
from ngdual.verification.manufactured import manufactured_case

ROUND_OFF = 1e-10  # relative difference of the two solvers' unknowns (measured: 3e-14-2e-11)


def _problem(name: str, order: int, level: int):
    overrides = [f"discretisation.order={order}", "discretisation.multipliers='facet'"]
    if name.startswith("thesis-3.46"):
        overrides.append("contact.ends='consistent'")
    scene = load_scene(name, overrides)
    return assemble(scene, build_mesh(scene.geometry, level)), solver_settings(scene)


def _assert_same_solution(name: str, order: int, level: int) -> None:
    _assert_same(*_problem(name, order, level))


def _assert_same(problem, settings) -> None:
    hybrid = active_set_solve(problem, settings)
    conforming = conforming_active_set(problem, settings)
    assert np.max(np.abs(hybrid.x - conforming.x)) <= ROUND_OFF * np.max(np.abs(conforming.x))
    assert max(hybrid.residuals.values()) < 1e-11
    if settings.model.law != "none":
        assert np.allclose(hybrid.friction_bound, conforming.friction_bound, rtol=0,
                           atol=ROUND_OFF * np.max(conforming.friction_bound))


@pytest.mark.parametrize("order", [0, 1, 2])
@pytest.mark.parametrize("name", ["thesis-3.46-frictionless", "thesis-3.46-tresca",
                                  "thesis-3.46-coulomb"])
def test_the_hybridised_solution_is_the_conforming_one_on_example_3_46(name, order):
    _assert_same_solution(name, order, 1 if order == 2 else 2)


def test_the_hybridised_solution_is_the_conforming_one_on_hertz_at_order_1():
    _assert_same_solution("hertz-cylinder", 1, 1)


@pytest.mark.parametrize("order", [1, 2])
def test_the_hybridised_solution_is_the_conforming_one_on_the_manufactured_case(order):
    scene = manufactured_case("frictionless").scene(order=order)
    _assert_same(assemble(scene, build_mesh(scene.geometry, 2)), solver_settings(scene))


@pytest.mark.slow
@pytest.mark.parametrize("name, order, level", [("hertz-cylinder", 2, 2),
                                                ("hertz-cylinder", 1, 3),
                                                ("thesis-3.46-coulomb", 2, 3)])
def test_the_hybridised_solution_is_the_conforming_one_on_finer_levels(name, order, level):
    _assert_same_solution(name, order, level)


@pytest.mark.parametrize("order", [1, 2])
def test_the_broken_peers_block_sums_to_the_conforming_one_bit_for_bit(order):
    """E^T K_b E of the broken RT_k rows is the conforming PEERS_k block (same element
    matrices, at most two summands per entry)."""
    problem, _ = _problem("thesis-3.46-frictionless", order, 1)
    lame = problem.scene.material.lame
    n = problem.K.shape[0]
    difference = broken_peers(problem.spaces, lame).summed(n) - conforming_peers(
        problem.spaces, lame, n)
    assert np.max(np.abs(difference.data), initial=0.0) == 0.0


def test_the_products_and_blocks_of_an_unformed_k_are_those_of_k(monkeypatch):
    """problem.apply (E^T K_b E x plus the boundary couplings) and the multiplier blocks of
    ``problem.block`` (from the boundary part) equal K x and K's blocks once K is formed, and
    the hybridised solver of order k never sums K's PEERS block (it takes K x from apply)."""
    from ngdual.forms import BrokenPeers

    problem, settings = _problem("thesis-3.46-coulomb", 1, 1)
    summed = BrokenPeers.summed

    def refuse(*args):
        raise AssertionError("the hybridised solver summed K's PEERS block")

    monkeypatch.setattr(BrokenPeers, "summed", refuse)
    solution = active_set_solve(problem, settings)
    x = solution.x
    applied = problem.apply(x)
    blocks = [problem.block(problem.sigma, problem.lam_n),
              problem.block(problem.index("lam_t"), problem.sigma)]
    monkeypatch.setattr(BrokenPeers, "summed", summed)
    K = problem.K
    assert np.max(np.abs(applied - K @ x)) <= 1e-13 * np.max(np.abs(abs(K) @ np.abs(x)))
    for block, rows, cols in zip(blocks, (problem.sigma, problem.index("lam_t")),
                                 (problem.lam_n, problem.sigma)):
        assert (block != K[rows][:, cols]).nnz == 0


def test_the_hybridised_matrix_is_symmetric_positive_definite():
    problem, _ = _problem("thesis-3.46-coulomb", 1, 1)
    H = HybridSystem(problem, friction=True).H.toarray()
    assert np.array_equal(H, H.T)
    assert np.linalg.eigvalsh(H)[0] > 0.0


@pytest.mark.parametrize("settings", [[], ["discretisation.order=1",
                                           "contact.ends='consistent'"]])
def test_the_default_solver_is_the_hybridised_one_at_every_order(settings):
    """The thesis' configuration and order k run through the one hybridised system."""
    solution = solve_scene(load_scene("thesis-3.46-frictionless", settings), 1)
    assert solution.method == "active-set" and "hybridize" in solution.timings


@pytest.mark.parametrize("name", ["thesis-3.46-frictionless", "hertz-cylinder"])
def test_the_thesis_configuration_agrees_with_the_conforming_solver(name):
    """Order 0 with the thesis' P1 hats on h~: the hybridised solver against the sparse LU
    of K (no shared factorisation, no shared condensation)."""
    scene = load_scene(name)
    problem = assemble(scene, build_mesh(scene.geometry, 2))
    settings = solver_settings(scene)
    hybrid = active_set_solve(problem, settings)
    conforming = conforming_active_set(problem, settings)
    scale = np.max(np.abs(conforming.x))
    assert np.max(np.abs(hybrid.x - conforming.x)) <= ROUND_OFF * scale


CLAMPED = ["boundary.neumann=[]", "boundary.dirichlet=['top', 'bottom', 'left', 'right']",
           "loads.body_force=['1', '-2']"]


@pytest.mark.parametrize("order, overrides", [
    (1, ["boundary.neumann=['top', 'bottom']"]),
    (0, CLAMPED), (1, CLAMPED), (2, CLAMPED)])
def test_without_contact_the_hybridised_solution_is_the_sparse_lu_one(order, overrides):
    """Gamma_C relabelled Gamma_N, or every side clamped (no boundary multiplier: NGSolve's
    static condensation eliminates every triangle): the linear problem, against UMFPACK
    on K."""
    scene = load_scene("thesis-3.46-frictionless", [
        f"discretisation.order={order}", "contact.ends='consistent'", "boundary.contact=[]",
        *overrides])
    problem = assemble(scene, build_mesh(scene.geometry, 1))
    hybrid = active_set_solve(problem, solver_settings(scene))
    lu = solve_linear(problem)
    assert np.max(np.abs(hybrid.x - lu.x)) <= ROUND_OFF * np.max(np.abs(lu.x))


def test_the_hybridised_solution_is_the_conforming_one_on_cattaneo_mindlin():
    """Cattaneo-Mindlin at k = 1, level 2 (nu = 0.4999): the Schur complement's moments
    carry the round-off of the Cholesky factors; corrected by the moments on K where they
    must be (whether a correction is needed is the rounding of this machine's factors), the
    hybridised solution is the conforming one, checked on K: both satisfy (3.62) to the
    relative residual TOLERANCE of the problem's scales, and the compliance's condition
    (lambda + 2 mu) / mu = 5001 lets two such solutions differ by up to about ten times
    that (measured: 2e-9)."""
    problem, settings = _problem("cattaneo-mindlin", 1, 2)
    hybrid = active_set_solve(problem, settings)
    conforming = conforming_active_set(problem, settings)
    assert max(hybrid.residuals.values()) <= TOLERANCE
    assert np.max(np.abs(hybrid.x - conforming.x)) <= 1e-8 * np.max(np.abs(conforming.x))


@pytest.mark.parametrize("order", [1, 2])
def test_the_element_schur_complements_sum_to_the_sparse_product(order):
    """C^T B^{-1} C from the dense blocks of every triangle (in batches, the last one
    short) is the product of the sparse matrices, to round-off."""
    problem, _ = _problem("thesis-3.46-coulomb", order, 2)
    hybrid = HybridSystem(problem, friction=True)
    sparse = (hybrid.A_LI.T @ (hybrid.B_inv @ hybrid.A_LI)).toarray()
    for chunk in (2048, 37):
        batched = element_schur(hybrid.B_inv, hybrid.A_LI, chunk).toarray()
        assert np.max(np.abs(batched - sparse)) <= 1e-14 * np.max(np.abs(sparse))


@pytest.mark.parametrize("order", [0, 1, 2])
def test_ngsolves_static_condensation_is_the_element_schur_complement(order):
    """On eta and mu, NGSolve's static condensation of every triangle and the batched
    element Schur complements from the broken matrix's blocks, two independent
    eliminations, give the same matrix to round-off."""
    problem, _ = _problem("thesis-3.46-coulomb", order, 2)
    hybrid = HybridSystem(problem, friction=True)
    mesh, n_local = problem.spaces.mesh, hybrid._n_local
    every = ngs.BitArray(mesh.ne)
    every.Set()
    form = condensation.condensed_form(problem.broken, order, every)
    condensed = -to_scipy(form.mat)[n_local:][:, n_local:]
    n_g = condensed.shape[0]
    at = hybrid._blocks   # the blocks of every triangle, with every triangle's edge coupling
    blocks = condensation.ElementBlocks(
        at.matrix, n_local, at.rt_ranges, condensation.edge_coupling(
            problem.broken.fes.components[0], form.space.components[-1], order), at.coupled)
    B_inv, A_LI = blocks.of(
        condensation.local_dofs(problem.broken.fes, np.arange(mesh.ne), n_local))
    blocks = element_schur(B_inv, A_LI)[:n_g][:, :n_g]
    assert abs(condensed - blocks).max() <= 1e-12 * abs(blocks).max()


def test_the_element_schur_complements_keep_explicit_zeros_out_of_the_way():
    """NGSolve's patterns hold explicit zeros: a column a triangle touches only with zeros
    (here its last one) must not take another column's place."""
    rng = np.random.default_rng(0)
    size, n_tri, n_glob = 3, 4, 7
    blocks = rng.normal(size=(n_tri, size, size)) + 4 * np.eye(size)
    B_inv = sp.bsr_matrix((np.linalg.inv(blocks), np.arange(n_tri), np.arange(n_tri + 1)),
                          shape=(n_tri * size, n_tri * size))
    dense = np.zeros((n_tri * size, n_glob))
    for t in range(n_tri):
        dense[t * size:(t + 1) * size, t:t + 3] = rng.normal(size=(size, 3))
    A = sp.csr_matrix(dense)
    rows, cols = [0, 1, 2], [6, 6, 6]  # triangle 0 touches column 6 with zeros only
    A = sp.csr_matrix((np.concatenate([A.data, np.zeros(3)]),
                       (np.concatenate([A.tocoo().row, rows]),
                        np.concatenate([A.tocoo().col, cols]))), shape=A.shape)
    assert A.nnz == np.count_nonzero(dense) + 3
    expected = dense.T @ (B_inv @ dense)
    assert np.allclose(element_schur(B_inv, A).toarray(), expected, rtol=0, atol=1e-13)
