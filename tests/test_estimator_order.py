"""The indicators of (4.50) at order k: exactness, effectivity and rate against exact solutions.

* PEERS_k reproduces a displacement that is a polynomial of degree k (sigma of degree
  k - 1 lies in RT_k, u in P_k, the rotation in P_{k+1}, the facet multipliers in P_k), so
  every term of (4.50) must vanish to round-off: the stress terms, and the displacement
  terms only if ``u_volume`` is h_T^2 ||w_h - grad_h u_h||^2 (with the thesis'
  h_T^2 ||w_h||^2 it is h_T^2 ||grad u||^2, not small).
* On a smooth solution (trigonometric u on the unit square, Dirichlet and Neumann sides)
  and on the manufactured frictionless contact case of
  :mod:`ngdual.verification.manufactured` (contact set [-2, 2], exact sigma piecewise
  polynomial in strips aligned with the mesh), the estimate falls with the error's order
  k + 1 in h_N = N^{-1/2} and the effectivity index, estimate / ||sigma - sigma_h||_{C^{-1}}
  (the compliance norm), stays in a fixed band.

Run with ``pytest -s`` to see the tables.
"""

import math
from functools import cache

import ngsolve as ngs
import numpy as np
import pytest
from test_manufactured_convergence import elasticity_fields, poly_add, poly_scale, poly_text

from ngdual import peers
from ngdual.estimator import TERMS, estimate
from ngdual.mesh import build_mesh
from ngdual.quantities import fields
from ngdual.rates import observed_rates
from ngdual.scene import Discretisation, Geometry, Loads, Material, Scene, validate
from ngdual.solvers import solve_on_mesh
from ngdual.verification.integrate import PiecewiseQuadrature
from ngdual.verification.manufactured import manufactured_case
from ngdual.verification.manufactured_errors import _coefficient

E, NU = 100.0, 0.3
PENTAGON = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 2.0), (0.0, 1.0)]
SIDES = ["bottom", "right", "roof_right", "roof_left", "left"]
SQUARE = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
SQUARE_SIDES = ["bottom", "right", "top", "left"]
# the measured band (docs/theory/estimator.md, "The estimator at order k"): 21-36 at
# k = 1, 2 on both problems, 23-26 for the thesis' k = 0 on the contact case
EFFECTIVITY_BAND = (20.0, 40.0)
RATE_SLACK = 0.35            # |rate of the estimate - rate of the error| on every level
ORDER_SLACK = 0.2            # |rate of the estimate - (k + 1)| on the last level


def polynomial_scene(order: int) -> Scene:
    """u of degree k on the pentagon, (2 x^k - 2 y^k + x^(k-1) y, 2 x^k + 4 y^k - 2 x) / 20
    plus a translation (grad u not symmetric), Neumann on roof_right (normal (1, 1)/sqrt 2),
    Dirichlet elsewhere."""
    lam, mu = Material(E, NU).lame
    u = [poly_add({(order, 0): 0.1, (0, order): -0.1, (0, 0): 0.3}, {(order - 1, 1): 0.05}),
         {(order, 0): 0.1, (0, order): 0.2, (1, 0): -0.1, (0, 0): -0.2}]
    _, sigma, div_sigma = elasticity_fields(u, lam, mu)
    n = 1 / math.sqrt(2)
    traction = [poly_scale(poly_add(sigma[i][0], sigma[i][1]), n) for i in range(2)]
    sc = Scene(name=f"polynomial-{order}",
               geometry=Geometry(kind="polygon", points=PENTAGON, labels=SIDES, maxh=0.5),
               boundary={"dirichlet": [s for s in SIDES if s != "roof_right"],
                         "neumann": ["roof_right"]},
               material=Material(E, NU),
               loads=Loads(body_force=[poly_text(poly_scale(d, -1)) for d in div_sigma],
                           traction=[poly_text(t) for t in traction],
                           displacement=[poly_text(c) for c in u]),
               discretisation=Discretisation(order=order))
    validate(sc)
    return sc


@pytest.mark.parametrize("order", [1, 2])
def test_every_term_vanishes_when_peers_k_reproduces_a_polynomial_of_degree_k(order):
    sc = polynomial_scene(order)
    solution = solve_on_mesh(sc, build_mesh(sc.geometry, 1))
    est = estimate(solution)
    f = fields(solution)
    mesh = solution.problem.fes.mesh
    # the squares of sigma_h and of h grad u_h: the scales of the stress and strain terms
    scale = min(ngs.Integrate(ngs.InnerProduct(f.sigma, f.sigma), mesh),
                est.h.min()**2 * ngs.Integrate(f.u[0]**2 + f.u[1]**2, mesh))
    sums = est.summed()
    print(f"\nk = {order}, polynomial of degree k, summed squared terms:",
          {k: f"{v:.1e}" for k, v in sums.items()}, f"scale {scale:.1e}")
    assert set(est.terms) == set(TERMS)
    for name, value in sums.items():
        assert value <= 1e-20 * scale, (name, value)


# --- a smooth solution: u = (sin pi x sin pi y, cos pi x cos pi y), div u = 0 -------------------

def smooth_scene(order: int) -> Scene:
    """The unit square, Neumann on the right side, the exact u on the others.

    div u = 0, so sigma = 2 mu eps(u) = 2 mu pi cos(pi x) sin(pi y) diag(1, -1) and
    f = -div sigma = 2 mu pi^2 u; on x = 1 the traction is (-2 mu pi sin(pi y), 0).
    """
    _, mu = Material(E, NU).lame
    u = ["sin(pi*x)*sin(pi*y)", "cos(pi*x)*cos(pi*y)"]
    sc = Scene(name="smooth-square",
               geometry=Geometry(kind="polygon", points=SQUARE, labels=SQUARE_SIDES, maxh=0.3),
               boundary={"dirichlet": ["bottom", "top", "left"], "neumann": ["right"]},
               material=Material(E, NU),
               loads=Loads(body_force=[f"{2 * mu * math.pi**2!r}*{c}" for c in u],
                           traction=[f"{-2 * mu * math.pi!r}*sin(pi*y)", "0"],
                           displacement=u),
               discretisation=Discretisation(order=order))
    validate(sc)
    return sc


def smooth_sigma(mu: float) -> ngs.CoefficientFunction:
    s = 2 * mu * math.pi * ngs.cos(math.pi * ngs.x) * ngs.sin(math.pi * ngs.y)
    return ngs.CF((s, 0, 0, -s), dims=(2, 2))


def compliance_norm(error, solution, integrate) -> float:
    """||e||_{C^{-1}} = (int e : C^{-1} e dx)^{1/2}."""
    lam, mu = solution.problem.scene.material.lame
    return math.sqrt(integrate(ngs.InnerProduct(peers.compliance(error, lam, mu), error)))


def smooth_row(order: int, level: int) -> dict:
    sc = smooth_scene(order)
    solution = solve_on_mesh(sc, build_mesh(sc.geometry, level))
    mesh = solution.problem.fes.mesh
    error = smooth_sigma(sc.material.lame[1]) - fields(solution).sigma
    rule = 2 * peers.stress_degree("peers", order) + 6
    return _row(solution, compliance_norm(error, solution,
                                          lambda cf: ngs.Integrate(cf, mesh, order=rule)))


def contact_row(order: int, level: int) -> dict:
    case = manufactured_case("frictionless")
    sc = case.scene(order=order)
    solution = solve_on_mesh(sc, build_mesh(sc.geometry, level))
    ex = case.exact
    breaks = sorted({b for p in (*ex.sigma[0], *ex.sigma[1]) for b in p.breaks})
    quadrature = PiecewiseQuadrature(solution.problem.fes.mesh, breaks,
                                     max(2 * ex.degree, 2 * peers.stress_degree("peers", order)))
    exact = ngs.CF(tuple(_coefficient(ex.sigma[i][j]) for i in range(2) for j in range(2)),
                   dims=(2, 2))
    return _row(solution, compliance_norm(exact - fields(solution).sigma, solution,
                                          quadrature.integrate))


def _row(solution, error: float) -> dict:
    est = estimate(solution)
    return {"ndof": sum(solution.problem.spaces.dofs().values()), "error": error,
            "estimate": est.total, "effectivity": est.total / error}


@cache
def table(problem: str, order: int, levels: tuple[int, ...]) -> list[dict]:
    row = {"smooth": smooth_row, "contact": contact_row}[problem]
    rows = [row(order, level) for level in levels]
    ndof = [r["ndof"] for r in rows]
    for key in ("error", "estimate"):
        for r, rate in zip(rows, observed_rates(ndof, [r[key] for r in rows])):
            r[key + "_rate"] = rate
    print(f"\n{problem}, k = {order}: level, unknowns, ||sigma - sigma_h||_C^-1 (rate), "
          "estimate (rate), effectivity")
    for level, r in zip(levels, rows):
        rates = ("" if r["error_rate"] is None
                 else f" ({r['error_rate']:.2f})", "" if r["estimate_rate"] is None
                 else f" ({r['estimate_rate']:.2f})")
        print(f"{level:3d} {r['ndof']:7d} {r['error']:.3e}{rates[0]} {r['estimate']:.3e}"
              f"{rates[1]} {r['effectivity']:.2f}")
    return rows


def check_effectivity_and_rate(rows: list[dict], order: int) -> None:
    low, high = EFFECTIVITY_BAND
    assert all(low <= r["effectivity"] <= high for r in rows), [r["effectivity"] for r in rows]
    assert all(abs(r["estimate_rate"] - r["error_rate"]) <= RATE_SLACK for r in rows[1:]), rows
    assert abs(rows[-1]["estimate_rate"] - (order + 1)) <= ORDER_SLACK, rows[-1]


@pytest.mark.parametrize("problem", ["smooth", "contact"])
def test_the_estimate_of_order_1_falls_like_the_error_at_order_2_in_a_fixed_band(problem):
    check_effectivity_and_rate(table(problem, 1, (1, 2, 3)), 1)


@pytest.mark.slow
@pytest.mark.parametrize("problem", ["smooth", "contact"])
@pytest.mark.parametrize("order", [1, 2])
def test_the_estimate_of_order_k_falls_like_the_error_in_a_fixed_band_over_four_levels(
        problem, order):
    check_effectivity_and_rate(table(problem, order, (1, 2, 3, 4)), order)


def test_the_facet_multipliers_jump_less_than_the_estimate():
    """The facet multipliers are discontinuous at the vertices of Gamma_C; their jumps are
    not a term of the estimator (they fall like h^{k+1/2}, docs/theory/estimator.md), and on
    the manufactured contact case they are below 1 % of the estimate."""
    case = manufactured_case("frictionless")
    sc = case.scene(order=1)
    solution = solve_on_mesh(sc, build_mesh(sc.geometry, 2))
    pb = solution.problem
    gamma_c = pb.spaces.gamma_c
    fine = pb.to_fine(solution.x)
    ends = {}
    for name in ("lam_n", "lam_t"):
        r = pb.fes.Range(pb.names.index(name))
        ends[name] = fine[r.start:r.stop][gamma_c.edge_dofs]
    jumps = np.hypot(ends["lam_n"][1:, 0] - ends["lam_n"][:-1, 1],
                     ends["lam_t"][1:, 0] - ends["lam_t"][:-1, 1])
    assert len(gamma_c.coarse.chains) == 1
    assert np.sqrt(np.sum(jumps**2)) < 0.01 * estimate(solution).total
