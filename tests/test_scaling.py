"""A solve's answer and its verdict do not depend on the units.

Linear elasticity with Signorini contact is invariant under a change of units: with the
modulus E and every traction scaled by e and every length (the domain, the gap, the
prescribed displacements) by c, the displacement scales by c, the stress by e and a force
per unit thickness by e c, and the contact and stick sets stay. The discrete problem on the
equally scaled mesh has the scaled discrete solution, so the contact force, the
multipliers and the verdict "converged" must follow, whatever the order k and the multiplier
family (the convergence test measures every residual against the problem's scales:
:mod:`ngdual.solvers.scales`). Scaling the friction bound alone changes the answer but
not the verdict: bounds from 1e-6 to 1e6 times the contact force's size solve.
"""

import copy

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ngdual as nd
from ngdual.boundary import BoundaryMeshes
from ngdual.forms import assemble
from ngdual.mesh import build_mesh, moved_mesh
from ngdual.scene import read_toml, scene_from_dict
from ngdual.solvers import solve_problem

CONFIGURATIONS = [(0, "coarse"), (0, "facet"), (1, "facet"), (1, "coarse"), (2, "facet"),
                  (2, "coarse")]
AGREEMENT = 1e-8   # the scaled answers agree to this (round-off of each solve: below 1e-10)


def scaled_document(name: str, order: int, family: str, e: float = 1.0, c: float = 1.0,
                    law: dict | None = None) -> dict:
    """The shipped scene ``name`` at order k and family, with E and the tractions times e and
    the lengths times c (points, arc centres, mesh sizes, the foundation, the displacements)."""
    data = copy.deepcopy(read_toml(name)[1])
    data["discretisation"] = {"order": order, "multipliers": family}
    geo = data["geometry"]
    geo["points"] = [[c * v for v in p] for p in geo["points"]]
    geo["arcs"] = {k: [c * v for v in p] for k, p in geo.get("arcs", {}).items()}
    geo["maxh"] = c * geo["maxh"]
    geo["side_maxh"] = {k: c * v for k, v in geo.get("side_maxh", {}).items()}
    data["material"]["E"] *= e
    foundation = data["contact"]["foundation"]
    foundation["point"] = [c * v for v in foundation["point"]]
    data["loads"]["displacement"] = [repr(c * float(v)) for v in data["loads"]["displacement"]]
    if law is not None:
        data["friction"] = law
    data.pop("benchmark", None)
    return data


def solved(data: dict, mesh, c: float = 1.0):
    scene = scene_from_dict(data)
    if c != 1.0:
        mesh = moved_mesh(mesh, c * np.eye(2))
    problem = assemble(scene, mesh, BoundaryMeshes.for_scene(scene, mesh))
    return solve_problem(problem)


def contact_force(solution) -> np.ndarray:
    return np.asarray(nd.force_balance(solution).resultant)


def base_mesh(name: str = "hertz-cylinder", level: int = 1):
    return build_mesh(scene_from_dict(read_toml(name)[1]).geometry, level)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(configuration=st.sampled_from(CONFIGURATIONS), e_exp=st.integers(-3, 7),
       c_exp=st.integers(-3, 3))
def test_scaling_modulus_and_lengths_scales_the_answer_and_keeps_the_verdict(configuration,
                                                                             e_exp, c_exp):
    order, family = configuration
    e, c = 10.0 ** e_exp, 10.0 ** c_exp
    mesh = base_mesh()
    original = solved(scaled_document("hertz-cylinder", order, family), mesh)
    scaled = solved(scaled_document("hertz-cylinder", order, family, e, c), mesh, c)
    assert original.converged and scaled.converged
    force = contact_force(original)
    assert np.linalg.norm(force) > 0
    assert np.allclose(contact_force(scaled) / (e * c), force, rtol=0,
                       atol=AGREEMENT * np.linalg.norm(force))
    lam, lam_scaled = (s.x[s.problem.lam_n] for s in (original, scaled))
    assert np.allclose(lam_scaled / c, lam, rtol=0, atol=AGREEMENT * np.max(np.abs(lam)))


@pytest.mark.parametrize("order, family", CONFIGURATIONS)
def test_steel_in_pascals_and_metres_is_the_scaled_answer(order, family):
    """E = 2.1e11 Pa against the scene's 2e5 (e = 1.05e6), lengths in metres against
    millimetres (c = 1e-3)."""
    e, c = 2.1e11 / 2e5, 1e-3
    mesh = base_mesh()
    original = solved(scaled_document("hertz-cylinder", order, family), mesh)
    scaled = solved(scaled_document("hertz-cylinder", order, family, e, c), mesh, c)
    assert scaled.converged
    force = contact_force(original)
    assert np.allclose(contact_force(scaled) / (e * c), force, rtol=0,
                       atol=AGREEMENT * np.linalg.norm(force))


FRICTION_ORDERS = [(0, "coarse"), (0, "facet"), (1, "facet"), (2, "facet")]


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(configuration=st.sampled_from(FRICTION_ORDERS), exponent=st.integers(-6, 6),
       coulomb=st.booleans())
def test_friction_bounds_far_from_one_solve_and_hold(configuration, exponent, coulomb):
    """A Tresca bound of 10^exponent times the contact pressure's size (the Hertz peak is
    about 2 800) or Coulomb mu_f = 10^exponent (up to 10): converged, and no physics check
    fails (the shear within the bound, no tension, no penetration, the force balance)."""
    order, family = configuration
    law = {"law": "coulomb", "mu": 10.0 ** min(exponent, 1)} if coulomb else \
        {"law": "tresca", "bound": repr(2800.0 * 10.0 ** exponent)}
    data = scaled_document("cattaneo-mindlin", order, family, law=law)
    solution = solved(data, base_mesh("cattaneo-mindlin"))
    assert solution.converged
    assert [w.code for w in solution.warnings] == []
