"""Boundary multipliers of order k (ngdual.verification.multipliers).

* Two independent paths agree: the thesis' coarse P1 multipliers on h~ = 2h, built here from
  Legendre polynomials on the fine edges and paired through a SurfaceL2 host, give the
  inf-sup constants of ``ngdual bench infsup`` (assembled by ngdual.forms from the coarse
  P1 prolongation) on the shipped scenes, and the mass and arc-length stiffness of the
  coarse P1 space of ngdual.boundary.
* The facet P_k multipliers of the contact solver (ngdual.boundary.facet, Bernstein basis,
  d assembled by ngdual.forms) have the constants of this module's facet family, k = 1, 2.
* The chosen pairs -- continuous degree k + 1 on h~ = 2h and discontinuous P_k on the fine
  edges -- keep beta_h above a fixed bound and gamma_h below one, k = 0, 1, 2, over four
  refinements (the tables of docs/theory/order.md: the unit square, and Example 3.46 with
  Gamma_N and Gamma_C); on h~ = h the continuous multipliers against PEERS_k lose
  stability like h.
"""

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.polynomial import legendre

from ngdual import peers
from ngdual.boundary import CoarseMesh
from ngdual.boundary.facet import bernstein_values
from ngdual.forms import assemble
from ngdual.mesh import build_mesh
from ngdual.scene import SceneError, load_scene
from ngdual.studies.bench.infsup import infsup
from ngdual.verification import multipliers as m
from ngdual.verification.infsup import dense_singular_values, gram_matrix
from ngdual.verification.order import unit_square

DOCS = Path(__file__).resolve().parents[1] / "docs" / "theory" / "order.md"
CHOSEN = (("coarse", 2), ("facet", 1))
BETA_MIN = 0.65     # below every beta_h of the chosen pairs, PEERS_k and AFW_k, k <= 2
GAMMA_MAX = 2.0     # above every gamma_h of the chosen pairs


def documented(family: str, multipliers: str, ratio: int, k: int) -> list[tuple[float, float]]:
    """(beta_h, gamma_h) on levels 1-4 of the multiplier table in docs/theory/order.md."""
    for line in DOCS.read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells[:4] == [family.upper(), multipliers, str(ratio), str(k)] and len(cells) == 8:
            return [(float(c.split()[0]), float(c.split()[1].strip("()"))) for c in cells[4:]]
    raise LookupError(f"{family} {multipliers} {ratio} {k} in {DOCS}")


def model(multipliers: str, ratio: int, k: int, levels, family: str = "peers") -> list[dict]:
    return [m.constants(unit_square(level), m.model_parts(), multipliers, k, ratio, family)
            for level in levels]


@pytest.mark.parametrize("name", ["thesis-3.46-frictionless", "wedge"])
def test_the_coarse_p1_pairing_gives_the_constants_of_ngdual_bench_infsup(name):
    scene = load_scene(name, [])
    for level in (1, 2):
        assert m.scene_constants(scene, level)["beta"] == pytest.approx(
            infsup(scene, level)["beta"], rel=1e-10)


@pytest.mark.parametrize("k", [1, 2])
def test_the_facet_multipliers_of_the_contact_solver_have_the_constants_of_the_facet_family(k):
    """The solver's facet P_k (Bernstein coefficients on a Discontinuous H1 host, d assembled
    by ngdual.forms) against this module's (Legendre on a SurfaceL2 host), in one norm."""
    scene = load_scene("thesis-3.46-frictionless",
                       [f"discretisation.order={k}", "discretisation.multipliers=facet",
                        "contact.ends='consistent'"])
    mesh = build_mesh(scene.geometry, 1)
    problem = assemble(scene, mesh)
    B = problem.block(problem.sigma, problem.index("phi1", "phi2", "lam_t", "lam_n")).toarray()
    X = gram_matrix(problem)[problem.sigma][:, problem.sigma]
    # the Legendre coefficients of the Bernstein polynomials of one edge
    t = (legendre.leggauss(k + 1)[0] + 1) / 2
    to_legendre = legendre.legfit(2 * t - 1, bernstein_values(k, t), k)
    stresses, norms = m.Stresses.of(mesh, "peers", k), []
    for part in m.scene_parts(scene, mesh):
        basis = m.multiplier_basis(mesh, part, "facet", k, ratio=1)
        T = sla.block_diag(*[to_legendre] * (2 * basis.n_dofs // (k + 1)))
        norms.append(T.T @ m.pair(basis, part, stresses.fes, stresses.names, k).norm @ T)
    solver = dense_singular_values(X, B, sla.block_diag(*norms), indices=(0, -1))
    mine = m.scene_constants(load_scene("thesis-3.46-frictionless", []), 1, "facet", k, 1)
    assert solver == pytest.approx([mine["beta"], mine["gamma"]], rel=1e-10)


def test_the_coarse_p1_basis_has_the_mass_and_stiffness_of_the_coarse_p1_space():
    mesh = unit_square(2)
    coarse = CoarseMesh.from_fine(mesh, ["bottom"], 2)
    stresses = m.Stresses.of(mesh, "peers", 0)
    pairing = m.pair(m.coarse_basis(coarse, 0), m.model_parts()[0], stresses.fes,
                     stresses.names, 0)
    mass, stiff = coarse.p1_mass_stiffness()
    assert pairing.mass == pytest.approx(mass, abs=1e-14)
    assert pairing.stiff == pytest.approx(stiff, abs=1e-10)


def test_the_facet_space_has_the_dimension_of_the_normal_traces_of_rt_k_on_the_part():
    for k in (0, 1):
        mesh = unit_square(1)
        basis = m.multiplier_basis(mesh, m.model_parts()[0], "facet", k, ratio=1)
        stresses = m.Stresses.of(mesh, "peers", k)
        B = m.pair(basis, m.model_parts()[0], stresses.fes, stresses.names, k).B
        # one row of RT_k traces per fine edge and degree: the pairing is onto them
        assert basis.n_dofs == 4 * (k + 1)
        assert np.linalg.matrix_rank(B.toarray()) == 2 * basis.n_dofs


@pytest.mark.parametrize("multipliers, ratio", CHOSEN)
@pytest.mark.parametrize("k", [0, 1])
def test_the_chosen_pairs_have_the_documented_constants_on_two_levels(multipliers, ratio, k):
    rows = model(multipliers, ratio, k, levels=(1, 2))
    found = [(r["beta"], r["gamma"]) for r in rows]
    expected = documented("peers", multipliers, ratio, k)[:2]
    assert [b for b, _ in found] == pytest.approx([b for b, _ in expected], abs=5e-5)
    assert [g for _, g in found] == pytest.approx([g for _, g in expected], abs=5e-3)
    assert min(b for b, _ in found) > BETA_MIN and max(g for _, g in found) < GAMMA_MAX


@pytest.mark.parametrize("multipliers, ratio", CHOSEN)
def test_the_chosen_pairs_of_order_1_on_example_3_46_have_the_documented_constants(
        multipliers, ratio):
    scene = load_scene("thesis-3.46-frictionless", [])
    found = [m.scene_constants(scene, level, multipliers, 1, ratio)["beta"] for level in (1, 2)]
    expected = [b for b, _ in documented("3.46", multipliers, ratio, 1)[:2]]
    assert found == pytest.approx(expected, abs=5e-5)
    assert min(found) > BETA_MIN


@pytest.mark.parametrize("k", [0, 1])
def test_continuous_multipliers_on_the_fine_mesh_lose_stability_like_h(k):
    betas = [r["beta"] for r in model("coarse", 1, k, levels=(1, 2, 3))]
    assert np.diff(np.log2(betas)) == pytest.approx([-1, -1], abs=0.1)


def test_facet_multipliers_on_a_coarse_mesh_are_refused():
    with pytest.raises(SceneError):
        m.multiplier_basis(unit_square(1), m.model_parts()[0], "facet", 0, ratio=2)
    with pytest.raises(SceneError):
        m.multiplier_basis(unit_square(1), m.model_parts()[0], "mortar", 0)


@pytest.mark.slow
@pytest.mark.parametrize("family", peers.FAMILIES)
@pytest.mark.parametrize("multipliers, ratio", CHOSEN)
@pytest.mark.parametrize("k", [0, 1, 2])
def test_the_chosen_pairs_stay_above_a_fixed_bound_over_four_refinements(
        family, multipliers, ratio, k):
    rows = model(multipliers, ratio, k, levels=(1, 2, 3, 4), family=family)
    betas, gammas = [r["beta"] for r in rows], [r["gamma"] for r in rows]
    expected = documented(family, multipliers, ratio, k)
    assert betas == pytest.approx([b for b, _ in expected], abs=5e-5)
    assert gammas == pytest.approx([g for _, g in expected], abs=5e-3)
    assert min(betas) > BETA_MIN and max(gammas) < GAMMA_MAX
    assert betas[-1] / betas[-2] > 0.97        # settled: the last refinement moves it little
