"""``ngdual bench``: every benchmark prints its table and writes one valid record per row
with the package versions (structure, not speed), and its numbers are the pipeline's."""

import json

import pytest

from ngdual.cli import main
from ngdual.studies.bench.limit_ratio import CASES, SOLVERS

RECORD_KEYS = {"case", "scene", "level", "solver", "method", "ndof", "dofs", "converged",
               "iterations", "seconds_assemble", "seconds_total", "seconds_parts",
               "linear_seconds", "linear", "limit_ratio", "limit_ratio_fastest", "nnz_factor",
               "residuals", "norms", "peak_rss_mb", "peak_rss_scope", "versions"}


@pytest.mark.slow
def test_bench_levels_1_2_3_writes_valid_json(tmp_path, capsys):
    path = tmp_path / "bench.json"
    assert main(["bench", "limit-ratio", "--levels", "1", "2", "3", "--json", str(path)]) == 0
    run = json.loads(path.read_text())
    records = run["records"]
    assert {(r["case"], r["level"], r["solver"]) for r in records} == {
        (c, lvl, s) for c in CASES for lvl in (1, 2, 3) for s in SOLVERS}
    for r in records:
        assert RECORD_KEYS <= set(r), RECORD_KEYS - set(r)
        assert r["converged"] and r["error"] is None
        assert r["limit_ratio"] > 0 and r["seconds_total"] > 0 and r["peak_rss_mb"] > 0
        assert r["versions"]["ngsolve"] and r["versions"]["cvxopt"]
        assert r["iterations"]["outer"] >= 1
    by = {(r["case"], r["level"], r["solver"]): r for r in records}
    for case in CASES:
        for level in (1, 2, 3):
            # every variant reaches the same discrete solution
            norms = [by[case, level, s]["norms"]["sigma_X"] for s in SOLVERS]
            assert max(norms) - min(norms) <= 1e-6 * max(norms)
    assert by["thesis-3.46", 3, "active-set"]["nnz_factor"] > 0
    assert "machine" in run and run["versions"]["python"]
    table = capsys.readouterr().out
    assert "active-set" in table and "ratio" in table


def test_bench_rejects_unknown_solver(capsys):
    assert main(["bench", "limit-ratio", "--levels", "1", "--solvers", "newton"]) == 2
    assert "newton" in capsys.readouterr().err


def run_bench(tmp_path, *argv) -> dict:
    path = tmp_path / "bench.json"
    assert main(["bench", *argv, "--json", str(path)]) == 0
    study = json.loads(path.read_text())
    assert study["benchmark"] == argv[0]
    assert study["versions"]["ngsolve"] and study["machine"]["cpu_count"]
    return study


@pytest.mark.slow
def test_levels_solve_each_level_in_its_own_process_as_ngdual_solve_does(tmp_path, capsys):
    from ngdual.quantities import norms
    from ngdual.scene import load_scene
    from ngdual.solvers import solve_scene

    study = run_bench(tmp_path, "levels", "--levels", "1", "2")
    assert [r["level"] for r in study["records"]] == [1, 2]
    solution = solve_scene(load_scene("thesis-3.46-frictionless"), 2)
    expected = {k: v for k, v in norms(solution).items() if v is not None}
    assert {k: study["records"][1]["norms"][k] for k in expected} == pytest.approx(expected,
                                                                                   rel=1e-12)
    assert study["records"][1]["ndof"] == solution.problem.K.shape[0]
    assert all(r["peak_rss_mb"] > 0 and r["converged"] for r in study["records"])
    assert "sigma_X" in capsys.readouterr().out


def test_estimator_cost_times_the_estimate_and_one_linear_solve(tmp_path):
    study = run_bench(tmp_path, "estimator-cost", "--levels", "1", "--repeat", "1")
    (row,) = study["records"]
    assert row["estimate_s"] > 0 and row["linear_solve_s"] > 0
    assert row["ratio"] == pytest.approx(row["estimate_s"] / row["linear_solve_s"])
    assert row["elements"] == 32


def test_infsup_constants_of_the_thesis_example_match_the_readme(tmp_path):
    study = run_bench(tmp_path, "infsup", "--scenes", "thesis-3.46-frictionless",
                      "--levels", "1", "2")
    # the README's table: 0.732 and 0.723 on levels 1 and 2
    assert [round(r["beta"], 3) for r in study["records"]] == [0.732, 0.723]


def test_primal_peer_reports_the_hertz_errors_and_rejects_a_law_without_friction(tmp_path,
                                                                                  capsys):
    study = run_bench(tmp_path, "primal-peer", "--levels", "1", "--orders", "1")
    (row,) = study["records"]
    assert row["converged"] and row["theta"] == -1.0 and row["gamma0"] == 1.0
    # P1 on level 1: the contact half-width within 2 % of Hertz's, the force balanced
    assert row["a_measured"] == pytest.approx(row["a_hertz"], rel=0.02)
    assert row["reaction"] == pytest.approx(row["force"], rel=0.01)
    assert main(["bench", "primal-peer", "--law", "tresca"]) == 2
    assert "--law" in capsys.readouterr().err


def test_adaptive_splits_every_step_into_phases_that_add_up_to_its_wall_time(tmp_path):
    from ngdual.afem import adapt
    from ngdual.scene import load_scene

    study = run_bench(tmp_path, "adaptive", "--scene", "thesis-3.46-frictionless", "--set",
                      "contact.ends=consistent", "--orders", "0", "--goal", "stress", "--tol", "0",
                      "--level", "1", "--steps", "3", "--theta", "0.5")
    records = study["records"]
    history = adapt(load_scene("thesis-3.46-frictionless", ["contact.ends=consistent"]),
                    marking="dorfler", theta=0.5, steps=3, level=1)
    assert [r["ndof"] for r in records] == [h["dofs"]["total"] for h in history]
    assert records[0]["seconds"]["refine"] == 0 < records[1]["seconds"]["refine"]
    for r in records:
        seconds = r["seconds"]
        phases = sum(v for k, v in seconds.items()
                     if v is not None and not k.startswith(("step", "unit")))
        assert phases == pytest.approx(seconds["step"], rel=1e-12)
        assert 0 < seconds["unit_cholesky"] < seconds["unit_factorize"] < seconds["unit"]
        assert seconds["unit"] < seconds["step"]
        assert seconds["unit_factorize"] - seconds["unit_cholesky"] == pytest.approx(
            seconds["hybridize"])
        assert seconds["unit"] - seconds["unit_factorize"] == pytest.approx(
            seconds["assemble"])
        assert r["ratio"] == pytest.approx(seconds["step"] / seconds["unit"])
        assert r["ratio_factorize"] == pytest.approx(seconds["step"] / seconds["unit_factorize"])


def test_adaptive_shows_every_order_s_steps_growth_solve_and_fixed_cost(tmp_path, capsys):
    study = run_bench(tmp_path, "adaptive", "--orders", "0", "1", "--tol", "0.05")
    assert (study["goal"], study["tol"], study["growth"]) == ("pressure", 0.05, 1.5)
    records = study["records"]
    assert {r["order"] for r in records} == {0, 1}
    for order in (0, 1):
        steps = [r for r in records if r["order"] == order]
        assert [r["step"] for r in steps] == list(range(len(steps)))
        assert steps[0]["growth"] is None
        for before, r in zip(steps, steps[1:]):
            assert r["growth"] == pytest.approx(r["ndof"] / before["ndof"], rel=1e-12)
        assert steps[-1]["stopped_by"] == "tol"
        for r in steps:
            assert r["solve_s"] == pytest.approx(r["timings_s"]["factorize"]
                                                 + r["timings_s"]["solve"], rel=1e-12)
            assert r["fixed_s"] == pytest.approx(r["seconds"]["step"] - r["solve_s"], rel=1e-12)
            assert r["fixed_ratio"] == pytest.approx(r["fixed_s"] / r["solve_s"], rel=1e-12)
    header = capsys.readouterr().out.splitlines()[0].split()
    assert {"k", "unknowns", "growth", "solve", "fixed", "fixed/solve"} <= set(header)


def test_adaptive_rejects_an_order_and_a_growth_it_does_not_have(capsys):
    assert main(["bench", "adaptive", "--orders", "3"]) == 2
    assert main(["bench", "adaptive", "--growth", "5"]) == 2
    err = capsys.readouterr().err
    assert "--orders" in err and "--growth" in err
