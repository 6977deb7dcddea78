"""The Uzawa algorithms (Algorithm 3.38, Algorithm 3.41 with Tresca, Remark 3.45 with Coulomb)
at every order k and with both multiplier families reach the active-set solution.

The two solvers share the assembled problem and nothing else: the active-set method ends on
its sets to round-off, Uzawa stops on a relative increment eps. A contraction with factor q
stopped at an increment eps is within q / (1 - q) eps of its fixed point; q is read off the
run's own history (its mean contraction from the first step to the last), and the tolerance
is twice that bound (tests/test_behaviour_unchanged.py derives its Uzawa tolerance the same
way). Measured on Example 3.46 (consistent ends), x relative to the active-set x: 0.2 to 3
eps without friction, 0.6 to 7 eps with friction, against 2 q / (1 - q) = 1.7 to 18.
"""

import functools

import numpy as np
import pytest

from ngdual import post
from ngdual.forms import assemble
from ngdual.mesh import build_mesh
from ngdual.scene import load_scene
from ngdual.solution import ConvergenceError
from ngdual.solvers import solve_scene
from ngdual.solvers.settings import NestedUzawaSettings, UzawaSettings, solver_settings

EPS = 1e-10  # solver.eps of Algorithm 3.38
EPS_FRICTION = 1e-9  # solver.eps1 and eps2 of Algorithm 3.41 / Remark 3.45


def _overrides(order, family):
    return [f"discretisation.order={order}", f"discretisation.multipliers={family}",
            "contact.ends=consistent"]


@functools.cache
def _pair(name, order, family, level):
    """(active-set, Uzawa) solutions of ``name`` at ``order`` with ``family`` on ``level``."""
    eps = ([f"solver.eps={EPS}"] if name.endswith("frictionless")
           else [f"solver.eps1={EPS_FRICTION}", f"solver.eps2={EPS_FRICTION}"])
    common = _overrides(order, family)
    reference = solve_scene(load_scene(name, common + ["solver.method=active-set"]), level)
    uzawa = solve_scene(load_scene(name, common + ["solver.method=uzawa"] + eps), level)
    return reference, uzawa


def _tolerance(solution, eps):
    """2 q / (1 - q) eps, q the mean contraction of the run's increments."""
    history = solution.history
    q = (history[-1] / history[0]) ** (1.0 / (len(history) - 1))
    return 2 * q / (1 - q) * eps


def _relative(a, b):
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


@pytest.mark.parametrize("order, family", [(0, "facet"), (1, "facet"), (2, "facet"),
                                           (1, "coarse"), (2, "coarse")])
def test_uzawa_is_a_valid_choice_at_every_order_and_family(order, family):
    for name, kind in (("thesis-3.46-frictionless", UzawaSettings),
                       ("thesis-3.46-tresca", NestedUzawaSettings)):
        if family == "coarse" and kind is NestedUzawaSettings:
            continue   # friction with the coarse family at order k is refused for every solver
        scene = load_scene(name, _overrides(order, family) + ["solver.method=uzawa"])
        assert isinstance(solver_settings(scene), kind)


FRICTIONLESS = [(0, "facet", 2), (1, "facet", 2), (2, "facet", 2), (1, "coarse", 2),
                (2, "coarse", 1)]


@pytest.mark.parametrize("order, family, level", FRICTIONLESS)
def test_uzawa_reaches_the_active_set_solution_without_friction(order, family, level):
    reference, uzawa = _pair("thesis-3.46-frictionless", order, family, level)
    assert uzawa.method == "uzawa-h12" and uzawa.converged
    assert _relative(uzawa.x, reference.x) <= _tolerance(uzawa, EPS)
    lam_n = uzawa.part("lam_n")
    assert lam_n.min() >= 0.0      # the clip / NNLS keeps every Bernstein coefficient >= 0
    assert 0 < post.contact_summary(uzawa)["nodes_in_contact"] \
        == post.contact_summary(reference)["nodes_in_contact"]


FRICTION = [("thesis-3.46-tresca", 1, 2), ("thesis-3.46-coulomb", 1, 2),
            ("thesis-3.46-tresca", 2, 1), ("thesis-3.46-coulomb", 2, 1),
            ("thesis-3.46-tresca", 0, 2), ("thesis-3.46-coulomb", 0, 2)]


@pytest.mark.parametrize("name, order, level", FRICTION)
def test_nested_uzawa_reaches_the_active_set_solution_with_the_facet_multipliers(
        name, order, level):
    """The friction law on the Bernstein coefficients (ngdual.friction.MomentFriction): nu_i
    in [-1, 1] and F_i per coefficient, the box projection coefficient by coefficient."""
    reference, uzawa = _pair(name, order, "facet", level)
    assert uzawa.method.startswith("nested-uzawa") and uzawa.converged
    assert _relative(uzawa.x, reference.x) <= _tolerance(uzawa, EPS_FRICTION)
    # nu and F are reported per fine edge, as the active-set method reports them
    assert uzawa.nu.shape == reference.nu.shape == (len(reference.problem.spaces.gamma_c),)
    assert np.abs(uzawa.nu).max() <= 1.0
    assert _relative(uzawa.friction_bound, reference.friction_bound) \
        <= _tolerance(uzawa, EPS_FRICTION)
    r = uzawa.residuals
    assert r["nu_bound"] == 0.0 and r["tangential"] < 1e-12
    assert r["nu_sign"] < 1e-6 and r["sigma_t_bound"] < 1e-12
    assert uzawa.warnings == reference.warnings == []


def test_the_h12_metric_of_the_facet_multipliers_keeps_the_steps_independent_of_the_level():
    """The metric of the facet family (broken H^1 with penalised jumps, the clamped ends in
    H^{1/2}_00, ngdual.boundary.FacetMesh.mass_stiffness) is H^{1/2}-equivalent: at k = 1
    Algorithm 3.38 takes 57, 55, 56 steps on levels 1-3 of Example 3.46 (eps = 1e-10)."""
    scene = load_scene("thesis-3.46-frictionless", _overrides(1, "facet")
                       + ["solver.method=uzawa", f"solver.eps={EPS}"])
    steps = [solve_scene(scene, level).iterations["outer"] for level in (1, 2, 3)]
    assert max(steps) <= 1.2 * min(steps), steps


def test_a_plain_step_that_would_not_contract_is_refused_with_its_bound():
    """The Euclidean metric takes rho itself: for the facet multipliers of order 0 the bound
    of the contact iteration is 2.05 on level 2, so rho = 1 is refused before iterating and
    a step below 2 / 2.05 converges to the active-set solution."""
    scene = load_scene("thesis-3.46-frictionless", _overrides(0, "facet")
                       + ["solver.method=uzawa", "solver.metric=euclidean"])
    with pytest.raises(ConvergenceError, match="does not contract.*lambda_max = 2.0"):
        solve_scene(scene, 2)
    slower = load_scene("thesis-3.46-frictionless", _overrides(0, "facet")
                        + ["solver.method=uzawa", "solver.metric=euclidean", "solver.rho=0.9",
                           f"solver.eps={EPS}"])
    uzawa = solve_scene(slower, 2)
    reference, _ = _pair("thesis-3.46-frictionless", 0, "facet", 2)
    assert _relative(uzawa.x, reference.x) <= _tolerance(uzawa, EPS)


@pytest.mark.parametrize("order, family", [(0, "facet"), (1, "facet"), (2, "facet"),
                                           (2, "coarse")])
def test_the_mass_and_stiffness_of_the_multipliers_are_exact_on_polynomials(order, family):
    """M and L of the metric integrate u = 16 - x^2 on Gamma_C = [-4, 4] x {-1} exactly where
    the space holds it (P_{k+1} continuous at degree 2, P_k with k = 2 on the fine edges),
    and the jumps of the facet family's P0 / P1 interpolants only add to L."""
    scene = load_scene("thesis-3.46-frictionless", _overrides(order, family))
    contact = assemble(scene, build_mesh(scene.geometry, 2)).spaces.contact
    mass, stiff = contact.mass_stiffness()
    u = contact.interpolant(lambda p, e: 16 - p[:, 0] ** 2)
    u = u[0] if isinstance(u, tuple) else u
    exact_l2, exact_h1 = 2 * (256 * 4 - 2 * 16 * 64 / 3 + 4 ** 5 / 5), 2 * 4 * 64 / 3
    if order == 2 or family == "coarse":
        assert u @ mass @ u == pytest.approx(exact_l2, rel=1e-12)
        assert u @ stiff @ u == pytest.approx(exact_h1, rel=1e-12)
    else:
        assert u @ stiff @ u > 0.9 * exact_h1
    assert np.allclose(mass, mass.T) and np.allclose(stiff, stiff.T)
