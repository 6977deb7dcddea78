"""Every solve is checked for what a user should not believe (:mod:`ngdual.checks`).

Each check fires on a solution that violates it and stays silent on right answers; the
warnings reach ``Solution.warnings``, Python's warnings (``nd.solve``), ``result.json``,
the printed result, adaptive histories, and ``--strict`` turns them into exit status 4
with nothing written.
"""

import json
import warnings
from dataclasses import replace
from functools import cache

import numpy as np
import pytest

import ngdual as nd
from ngdual.checks import (
    FORCE_BALANCE_TOL,
    TENSION_TOL,
    contact_forces,
    displacement_scale,
    friction_forms_of,
    physics_checks,
)
from ngdual.cli import main
from ngdual.cli.output import EXIT_WARNINGS
from ngdual.scene import load_scene
from ngdual.solution import PhysicsWarning
from ngdual.solvers import solve_scene

CONSISTENT = ("contact.ends='consistent'",)
FAR_FOUNDATION = ('contact.foundation={point=[0.0, -1e6], normal=[0.0, 1.0]}',)


@cache
def solved(name: str, level: int | None = None, overrides: tuple = ()):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        return solve_scene(load_scene(name, list(overrides)), level)


def codes(solution) -> set[str]:
    return {w.code for w in solution.warnings}


def test_thesis_ends_warn_of_the_force_balance_the_tension_and_the_end_values():
    """Example 3.46 with the thesis' C_h~ (lambda = 0 at the clamped corners, g = 0.01):
    the corner cells pull, so the resultant of sigma n on Gamma_C differs from the force
    the multipliers see by more than that force itself."""
    solution = solved("thesis-3.46-frictionless", 2)
    balance = contact_forces(solution)
    assert np.linalg.norm(balance.resultant - balance.multiplier_force) > np.linalg.norm(
        balance.multiplier_force)
    assert balance.end_moments.max() > 0  # a fixed-end hat pulls
    assert codes(solution) == {"tension", "force-balance", "thesis-ends"}
    for found in solution.warnings:
        assert "\n" not in found.message and found.value > found.tolerance
        assert 'contact.ends = "consistent"' in found.message  # the remedy
    balance_warning = next(w for w in solution.warnings if w.code == "force-balance")
    assert "1.64x the multiplier force" in balance_warning.message
    assert "g - u_D.n = 0.01" in balance_warning.message  # the cause, with its size


def test_consistent_ends_balance_the_forces_of_example_3_46():
    """The same geometry with the end values the data prescribe: no warning from level 2
    on, the mismatch a discretisation error far below the tolerance."""
    for level in (2, 3):
        solution = solved("thesis-3.46-frictionless", level, CONSISTENT)
        assert solution.warnings == [], solution.warnings
        balance = contact_forces(solution)
        assert balance.mismatch < FORCE_BALANCE_TOL / 5 and balance.tension < 1e-9


@pytest.mark.slow
@pytest.mark.parametrize("name", ["hertz-cylinder", "flat-punch", "cattaneo-mindlin", "wedge",
                                  "punch-on-foundation"])
def test_the_shipped_contact_scenes_warn_of_nothing_on_their_default_level(name):
    assert solved(name).warnings == []


def test_the_wedge_has_no_tension_in_what_the_contact_conditions_control():
    """The fine-edge sigma_n of the wedge alternates at the edge of its contact zone (a
    quarter of int |sigma_n| ds is tensile on level 3), a mode orthogonal to every h~ hat;
    the hat moments d_Cn(mu_i, sigma), which (3.62) keeps <= 0, have no tension."""
    solution = solved("wedge")
    forms = friction_forms_of(solution)
    sigma_n, length = forms.T_n @ solution.x, forms.lengths
    fine_tension = np.sum(length * np.maximum(sigma_n, 0)) / np.sum(length * np.abs(sigma_n))
    assert fine_tension > 0.2
    moments = forms.midpoint_hats.T @ (length * sigma_n)
    assert moments.max() <= 1e-12 * np.abs(moments).max()
    assert contact_forces(solution).tension < 1e-9


def test_penetration_fires_where_lambda_n_is_negative():
    solution = solved("hertz-cylinder", 1)
    x = solution.x.copy()
    lam_n = solution.problem.lam_n
    x[lam_n[0]] = -0.01 * displacement_scale(solution)
    found = physics_checks(replace(solution, x=x))
    assert [w.code for w in found] == ["penetration"]
    assert found[0].value == pytest.approx(0.01, rel=0.2)


def test_the_friction_bound_fires_where_the_shear_exceeds_it():
    """Halve the bound F of a converged Coulomb solution: its slipping nodes carry twice
    the shear the bound allows."""
    solution = solved("cattaneo-mindlin", 2)
    assert "friction-bound" not in codes(solution)
    found = physics_checks(replace(solution, friction_bound=0.5 * solution.friction_bound))
    assert "friction-bound" in {w.code for w in found}


def test_a_contact_zone_running_into_a_clamped_end_is_named():
    """g = 0 under Example 3.46: the body rests on the foundation up to its clamped
    corners, so the h~ nodes next to both ends are in contact."""
    solution = solved("thesis-3.46-coulomb-gap0", 2)
    assert "contact-at-clamped-end" in codes(solution)
    lam_n = solution.part("lam_n")
    assert lam_n[0] == lam_n[-1] == 0.0
    assert "contact-at-clamped-end" not in codes(solved("thesis-3.46-frictionless", 2,
                                                        CONSISTENT))


def test_thesis_ends_are_silent_where_they_agree_with_the_data():
    """g = 0 = u_D.n at the clamped ends: the thesis' lambda = 0 is the consistent value."""
    assert "thesis-ends" not in codes(solved("thesis-3.46-coulomb-gap0", 2))


@pytest.mark.parametrize("overrides", [FAR_FOUNDATION, ('loads.displacement=["0", "0"]',),
                                       ("contact.ends='consistent'", "contact.gap='1'")],
                         ids=["far-foundation", "no-load", "hanging"])
def test_mismatch_and_tension_are_finite_and_small_when_nothing_touches(overrides):
    """No contact force (the unloaded cylinder touches the plane at one node, with zero
    force): the force scale does not vanish with the contact force, so the ratios are
    finite and small, not round-off over round-off (or 9e9)."""
    name = "thesis-3.46-frictionless" if "contact.gap='1'" in overrides else "hertz-cylinder"
    solution = solved(name, 2, overrides)
    balance = contact_forces(solution)
    assert np.linalg.norm(balance.multiplier_force) <= 1e-4 * balance.scale
    summary = nd.result_record(solution)["contact"]
    assert 0 <= summary["force_mismatch"] < 0.01 and 0 <= summary["tension"] < 0.01
    assert solution.warnings == []


def test_nd_solve_issues_one_python_warning_per_failed_check():
    scene = load_scene("thesis-3.46-frictionless", ["geometry.level=1"])
    with pytest.warns(PhysicsWarning) as caught:
        solution = nd.solve(scene)
    assert [str(w.message) for w in caught] == [w.message for w in solution.warnings]
    with warnings.catch_warnings():
        warnings.simplefilter("error", PhysicsWarning)
        nd.solve(load_scene("hertz-cylinder", ["geometry.level=1"]))


def test_the_cli_prints_and_stores_the_warnings(tmp_path, capsys):
    out = tmp_path / "thesis"
    assert main(["solve", "thesis-3.46-frictionless", "--level", "2", "--out", str(out),
                 "--no-plots"]) == 0
    printed = capsys.readouterr().out.splitlines()
    warned = [k for k, line in enumerate(printed) if line.startswith("warning: ")]
    table_end = next(k for k, line in enumerate(printed) if line.startswith("time [s]"))
    assert len(warned) == 3 and min(warned) == table_end + 1
    assert "force balance" in printed[warned[1]] and "contact.ends" in printed[warned[1]]
    record = json.loads((out / "result.json").read_text())
    assert [w["code"] for w in record["warnings"]] == ["tension", "force-balance",
                                                       "thesis-ends"]
    assert record["contact"]["force_mismatch"] == pytest.approx(record["warnings"][1]["value"])


def test_strict_fails_with_its_own_status_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "thesis"
    assert main(["solve", "thesis-3.46-frictionless", "--level", "1", "--out", str(out),
                 "--strict"]) == EXIT_WARNINGS
    assert not out.exists()
    captured = capsys.readouterr()
    assert "warning: " in captured.out and "--strict" in captured.err
    ok = tmp_path / "hertz"
    assert main(["solve", "hertz-cylinder", "--level", "1", "--out", str(ok), "--no-plots",
                 "--strict"]) == 0
    assert json.loads((ok / "result.json").read_text())["warnings"] == []


def test_adapt_records_the_warnings_of_every_step_and_strict_stops_it(tmp_path, capsys):
    out = tmp_path / "adapt"
    assert main(["adapt", "thesis-3.46-frictionless", "--level", "1", "--steps", "2",
                 "--out", str(out)]) == 0
    history = json.loads((out / "history.json").read_text())["history"]
    assert all("force-balance" in {w["code"] for w in step["warnings"]} for step in history)
    assert "    warning: force balance" in capsys.readouterr().out
    strict = tmp_path / "strict"
    assert main(["adapt", "thesis-3.46-frictionless", "--level", "1", "--steps", "2",
                 "--out", str(strict), "--strict"]) == EXIT_WARNINGS
    assert not strict.exists()


def test_tolerances_separate_the_thesis_ends_from_the_consistent_ones():
    """The thesis' ends are a decade above the tolerances, consistent ends a decade below."""
    thesis = contact_forces(solved("thesis-3.46-frictionless", 2))
    consistent = contact_forces(solved("thesis-3.46-frictionless", 2, CONSISTENT))
    assert thesis.mismatch > 5 * FORCE_BALANCE_TOL and thesis.tension > 5 * TENSION_TOL
    assert consistent.mismatch < FORCE_BALANCE_TOL / 10
