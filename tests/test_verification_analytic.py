"""The computed contact tractions converge to the half-plane solutions.

Hertz: the h~-projected pressure's L2 error falls on every level 1-4 and is below 3 % on
level 4. Flat punch: the force on |x| < a/2 is P/3 and the contact zone is the punch face,
both to 1 %. Cattaneo-Mindlin: the stick half-width is within one h^ cell of
a sqrt(1 - |Q|/(mu_f P)). The benchmark settings and the separation of the finite-box error
are in :mod:`ngdual.verification.contact_benchmarks`.
"""

import json
import math

import numpy as np
import pytest

from ngdual.cli import main
from ngdual.verification import cattaneo_mindlin, flat_punch, hertz
from ngdual.verification.contact_benchmarks import domain_study, uniform_study
from ngdual.verification.traction import _nodes


def _integral(f, a, b):
    x, w = _nodes(a, b)
    return float(np.dot(w, f(x)))


def test_the_quadrature_integrates_square_root_ends_to_round_off():
    """x = m - r cos(pi t) removes sqrt(a - x) and 1/sqrt(a - x) at either end."""
    assert abs(_integral(lambda x: 1 / np.sqrt(1 - x * x), -1, 1) - math.pi) < 1e-12
    assert abs(_integral(lambda x: np.sqrt(1 - x * x), -1, 1) - math.pi / 2) < 1e-12


def test_exact_tractions_carry_the_forces_they_are_built_from():
    h = hertz(P=2000.0, R=10.0, E=2e5, nu=0.3)
    assert abs(_integral(h.pressure, -h.a, h.a) / 2000.0 - 1) < 1e-12
    assert abs(h.a - math.sqrt(4 * 2000 * 10 * (1 - 0.09) / (math.pi * 2e5))) < 1e-15
    punch = flat_punch(P=3.0, a=0.25)
    assert abs(_integral(punch.pressure, -0.125, 0.125) - 1.0) < 1e-12
    assert abs(_integral(punch.pressure, -0.25, 0.25) - 3.0) < 1e-12
    cm = cattaneo_mindlin(P=2000.0, Q=-300.0, R=10.0, E=2e5, nu=0.5, mu_f=0.3)
    cuts = (-cm.hertz.a, -cm.c, cm.c, cm.hertz.a)
    shear = sum(_integral(cm.shear, lo, hi) for lo, hi in zip(cuts[:-1], cuts[1:]))
    assert abs(shear / -300.0 - 1) < 1e-12
    assert abs(cm.c / cm.hertz.a - math.sqrt(0.5)) < 1e-12
    inside = np.linspace(-cm.c, cm.c, 7)[1:-1]
    assert np.all(np.abs(cm.shear(inside)) < 0.3 * cm.pressure(inside))   # stick
    outside = np.array([0.5 * (cm.c + cm.hertz.a)])
    assert abs(abs(cm.shear(outside)[0]) - 0.3 * cm.pressure(outside)[0]) < 1e-9  # slip


@pytest.mark.slow
def test_hertz_pressure_error_decreases_on_every_level_and_is_below_3_percent_on_level_4():
    rows = uniform_study("hertz", (1, 2, 3, 4))
    errors = [r["l2"] for r in rows]
    assert all(e1 < e0 for e0, e1 in zip(errors, errors[1:])), errors
    assert errors[-1] < 0.03, errors
    for row in rows[2:]:
        # the contact zone's end lies between a node in contact and one separated
        assert row["a_error"] <= row["h"], row
        # the compared pressure carries the force sigma n transmits
        assert abs(row["force"] / row["resultant"] - 1) < 1e-3, row


def test_flat_punch_force_on_the_core_is_a_third_and_the_contact_zone_is_the_punch():
    """Level 3: 0.64 % in the 16a box, of which about 0.1 % is the finite box
    (:func:`~ngdual.verification.contact_benchmarks.domain_study`)."""
    row, = uniform_study("flat-punch", (3,))
    assert row["force_core"] < 0.01, row
    assert row["width"] < 0.01, row
    assert row["l2_core"] < 0.01, row


def test_cattaneo_mindlin_stick_half_width_is_within_one_friction_cell():
    row, = uniform_study("cattaneo-mindlin", (3,))
    assert 0 < row["c"] < row["a"]   # a stick zone inside the contact zone
    assert row["c_cells"] <= 1.0, row
    assert abs(row["Q"]) < 0.3 * row["force"]


@pytest.mark.slow
def test_verify_quick_prints_the_tables_and_writes_them(tmp_path, capsys):
    path = tmp_path / "verify.json"
    assert main(["verify", "--quick", "--json", str(path)]) == 0
    out = capsys.readouterr().out
    for title in ("manufactured case frictionless", "benchmark hertz", "benchmark flat-punch",
                  "benchmark cattaneo-mindlin", "stick zone"):
        assert title in out
    data = json.loads(path.read_text())
    hertz_rows = data["benchmarks"]["hertz"]
    assert [r["level"] for r in hertz_rows] == [1, 2]
    assert hertz_rows[1]["l2"] < hertz_rows[0]["l2"]


@pytest.mark.slow
def test_flat_punch_domain_error_shrinks_with_the_box():
    """Extrapolated to h -> 0, the core force's error is the finite box's: it falls from
    8a to 32a and is below 0.3 % at 32a."""
    rows = domain_study("flat-punch", multiples=(8, 16, 32))
    domain = [abs(r["domain"]) for r in rows]
    assert domain[0] > domain[1] and domain[0] > domain[2], rows
    assert domain[2] < 0.003, rows


@pytest.mark.slow
def test_wedge_pressure_converges_to_the_blunt_wedge_solution():
    """The kinked Gamma_C of the wedge against p = (E* s / pi) arccosh(a/|x|), a = P/(E* s):
    the L2 error of p_h falls on every level (slowly: the contact zone spans few h~ cells
    and p is log-singular at the apex) and the contact zone lands within one h~ cell."""
    from ngdual.scene import load_scene
    from ngdual.solvers import solve_scene
    from ngdual.verification import pressure_errors, traction_profile, wedge

    errors = []
    for level in (2, 3, 4):
        scene = load_scene("wedge")
        solution = solve_scene(scene, level)
        exact = wedge(traction_profile(solution).force, 0.1, scene.material.E,
                      scene.material.nu)
        row = pressure_errors(solution, exact)
        assert row["max"] is None and math.isfinite(row["l2"])
        errors.append(row["l2"])
    assert errors[0] > errors[1] > errors[2], errors
    assert abs(row["half_width"] - row["a"]) <= row["htilde"], row
