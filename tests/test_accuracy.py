"""Accuracy on demand (issue 50): ``nd.solve(scene, tol=...)`` chooses the method by the rule
of :mod:`ngdual.accuracy` and reports what it did; the tolerance is reached by the estimate."""

import pytest

import ngdual as nd
from ngdual.accuracy import FASTEST_ORDER, fastest_method
from ngdual.post import result_record
from ngdual.scene import SceneError


@pytest.mark.parametrize("name, overrides, order, family, goal", [
    ("hertz-cylinder", [], FASTEST_ORDER, "facet", "pressure"),
    ("cattaneo-mindlin", [], FASTEST_ORDER, "facet", "pressure"),
    ("thesis-3.46-coulomb", [], 0, "coarse", "pressure"),         # the thesis keeps order 0
    ("hertz-cylinder", ["discretisation.order=2"], 2, "facet", "pressure"),   # declared
    ("thesis-3.46-frictionless", ["boundary.contact=[]", 'boundary.neumann=["top", "bottom"]'],
     0, "coarse", "stress"),                                      # no contact: the stress
])
def test_the_rule_chooses_order_family_and_goal(name, overrides, order, family, goal):
    method = fastest_method(nd.load_scene(name, overrides))
    assert (method.order, method.multipliers, method.goal) == (order, family, goal)
    assert method.reason


def test_an_order_asked_for_wins_over_the_rule():
    method = fastest_method(nd.load_scene("hertz-cylinder"), order=2)
    assert (method.order, method.multipliers, method.reason) == (2, "facet", "as asked")


def test_a_solve_to_a_tolerance_reaches_it_and_says_how():
    scene = nd.load_scene("hertz-cylinder")
    solution = nd.solve(scene, tol=0.05)
    acc = solution.accuracy
    assert acc["reached"] and acc["stopped_by"] == "tol"
    assert acc["relative_estimate"] <= 0.05 and acc["tol"] == 0.05
    assert acc["order"] == FASTEST_ORDER and acc["method"].startswith("adaptive, pressure goal")
    assert acc["solves"] == len(acc["unknowns_per_step"]) >= 1
    assert acc["unknowns"] == acc["unknowns_per_step"][-1]
    assert result_record(solution)["accuracy"]["tol"] == 0.05


@pytest.mark.parametrize("tol", [0.0, 1.0, -0.1, "0.01", True])
def test_a_bad_tolerance_is_a_scene_error_naming_it(tol):
    with pytest.raises(SceneError) as info:
        nd.solve(nd.load_scene("hertz-cylinder"), tol=tol)
    assert info.value.field == "tol"
