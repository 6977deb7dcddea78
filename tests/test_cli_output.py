"""What the command line writes besides result.json: VTK files ParaView can warp, one per
adaptive step with ``adapt --vtk``, plot labels in the scene's units, phase progress on
stderr for long runs, and help text for every subcommand and option.
"""

import argparse
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from ngdual.cli import main, parser

GAP = 0.01  # Example 3.46


def vtu_arrays(path) -> dict[str, np.ndarray]:
    """The ASCII data arrays of a .vtu file by name (points: "Points"), shape (n, components)."""
    arrays = {}
    for node in ET.parse(path).getroot().iter("DataArray"):
        if node.get("format") != "ascii":
            continue
        values = np.array(node.text.split(), float)
        arrays[node.get("Name")] = values.reshape(-1, int(node.get("NumberOfComponents", "1")))
    return arrays


def array_headers(path) -> dict[str, int]:
    """Name -> NumberOfComponents of every data array (appended binary data is skipped)."""
    head = path.read_bytes().split(b"<AppendedData", 1)[0].decode()
    return {node.get("Name"): int(node.get("NumberOfComponents", "1"))
            for node in ET.fromstring(head + "</Piece></UnstructuredGrid></VTKFile>"
                                      if "<AppendedData" in path.read_text(errors="ignore")
                                      else head).iter("DataArray")}


def test_vtk_output_has_the_displacement_and_the_contact_multiplier_as_vectors(tmp_path):
    assert main(["solve", "thesis-3.46-frictionless", "--level", "2", "--out", str(tmp_path),
                 "--vtk", "--no-plots"]) == 0
    volume = tmp_path / "solution.vtu"
    text = volume.read_bytes().split(b"<AppendedData", 1)[0].decode()
    assert 'Name="u" NumberOfComponents="3"' in text       # Warp By Vector needs 3
    contact = vtu_arrays(tmp_path / "solution_contact.vtu")
    points, lam = contact["Points"], contact["lambda"]
    assert lam.shape == (len(points), 3) and contact["traction"].shape[1] == 3
    assert np.allclose(points[:, 1], -1) and np.allclose(contact["normal"][:, :2], [0, -1])
    # on the bottom n = (0, -1), t = (n_2, -n_1) = (-1, 0): lambda = lambda_n n + lambda_t t
    assert np.allclose(lam[:, 0], -contact["lambda_t"][:, 0])
    assert np.allclose(lam[:, 1], -contact["lambda_n"][:, 0])
    assert np.allclose(lam[:, 2], 0)
    # where the gap is closed (lambda_n = 0) the body has moved down by the gap
    closed = np.abs(contact["lambda_n"][:, 0]) < 1e-12
    assert closed.sum() >= 3
    assert np.allclose(contact["u"][closed, 1], -GAP)
    # sigma n on the contact zone pushes into the body: traction_y = -sigma_n > 0
    assert np.all(contact["traction"][:, 1] == pytest.approx(-contact["sigma_n"][:, 0]))


def test_adapt_with_vtk_writes_one_vtk_file_per_step(tmp_path, capsys):
    assert main(["adapt", "thesis-3.46-frictionless", "--level", "1", "--steps", "2",
                 "--marking", "max", "--out", str(tmp_path), "--vtk"]) == 0
    for step in (0, 1):
        for name in (f"solution_step{step:02d}.vtu", f"solution_step{step:02d}_contact.vtu",
                     f"mesh_step{step:02d}.png"):
            assert (tmp_path / name).stat().st_size > 0, name
    assert not list(tmp_path.glob("solution_step02*"))
    assert "solution_stepNN.vtu" in capsys.readouterr().out


def test_bad_units_exit_2_naming_the_field_and_write_nothing(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["solve", "thesis-3.46-frictionless", "--level", "1", "--out", str(out),
                 "--set", "units.length=furlong", "--set", "units.stress=3"]) == 2
    err = capsys.readouterr().err
    assert "units.length" in err and "furlong" in err and "units.stress" in err
    assert not out.exists()


def test_the_solve_figures_carry_the_declared_units(tmp_path, monkeypatch):
    from ngdual import plot

    texts = []
    save = plot.save_figure

    def record(fig, target, *args, **kwargs):
        texts.append(plot.figure_texts(fig))
        return save(fig, target, *args, **kwargs)

    monkeypatch.setattr(plot, "save_figure", record)
    assert main(["solve", "thesis-3.46-frictionless", "--level", "1", "--out", str(tmp_path),
                 "--set", "units.length=mm", "--set", "units.stress=MPa"]) == 0
    von_mises, deformed, traces = texts
    assert von_mises["axes"][0]["xlabel"] == "$x_1$ [mm]"
    assert deformed["axes"][0]["xlabel"] == "$x_1$ [mm]"
    assert deformed["axes"][1]["label"] == r"displacement $|u_h|$ [mm]"
    bar = von_mises["axes"][1]["label"]
    assert bar.startswith(r"von Mises stress $\sigma_0$ [MPa]") and "percentile" in bar
    assert traces["axes"][0]["ylabel"] == r"pressure $p_h = -\sigma_n$ [MPa]"
    assert traces["axes"][2]["xlabel"] == r"$x_1$ on $\Gamma_C$ [mm]"


def test_a_large_solve_reports_its_phases_on_stderr(tmp_path, capsys, monkeypatch):
    import ngdual.cli.pipeline

    monkeypatch.setattr(ngdual.cli.pipeline, "LARGE_MESH", 0)   # every mesh counts as large
    assert main(["solve", "thesis-3.46-frictionless", "--level", "1", "--out", str(tmp_path),
                 "--no-plots"]) == 0
    err = capsys.readouterr().err
    phases = ["meshing level 1", "assembling on 32 triangles", "factorising and solving",
              "post-processing", "done"]
    positions = [err.find(f" s  {phase}") for phase in phases]
    assert -1 not in positions and positions == sorted(positions), err


def test_a_small_solve_prints_no_phases(tmp_path, capsys):
    assert main(["solve", "thesis-3.46-frictionless", "--level", "1", "--out", str(tmp_path),
                 "--no-plots"]) == 0
    assert "assembling" not in capsys.readouterr().err


def test_every_subcommand_and_option_has_help_text():
    subcommands = next(a for a in parser()._actions
                       if isinstance(a, argparse._SubParsersAction))
    described = {action.dest: action.help for action in subcommands._choices_actions}
    missing = [name for name in subcommands.choices if not described.get(name)]
    for name, sub in subcommands.choices.items():
        for action in sub._actions:
            if not action.help:
                missing.append(f"{name} {'/'.join(action.option_strings) or action.dest}")
    assert not missing, missing


def test_a_reader_that_stops_early_is_not_reported_as_a_bug():
    """``ngdual scenes | head -1``: the broken pipe ends ngdual like SIGPIPE ends a Unix tool
    (status 141), without an 'internal error' line."""
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-m", "ngdual", "scenes"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    proc.stdout.close()  # before ngdual writes anything: its first flush meets a broken pipe
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 141, err
    assert "internal error" not in err and "Traceback" not in err, err


def test_the_adapt_help_states_the_loops_own_defaults():
    """``ngdual adapt --help`` names the defaults ``nd.adapt`` takes (ngdual.loop_defaults:
    theta 0.5, with --tol 0.9; 5 solves, with --tol at most 30; with --tol from level 1)."""
    import re

    from ngdual import loop_defaults as d
    from ngdual.cli import parser

    sub = next(a for a in parser()._actions if isinstance(a, argparse._SubParsersAction))
    text = " ".join(sub.choices["adapt"].format_help().split())
    assert re.search(rf"default {d.THETA:g}, the thesis'; with --tol {d.THETA_TOL:g}\b", text)
    assert re.search(rf"default {d.STEPS}\); with --tol the largest number \(default "
                     rf"{d.STEPS_TOL}\)", text)
    assert re.search(rf"with --tol {d.LEVEL_TOL}\)", text)
    # and the loop takes the same ones (a run records theta: tests/test_goal.py)
    from ngdual.afem import loop_defaults

    assert loop_defaults(None, None, None) == (d.THETA, d.STEPS, None)
    assert loop_defaults(0.01, None, None) == (d.THETA_TOL, d.STEPS_TOL, d.LEVEL_TOL)
