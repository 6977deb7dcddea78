"""The contact picture shows what to read: p_h and q_h, against the scene's analytic solution.

* ``ContactTraces.pressure`` and ``shear`` are the h~ hat projections p_h, q_h that the
  contact conditions of (3.62) control: weighted with int mu_i they sum to the force the
  multipliers see (``force_balance``), and where Gamma_C has free ends to the resultant of
  sigma n on Gamma_C, the whole contact force.
* On hertz-cylinder p_h is the Hertz pressure of the force it carries; on cattaneo-mindlin
  q_h points the way of the Cattaneo-Mindlin shear and sticks inside the contact zone.
* The y-range of the picture holds every p_h, also the tension at the clamped ends of
  Example 3.46 with the thesis' end values.
* The ``[benchmark]`` table is optional and validated like every table.
"""

import matplotlib.pyplot as plt
import numpy as np
import pytest

import ngdual as nd
from ngdual.cli.pipeline import solution_figures
from ngdual.scene import SceneError, load_scene, read_toml, scene_from_dict
from ngdual.verification.benchmark import (
    benchmark_traces,
    center_coordinate,
    exact_solution,
    plane_direction,
)
from ngdual.verification.traction import traction_profile


@pytest.fixture(scope="module")
def hertz():
    return nd.solve(load_scene("hertz-cylinder"))          # level 3, the shipped one


def hat_integrals(solution) -> np.ndarray:
    """int mu_i ds of every h~ hat with a dof, from the h~ node coordinates."""
    coarse = solution.problem.spaces.contact
    out = []
    for c, chain in enumerate(coarse.chains):
        points = chain.path_points[coarse.nodes[c]]
        edges = np.linalg.norm(np.diff(points, axis=0), axis=1)
        left, right = np.concatenate([[0.0], edges]), np.concatenate([edges, [0.0]])
        if chain.closed:
            left[0] = right[-1] = edges[-1]
        positions = list(coarse.nodes[c])
        out += [0.5 * (left[positions.index(q)] + right[positions.index(q)])
                for q in coarse.dof_positions(c)]
    return np.array(out)


@pytest.mark.parametrize("name, level", [("thesis-3.46-coulomb", 2), ("flat-punch", 1)])
def test_p_h_and_q_h_weighted_by_the_hats_sum_to_the_multiplier_force(name, level):
    solution = nd.solve(load_scene(name, [f"geometry.level={level}"]))
    traces = nd.contact_traces(solution)
    balance = nd.force_balance(solution)
    weights = hat_integrals(solution)
    normal = solution.problem.spaces.gamma_c.normals[0]        # a straight Gamma_C
    tangent = np.array([normal[1], -normal[0]])                # t of (3.24)
    scale = np.linalg.norm(balance.multiplier_force)
    assert weights @ traces.pressure == pytest.approx(-balance.multiplier_force @ normal,
                                                      abs=1e-6 * scale)
    assert weights @ traces.shear == pytest.approx(balance.multiplier_force @ tangent,
                                                   abs=1e-6 * scale)
    if name == "flat-punch":   # free ends: the hats sum to one, p_h carries the whole force
        assert weights @ traces.pressure == pytest.approx(-balance.resultant @ normal,
                                                          rel=1e-6)
        assert np.all(traces.pressure > 0) and not len(traces.end_xy)


def test_p_h_is_the_hertz_pressure_of_the_force_it_carries(hertz):
    traces = nd.contact_traces(hertz)
    scene = hertz.problem.scene
    exact = exact_solution(scene, traction_profile(hertz).force)
    s = traces.coarse_xy @ plane_direction(scene) - center_coordinate(scene)
    # measured on level 3: peak 0.08 %, largest nodal error 6.8 % of p0 (at the zone's edge)
    assert traces.pressure.max() == pytest.approx(exact.p0, rel=0.01)
    assert np.max(np.abs(traces.pressure - exact.pressure(s))) < 0.1 * exact.p0
    htilde = np.max(np.diff(np.sort(traces.coarse_xy[:, 0])))
    assert np.all(np.abs(s[traces.coarse_in_contact]) < exact.a + htilde)
    assert np.all(traces.coarse_status[traces.coarse_in_contact] == "contact")


@pytest.mark.slow
def test_q_h_points_the_way_of_the_cattaneo_mindlin_shear_and_sticks_inside_the_zone():
    solution = nd.solve(load_scene("cattaneo-mindlin"))
    traces = nd.contact_traces(solution)
    exact = benchmark_traces(solution)
    assert traces.friction and exact.shear is not None
    at_nodes = np.interp(traces.coarse_xy[:, 0], np.sort(exact.x),
                         exact.shear[np.argsort(exact.x)])
    inside = np.abs(at_nodes) > 0.2 * np.abs(at_nodes).max()
    assert inside.sum() >= 3
    assert np.all(np.sign(traces.shear[inside]) == np.sign(at_nodes[inside]))
    stick = traces.coarse_xy[traces.coarse_status == "stick", 0]
    assert len(stick) and np.all(np.abs(stick) < exact.solution.hertz.a)


def test_the_y_range_holds_every_p_h_and_the_exact_curve_is_drawn(hertz):
    fig = nd.plot_contact_traces(nd.contact_traces(hertz), exact=benchmark_traces(hertz))
    low, high = fig.axes[0].get_ylim()
    traces = nd.contact_traces(hertz)
    assert low <= traces.pressure.min() and traces.pressure.max() <= high
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any(text.startswith("Hertz, P = ") for text in legend)
    plt.close(fig)


@pytest.mark.slow
def test_the_tension_at_clamped_ends_with_the_thesis_end_values_is_on_scale_and_named():
    solution = nd.solve(load_scene("thesis-3.46-frictionless", ["geometry.level=2"]))
    traces = nd.contact_traces(solution)
    assert len(traces.end_xy) == 2 and traces.end_pressure.min() < 0    # tension
    assert np.all(traces.pressure >= 0)          # (3.62) wherever a contact condition acts
    fig = nd.plot_contact_traces(traces)
    low, high = fig.axes[0].get_ylim()
    values = np.concatenate([traces.pressure, traces.end_pressure])
    assert low <= values.min() and values.max() <= high
    assert any("tension at a fixed end" in t.get_text() for t in fig.axes[0].texts)
    plt.close(fig)


@pytest.mark.slow
def test_the_cli_picture_of_a_scene_with_a_benchmark_is_written(tmp_path):
    solution = nd.solve(load_scene("hertz-cylinder", ["geometry.level=1"]))
    written = solution_figures(solution, tmp_path)
    assert (tmp_path / "contact_traces.png") in written
    assert (tmp_path / "contact_traces.png").stat().st_size > 0


def test_the_shipped_contact_scenes_name_their_analytic_solution():
    kinds = {name: load_scene(name).benchmark.kind
             for name in ("hertz-cylinder", "flat-punch", "cattaneo-mindlin", "wedge",
                          "thesis-3.46-frictionless")}
    assert kinds == {"hertz-cylinder": "hertz", "flat-punch": "flat-punch",
                     "cattaneo-mindlin": "cattaneo-mindlin", "wedge": "wedge",
                     "thesis-3.46-frictionless": "none"}
    punch = exact_solution(load_scene("flat-punch"), P=3.0)
    assert punch.a == 0.25 and punch.force_within(0.125) == pytest.approx(1.0)


def test_the_benchmark_table_is_optional():
    _, data = read_toml("hertz-cylinder")
    del data["benchmark"]
    scene = scene_from_dict(data, ["geometry.level=1"])
    assert scene.benchmark.kind == "none" and exact_solution(scene, 1.0) is None
    assert benchmark_traces(nd.solve(scene)) is None


@pytest.mark.parametrize("overrides, field", [
    (['benchmark.kind="parabola"'], "benchmark.kind"),
    (["benchmark.slope=0.1"], "benchmark.slope"),                 # hertz reads the radius
    (['benchmark.kind="wedge"', "benchmark.radius=10.0"], "benchmark.slope"),  # missing
    (["benchmark.radius=-1.0"], "benchmark.radius"),
    (['benchmark.kind="cattaneo-mindlin"'], "benchmark.kind"),    # frictionless scene
    (["benchmark.center=[1.0]"], "benchmark.center"),
    (['benchmark.radius="ten"'], "benchmark.radius"),
])
def test_a_bad_benchmark_table_is_a_scene_error_naming_its_field(overrides, field):
    with pytest.raises(SceneError) as err:
        load_scene("hertz-cylinder", overrides)
    assert field in err.value.fields, err.value


def test_traces_of_something_else_are_refused_naming_the_argument():
    with pytest.raises(TypeError, match="^solution: must be an ngdual Solution"):
        nd.contact_traces(None)
    with pytest.raises(TypeError, match="^traces: must be the ContactTraces"):
        nd.plot_contact_traces(None)
    with pytest.raises(SceneError, match="no contact boundary") as err:
        nd.contact_traces(nd.solve(load_scene("thesis-3.46-frictionless", [
            "geometry.level=1", 'boundary.dirichlet=["left", "right"]',
            'boundary.neumann=["top", "bottom"]', 'boundary.contact=[]'])))
    assert err.value.field == "solution"
