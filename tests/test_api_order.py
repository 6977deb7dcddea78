"""``nd.solve(scene, order=k, multipliers=...)``: the order k of PEERS_k and the multiplier
family as arguments, validated like every argument and solving the same problem as the
scene's ``[discretisation]`` entries."""

import numpy as np
import pytest

import ngdual as nd
from ngdual.scene import SceneError, SceneTypeError
from ngdual.solvers.dispatch import with_discretisation
from ngdual.verification.manufactured import manufactured_case
from ngdual.verification.manufactured_errors import volume_errors

CONSISTENT = "contact.ends='consistent'"   # the facet multipliers have no thesis ends
pytestmark = pytest.mark.filterwarnings("ignore::ngdual.solution.PhysicsWarning")


def test_the_order_argument_solves_the_problem_of_the_scenes_order_entry():
    scene = nd.load_scene("thesis-3.46-frictionless", [CONSISTENT])
    by_argument = nd.solve(scene, 1, order=1)
    by_entry = nd.solve(nd.load_scene("thesis-3.46-frictionless",
                                      ["discretisation.order=1", CONSISTENT]), 1)
    assert by_argument.problem.scene.discretisation.order == 1
    assert by_argument.problem.scene.discretisation.family == "facet"
    assert np.array_equal(by_argument.x, by_entry.x)
    assert scene.discretisation.order == 0                     # the scene is not changed


def test_order_0_and_no_arguments_are_the_thesis_method_bit_for_bit():
    scene = nd.load_scene("thesis-3.46-coulomb")
    assert with_discretisation(scene) is scene
    assert np.array_equal(nd.solve(scene, 1, order=0).x, nd.solve(scene, 1).x)


def test_the_multipliers_argument_at_order_0_gives_the_facet_family():
    scene = nd.load_scene("thesis-3.46-frictionless", [CONSISTENT])
    solution = nd.solve(scene, 1, multipliers="facet")
    assert solution.problem.scene.discretisation.family == "facet"
    assert solution.method == "active-set"


def test_order_1_is_closer_to_the_exact_manufactured_stress_than_order_0():
    """On the same mesh PEERS_1's stress error is far below PEERS_0's (exact solution)."""
    case = manufactured_case("frictionless")
    scene = case.scene()
    errors = [volume_errors(case, nd.solve(scene, 2, order=k))["sigma"] for k in (0, 1)]
    assert errors[1] < 0.2 * errors[0], errors


@pytest.mark.parametrize("arguments, error, field", [
    ({"order": 3}, SceneError, "order"),
    ({"order": -1}, SceneError, "order"),
    ({"order": True}, SceneTypeError, "order"),
    ({"order": "1"}, SceneTypeError, "order"),
    ({"order": 1.0}, SceneTypeError, "order"),
    ({"multipliers": 1}, SceneTypeError, "multipliers"),
    ({"multipliers": "hats"}, SceneError, "multipliers"),
])
def test_a_bad_order_or_family_argument_is_refused_naming_the_argument(arguments, error,
                                                                        field):
    scene = nd.load_scene("thesis-3.46-frictionless", [CONSISTENT])
    with pytest.raises(error) as caught:
        nd.solve(scene, 1, **arguments)
    assert caught.value.field == field



def test_order_1_with_the_thesis_end_values_names_the_scenes_contact_ends():
    with pytest.raises(SceneError) as caught:
        nd.solve(nd.load_scene("thesis-3.46-frictionless"), 1, order=1)
    assert caught.value.field == "contact.ends"
