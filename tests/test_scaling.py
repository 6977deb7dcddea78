"""A solve's answer and its verdict do not depend on the units.

Linear elasticity with Signorini contact and Tresca friction is invariant under a change of
units: with the modulus E, the tractions and the Tresca bound scaled by e and every length
(the domain, the gap, the prescribed displacements) by c, the displacement scales by c,
the stress by e and a force per unit thickness by e c, and the contact and stick sets stay
(Coulomb's mu_f has no unit). The discrete problem on the equally scaled mesh has the
scaled discrete solution, so the contact force, the multipliers and the verdict
"converged" must follow on every shipped scene, whatever the order k and the multiplier
family (the convergence test measures every residual against the problem's scales:
:mod:`ngdual.solvers.convergence`). Scaling the friction bound alone changes the answer but not
the verdict: bounds from 1e-6 to 1e6 times the scene's pressure and mu_f from 1e-6 to 10
solve.
"""

import copy
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ngdual as nd
from ngdual.boundary import BoundaryMeshes
from ngdual.forms import assemble
from ngdual.mesh import build_mesh, moved_mesh
from ngdual.scene import read_toml, scene_from_dict, shipped_scenes
from ngdual.solvers import solve_problem

CONFIGURATIONS = [(0, "coarse"), (0, "facet"), (1, "facet"), (1, "coarse"), (2, "facet"),
                  (2, "coarse")]
SCENES = sorted(shipped_scenes())
FAST = {"hertz-cylinder"}
AGREEMENT = 1e-8   # the scaled answers agree to this (measured: below 1e-10)
STEEL = 2.1e11 / 2e5   # E in pascals against the scenes' megapascals
METRES = 1e-3          # lengths in metres against millimetres


def in_units(expression: str, factor: float, c: float) -> str:
    """``factor`` times the expression of x, y at the points (x / c, y / c)."""
    moved = re.sub(r"\b([xy])\b", lambda m: f"({m.group(1)}/{c!r})", str(expression))
    return f"{factor!r}*({moved})"


def document(name: str, order: int, family: str, e: float = 1.0, c: float = 1.0,
             law: dict | None = None) -> dict:
    """The shipped scene ``name`` on level 1 at order k and family, with E, the tractions and
    the Tresca bound times e and the lengths times c (points, arc centres, mesh sizes, the
    foundation, the gap and the displacements; the formulas of x, y in the scaled
    coordinates). Example 3.46's ends are the consistent ones where its own are refused."""
    data = copy.deepcopy(read_toml(name)[1])
    data["discretisation"] = {"order": order, "multipliers": family}
    geo = data["geometry"]
    geo["level"] = 1
    if "points" in geo:
        geo["points"] = [[c * v for v in p] for p in geo["points"]]
        geo["arcs"] = {k: [c * v for v in p] for k, p in geo.get("arcs", {}).items()}
        geo["maxh"] = c * geo["maxh"]
        geo["side_maxh"] = {k: c * v for k, v in geo.get("side_maxh", {}).items()}
    else:
        assert c == 1.0, "the thesis' own geometry has its fixed size"
    data["material"]["E"] *= e
    loads = data.setdefault("loads", {})
    for key, factor in (("displacement", c), ("traction", e), ("body_force", e / c)):
        if key in loads:
            loads[key] = [in_units(v, factor, c) for v in loads[key]]
    contact = data.setdefault("contact", {})
    if "foundation" in contact:
        contact["foundation"]["point"] = [c * v for v in contact["foundation"]["point"]]
    if "gap" in contact:
        contact["gap"] = in_units(contact["gap"], c, c)
    if order > 0 or family == "facet":
        contact["ends"] = "consistent"
    friction = data.setdefault("friction", {"law": "none"})
    if law is not None:
        friction.clear()
        friction.update(law)
    if friction.get("law") == "tresca":
        friction["bound"] = in_units(friction["bound"], e, c)
    data.pop("benchmark", None)
    return data


def admitted(name: str, order: int, family: str) -> bool:
    """Friction at k >= 1 is posed with the facet multipliers only."""
    law = read_toml(name)[1].get("friction", {}).get("law", "none")
    return not (law != "none" and order >= 1 and family == "coarse")


def movable(name: str) -> bool:
    return "points" in read_toml(name)[1]["geometry"]


def solved(data: dict, mesh, c: float = 1.0):
    scene = scene_from_dict(data)
    if c != 1.0:
        mesh = moved_mesh(mesh, c * np.eye(2))
    problem = assemble(scene, mesh, BoundaryMeshes.for_scene(scene, mesh))
    return solve_problem(problem)


def contact_force(solution) -> np.ndarray:
    return np.asarray(nd.force_balance(solution).resultant)


def base_mesh(name: str):
    return build_mesh(scene_from_dict(read_toml(name)[1]).geometry, 1)


def assert_scaled(original, scaled, e: float, c: float) -> None:
    assert original.converged and scaled.converged
    force = contact_force(original)
    # a scene out of contact on level 1 (a gap of up to 2) has a round-off force: the body's
    # stress (||sigma_h||, a force per unit thickness) is the scale then
    scale = max(np.linalg.norm(force), nd.norms(original)["sigma_X"])
    assert np.allclose(contact_force(scaled) / (e * c), force, rtol=0,
                       atol=AGREEMENT * scale)
    # lambda_n = g - u_n against the displacement scale (g = 0: lambda_n is round-off)
    lam, lam_scaled = (s.x[s.problem.lam_n] for s in (original, scaled))
    moved = original.x[original.problem.index("u1", "u2", "lam_n")]
    assert np.allclose(lam_scaled / c, lam, rtol=0, atol=AGREEMENT * np.max(np.abs(moved)))


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(configuration=st.sampled_from(CONFIGURATIONS), e_exp=st.integers(-3, 7),
       c_exp=st.integers(-3, 3))
def test_scaling_modulus_and_lengths_scales_the_answer_and_keeps_the_verdict(configuration,
                                                                             e_exp, c_exp):
    order, family = configuration
    e, c = 10.0 ** e_exp, 10.0 ** c_exp
    mesh = base_mesh("hertz-cylinder")
    assert_scaled(solved(document("hertz-cylinder", order, family), mesh),
                  solved(document("hertz-cylinder", order, family, e, c), mesh, c), e, c)


CASES = [pytest.param(name, order, family, marks=() if name in FAST else pytest.mark.slow)
         for name in SCENES for order, family in CONFIGURATIONS if admitted(name, order, family)]


@pytest.mark.parametrize("name, order, family", CASES)
def test_steel_in_pascals_and_metres_is_the_scaled_answer(name, order, family):
    """E = 2.1e11 Pa against the scene's 2e5 MPa, lengths in metres against millimetres
    (Example 3.46, whose geometry is the thesis' own: pascals only)."""
    c = METRES if movable(name) else 1.0
    mesh = base_mesh(name)
    assert_scaled(solved(document(name, order, family), mesh),
                  solved(document(name, order, family, STEEL, c), mesh, c), STEEL, c)


FRICTION_ORDERS = [(0, "coarse"), (0, "facet"), (1, "facet"), (2, "facet")]
FRICTION_SCENES = ["cattaneo-mindlin", "hertz-cylinder", "thesis-3.46-frictionless",
                   "punch-on-foundation"]
PRESSURE = {"cattaneo-mindlin": 2800.0, "hertz-cylinder": 2800.0,
            "thesis-3.46-frictionless": 800.0, "punch-on-foundation": 100.0}


@settings(max_examples=16, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(FRICTION_SCENES), configuration=st.sampled_from(FRICTION_ORDERS),
       exponent=st.integers(-6, 6), coulomb=st.booleans())
def test_friction_bounds_far_from_one_solve_and_hold(name, configuration, exponent, coulomb):
    """A Tresca bound of 10^exponent times the scene's contact pressure (the Hertz peak is
    about 2 800) or Coulomb mu_f = 10^exponent (at most 10): converged, the shear within
    the bound and no penetration, at every order. (Example 3.46 on level 1 warns of tension
    and the force balance at its clamped ends whatever the friction: from level 2 on it
    does not, README.)"""
    order, family = configuration
    law = {"law": "coulomb", "mu": 10.0 ** min(exponent, 1)} if coulomb else \
        {"law": "tresca", "bound": repr(PRESSURE[name] * 10.0 ** exponent)}
    data = document(name, order, family, law=law)
    if name.startswith("thesis-3.46"):
        data["contact"]["ends"] = "consistent"
    solution = solved(data, base_mesh(name))
    assert solution.converged
    codes = [w.code for w in solution.warnings]
    assert "friction-bound" not in codes and "penetration" not in codes, codes
