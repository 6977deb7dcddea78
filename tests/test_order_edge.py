"""Gamma_C of the facet multipliers at order k (issue 27): its settings, its curve, its traces.

* The facet P_k multipliers live on the fine edges, discontinuous from edge to edge: no h~
  or h^ mesh, no value at an end of Gamma_C. ``contact.htilde_factor``, ``hhat_factor`` and
  ``ends`` other than their defaults would do nothing, so the scene is refused, naming the
  field.
* On an arc the gap and the normal are those of the arc, not of its chords (truth: the
  circle; Hertz's pressure on the core of the contact zone).
* ``contact_traces`` reads the moments the sign conditions control at the control points
  (truth: they sum to the contact force) and samples the P_k traces.
"""

import ngsolve as ngs
import numpy as np
import pytest

from ngdual.boundary.facet import bernstein_values
from ngdual.contact import curve_normal
from ngdual.forms import Spaces
from ngdual.mesh import build_mesh
from ngdual.scene import SceneError, gap_at, load_scene
from ngdual.solvers import solve_scene
from ngdual.trace import contact_traces
from ngdual.verification.analytic import hertz
from ngdual.verification.traction import traction_profile

FACET = ["discretisation.order=1"]
CONSISTENT = "contact.ends='consistent'"


@pytest.mark.parametrize("overrides, field", [
    ([], "contact.ends"),
    (["contact.ends='thesis'"], "contact.ends"),
    ([CONSISTENT, "contact.htilde_factor=4"], "contact.htilde_factor"),
    ([CONSISTENT, "contact.hhat_factor=1"], "contact.hhat_factor"),
    (["discretisation.order=0", "discretisation.multipliers='facet'", CONSISTENT,
      "contact.htilde_factor=1"], "contact.htilde_factor"),
])
def test_a_coarse_mesh_setting_with_facet_multipliers_is_a_scene_error_naming_it(overrides,
                                                                                  field):
    """Example 3.46 sets ends = "thesis" (the thesis' C_h~ of (3.61)): at order k it must
    say "consistent", the one end treatment the facet multipliers have."""
    with pytest.raises(SceneError) as err:
        load_scene("thesis-3.46-frictionless", FACET + overrides)
    assert err.value.field == field
    assert "facet" in str(err.value)


def test_the_defaults_of_the_coarse_mesh_settings_are_accepted_with_facet_multipliers():
    """Example 3.46 states htilde_factor = hhat_factor = 2, the defaults: accepted."""
    scene = load_scene("thesis-3.46-frictionless", FACET + [CONSISTENT])
    assert scene.discretisation.family == "facet"
    assert (scene.contact.htilde_factor, scene.contact.hhat_factor) == (2, 2)


def test_the_coarse_mesh_settings_stay_free_with_the_thesis_multipliers():
    scene = load_scene("thesis-3.46-frictionless", ["contact.htilde_factor=4"])
    assert scene.discretisation.family == "coarse" and scene.contact.ends == "thesis"


def _facet_gamma_c(name, order, level):
    scene = load_scene(name, [f"discretisation.order={order}"])
    return scene, Spaces.build(scene, build_mesh(scene.geometry, level)).gamma_c


def test_the_gap_of_the_facet_multipliers_is_the_gap_of_the_arc_not_of_its_chords():
    """hertz-cylinder's bottom is the arc |x - (0, 10)| = 10 above the plane y = 0: at every
    control point x of a chord, g_h is the distance from the arc's point on the radius
    through x to the plane along the arc's normal (truth: the circle); the chord lies
    inside the arc by its sagitta."""
    scene, gamma_c = _facet_gamma_c("hertz-cylinder", 2, 1)
    t = np.array([0.0, 0.5, 1.0])
    starts = np.vstack([c.path_points[:-1] for c in gamma_c.coarse.chains])
    stops = np.vstack([c.path_points[1:] for c in gamma_c.coarse.chains])
    edges = np.repeat(np.arange(len(starts)), 3)
    points = (starts[:, None] + t[None, :, None] * (stops - starts)[:, None]).reshape(-1, 2)
    moved, normals = gamma_c.on_curve(points, edges)
    centre = np.array([0.0, 10.0])
    assert np.allclose(np.linalg.norm(moved - centre, axis=1), 10.0, rtol=0, atol=1e-12)
    assert np.allclose(normals, (moved - centre) / 10.0, rtol=0, atol=1e-14)
    # the sagitta of a chord of length |e| at its parameter t: t (1 - t) |e|^2 / (2 R)
    sagitta = np.linalg.norm(moved - points, axis=1)
    assert sagitta == pytest.approx(np.tile(t * (1 - t), len(starts)) * gamma_c.lengths[edges]**2
                                    / 20, rel=1e-3, abs=1e-12)
    exact = moved[:, 1] / -normals[:, 1]
    coefficients = gamma_c.coarse.interpolant(
        lambda p, e: gap_at(scene.contact, *gamma_c.on_curve(p, e)))
    interpolated = (coefficients.reshape(-1, 3) @ bernstein_values(2, t).T).ravel()
    assert interpolated == pytest.approx(exact, rel=1e-12)


def test_the_facet_multipliers_pair_with_the_normal_of_the_arc():
    """d_Cn(mu, tau) = int mu n_c.(tau n) ds with n_c the arc's outward normal: on every
    chord the radial direction from the centre (0, 10), which differs from the chord's
    normal away from its midpoint; on the flat punch the edge normal itself."""
    def squared_distance(scene, label, other):
        mesh = build_mesh(scene.geometry, 1)
        n_c = curve_normal(scene, mesh)
        other = other(mesh)
        return ngs.Integrate(ngs.InnerProduct(n_c - other, n_c - other), mesh, ngs.BND,
                             definedon=mesh.Boundaries(label))

    hertz_scene = load_scene("hertz-cylinder", ["discretisation.order=1"])
    radial = ngs.CF((ngs.x, ngs.y - 10.0))
    assert squared_distance(hertz_scene, "bottom",
                            lambda mesh: radial / ngs.sqrt(radial * radial)) < 1e-24
    assert squared_distance(hertz_scene, "bottom", lambda mesh: ngs.specialcf.normal(2)) > 1e-6
    punch = load_scene("flat-punch", ["discretisation.order=1"])
    assert squared_distance(punch, "punch", lambda mesh: ngs.specialcf.normal(2)) == 0.0


def test_on_straight_sides_the_gap_of_the_facet_multipliers_is_that_of_the_edges():
    _, gamma_c = _facet_gamma_c("flat-punch", 2, 1)
    points = gamma_c.midpoints
    moved, normals = gamma_c.on_curve(points, np.arange(len(points)))
    assert np.array_equal(moved, points) and np.array_equal(normals, gamma_c.normals)


@pytest.mark.filterwarnings("ignore::ngdual.solution.PhysicsWarning")
def test_hertz_at_order_2_has_the_pressure_of_hertz_on_the_core_of_the_contact_zone():
    """The P_2 trace -sigma_nn on |x| < a/2 against Hertz's p0 sqrt(1 - x^2 / a^2) for the
    computed force (the block is finite: Hertz's half-plane differs by about 1 %). With the
    gap of the chords instead of the arc the core error is 20 % on level 1."""
    scene = load_scene("hertz-cylinder", ["discretisation.order=2"])
    traces = contact_traces(solve_scene(scene, 1))
    force = float(np.sum(traces.edge_length * -traces.sigma_n))
    exact = hertz(force, 10.0, scene.material.E, scene.material.nu)
    x, p = traces.trace_xy[..., 0].ravel(), -traces.trace_sigma_n.ravel()
    core = np.abs(x) < exact.a / 2
    error = np.abs(p[core] - exact.pressure(x[core])).max() / exact.p0
    assert core.sum() >= 4 and error < 0.03, error


@pytest.mark.filterwarnings("ignore::ngdual.solution.PhysicsWarning")
def test_the_traces_at_order_1_are_read_at_the_control_points_of_the_fine_edges():
    """contact_traces of a facet solution: the pressure at every control point is the moment
    its contact condition signs, over int psi_i (so the moments sum to the contact force),
    the sampled P_1 traces interpolate their edge means, and the labels name control
    points (a straight Gamma_C, where the multipliers pair with the edge normal)."""
    solution = solve_scene(load_scene("thesis-3.46-frictionless", FACET + [CONSISTENT]), 1)
    traces = contact_traces(solution)
    gamma_c = solution.problem.spaces.gamma_c
    mass = gamma_c.hat_means(solution.problem.spaces.prolongations["lam_n"]).T @ gamma_c.lengths
    assert traces.node_kind == "control point"
    assert np.sum(traces.pressure * mass) == pytest.approx(
        np.sum(-traces.sigma_n * traces.edge_length), rel=1e-12)
    assert np.all(traces.pressure[traces.coarse_in_contact] >= 0)
    # the P_1 trace sampled at 6 equispaced points: its mean by the trapezoidal rule is exact
    # (up to the evaluation a round-off inside the triangle)
    samples = traces.trace_sigma_n
    mean = (samples[:, 1:] + samples[:, :-1]).sum(axis=1) / (2 * (samples.shape[1] - 1))
    assert mean == pytest.approx(traces.sigma_n, rel=1e-8, abs=1e-5 * np.abs(mean).max())
    assert traces.edge_active.sum() == np.count_nonzero(
        traces.coarse_in_contact.reshape(-1, 2).any(axis=1))


@pytest.mark.filterwarnings("ignore::ngdual.solution.PhysicsWarning")
def test_the_traction_profile_at_order_1_is_the_trace_and_integrates_to_the_contact_force():
    """The analytic curves of ``ngdual solve`` are drawn for the profile's force: at order k
    it is the P_k trace itself, whose integral is int -sigma_n ds exactly at k = 1 (up to its
    evaluation a share 1e-6 of |e| inside the triangle, ngdual.post.INSIDE)."""
    solution = solve_scene(load_scene("thesis-3.46-frictionless", FACET + [CONSISTENT]), 1)
    traces, profile = contact_traces(solution), traction_profile(solution)
    assert profile.force == pytest.approx(np.sum(-traces.sigma_n * traces.edge_length),
                                          rel=1e-6)
    assert np.array_equal(profile.pressure, -traces.trace_sigma_n.ravel())
