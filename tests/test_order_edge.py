"""The contact settings of the coarse multipliers with the facet multipliers (issue 27).

The facet P_k multipliers live on the fine edges, discontinuous from edge to edge: no h~ or
h^ mesh, no value at an end of Gamma_C. ``contact.htilde_factor``, ``hhat_factor`` and
``ends`` other than their defaults would do nothing, so the scene is refused, naming the
field; the defaults describe what the facet family does.
"""

import pytest

from ngdual.scene import SceneError, load_scene

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
