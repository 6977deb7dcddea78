"""`ngdual solve` prints the table and writes result.json with the fields of SPEC section 6."""

import json

from ngdual.cli import main

KEYS = {"scene", "level", "converged", "dofs", "norms", "contact", "iterations", "residuals",
        "timings_s", "versions"}


def test_solve_writes_the_result_record(tmp_path, capsys):
    assert main(["solve", "thesis-3.46-frictionless", "--level", "2", "--out", str(tmp_path),
                 "--vtk"]) == 0
    out = capsys.readouterr().out
    assert "sigma_X=" in out and "nodes_in_contact=" in out
    record = json.loads((tmp_path / "result.json").read_text())
    assert KEYS <= set(record)
    assert record["level"] == 2 and record["converged"] is True
    assert set(record["dofs"]) == {"X", "M", "S", "N", "C", "L"}
    assert record["dofs"]["X"] == 680
    assert set(record["norms"]) == {"sigma_X", "u", "eta", "phi", "lam_t", "lam_n", "nu"}
    assert record["norms"]["nu"] is None
    assert set(record["contact"]) == {"nodes_in_contact", "stick_nodes", "slip_nodes", "F_abs",
                                      "resultant", "multiplier_force", "force_mismatch",
                                      "tension"}
    assert set(record["timings_s"]) == {"assemble", "factorize", "solve", "total"}
    assert record["versions"]["ngsolve"] and record["versions"]["ngdual"]
    assert record["contact"]["nodes_in_contact"] > 0
    for name in ("von_mises.png", "contact_traces.png", "solution.vtu"):
        assert (tmp_path / name).stat().st_size > 0
    assert not list(tmp_path.glob("*.tmp"))


def test_scene_without_contact_is_one_linear_solve(tmp_path):
    assert main(["solve", "thesis-3.46-frictionless", "--level", "1", "--out", str(tmp_path),
                 "--no-plots", "--set", "boundary.contact=[]",
                 "--set", "boundary.dirichlet=['left', 'right', 'bottom']"]) == 0
    record = json.loads((tmp_path / "result.json").read_text())
    assert record["method"] == "linear" and record["dofs"]["C"] == 0


def test_dofs_command_prints_table_3_1(capsys):
    assert main(["dofs", "thesis-3.46-frictionless", "--levels", "1", "2"]) == 0
    out = capsys.readouterr().out
    assert "680" in out and "180" in out


def test_non_rectangular_scene_solves_with_contact(tmp_path):
    assert main(["solve", "punch-on-foundation", "--out", str(tmp_path), "--no-plots"]) == 0
    record = json.loads((tmp_path / "result.json").read_text())
    assert record["converged"] and record["contact"]["nodes_in_contact"] >= 1
    assert record["residuals"]["sigma_n_positive"] < 1e-7
    assert record["residuals"]["lambda_n_negative"] == 0.0


def test_checks_before_work_accept_an_existing_output_folder_and_debug_after_the_command(
        tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("kept")
    assert main(["solve", "thesis-3.46-frictionless", "--level", "1", "--no-plots", "--out",
                 str(tmp_path), "--debug"]) == 0
    assert (tmp_path / "result.json").is_file() and (tmp_path / "notes.txt").read_text() == "kept"
    assert "Traceback" not in capsys.readouterr().err


def test_a_refused_size_names_the_override_and_the_override_is_honoured(tmp_path, capsys,
                                                                       monkeypatch):
    import ngdual.budget

    monkeypatch.setattr(ngdual.budget, "available_memory", lambda: 1e6)
    args = ["solve", "thesis-3.46-frictionless", "--level", "1", "--no-plots", "--out",
            str(tmp_path)]
    assert main(args) == 2
    assert "--allow-large" in capsys.readouterr().err and not any(tmp_path.iterdir())
    assert main([*args, "--allow-large"]) == 0
    assert (tmp_path / "result.json").is_file()
