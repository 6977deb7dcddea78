"""The primal peer (P1/P2 displacements, Nitsche contact, semismooth Newton) against Hertz
and Cattaneo-Mindlin (ngdual.studies.primal_peer), and the peer and ngdual on the curved and
kinked contact boundaries of the shipped scenes (pressure samples of
ngdual.verification.overkill on a Gamma_C that is a graph over x)."""

import math

import numpy as np
import pytest

import ngdual as nd
from ngdual.mesh import build_mesh, polygon_mesh
from ngdual.studies.primal_peer import (
    NewtonError,
    cattaneo_mindlin_case,
    hertz_case,
    hertz_mesh,
    hertz_pressure,
    primal_samples,
    solve_primal,
    solve_scene_primal,
)
from ngdual.studies.primal_peer.result import ContactEdges
from ngdual.verification import hertz, wedge
from ngdual.verification.overkill import (
    edge_samples,
    graph_over_x,
    nodes_to_samples,
    solution_samples,
    true_errors,
)
from ngdual.verification.traction import traction_profile

# the Hertz and Cattaneo-Mindlin studies on graded meshes to level 5 are slow; the pressure
# samples on curved and kinked Gamma_C and the coarse scene solves are fast
slow = pytest.mark.slow

# Hertz on levels 1, 3, 5 of the block graded towards the contact, contact edges of length
# HC / 2^(level-1): two refinements (h / 4) between tested levels. The pressure has
# square-root edges at +-a, so its L2 error is O(h / a) for P1 and P2 alike, with a constant
# that depends on where +-a falls inside its element and varies by a factor up to about 4
# between meshes (documented in the module): one refinement need not reduce the error, two do.
# P2 starts twice as coarse (22k DOFs at the finest level instead of 44k; P1: 11k).
HC = {1: 0.05, 2: 0.1}
LEVELS = (1, 3, 5)
# Tolerance at the finest level: C h / a (h / a = 1 / 51 for P1, 1 / 26 for P2, a = 0.16
# for this load) with C above the worst constant seen over several meshes and loads
# (P1: 0.6-1.2, P2: 0.1-0.4).
L2_CONSTANT = {1: 1.5, 2: 0.5}


@pytest.fixture(scope="module")
def hertz_rows():
    return {order: [hertz_case(order, level, mesh_kw={"hc": HC[order]}) for level in LEVELS]
            for order in (1, 2)}


@slow
@pytest.mark.parametrize("order", [1, 2])
def test_hertz_pressure_error_decreases_and_is_small(hertz_rows, order):
    rows = hertz_rows[order]
    errors = [r.l2_error for r in rows]
    assert all(e1 > e2 for e1, e2 in zip(errors, errors[1:])), errors
    finest = rows[-1]
    assert errors[-1] < L2_CONSTANT[order] * finest.hc / finest.a_hertz, errors
    # the contact set {p_h > 0} has the Hertz half-width of the computed force, within two
    # contact edges (the edge of the discrete contact set is only located within elements)
    assert abs(finest.a_measured - finest.a_hertz) < 2 * finest.hc
    # the test would be void without a resolved contact zone
    assert finest.a_hertz > 20 * finest.hc


@slow
@pytest.mark.parametrize("order", [1, 2])
def test_hertz_total_force_is_consistent(hertz_rows, order):
    finest = hertz_rows[order][-1]
    # global equilibrium: int p over Gamma_C equals the Galerkin reaction on the pushed bottom;
    # they differ only by the quadrature of the kink of [P_n]_- (bonus order vs default)
    assert finest.force > 0
    assert finest.reaction == pytest.approx(finest.force, rel=1e-3)
    # the force is the one the displacement field carries: the approach u_y(0, -a) - u_y(0, 0)
    # matches McEwen's half-plane solution for this force; the finite block (H = L = 4 ~ 25 a)
    # adds a smooth strain of relative size a few percent (it grows linearly with depth):
    # P2 agrees to about 2 %, P1 (coarse far field) to about 4 %
    assert finest.approach_ratio == pytest.approx(1.0, abs=0.06)
    # the prescribed displacement is delta = 0.05 upwards: the contact force is what a
    # cylinder pushed into the block by less than delta produces, so the surface point under
    # it moved by ~0 and the material in between is compressed (u_y increasing with depth)
    u = finest.result.u
    mesh = u.space.mesh
    uy = [u(mesh(0.0, -d))[1] for d in (0.0, 0.5, 1.0, 2.0)]
    assert abs(uy[0]) < 1e-3 * 0.05
    assert all(a < b for a, b in zip(uy, uy[1:])) and uy[-1] < 0.05


@slow
def test_hertz_newton_converges_in_a_handful_of_steps(hertz_rows):
    for rows in hertz_rows.values():
        for r in rows:
            res = r.result
            assert res.converged
            assert res.newton_iterations <= 12, res.residuals
            assert res.residuals[-1] <= 1e-10 * res.residuals[0]
            # semismooth Newton ends with a (near) exact step once the active set is right
            assert res.residuals[-1] < 1e-3 * res.residuals[-2]


@slow
def test_newton_failure_raises_instead_of_reporting_converged():
    mesh = hertz_mesh(1, hc=HC[1])
    with pytest.raises(NewtonError):
        solve_primal(mesh, E=1.0, nu=0.3, dirichlet=["bottom"], neumann=["left", "right"],
                     contact=["contact"], displacement=(0, 0.05), gap="x*x/2", order=1,
                     max_newton=2)


@slow
def test_pressure_at_points(hertz_rows):
    res = hertz_rows[1][1].result
    mid = np.column_stack([res.x_mid, np.zeros_like(res.x_mid)])
    assert np.allclose(res.pressure(mid), res.pressure_mid, rtol=1e-10, atol=1e-14)
    assert np.all(res.pressure_mid >= 0)
    assert np.all(res.traction_mid == 0)  # frictionless
    a = hertz_pressure(0.0, res.contact_force, 1.0, 1.0, 0.3)[1]
    assert np.all(res.pressure_mid[np.abs(res.x_mid) > 1.5 * a] == 0)
    assert res.pressure([[0.0, 0.0]])[0] > 0


@pytest.fixture(scope="module")
def cattaneo_rows():
    return [cattaneo_mindlin_case(2, level) for level in (1, 2)]


@slow
def test_cattaneo_mindlin_stick_zone(cattaneo_rows):
    for r in cattaneo_rows:
        # a partial-slip state, otherwise c = a or c = 0 would be trivially matched
        assert 0.3 < r.c_formula / r.a_hertz < 0.9
        # friction opposes the tangential shift (+x) of the bottom and stays below mu P
        assert r.Q < 0 and abs(r.Q) < 0.3 * r.P
        # the stick set {|P_t| < s} is located within elements: two contact edges
        assert abs(r.c_measured - r.c_formula) < 2 * r.hc, (r.c_measured, r.c_formula)
        assert r.result.newton_iterations <= 15
    # the shear traction converges to Cattaneo-Mindlin's (kinks at +-c, square-root edges
    # at +-a: O(h / a), h / a = 1 / 13 on level 2; tolerance 2 h / a)
    errors = [r.traction_l2_error for r in cattaneo_rows]
    last = cattaneo_rows[-1]
    assert errors[-1] < errors[0] and errors[-1] < 2 * last.hc / last.a_hertz, errors


@slow
def test_tresca_stick_zone():
    r = cattaneo_mindlin_case(2, 2, law="tresca")
    assert 0.3 < r.c_formula / r.a_hertz < 0.9
    assert abs(r.c_measured - r.c_formula) < 2 * r.hc, (r.c_measured, r.c_formula)
    assert math.isfinite(r.traction_l2_error)
    assert r.traction_l2_error < 2 * r.hc / r.a_hertz


@pytest.mark.parametrize("order, nu, mixed, rtol", [
    pytest.param(1, 0.3, False, 1e-8, marks=slow),
    pytest.param(2, 0.3, False, 1e-8, marks=slow),
    # Taylor-Hood, lam / mu = 5000: the linear u and constant pressure lie in its space too
    (2, 0.4999, True, 1e-7),
])
def test_uniform_compression_with_free_sides_touching_contact(order, nu, mixed, rtol):
    """Patch test: the whole top is in contact up to the traction-free sides.

    The bottom gets the displacement of the uniaxial plane-strain state sigma_yy = -p,
    sigma_xx = sigma_xy = 0 with u = 0 on the top (the flat foundation, g = 0), which is in
    the discrete space; Nitsche's method is consistent, so p_h = p on every contact edge,
    including those at the corners where Gamma_C meets the free sides, however large lam.
    """
    E, p, H = 2.0, 0.01, 1.0
    mesh = polygon_mesh([(-1, -H), (1, -H), (1, 0), (-1, 0)],
                        ["bottom", "right", "contact", "left"], maxh=0.3)
    exx, eyy = p * nu * (1 + nu) / E, -p * (1 - nu**2) / E
    res = solve_primal(mesh, E=E, nu=nu, dirichlet=["bottom"], neumann=["left", "right"],
                       contact=["contact"], displacement=(f"{exx!r}*x", f"{-eyy * H!r}"),
                       gap=0.0, order=order, mixed=mixed)
    assert np.allclose(res.pressure_mid, p, rtol=rtol)
    assert np.allclose(res.traction_mid, 0.0)
    assert res.contact_force == pytest.approx(2 * p, rel=rtol)
    assert res.support_force == pytest.approx([0.0, 2 * p], abs=rtol * p)
    assert res.contact_length == pytest.approx(2.0)


# --- curved and kinked contact boundaries: the shipped scenes -------------------------------

def _contact_edges(mesh, scene):
    e = ContactEdges.of(mesh, scene.labels("contact"))
    return np.stack([e.p0, e.p1], axis=1)


@pytest.mark.parametrize("level", [1, 3])
def test_arc_length_weights_integrate_the_length_of_gamma_c_on_the_arc_mesh(level):
    scene = nd.load_scene("hertz-cylinder")
    edges = _contact_edges(build_mesh(scene.geometry, level), scene)
    length = np.linalg.norm(edges[:, 1] - edges[:, 0], axis=1)
    # the vertices lie on the arc of radius R = 10 around (0, 10): a curved Gamma_C
    R = 10.0
    assert np.allclose(np.hypot(edges[..., 0], edges[..., 1] - R), R, rtol=1e-12)
    _, w = edge_samples(edges, 4)
    assert w.sum() == pytest.approx(length.sum(), rel=1e-13)
    # the inscribed polygon is shorter than the arc by sum R phi_e^3 / 24 <= arc (h/R)^2 / 24
    arc = 2 * R * math.asin(4 / R)
    assert 0 < arc - w.sum() <= arc * (length.max() / R) ** 2 / 24 * 1.01


def test_ngdual_pressure_weights_integrate_the_kinked_gamma_c_exactly():
    scene = nd.load_scene("wedge")
    samples = solution_samples(nd.solve(scene, level=1))
    reference = {"x": samples["p_nodes"], "p": samples["p"]}
    x, w, _ = nodes_to_samples(samples["p_nodes"], samples["p"], reference, samples["p_edges"])
    assert w.sum() == pytest.approx(2 * math.hypot(4.0, 0.4), rel=1e-13)
    # a candidate compared with itself has no error, also across the pressure's jump at the
    # apex (each flank's value on its side)
    error = true_errors(samples, samples, *scene.material.lame)
    assert error["pressure_rel"] < 1e-14


def test_a_kink_keeps_each_flank_s_pressure_on_its_side():
    solution = nd.solve(nd.load_scene("wedge"), level=1)
    profile = traction_profile(solution)
    left_chain, right_chain = np.split(np.arange(len(profile.x)), profile.chain_starts[1:])
    apex_left = profile.pressure[left_chain[np.argmax(profile.x[left_chain])]]
    apex_right = profile.pressure[right_chain[np.argmin(profile.x[right_chain])]]
    assert apex_left != apex_right  # the multipliers jump at the kink
    samples = solution_samples(solution)
    near = np.interp([-1e-9, 1e-9], samples["p_nodes"], samples["p"])
    assert near == pytest.approx([apex_left, apex_right], rel=1e-6)


@pytest.mark.parametrize("edges", [
    [[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [1.0, 1.0]]],      # a vertical edge
    [[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [0.5, 0.5]]],      # folding back over x
])
def test_pressure_samples_refuse_a_gamma_c_that_is_not_a_graph_over_x(edges):
    with pytest.raises(ValueError, match="graph over x"):
        graph_over_x(np.array(edges))


def _analytic_error(scene, result) -> float:
    """Relative L2 error on Gamma_C (arc length) of the peer's pressure against the
    half-plane solution of the peer's own force."""
    samples = primal_samples(scene, result, 4)
    x, w, p = samples["p_x"], samples["p_w"], samples["p"]
    E, nu = scene.material.E, scene.material.nu
    force = float(np.sum(w * p))
    if scene.name == "wedge":
        exact = wedge(force, 0.1, E, nu).pressure(x)
    else:
        exact = hertz(force, 10.0, E, nu).pressure(x)
    return math.sqrt(np.sum(w * (p - exact) ** 2) / np.sum(w * exact**2))


def test_p2_peer_pressure_on_the_arc_approaches_hertz_on_coarse_meshes():
    scene = nd.load_scene("hertz-cylinder")
    errors = [_analytic_error(scene, solve_scene_primal(scene, level, 2)[0])
              for level in (1, 2)]
    # contact edges of 0.25 and 0.125 against a = 0.34: O(h / a) with the constant of P2
    # (0.1 - 0.4, the module docstring of nitsche.py)
    assert errors[1] < errors[0] < 0.4 * 0.25 / 0.34 * 2, errors
    assert errors[1] < 0.4 * 0.125 / 0.34 * 1.5, errors


@slow
def test_p2_peer_pressure_on_the_arc_converges_to_hertz_up_to_the_finite_body():
    """The half-plane pressure is only approximately that of the finite body (8 x 4, top
    clamped, a = 0.34): measured, the P2 peer on the scene's mesh refined five more times
    around the contact zone (172 000 DOFs) differs from Hertz by 1.5 %, ngdual on uniform
    level 6 (1.7 million DOFs) by 1.8 %, so the analytic pressure confirms the discrete one
    to about 2 % and no better. Measured errors on levels 2, 3, 4: 6.5 %, 3.6 %, 2.4 %."""
    scene = nd.load_scene("hertz-cylinder")
    errors = [_analytic_error(scene, solve_scene_primal(scene, level, 2)[0])
              for level in (2, 3, 4)]
    assert errors[0] > errors[1] > errors[2], errors
    assert errors[-1] < 0.03, errors


def _box_refined(scene, level: int, times: int, box: float):
    """The scene's mesh on ``level`` refined ``times`` times in |x| < box, y < box (the
    contact zone) by ngdual's REFINE step, with its coarse boundary meshes."""
    from ngdual.afem import refine_with_boundary
    from ngdual.boundary import BoundaryMeshes
    from ngdual.mesh import mesh_arrays

    mesh = build_mesh(scene.geometry, level)
    coarse = BoundaryMeshes.for_scene(scene, mesh)
    for _ in range(times):
        vertices, triangles = mesh_arrays(mesh)
        centre = vertices[triangles].mean(axis=1)
        marked = (np.abs(centre[:, 0]) < box) & (centre[:, 1] < box)
        mesh, coarse = refine_with_boundary(scene, mesh, coarse, marked)
    return mesh, coarse


def _pressure_differences(scene, mesh, coarse) -> tuple[float, float, float]:
    """ngdual and the P2 peer on the same mesh: the relative L2 difference of their
    pressures on Gamma_C, and the peer's and ngdual's errors against the half-plane
    solution of their own forces."""
    from ngdual.solvers.dispatch import solve_on_mesh
    from ngdual.studies.primal_peer import primal_arguments

    ours = solution_samples(solve_on_mesh(scene, mesh, coarse))
    peer = primal_samples(scene, solve_primal(mesh, **primal_arguments(scene), order=2), 2)
    difference = true_errors(peer, ours, *scene.material.lame)["pressure_rel"]
    E, nu = scene.material.E, scene.material.nu
    exact = (lambda P: wedge(P, 0.1, E, nu)) if scene.name == "wedge" else (
        lambda P: hertz(P, 10.0, E, nu))
    own = {"x": ours["p_nodes"], "p": ours["p"]}
    errors = []
    for x, w, p in ((peer["p_x"], peer["p_w"], peer["p"]),
                    nodes_to_samples(ours["p_nodes"], ours["p"], own, ours["p_edges"])):
        p_exact = exact(float(np.sum(w * p))).pressure(x)
        errors.append(math.sqrt(np.sum(w * (p - p_exact) ** 2) / np.sum(w * p_exact**2)))
    return difference, *errors


@slow
@pytest.mark.parametrize("name, times, box, agree, analytic", [
    # measured: differences 7.5 % -> 2.4 %; errors against Hertz 1.7 % (peer), 1.9 % (ngdual)
    ("hertz-cylinder", (2, 4), 0.5, 0.035, (0.025, 0.03)),
    # the log-singular pressure at the apex of the V is resolved by few h~ edges (a = 0.056):
    # differences 38 % -> 16 %; errors against the wedge solution 4.4 % (peer), 13 % (ngdual)
    ("wedge", (3, 5), 0.12, 0.2, (0.06, 0.15)),
])
def test_peer_and_ngdual_pressures_converge_to_each_other_on_the_same_mesh(
        name, times, box, agree, analytic):
    scene = nd.load_scene(name)
    coarse_difference, _, _ = _pressure_differences(scene, *_box_refined(scene, 2, times[0], box))
    difference, peer_error, ours_error = _pressure_differences(
        scene, *_box_refined(scene, 2, times[1], box))
    assert difference < coarse_difference / 2, (coarse_difference, difference)
    assert difference < agree
    assert peer_error < analytic[0] and ours_error < analytic[1], (peer_error, ours_error)


def test_p2_peer_pressure_on_cattaneo_mindlin_approaches_hertz():
    """nu = 0.4999 decouples the normal problem from the tangential one: the pressure under
    the sheared cylinder is Hertz's. The scene's P2 peer is Taylor-Hood (the displacement
    form locks: 19 % on level 2, 30-48 % on levels 3-5); measured 8.9 % and 5.7 % on levels
    1 and 2 (2.9 %, 2.3 % on levels 3, 4, where the finite body's ~1.5 % shows)."""
    scene = nd.load_scene("cattaneo-mindlin")
    errors = [_analytic_error(scene, solve_scene_primal(scene, level, 2)[0])
              for level in (1, 2)]
    assert errors[1] < errors[0] < 0.12, errors
    assert errors[1] < 0.07, errors
