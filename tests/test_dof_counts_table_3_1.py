"""Level k of Example 3.46 reproduces the DOF counts of Table 3.1 exactly (no solving)."""

import pytest

from ngdual.forms import Spaces
from ngdual.mesh import refine_uniformly, thesis_mesh
from ngdual.scene import load_scene

# Table 3.1 of the thesis: Dof(X_h), Dof(M_h), Dof(S_h), Dof(N), Dof(C), Dof(Lambda) (h^ = 2h~)
TABLE_3_1 = {
    1: (180, 64, 27, 6, 3, 2),
    2: (680, 256, 85, 14, 7, 4),
    3: (2640, 1024, 297, 30, 15, 8),
    4: (10400, 4096, 1105, 62, 31, 16),
    5: (41280, 16384, 4257, 126, 63, 32),
    6: (164480, 65536, 16705, 254, 127, 64),
    7: (656640, 262144, 66177, 510, 255, 128),
    8: (2624000, 1048576, 263425, 1022, 511, 256),
}


@pytest.mark.parametrize("level", sorted(TABLE_3_1))
def test_dofs_match_table_3_1(level):
    scene = load_scene("thesis-3.46-coulomb")
    dofs = Spaces.build(scene, thesis_mesh(level)).dofs()
    assert tuple(dofs[k] for k in "XMSNCL") == TABLE_3_1[level]


def test_hhat_equal_htilde_doubles_the_nu_dofs():
    scene = load_scene("thesis-3.46-coulomb", ["contact.hhat_factor=1"])
    assert Spaces.build(scene, thesis_mesh(3)).dofs()["L"] == 2 * TABLE_3_1[3][5]


@pytest.mark.parametrize("level", [2, 3, 4])
def test_netgen_refinement_gives_the_same_counts(level):
    """mesh.Refine() keeps stale coarse edges in NGSolve: spaces must be compressed."""
    scene = load_scene("thesis-3.46-coulomb")
    mesh = refine_uniformly(thesis_mesh(1), level - 1)
    dofs = Spaces.build(scene, mesh).dofs()
    assert tuple(dofs[k] for k in "XMSNCL") == TABLE_3_1[level]


def test_frictionless_scene_builds_no_nu_space():
    scene = load_scene("thesis-3.46-frictionless")
    assert Spaces.build(scene, thesis_mesh(2)).dofs()["L"] == 0
