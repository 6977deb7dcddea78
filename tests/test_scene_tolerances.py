"""Geometric checks compare with the scene's round-off, so moved copies of valid scenes pass
and solve to the same answer.

Elasticity and the Signorini conditions are invariant under rigid motions: a scene rotated
and translated as a whole (points, arc centres, the foundation line, constant loads) has the
rotated solution. netgen meshes a rotated domain differently, so the answers are compared on
the rotated copy of the same mesh (:func:`ngdual.mesh.moved_mesh`), where they agree to
round-off, whatever the discretisation error.
"""

import copy

import ngsolve as ngs
import numpy as np
import pytest

import ngdual as nd
from ngdual import geometry
from ngdual.boundary import BoundaryMeshes
from ngdual.forms import assemble
from ngdual.mesh import build_mesh, moved_mesh
from ngdual.quantities import fields
from ngdual.scene import DISCRETE_GAPS, SceneError, read_toml, scene_from_dict
from ngdual.scene.contact import round_off
from ngdual.solvers import solve_problem


def rotation(degrees: float) -> np.ndarray:
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return np.array([[c, -s], [s, c]])


def moved_document(data: dict, degrees: float, shift=(0.0, 0.0)) -> dict:
    """The scene document ``data`` rotated by ``degrees`` about the origin, then shifted:
    points, arc centres and the foundation line move, the constant loads turn."""
    r, shift = rotation(degrees), np.asarray(shift, dtype=float)
    out = copy.deepcopy(data)
    geo, contact, loads = out["geometry"], out.get("contact", {}), out.get("loads", {})

    def place(p):
        return [float(v) for v in r @ np.asarray(p, dtype=float) + shift]

    geo["points"] = [place(p) for p in geo["points"]]
    geo["arcs"] = {label: place(c) for label, c in geo.get("arcs", {}).items()}
    if "foundation" in contact:
        f = contact["foundation"]
        contact["foundation"] = {"point": place(f["point"]),
                                 "normal": [float(v) for v in r @ np.asarray(f["normal"])]}
    for key, pair in loads.items():
        values = np.array([float(v) for v in pair])  # constant vectors only
        loads[key] = [repr(float(v)) for v in r @ values]
    return out


def shipped(name: str) -> dict:
    return read_toml(name)[1]


def solve_on(scene, mesh):
    problem = assemble(scene, mesh, BoundaryMeshes.for_scene(scene, mesh))
    return solve_problem(problem)


def contact_force(solution) -> float:
    return float(np.linalg.norm(nd.force_balance(solution).resultant))


# ---------------------------------------------------------------- the round-off itself

def test_the_round_off_is_relative_to_the_size_and_the_place_of_the_domain():
    unit = geometry.sides([[0, 0], [1, 0], [1, 1], [0, 1]], list("abcd"))
    tiny = geometry.sides([[0, 0], [1e-6, 0], [1e-6, 1e-6], [0, 1e-6]], list("abcd"))
    far = geometry.sides([[1e6, 0], [1e6 + 1, 0], [1e6 + 1, 1], [1e6, 1]], list("abcd"))
    assert geometry.round_off(unit) == geometry.ROUND_OFF
    assert geometry.round_off(tiny) == pytest.approx(1e-6 * geometry.ROUND_OFF)
    # coordinates of size 1e6 carry round-off of 1e6 eps, whatever the domain's size
    assert geometry.round_off(far) == pytest.approx((1e6 + 1) * geometry.ROUND_OFF)
    assert geometry.round_off(far) > 1e3 * 1e6 * np.finfo(float).eps


@pytest.mark.parametrize("scale", [1e-9, 1.0, 1e9])
def test_a_penetration_beyond_round_off_is_refused_at_every_scale(scale):
    """Scaling a scene scales its round-off: a gap of -1e-6 of the size, or a foundation
    line 1e-6 of it inside the body, is refused in any unit; -1e-13 (round-off) is not."""
    data = shipped("flat-punch")
    geo = data["geometry"]
    geo["points"] = [[scale * c for c in p] for p in geo["points"]]
    geo["maxh"] *= scale
    geo["side_maxh"] = {k: v * scale for k, v in geo["side_maxh"].items()}
    data["loads"]["displacement"] = ["0", repr(-0.01 * scale)]
    for depth, refused in ((1e-6, True), (1e-13, False)):
        line = {"foundation": {"point": [0.0, depth * scale], "normal": [0.0, 1.0]}}
        formula = {"gap": repr(-depth * scale)}
        for contact, field in ((line, "contact.foundation"), (formula, "contact.gap")):
            data["contact"] = contact
            if refused:
                with pytest.raises(SceneError) as err:
                    scene_from_dict(data)
                assert err.value.fields == [field]
            else:
                scene_from_dict(data)


# ---------------------------------------------------------------- the contact patch test

PATCH = {
    "geometry": {"kind": "polygon", "points": [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]],
                 "labels": ["bottom", "right", "top", "left"], "maxh": 0.3, "level": 1},
    "boundary": {"dirichlet": ["top"], "neumann": ["left", "right"], "contact": ["bottom"]},
    "material": {"E": 200000.0, "nu": 0.3},
    "contact": {"foundation": {"point": [0.0, 0.0], "normal": [0.0, 1.0]}},
}
PRESSURE = 100.0


def patch_document(degrees: float) -> dict:
    """A block on a rigid foundation under the uniform pressure p, rotated by ``degrees``.

    sigma = -p e2 (x) e2 in plane strain has u = (nu (1+nu) p x / E, -(1-nu^2) p y / E): the
    top is displaced by it, the sides are free and the bottom touches the foundation
    everywhere (u_n = -u_2 = 0 = g), so the exact contact pressure is p. In the rotated
    frame u_D(X) = R u(R^T X).
    """
    data = moved_document(PATCH, degrees)
    e, nu = PATCH["material"]["E"], PATCH["material"]["nu"]
    grad_u = np.diag([nu * (1 + nu) * PRESSURE / e, -(1 - nu**2) * PRESSURE / e])
    r = rotation(degrees)
    grad = r @ grad_u @ r.T  # u_D(X) = grad X, linear through the origin
    data["loads"] = {"displacement": [f"{float(grad[i, 0])!r}*x + {float(grad[i, 1])!r}*y"
                                      for i in (0, 1)]}
    return data


@pytest.mark.parametrize("degrees", [0.0, 30.0])
def test_the_rotated_patch_test_is_accepted_and_gives_the_constant_pressure(degrees):
    scene = scene_from_dict(patch_document(degrees))
    solution = nd.solve(scene)
    n = rotation(degrees) @ np.array([0.0, -1.0])
    exact = -PRESSURE * np.outer(n, n)
    sigma = fields(solution).sigma
    mesh = solution.problem.fes.mesh
    for el in mesh.Elements(ngs.VOL):
        centre = np.mean([mesh[v].point for v in el.vertices], axis=0)
        value = np.array(sigma(mesh(*centre))).reshape(2, 2)
        assert np.abs(value - exact).max() <= 1e-8 * PRESSURE


# ---------------------------------------------------------------- shipped scenes, moved

@pytest.mark.parametrize("name", ["hertz-cylinder", "flat-punch", "cattaneo-mindlin"])
@pytest.mark.parametrize("degrees, shift", [(30.0, (0.0, 0.0)), (90.0, (0.0, 0.0)),
                                            (17.0, (1.3e3, -7.1e3))])
def test_rotated_and_translated_shipped_scenes_are_accepted(name, degrees, shift):
    scene = scene_from_dict(moved_document(shipped(name), degrees, shift))
    assert round_off(scene) < 1e-9 * max(1.0, float(np.abs(shift).max()))


LEVELS = {"hertz-cylinder": 2, "flat-punch": 2, "cattaneo-mindlin": 2}


@pytest.mark.parametrize("discrete_gap", [DISCRETE_GAPS[0], *(
    pytest.param(gap, marks=pytest.mark.slow) for gap in DISCRETE_GAPS[1:])])
@pytest.mark.parametrize("name", ["hertz-cylinder", "flat-punch", "cattaneo-mindlin"])
def test_a_rotated_scene_on_the_rotated_mesh_has_the_same_force_and_stress_norm(name,
                                                                                discrete_gap):
    """Measured: 1e-14 to 7e-14 relative with the direct solves, 2e-11 to 5e-11 with the
    Coulomb fixed point of cattaneo-mindlin (level 2, either discrete gap)."""
    degrees = 30.0
    data = shipped(name)
    data.setdefault("contact", {})["discrete_gap"] = discrete_gap
    original = scene_from_dict(data)
    turned = scene_from_dict(moved_document(data, degrees))
    mesh = build_mesh(original.geometry, LEVELS[name])
    first = solve_on(original, mesh)
    second = solve_on(turned, moved_mesh(mesh, rotation(degrees)))
    assert first.converged and second.converged
    assert contact_force(first) > 0
    assert contact_force(second) == pytest.approx(contact_force(first), rel=1e-6)
    assert nd.norms(second)["sigma_X"] == pytest.approx(nd.norms(first)["sigma_X"], rel=1e-6)
    assert np.allclose(nd.force_balance(second).resultant,
                       rotation(degrees) @ nd.force_balance(first).resultant,
                       rtol=0, atol=1e-6 * contact_force(first))


def test_a_moved_mesh_keeps_its_numbering_and_labels_and_refines_straight():
    mesh = build_mesh(scene_from_dict(shipped("hertz-cylinder")).geometry, 1)
    r = rotation(30.0)
    moved = moved_mesh(mesh, r, (5.0, -2.0))
    before = np.array([v.point for v in mesh.vertices])
    after = np.array([v.point for v in moved.vertices])
    assert np.allclose(after, before @ r.T + [5.0, -2.0], atol=1e-13)
    assert moved.GetBoundaries() == mesh.GetBoundaries()
    assert [[v.nr for v in el.vertices] for el in moved.Elements(ngs.VOL)] == \
        [[v.nr for v in el.vertices] for el in mesh.Elements(ngs.VOL)]
    # refined without the unmoved curves: the new vertices are the edge midpoints
    moved.Refine()
    refined = np.array([v.point for v in moved.vertices])
    assert np.allclose(refined[:len(after)], after)
    xy = after @ np.linalg.inv(r).T - np.array([5.0, -2.0]) @ np.linalg.inv(r).T
    assert xy.shape == before.shape
    with pytest.raises(ValueError, match="positive determinant"):
        moved_mesh(mesh, np.diag([1.0, -1.0]))
