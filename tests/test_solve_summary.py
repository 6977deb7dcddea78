"""`ngdual solve` prints first what a student reads: the contact zone, the peak pressure and
the forces in the scene's units, beside the analytic values of the scene's benchmark."""

import json
import math
import re

import pytest

from ngdual.cli import main
from ngdual.scene import load_scene
from ngdual.verification.analytic import hertz


def _row(out: str, label: str) -> list[float]:
    """The numbers of the first summary row starting with ``label``."""
    line = next(line for line in out.splitlines() if line.startswith(label))
    return [float(v) for v in re.findall(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?",
                                         line[len(label):])]


def _solve(name, tmp_path, capsys, *extra):
    assert main(["solve", name, "--out", str(tmp_path), "--no-plots", *extra]) == 0
    return capsys.readouterr().out


def test_hertz_on_its_default_level_prints_a_p0_and_the_force_beside_hertz(tmp_path, capsys):
    out = _solve("hertz-cylinder", tmp_path, capsys)
    assert out.index("contact half-width") < out.index("norms and residuals of (3.62)")
    force = _row(out, "normal force P")[0]
    a_h, a, _, spacing = _row(out, "contact half-width a")
    p_h, p0 = _row(out, "peak pressure p0")[:2]
    scene = load_scene("hertz-cylinder")
    truth = hertz(force, scene.benchmark.radius, scene.material.E, scene.material.nu)
    # the printed Hertz column is Hertz's formula for the printed force (4 digits each)
    assert a == pytest.approx(truth.a, rel=1e-3) and p0 == pytest.approx(truth.p0, rel=1e-3)
    # the computed peak pressure within 2 % of Hertz; the half-width is the extent of the
    # nodes in contact: Hertz's a lies within one node spacing of it
    assert abs(p_h / truth.p0 - 1) < 0.02
    assert abs(a_h - truth.a) <= spacing
    # the force is the resultant of sigma n the (3.62) record prints
    resultant = json.loads((tmp_path / "result.json").read_text())["contact"]["resultant"]
    assert force == pytest.approx(resultant[1], rel=1e-3)


def test_frictionless_runs_print_no_stick_or_slip(tmp_path, capsys):
    out = _solve("hertz-cylinder", tmp_path, capsys, "--level", "1")
    assert "stick" not in out and "slip" not in out
    out = _solve("thesis-3.46-frictionless", tmp_path, capsys, "--level", "2")
    assert "stick" not in out and "slip" not in out


def test_cattaneo_mindlin_on_its_default_shows_stick_between_slip_and_the_peak_shear(
        tmp_path, capsys):
    out = _solve("cattaneo-mindlin", tmp_path, capsys)
    q_h, q_peak = _row(out, "peak shear |q_h|")[:2]
    assert abs(q_h / q_peak - 1) < 0.10
    summary = json.loads((tmp_path / "result.json").read_text())["summary"]
    (lo, hi), = summary["stick"]
    left, right = summary["slip"]
    assert left[1] < lo and hi < right[0]
    # the analytic peak is mu_f p0 sqrt(1 - c^2/a^2) = mu_f p0 sqrt(|Q| / (mu_f P))
    bench = summary["benchmark"]["values"]
    mu_f = load_scene("cattaneo-mindlin").friction.mu
    assert bench["peak_shear"] == pytest.approx(
        mu_f * bench["peak_pressure"] * math.sqrt(1 - (bench["stick_half_width"]
                                                       / bench["half_width"]) ** 2), rel=1e-9)


def test_the_summary_numbers_have_four_significant_digits(tmp_path, capsys):
    out = _solve("hertz-cylinder", tmp_path, capsys, "--level", "1")
    summary = out[:out.index("norms and residuals")]
    assert not re.search(r"\d\.\d{5,}", summary)
    assert "resultant=[" in out and not re.search(r"resultant=\[[^]]*\d{6,}", out)
