"""The coarse multipliers of order k: continuous P_{k+1} on h~ in the Bernstein basis
(``discretisation.multipliers = "coarse"`` at k = 1, 2, :mod:`ngdual.boundary.coarse_order`)."""

import numpy as np
import pytest
import scipy.sparse as sp

import ngdual as nd
from ngdual.afem import adapt
from ngdual.boundary import CoarseMesh
from ngdual.boundary.coarse_order import CoarseOrderMesh
from ngdual.boundary.facet import bernstein_values
from ngdual.forms import assemble
from ngdual.mesh import build_mesh
from ngdual.scene import SceneError, load_scene
from ngdual.solvers.conforming import conforming_active_set
from ngdual.solvers.dispatch import solve_problem
from ngdual.solvers.qp import solve_qp
from ngdual.solvers.settings import Model, solver_settings
from ngdual.verification.multipliers import coarse_basis


def _scene(name: str, order: int, *more: str):
    ends = ["contact.ends='consistent'"] if name.startswith("thesis") else []
    return load_scene(name, [f"discretisation.order={order}",
                             "discretisation.multipliers='coarse'", *ends, *more])


def _problem(name: str, order: int, level: int):
    scene = _scene(name, order)
    return scene, assemble(scene, build_mesh(scene.geometry, level))


@pytest.mark.parametrize("order", [1, 2])
def test_the_coarse_bernstein_functions_sum_to_one_and_are_continuous_along_gamma_c(order):
    """Unknowns and fixed-end coefficients all one give mu = 1 on every fine edge: the
    Bernstein basis of degree k + 1 is a partition of unity on every h~ edge, and the shared
    node coefficients make it continuous (P reproduces the constant exactly)."""
    scene, problem = _problem("thesis-3.46-frictionless", order, 2)
    spaces = problem.spaces
    assert isinstance(spaces.contact, CoarseOrderMesh)
    ones = (spaces.prolongations["lam_n"] @ np.ones(spaces.coarse_ndof("lam_n"))
            + spaces.end_hats["lam_n"] @ np.ones(spaces.end_hats["lam_n"].shape[1]))
    means = spaces.gamma_c.hat_means(sp.csr_matrix(ones[:, None])).toarray().ravel()
    assert np.allclose(means, 1.0, rtol=0, atol=1e-13)
    # any coefficients: the end value of every fine edge is the start value of the next
    mu = spaces.prolongations["lam_n"] @ np.random.default_rng(0).random(
        spaces.coarse_ndof("lam_n"))
    edge_dofs = spaces.gamma_c.edge_dofs
    assert np.allclose(mu[edge_dofs[:-1, 1]], mu[edge_dofs[1:, 0]], rtol=0, atol=1e-13)
    # (k + 1) coefficients per h~ edge, the nodes shared: N_C = (k + 1) n_edges - fixed ends + 1
    contact = spaces.contact
    assert spaces.dofs()["C"] == (order + 1) * contact.n_edges + 1 - len(contact.end_points())
    # every unknown has a node view: a chain vertex within a fine edge of its control point
    positions = np.concatenate([contact.dof_positions(c) for c in range(len(contact.chains))])
    points = np.vstack([chain.path_points[contact.dof_positions(c)]
                        for c, chain in enumerate(contact.chains)])
    assert len(positions) == spaces.dofs()["C"]
    assert np.max(np.linalg.norm(points - contact.node_points(), axis=1)) \
        <= 0.5 * np.max(spaces.gamma_c.lengths) + 1e-12


@pytest.mark.parametrize("order", [1, 2])
def test_the_coarse_space_is_the_one_whose_inf_sup_constants_docs_tabulate(order):
    """The Bernstein unknowns span the same space as the hats and Legendre bubbles of
    ngdual.verification.multipliers.coarse_basis (built independently, for the inf-sup
    table of docs/theory/order.md): equal dimensions, and the values of either basis on
    every fine edge are combinations of the other's."""
    scene, problem = _problem("thesis-3.46-frictionless", order, 2)
    mine = problem.spaces.contact
    basis = coarse_basis(CoarseMesh(mine.chains, mine.nodes, mine.free, mine.breaks), order)
    n, p = mine.n_coefficients, order + 1
    t = np.linspace(0, 1, 2 * p + 1)
    R = mine.restriction()[:, :n].toarray()
    ours = np.vstack([bernstein_values(p, t) @ R[p_e:p_e + p + 1]
                      for p_e in range(0, R.shape[0], p + 1)])
    theirs = np.zeros((len(ours), basis.n_dofs))
    for e, dofs in enumerate(basis.dofs):
        theirs[e * len(t):(e + 1) * len(t), dofs] = basis.values(e, t).T
    assert basis.n_dofs == n
    rank = np.linalg.matrix_rank
    assert rank(ours) == rank(theirs) == rank(np.hstack([ours, theirs])) == n


@pytest.mark.parametrize("order", [1, 2])
def test_the_gap_interpolant_of_degree_k_plus_1_is_a_gap_of_that_degree_itself(order):
    """On the straight Gamma_C of Example 3.46 a gap of degree k + 1 in x is its own
    interpolant on the h~ mesh: its means over every fine edge (the prolongation to the
    host) are the gap's, integrated exactly by Gauss."""
    gap = f"0.01 + 0.0001*(x + 4)**{order + 1}"
    scene = _scene("thesis-3.46-frictionless", order, f"contact.gap='{gap}'",
                   "contact.discrete_gap='nodal'")
    problem = assemble(scene, build_mesh(scene.geometry, 2))
    spaces, gamma_c = problem.spaces, problem.spaces.gamma_c
    coefficients = gamma_c.gap_interpolant(spaces.prolongations["lam_n"],
                                           spaces.end_hats["lam_n"])
    means = gamma_c.hat_means(sp.csr_matrix(coefficients[:, None])).toarray().ravel()
    t, w = np.polynomial.legendre.leggauss(order + 2)
    starts = np.vstack([chain.path_points[:-1] for chain in spaces.contact.chains])
    stops = np.vstack([chain.path_points[1:] for chain in spaces.contact.chains])
    x = starts[:, :1] + 0.5 * (t + 1)[None, :] * (stops[:, :1] - starts[:, :1])
    exact = 0.5 * (0.01 + 0.0001 * (x + 4) ** (order + 1)) @ w
    assert np.allclose(means, exact, rtol=0, atol=1e-14)


@pytest.mark.parametrize("name, order, level", [
    ("thesis-3.46-frictionless", 1, 1), ("thesis-3.46-frictionless", 1, 2),
    ("thesis-3.46-frictionless", 2, 1), ("thesis-3.46-frictionless", 2, 2),
    ("hertz-cylinder", 1, 1), ("hertz-cylinder", 2, 1),
])
def test_both_active_set_solvers_give_the_qp_solution_with_the_coarse_multipliers(
        name, order, level):
    """The hybridised solver (the default), the conforming one and Clarabel's QP solve the
    same frictionless problem to round-off, with lambda_n >= 0 on the Bernstein unknowns."""
    scene, problem = _problem(name, order, level)
    settings = solver_settings(scene)
    hybrid = solve_problem(problem, settings)
    conforming = conforming_active_set(problem, settings)
    qp = solve_qp(problem, Model.of(scene))
    scale = np.max(np.abs(hybrid.x))
    assert hybrid.method == "active-set"
    assert np.max(np.abs(hybrid.x - qp.x)) <= 1e-9 * scale
    assert np.max(np.abs(conforming.x - qp.x)) <= 1e-9 * scale
    assert max(hybrid.residuals.values()) < 1e-11
    assert np.min(hybrid.x[problem.lam_n]) >= -1e-12 * np.max(hybrid.x[problem.lam_n])


@pytest.mark.parametrize("overrides, field", [
    (["friction.law='coulomb'", "friction.mu=0.5"], "friction.law"),
])
def test_what_the_coarse_multipliers_cannot_solve_at_order_k_is_a_scene_error(overrides, field):
    with pytest.raises(SceneError) as err:
        _scene("thesis-3.46-frictionless", 1, *overrides)
    assert err.value.field == field


@pytest.mark.parametrize("goal", ["stress", "pressure"])
def test_adapt_runs_with_the_coarse_multipliers_of_order_1_and_keeps_their_mesh_nested(goal):
    """The adaptive loop carries the h~ mesh over (CoarseMesh.follow) and the estimator and
    the goal read the multipliers of degree k + 1 through their prolongation."""
    history = adapt(_scene("hertz-cylinder", 1), steps=2, level=1, goal=goal)
    assert len(history) == 2
    assert all(np.isfinite(r["estimator"]) and r["estimator"] > 0 for r in history)
    assert history[1]["elements"] > history[0]["elements"]


def test_the_coarse_family_is_measured_by_its_traces_which_converge():
    """At order k the pressure samples of the coarse family are the traces -sigma_nn^h
    (4k + 2 per fine edge; its unknowns are Bernstein coefficients on h~, not nodal
    values), and they approach a finer facet solution of Example 3.46 level by level."""
    from ngdual.studies.figures.hats import pressure_distance
    from ngdual.verification.overkill import solution_samples

    def samples(level, family):
        scene = load_scene("thesis-3.46-frictionless",
                           ["contact.ends=consistent", f"geometry.level={level}",
                            "discretisation.order=1", f"discretisation.multipliers={family}"])
        solution = nd.solve(scene)
        return solution, solution_samples(solution)

    _, reference = samples(3, "facet")
    distances = []
    for level in (1, 2):
        solution, coarse = samples(level, "coarse")
        assert len(coarse["p"]) == 6 * len(solution.problem.spaces.gamma_c.lengths)
        distances.append(pressure_distance(coarse, reference))
    assert distances[1] < 0.7 * distances[0] and distances[1] < 0.2, distances
