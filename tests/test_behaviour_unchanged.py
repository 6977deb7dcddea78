"""Refactoring does not change the numbers: every shipped scene, levels 1-4, gives the
result.json norms stored in ``tests/data/behaviour_norms.json`` (computed before the layout
work of issue 16 by ``tests/data/make_behaviour_norms.py``) to a relative 1e-10."""

import json
from pathlib import Path

import pytest

from ngdual.quantities import norms
from ngdual.scene import load_scene
from ngdual.solvers import solve_scene

STORED = json.loads((Path(__file__).parent / "data" / "behaviour_norms.json").read_text())
CASES = sorted(STORED["norms"])


@pytest.mark.parametrize("case", CASES)
def test_every_shipped_scene_gives_the_stored_norms_to_1e_10(case):
    name, level = case.rsplit("@", 1)
    got = norms(solve_scene(load_scene(name), int(level)))
    want = STORED["norms"][case]
    assert got.keys() == want.keys()
    for key, value in want.items():
        if value is None:
            assert got[key] is None, key
        else:
            assert got[key] == pytest.approx(value, rel=1e-10, abs=1e-14), (case, key)
