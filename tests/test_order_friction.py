"""Friction at order k (issue 27, item 3): Tresca and Coulomb on the facet P_k multipliers.

The law acts on every Bernstein coefficient, |t_t,i| <= F_i (:class:`ngdual.friction.
MomentFriction`). Both solvers of order k are tested: the default
(:mod:`ngdual.solvers.dispatch`) and the condensation of K onto the candidates
(:mod:`ngdual.solvers.conforming`, the default's fallback). Truth: the convex QP of
:mod:`ngdual.solvers.qp` for the same discrete problem (Clarabel on the whole sparse
system, nothing shared with either condensation or the semismooth Newton method; Coulomb
as its fixed point of Tresca QPs), and the physics checks of :mod:`ngdual.checks`
(friction bound, force balance, tension).
"""

import json

import numpy as np
import pytest

from ngdual.cli import main
from ngdual.forms import assemble
from ngdual.friction import tresca_moments
from ngdual.mesh import build_mesh
from ngdual.scene import load_scene
from ngdual.solvers import conforming, contact_problem, convergence, solve_problem
from ngdual.solvers.qp import solve_qp, solve_qp_friction
from ngdual.solvers.semismooth import semismooth_newton
from ngdual.solvers.settings import Model, solver_settings

QP_AGREEMENT = 1e-8  # Clarabel's interior point, not polished with friction (measured <= 1.1e-9)


def _problem(name: str, order: int, level: int):
    ends = [] if name == "hertz-cylinder" else ["contact.ends='consistent'"]
    scene = load_scene(name, [f"discretisation.order={order}", *ends])
    return assemble(scene, build_mesh(scene.geometry, level))


def _conforming(problem):
    """The conforming solver (condensation of K onto the candidates), not the default."""
    return conforming.conforming_active_set(problem, solver_settings(problem.scene))


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.parametrize("solve", [solve_problem, _conforming], ids=["default", "conforming"])
@pytest.mark.parametrize("name, order", [("thesis-3.46-tresca", 1),
                                         ("thesis-3.46-tresca", 2),
                                         ("thesis-3.46-coulomb", 1)])
def test_friction_at_order_k_is_the_solution_of_the_qp(name, order, solve):
    """The same stresses and multipliers as the QP (and for Coulomb its fixed point), with
    stick and slip on the coefficients and the bound held to round-off (the default solver
    and the conforming one)."""
    problem = _problem(name, order, 1)
    solution = solve(problem)
    qp = solve_qp_friction(problem, Model.of(problem.scene), tol=1e-9)
    for part in (problem.sigma, problem.lam_n, problem.index("lam_t")):
        assert _relative(solution.x[part], qp.x[part]) < QP_AGREEMENT
    if solve is _conforming:
        assert solution.residuals["friction_bound"] < 1e-12
        assert solution.residuals["slip"] < 1e-12
    t_n = (problem.K @ solution.x - problem.rhs)[problem.lam_n]
    t_t = (problem.K @ solution.x - problem.rhs)[problem.index("lam_t")]
    F = tresca_moments(problem) if "tresca" in name else 0.5 * np.maximum(-t_n, 0.0)
    slipping = np.abs(np.abs(t_t) - F) <= 1e-9 * np.max(F)
    sticking = (F > 0) & ~slipping
    assert slipping.any() and sticking.any()


@pytest.mark.parametrize("order", [1, 2])
def test_the_coulomb_solution_on_example_3_46_passes_every_physics_check(order):
    """Consistent ends, mu_f = 0.5: no tension, the contact force balanced, the friction
    bound |int_e sigma_t| <= sum F_i held on every fine edge."""
    problem = _problem("thesis-3.46-coulomb", order, 2)
    solution = solve_problem(problem)
    assert solution.warnings == []
    assert solution.residuals["coulomb_bound"] < 1e-10


def test_the_coulomb_check_at_order_k_takes_the_bound_as_the_solver_defines_it():
    """The check F_i = mu_f max(-t_n,i, 0) on K counts F_i = 0 where that bound vanishes
    (at most 1e-6 of its largest value, tolerances.friction_vanishes), as the fixed point
    sets it: a moment of -1e-7 of the largest where the body separates is no violation
    (a tolerance run of Example 3.46, mu_f = 0.5, k = 1, failed at its 15th solve on
    2.5e-7 of such a moment), one of -1e-5 is."""
    problem = _problem("thesis-3.46-coulomb", 1, 1)
    solution = solve_problem(problem)
    t_n = (problem.apply(solution.x) - problem.rhs)[problem.lam_n]
    F = 0.5 * np.maximum(-t_n, 0.0)
    assert convergence.residuals(problem, solution.x, "coulomb", 0.5, F)["coulomb_bound"] < 1e-9
    separated = np.flatnonzero(np.abs(t_n) < 1e-12 * np.max(np.abs(t_n)))
    assert len(separated)
    F[separated] = 0.0
    for share, fails in ((1e-7, False), (1e-5, True)):
        rhs = problem.rhs.copy()
        problem.rhs[problem.lam_n[separated[0]]] += share * np.max(np.abs(t_n))
        found = convergence.residuals(problem, solution.x, "coulomb", 0.5, F)
        problem.rhs[:] = rhs
        assert (found["coulomb_bound"] > 1e-9) == fails, (share, found["coulomb_bound"])


@pytest.mark.parametrize("name", ["thesis-3.46-frictionless", "thesis-3.46-coulomb"])
def test_condensing_onto_every_coefficient_gives_the_solution_of_the_candidates(name,
                                                                               monkeypatch):
    """The path of a singular K (a floating body: every multiplier eliminated, all N_C
    coefficients condensed) and the candidates' path solve the same discrete problem."""
    problem = _problem(name, 1, 1)
    candidates = _conforming(problem)
    monkeypatch.setattr(conforming.WholeFactorization, "regular", property(lambda self: False))
    every = _conforming(problem)
    assert every.iterations["condensed"] == len(problem.lam_n)
    assert candidates.iterations["condensed"] < len(problem.lam_n)
    assert _relative(every.x, candidates.x) < 1e-9


def test_hertz_condenses_onto_a_few_coefficients_around_the_contact_zone():
    """Hertz at k = 1: the candidates are the coefficients in contact and a few around them,
    a small part of Gamma_C, and each costs one solve."""
    problem = _problem("hertz-cylinder", 1, 1)
    solution = _conforming(problem)
    lam_n = solution.x[problem.lam_n]
    touching = int(np.sum(lam_n <= 1e-8 * np.max(lam_n)))
    assert touching <= solution.iterations["condensed"] <= 2 * touching
    assert solution.iterations["solves"] == solution.iterations["condensed"] + 2
    assert solution.iterations["condensed"] < len(problem.lam_n) / 4


@pytest.mark.slow
def test_the_command_line_reports_stick_slip_and_the_coulomb_ratio_at_order_1(tmp_path):
    """``ngdual solve`` with Coulomb friction at k = 1: the per-edge nu of the diagnostics,
    stick and slip, and |t_t| / |t_n| at most mu_f = 0.5 on every coefficient."""
    assert main(["solve", "thesis-3.46-coulomb", "--level", "1", "--set",
                 "discretisation.order=1", "--set", "contact.ends='consistent'",
                 "--out", str(tmp_path)]) == 0
    record = json.loads((tmp_path / "result.json").read_text())
    contact = record["contact"]
    assert contact["stick_nodes"] > 0 and contact["slip_nodes"] > 0
    assert contact["max_traction_ratio"] == pytest.approx(0.5, rel=1e-9)
    assert record["warnings"] == []


@pytest.mark.parametrize("order", [1, 2])
def test_the_conforming_solver_without_friction_is_the_solution_of_the_qp(order):
    """Frictionless Example 3.46: the candidates' condensation and Clarabel's polished QP."""
    problem = _problem("thesis-3.46-frictionless", order, 2)
    solution = _conforming(problem)
    qp = solve_qp(problem, Model.of(problem.scene))
    assert _relative(solution.x, qp.x) < 1e-9


FRICTIONAL_SCENES = ["cattaneo-mindlin", "thesis-3.46-tresca", "thesis-3.46-coulomb",
                     "thesis-3.46-coulomb-gap0", "thesis-3.46-coulomb-gap-abs",
                     "thesis-3.46-coulomb-gap-3125"]


def _frictional(name: str, order: int, level: int):
    ends = [] if name == "cattaneo-mindlin" else ["contact.ends='consistent'"]
    scene = load_scene(name, [f"discretisation.order={order}", *ends])
    return assemble(scene, build_mesh(scene.geometry, level))


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("name", FRICTIONAL_SCENES)
def test_every_shipped_frictional_scene_solves_at_order_k_with_quiet_physics_checks(name,
                                                                                      order):
    """Both solvers of order k solve every frictional scene on level 1 to round-off (their
    residuals on K are checked), the same solution (to 1e-8: 1.7e-9 on Cattaneo-Mindlin
    at k = 2, nu = 0.4999), and no physics check warns."""
    problem = _frictional(name, order, 1)
    default = solve_problem(problem)
    assert default.warnings == []
    assert _relative(_conforming(problem).x, default.x) < 1e-8


@pytest.mark.parametrize("name, order", [("thesis-3.46-coulomb-gap0", 1),
                                         ("thesis-3.46-coulomb-gap0", 2),
                                         ("thesis-3.46-coulomb-gap-abs", 1),
                                         ("thesis-3.46-coulomb-gap-abs", 2),
                                         ("cattaneo-mindlin", 1)])
def test_full_contact_and_stick_are_the_solution_of_the_qp(name, order):
    """g = 0 (a whole side in contact, lambda_n = 0), g = |x| (the contact zone two
    coefficients wide, both sticking: lambda = 0 on them) and Cattaneo-Mindlin: the default
    solver and Clarabel's fixed point of Tresca QPs. lambda_n and lambda_t are compared
    on the displacement scale (lambda_n vanishes on Gamma_C with g = 0); sigma to 1e-5
    only, the accuracy of the QP, which is not polished with friction: its slip residual
    on K is 1.1e-7 on g = |x| at k = 1 (the active set's 4.6e-13) and 9.4e-9 on
    Cattaneo-Mindlin, where nu = 0.4999 turns it into a stress difference of 4.5e-6."""
    problem = _frictional(name, order, 1)
    solution = solve_problem(problem)
    qp = solve_qp_friction(problem, Model.of(problem.scene), tol=1e-9)
    displacement = np.max(np.abs(qp.x[problem.index("u1", "u2", "lam_n", "lam_t")]))
    for part in (problem.lam_n, problem.index("lam_t")):
        assert np.max(np.abs(solution.x[part] - qp.x[part])) < QP_AGREEMENT * displacement
    assert _relative(solution.x[problem.sigma], qp.x[problem.sigma]) < 1e-5


def test_a_side_in_contact_and_sticking_is_solved_with_vanishing_multipliers():
    """t(z) = b - G z with t_n < 0 and |t_t| < F at z = 0: the solution is z = 0 (contact
    and stick on every coefficient), which the semismooth Newton method reaches in one
    step; the round-off of a zero z is no violation of the sign conditions."""
    rng = np.random.default_rng(3)
    A = rng.standard_normal((4, 4))
    G = 1e4 * (A @ A.T + 4 * np.eye(4))
    b = np.array([-600.0, -640.0, 150.0, -190.0])
    F = np.array([300.0, 310.0])
    state = semismooth_newton(G, b, 2, np.diag(F))
    assert np.max(np.abs(np.concatenate([state.lam_n, state.lam_t]))) < 1e-15
    assert np.allclose(state.nu, b[2:] / F, rtol=1e-12)


@pytest.mark.parametrize("order, level", [(1, 2), (2, 3)])
def test_the_coulomb_law_solved_on_the_fixed_points_sets_is_its_fixed_point(order, level,
                                                                           monkeypatch):
    """On the sets of a Tresca solution (contact_problem.coulomb_on_sets) the Coulomb problem is
    linear: solved there, the fixed point of Remark 3.45 stops after a few steps (the plain
    iteration takes 12-16, rate ~0.1) at the solution the plain iteration reaches, and
    F = mu_f (-t_n) holds on every coefficient."""
    problem = _problem("thesis-3.46-coulomb", order, level)
    fast = solve_problem(problem)
    monkeypatch.setattr(contact_problem, "coulomb_on_sets", lambda cond, mu_f, state: None)
    plain = solve_problem(problem)
    assert fast.iterations["outer"] <= 6 < plain.iterations["outer"]
    for part in (problem.sigma, problem.lam_n, problem.index("lam_t")):
        assert _relative(fast.x[part], plain.x[part]) < 1e-10
    assert fast.history[-1] <= 1e-12 and fast.residuals["friction_bound"] < 1e-12
