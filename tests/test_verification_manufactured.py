"""Manufactured contact solutions: exact errors, observed orders, exact contact and stick sets.

The cases (:mod:`ngdual.verification.manufactured`) live on the rectangle of Example 3.46
with Gamma_C = bottom and are built from their traces on Gamma_C, so the contact set
[-a, a], the stick set [-b, b] and the slip set between them are known exactly:

* ``frictionless``: a = 2, a coarse (h~) node on every level;
* ``tresca``: F = 1 on all of Gamma_C, a = 2, stick for |x| <= 1 and |x| >= 3, all on
  coarse and h^ nodes from level 3 on;
* ``coulomb``: mu_f = 0.5, a = 7/3, b = 2/3: not dyadic, so every set end point lies a third
  of the way into an h~ edge (and inside an h^ edge) on every level.

Why first order. The exact u is C^1 with piecewise polynomial second derivatives, so
sigma is in H^{3/2-eps}, in particular H^1, u and eta are in H^1, lambda_n and lambda_t are
C^1 on Gamma_C (in H^{3/2}). The approximation properties (3.89)-(3.91) of PEERS and of the
P1 multipliers on h~ = 2h then give O(h) best-approximation errors for sigma (L2), u, eta
and the multipliers. The inequality constraints add, by Falk's lemma, the consistency terms
d_Cn(I lambda_n - lambda_n, sigma) and q(I lambda_t - lambda_t, nu) with I the nodal
interpolant on h~ (admissible: I lambda_n >= 0): they vanish on every h~ edge that lies
inside the contact set (lambda_n = 0) or inside the separation set (sigma_n = 0), and on
the O(1) edges containing a set end point both factors are O(h~^2), so these terms are
O(h^3), below the O(h^2) of the squared error. Hence ||sigma - sigma_h||, ||u - u_h||,
||eta - eta_h|| = O(h) (Theorem 3.35 with the heuristic (3.94) for nu on h^ = 2h~).
div sigma = -f is piecewise polynomial with jumps across the lines x = +-a, +-b: its
P0 projection error is O(h) where those are mesh lines (the dyadic cases) and O(h^{1/2})
otherwise, so the H(div) error of ``coulomb`` converges at order 1/2 only.

Sets: the discrete contact set (h~ edges where lambda_n^h = 0) and stick set (h^ edges
with |nu| < 1 inside it) are compared with the exact ones by the length of the symmetric
difference. A grid cannot place an end point between its nodes (``*_resolution``, zero on
the dyadic cases); beyond that the end points are recovered within one edge, and exactly on
the dyadic cases except for one node next to the edge of the Tresca contact zone (see
:func:`ngdual.verification.manufactured_errors.contact_profile`).

Run with ``pytest -s`` to see the convergence tables.
"""

from functools import cache

import numpy as np
import pytest

from ngdual.expr import Expression
from ngdual.solvers import solve_scene
from ngdual.trace import contact_traces, friction_diagnostics
from ngdual.verification import (
    Piecewise,
    discrete_sets,
    format_study,
    manufactured_case,
    manufactured_study,
)

LEVELS = (2, 3, 4, 5)
CASES = ("frictionless", "tresca", "coulomb")
ON_NODES = ("frictionless", "tresca")
MIN_ORDER = 0.9
MIN_ORDER_HDIV_OFF_NODES = 0.4   # theory 1/2: div sigma jumps across lines inside elements


@cache
def study(name):
    rows = manufactured_study(name, LEVELS)
    print("\n" + format_study(rows))
    return rows


def order(rows, key, k):
    """Observed order between rows k-1 and k."""
    return np.log(rows[k - 1][key] / rows[k][key]) / np.log(rows[k - 1]["h"] / rows[k]["h"])


# --- the exact solutions -------------------------------------------------------------------------

def test_piecewise_calculus_is_exact_and_its_formulas_evaluate_alike():
    """Product rule, mirror and the scene formula agree with the NumPy values."""
    f = Piecewise.ramp(1.0, 3) * Piecewise.y() + Piecewise.x() ** 2
    g = Piecewise.ramp(-0.5, 2, right=False)
    x, y = np.linspace(-3, 3, 61), np.linspace(-1, 1, 61)
    lhs = (f * g).dx().numpy(x, y)
    rhs = (f.dx() * g + f * g.dx()).numpy(x, y)
    assert np.allclose(lhs, rhs, atol=1e-12)
    assert np.allclose(f.mirrored().numpy(x, y), f.numpy(-x, y))
    assert np.allclose(Expression((f * g).text()).numpy(x, y), (f * g).numpy(x, y), atol=1e-12)


@pytest.mark.parametrize("name", [*CASES, "coulomb-nodes", "frictionless-offnode"])
def test_exact_solution_satisfies_contact_and_friction_laws_with_the_stated_sets(name):
    """(3.1) on Gamma_C in ngdual's signs, and the contact / stick / slip sets as stated.

    lambda_n = g - u_n >= 0, sigma_n <= 0, lambda_n sigma_n = 0, sigma_n < 0 inside the
    contact set and lambda_n > 0 outside it; |sigma_t| <= F, sigma_t = F sign(lambda_t)
    where lambda_t = -u_t != 0 (slip against the traction), lambda_t = 0 with |sigma_t| < F
    inside the stick set; lambda_n = lambda_t = 0 at the ends of Gamma_C.
    """
    case = manufactured_case(name)
    ex = case.exact
    x = np.linspace(-4, 4, 4001)
    y = np.full_like(x, -1.0)
    sn, st = ex.sigma[1][1].numpy(x, y), ex.sigma[0][1].numpy(x, y)
    ln, lt = (ex.gap + ex.u[1].at_y(-1.0)).numpy(x, 0 * x), ex.u[0].numpy(x, y)
    F = ex.friction_bound.numpy(x, 0 * x)
    tol, stress_tol = 1e-12, 1e-10     # round-off of the expanded polynomials
    assert np.allclose(sn, case.sigma_n.numpy(x, 0 * x), atol=stress_tol)
    assert np.allclose(ln, case.lam_n.numpy(x, 0 * x), atol=tol)
    assert sn.max() <= stress_tol and ln.min() >= -tol and np.abs(sn * ln).max() <= tol
    assert abs(ln[0]) + abs(ln[-1]) + abs(lt[0]) + abs(lt[-1]) <= tol
    (lo, hi), = case.contact_set
    inside, outside = (x > lo + 1e-3) & (x < hi - 1e-3), (x < lo - 1e-3) | (x > hi + 1e-3)
    assert sn[inside].max() < 0
    assert ln[outside & (np.abs(x) < 4 - 1e-3)].min() > 0
    if case.law == "none":
        assert np.abs(st).max() <= stress_tol
    else:
        assert np.all(np.abs(st) <= F + stress_tol)
        moving = np.abs(lt) > 1e-9
        assert np.allclose(st[moving], F[moving] * np.sign(lt[moving]), atol=1e-10)
        (b0, b1), = case.stick_set
        stick = (x > b0 + 1e-3) & (x < b1 - 1e-3)
        slip = inside & ~((x > b0 - 1e-3) & (x < b1 + 1e-3))
        assert np.abs(lt[stick]).max() <= tol and np.all(np.abs(st[stick]) < F[stick])
        assert np.all(np.abs(lt[slip]) > 0) and np.all(F[slip] > 0)
    assert ex.gap.numpy(x, 0 * x).min() >= -tol


@pytest.mark.parametrize("name", CASES)
def test_exact_stress_is_the_elastic_stress_of_a_c1_displacement(name):
    """C^{-1} sigma = eps(u) exactly, and u, grad u are continuous across every breakpoint."""
    case = manufactured_case(name)
    ex = case.exact
    lam, mu = case.material.lame
    trace = ex.sigma[0][0] + ex.sigma[1][1]
    grad = [[ex.u[i].dx(), ex.u[i].dy()] for i in range(2)]
    x, y = np.linspace(-4, 4, 801), np.linspace(-1, 1, 801)
    for i in range(2):
        for j in range(2):
            compliance = (ex.sigma[i][j] - (lam / (2 * (lam + mu)) * trace if i == j else 0.0)) \
                / (2 * mu)
            strain = 0.5 * (grad[i][j] + grad[j][i])
            assert np.abs((compliance - strain).numpy(x, y)).max() < 1e-12
    for component in ex.u:
        jumps = component.jumps(1, ys=(-1.0, 0.0, 1.0)) + component.dy().jumps(0, ys=(-1.0, 1.0))
        assert max(jumps) < 1e-12, jumps
    assert max(p.degree for p in ex.div_sigma) > 0


# --- convergence ---------------------------------------------------------------------------------

@pytest.mark.parametrize("name", [CASES[0], *(pytest.param(c, marks=pytest.mark.slow)
                                              for c in CASES[1:])])
def test_sigma_u_eta_converge_at_first_order_and_the_multipliers_converge(name):
    """Orders on the last two refinements: sigma (L2), u, eta >= 0.9; sigma in H(div)
    >= 0.9 where the set end points are mesh lines, >= 0.4 (theory 1/2) otherwise;
    lambda_n, lambda_t decrease on every level from 3 on, at order >= 1 overall."""
    rows = study(name)
    last = len(rows) - 1
    for key in ("sigma", "u", "eta"):
        assert min(order(rows, key, last - 1), order(rows, key, last)) >= MIN_ORDER, key
    hdiv = MIN_ORDER if name in ON_NODES else MIN_ORDER_HDIV_OFF_NODES
    assert min(order(rows, "sigma_hdiv", last - 1), order(rows, "sigma_hdiv", last)) >= hdiv
    for key in ("lam_n", "lam_t"):
        errors = [row[key] for row in rows[1:]]
        assert all(b < a for a, b in zip(errors, errors[1:])), (key, errors)
        overall = np.log(errors[0] / errors[-1]) / np.log(rows[1]["h"] / rows[-1]["h"])
        assert overall >= 1.0, (key, overall)


@pytest.mark.parametrize("name", [CASES[0], *(pytest.param(c, marks=pytest.mark.slow)
                                              for c in CASES[1:])])
def test_contact_and_stick_sets_are_recovered_within_one_edge_per_end_point(name):
    """From level 3 on (h~ <= 1/2, below the set sizes): the set errors exceed what the grid
    forces by at most one h~ (contact) or h^ (stick) edge per end point; the contact set of
    ``frictionless`` is exact, the stick set of ``tresca`` too; the errors shrink."""
    rows = study(name)
    case = manufactured_case(name)
    for row in rows[1:]:
        assert row["contact_set"] <= row["contact_set_resolution"] + 2 * row["htilde"] + 1e-12
        if case.law != "none":
            assert row["stick_set"] <= row["stick_set_resolution"] + 2 * row["hhat"] + 1e-12
    if name == "frictionless":
        assert all(row["contact_set"] == 0 for row in rows)
    if name == "tresca":
        assert all(row["stick_set"] == 0 for row in rows[1:])
    for key in ("contact_set", "stick_set"):
        if rows[1][key]:
            assert rows[-1][key] <= 0.6 * rows[1][key], (key, rows[1][key], rows[-1][key])


def test_slipping_points_move_against_their_tangential_traction():
    """On h^ edges inside the exact slip set nu = sign(lambda_t) = sign of the exact
    sigma_t, and sigma_t^h u_t^h < 0 there: the sign convention of (3.62)_5,7 in the code."""
    case = manufactured_case("coulomb")
    solution = solve_scene(case.scene(), 4)
    diag = friction_diagnostics(solution)
    hat = solution.problem.spaces.friction
    chain, nodes = hat.chains[0], hat.nodes[0]
    ends = chain.path_points[nodes][:, 0]
    (lo, hi), (b0, b1) = case.contact_set[0], case.stick_set[0]
    checked = 0
    for j, (p, q) in enumerate(zip(ends[:-1], ends[1:])):
        p, q = min(p, q), max(p, q)
        if lo <= p and q <= hi and (q <= b0 or p >= b1):
            mid = 0.5 * (p + q)
            assert diag.nu[j] == pytest.approx(np.sign(case.exact.lam_t.numpy(mid, 0.0)))
            assert np.sign(case.sigma_t.numpy(mid, 0.0)) == np.sign(diag.nu[j])
            checked += 1
    assert checked >= 4
    tr = contact_traces(solution)
    slip = (tr.edge_xy[:, 0] > b1 + 0.3) & (tr.edge_xy[:, 0] < hi - 0.3)
    u_t = -np.interp(tr.edge_xy[slip, 0], tr.node_xy[:, 0], tr.lam_t)   # lambda_t = -u_t
    assert np.all(tr.sigma_t[slip] * u_t < 0)


@pytest.mark.parametrize("name", CASES)
def test_uzawa_reaches_the_same_discrete_solution_as_the_active_set_solver(name):
    """solver.method = "uzawa" (Algorithms 3.38 / 3.41, Remark 3.45) against the default."""
    case = manufactured_case(name)
    fast = solve_scene(case.scene("auto"), 3)
    uzawa = solve_scene(case.scene("uzawa"), 3)
    assert uzawa.method != fast.method
    assert np.abs(uzawa.x - fast.x).max() <= 1e-5 * np.abs(fast.x).max()
    assert discrete_sets(uzawa) == discrete_sets(fast)


@pytest.mark.slow
def test_both_end_treatments_pose_the_same_problem():
    """The exact lambda_n, lambda_t vanish at the clamped ends of Gamma_C, so the data's end
    values (contact.ends = "consistent") and the thesis' zeros give the same solution."""
    case = manufactured_case("tresca")
    consistent = solve_scene(case.scene(ends="consistent"), 3)
    thesis = solve_scene(case.scene(ends="thesis"), 3)
    assert np.abs(consistent.x - thesis.x).max() <= 1e-10 * np.abs(thesis.x).max()
