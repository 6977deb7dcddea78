"""``[loads] traction`` per Gamma_N side: a table keyed by boundary label acts like the one
formula pair that switches between the sides with ``ifpos``, sides not listed are free, and a
label that is not a Gamma_N side is refused naming ``loads.traction``."""

import numpy as np
import pytest

import ngdual as nd
from ngdual.checks import applied_load
from ngdual.cli import main
from ngdual.scene import SceneError, load_scene

TOP = "-800*ifpos(4 - x*x, 1 - x*x/2 + x**4/16, 0)"   # Example 3.46's load, zero at x = +-4
# Example 3.46 loaded on the top and on the right side x = 4, clamped on the left only
TWO_SIDES = ['boundary.neumann=["top", "right"]', 'boundary.dirichlet=["left"]',
             'contact.ends="consistent"']


def solve(traction: str):
    return nd.solve(load_scene("thesis-3.46-frictionless", [*TWO_SIDES,
                                                            f"loads.traction={traction}"]), 1)


def test_a_traction_per_side_gives_the_solution_of_the_equivalent_ifpos_formula():
    per_side = solve(f'{{top = ["0", "{TOP}"], right = ["-100", "0"]}}')
    # x = 4 only on the right side; the top's quadrature points stay left of x = 3.99
    formula = solve(f'["ifpos(x - 3.999999, -100, 0)", "{TOP}"]')
    assert np.linalg.norm(per_side.x - formula.x) <= 1e-8 * np.linalg.norm(formula.x)
    only_top = solve(f'{{top = ["0", "{TOP}"]}}')
    assert np.linalg.norm(per_side.x - only_top.x) > 1e-3 * np.linalg.norm(formula.x)


def test_the_resultant_of_a_per_side_traction_is_its_formulas_integrated_over_their_sides():
    load = applied_load(solve('{top = ["0", "-1"], right = ["-100", "0"]}'))
    assert load == pytest.approx([-100 * 2.0, -1 * 8.0], rel=1e-10)   # right 2 long, top 8


def test_a_side_not_listed_is_traction_free():
    assert load_scene("thesis-3.46-frictionless", [*TWO_SIDES, 'loads.traction={top = '
                      '["0", "-1"]}']).tractions() == {"top": ["0", "-1"], "right": ["0", "0"]}


@pytest.mark.parametrize("traction, field, words", [
    ('{topp = ["0", "-1"]}', "loads.traction", "'topp' is not a side of Gamma_N"),
    ('{left = ["0", "-1"]}', "loads.traction", "(top, right)"),
    ('{top = ["0"]}', "loads.traction.top", "pair"),
    ('{right = ["0", "1/(y - 1)"]}', "loads.traction.right[1]", "not finite on Gamma_N"),
    ('"0"', "loads.traction", "a table keyed by Gamma_N label"),
])
def test_a_bad_traction_table_is_refused_naming_its_field(traction, field, words):
    with pytest.raises(SceneError) as err:
        load_scene("thesis-3.46-frictionless", [*TWO_SIDES, f"loads.traction={traction}"])
    assert err.value.field == field and words in str(err.value)


def test_the_cli_refuses_a_bad_label_in_one_line_with_status_2(tmp_path, capsys):
    status = main(["solve", "thesis-3.46-frictionless", "--level", "1", "--out",
                   str(tmp_path / "out"), "--set", 'loads.traction={bottom = ["0", "-1"]}'])
    err = capsys.readouterr().err.strip()
    assert status == 2 and not (tmp_path / "out").exists()
    assert err.startswith("ngdual: error: loads.traction: 'bottom' is not a side of Gamma_N")
    assert len(err.splitlines()) == 1 and "Traceback" not in err
