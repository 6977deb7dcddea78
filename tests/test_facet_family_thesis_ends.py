"""``contact.ends = "thesis"``, the thesis' C_h~ of (3.61), is one rule for both multiplier
families: accepted at order 0 with the coarse multipliers (the thesis' space, whose tables it
reproduces), refused, naming ``contact.ends``, at every order k >= 1 and with the facet
multipliers at every order.
"""

import pytest

import ngdual as nd
from ngdual.cli import main

REFUSED = [(1, "coarse"), (2, "coarse"), (1, "facet"), (2, "facet"), (0, "facet")]


def _overrides(order, family):
    return [f"discretisation.order={order}", f"discretisation.multipliers='{family}'"]


@pytest.mark.parametrize("order, family", REFUSED)
def test_the_thesis_ends_away_from_order_0_coarse_are_a_scene_error_naming_contact_ends(
        order, family):
    with pytest.raises(nd.SceneError) as err:
        nd.load_scene("thesis-3.46-frictionless", _overrides(order, family))
    assert err.value.fields == ["contact.ends"]
    assert "consistent" in str(err.value) and f'"{family}"' in str(err.value)


@pytest.mark.parametrize("order, family", [(1, "coarse"), (0, "facet")])
def test_the_cli_refuses_the_thesis_ends_with_exit_status_2_and_one_line(order, family,
                                                                          tmp_path, capsys):
    status = main(["solve", "thesis-3.46-frictionless", "--level", "1", "--no-plots",
                   "--out", str(tmp_path), "--set", f"discretisation.order={order}",
                   "--set", f"discretisation.multipliers={family}"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2
    assert len(err) == 1 and "contact.ends" in err[0] and "(3.61)" in err[0]


def test_the_python_api_refuses_the_thesis_ends_when_solving_at_order_1():
    """``nd.solve(..., order=1, multipliers="coarse")`` validates the scene it solves."""
    scene = nd.load_scene("thesis-3.46-frictionless")
    with pytest.raises(nd.SceneError) as err:
        nd.solve(scene, 1, order=1, multipliers="coarse")
    assert err.value.field == "contact.ends"


@pytest.mark.parametrize("order, family", [(1, "coarse"), (1, "facet"), (0, "facet")])
def test_consistent_ends_are_accepted_by_both_families_at_every_order(order, family):
    scene = nd.load_scene("thesis-3.46-frictionless",
                          _overrides(order, family) + ["contact.ends='consistent'"])
    assert scene.discretisation.family == family


def test_the_thesis_scene_keeps_its_ends_and_its_coarse_multipliers_at_order_0():
    """Order 0 with the coarse multipliers is the thesis' method: the scene as shipped."""
    scene = nd.load_scene("thesis-3.46-frictionless")
    assert (scene.contact.ends, scene.discretisation.order,
            scene.discretisation.family) == ("thesis", 0, "coarse")
    solution = nd.solve(scene, 1)
    assert solution.converged
