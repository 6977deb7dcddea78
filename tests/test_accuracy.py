"""Accuracy on demand (issue 50): ``nd.solve(scene, tol=...)`` chooses the method by the rule
of :mod:`ngdual.accuracy` and reports what it did; the tolerance is reached by the estimate."""

import json

import pytest

import ngdual as nd
from ngdual.accuracy import FASTEST_ORDER, SMOOTH_ORDER, fastest_method, fixed_singularities
from ngdual.post import result_record
from ngdual.scene import SceneError


@pytest.mark.parametrize("name, overrides, order, family, goal", [
    ("hertz-cylinder", [], SMOOTH_ORDER, "facet", "pressure"),      # free ends only
    ("cattaneo-mindlin", [], SMOOTH_ORDER, "facet", "pressure"),
    ("wedge", [], FASTEST_ORDER, "facet", "pressure"),               # a kink
    ("flat-punch", [], FASTEST_ORDER, "facet", "pressure"),          # edges running straight
    ("punch-on-foundation", [], FASTEST_ORDER, "facet", "pressure"),  # clamped ends
    ("thesis-3.46-coulomb", [], 0, "coarse", "pressure"),         # the thesis keeps order 0
    ("hertz-cylinder", ["discretisation.order=2"], 2, "facet", "pressure"),   # declared
    ("thesis-3.46-frictionless", ["boundary.contact=[]", 'boundary.neumann=["top", "bottom"]'],
     0, "coarse", "stress"),                                      # no contact: the stress
])
def test_the_rule_chooses_order_family_and_goal(name, overrides, order, family, goal):
    method = fastest_method(nd.load_scene(name, overrides))
    assert (method.order, method.multipliers, method.goal) == (order, family, goal)
    assert method.reason


@pytest.mark.parametrize("name, overrides, expected", [
    ("hertz-cylinder", [], []),
    ("wedge", [], ["a kink at (0, 0)"]),
    ("flat-punch", [], ["a free side running straight on at (-0.25, 0)",
                        "a free side running straight on at (0.25, 0)"]),
    ("punch-on-foundation", [], ["a junction with Gamma_D at (2, 0)",
                                 "a junction with Gamma_D at (-2, 0)"]),
    # the same cylinder with its free sides clamped: Gamma_C meets Gamma_D
    ("hertz-cylinder", ['boundary.dirichlet=["left", "right", "top"]', "boundary.neumann=[]",
                        'loads.displacement=["0", "-0.01"]'], "clamped"),
])
def test_the_fixed_singular_points_of_the_pressure_are_read_from_gamma_c(name, overrides,
                                                                          expected):
    """The order follows where the pressure may be singular whatever the load: a kink, a
    junction with Gamma_D, an end where the boundary runs straight on; free ends of the
    contact zone alone (Hertz) leave the higher order its rate."""
    found = fixed_singularities(nd.load_scene(name, overrides))
    if expected == "clamped":
        assert found and all(f.startswith("a junction with Gamma_D") for f in found)
    else:
        assert sorted(found) == sorted(expected)


def test_a_pressure_singular_at_an_end_of_gamma_c_is_measured_on_its_middle_half():
    """The flat punch's edges meet free sides running straight on: p ~ d^(-1/2) is not in
    L2 there, and the study measures the core |x| < a/2; so does the rule."""
    assert fastest_method(nd.load_scene("flat-punch")).window == (-0.125, 0.125)
    assert fastest_method(nd.load_scene("hertz-cylinder")).window is None
    solution = nd.solve(nd.load_scene("flat-punch"), tol=0.05)
    assert solution.accuracy["reached"] and "on -0.125 <= x <= 0.125" in \
        solution.accuracy["method"]


def test_a_thesis_scene_keeps_order_0_and_measures_away_from_its_clamped_ends():
    """Example 3.46's thesis end values leave sigma ~ 1/r at the clamped ends of Gamma_C:
    the pressure error there is infinite, its middle half is measured and reached."""
    solution = nd.solve(nd.load_scene("thesis-3.46-frictionless"), tol=0.05)
    acc = solution.accuracy
    assert acc["reached"] and (acc["order"], acc["multipliers"]) == (0, "coarse")
    assert acc["window"] == (-2.0, 2.0)


def test_an_order_asked_for_wins_over_the_rule():
    method = fastest_method(nd.load_scene("hertz-cylinder"), order=2)
    assert (method.order, method.multipliers, method.reason) == (2, "facet", "as asked")


def test_a_solve_to_a_tolerance_reaches_it_and_says_how():
    scene = nd.load_scene("hertz-cylinder")
    solution = nd.solve(scene, tol=0.05)
    acc = solution.accuracy
    assert acc["reached"] and acc["stopped_by"] == "tol"
    assert acc["relative_estimate"] <= 0.05 and acc["tol"] == 0.05
    assert acc["order"] == SMOOTH_ORDER and acc["method"].startswith("adaptive, pressure goal")
    assert acc["solves"] == len(acc["unknowns_per_step"]) >= 1
    assert acc["unknowns"] == acc["unknowns_per_step"][-1]
    assert result_record(solution)["accuracy"]["tol"] == 0.05


@pytest.mark.parametrize("tol", [0.0, 1.0, -0.1, "0.01", True])
def test_a_bad_tolerance_is_a_scene_error_naming_it(tol):
    with pytest.raises(SceneError) as info:
        nd.solve(nd.load_scene("hertz-cylinder"), tol=tol)
    assert info.value.field == "tol"


def test_the_command_line_solves_to_a_tolerance_and_says_how(tmp_path, capsys):
    from ngdual.cli import main

    out = tmp_path / "out"
    assert main(["solve", "hertz-cylinder", "--tol", "0.05", "--out", str(out),
                 "--no-plots"]) == 0
    printed = capsys.readouterr().out
    assert "accuracy  adaptive, pressure goal, k = 2" in printed and "an adapted mesh" in printed
    record = json.loads((out / "result.json").read_text())
    assert record["accuracy"]["reached"] and record["accuracy"]["tol"] == 0.05


@pytest.mark.parametrize("tol", ["0", "2", "nan"])
def test_a_bad_tolerance_on_the_command_line_exits_2_writing_nothing(tmp_path, tol, capsys):
    from ngdual.cli import main

    out = tmp_path / "out"
    assert main(["solve", "hertz-cylinder", "--tol", tol, "--out", str(out)]) == 2
    assert "--tol" in capsys.readouterr().err and not out.exists()
