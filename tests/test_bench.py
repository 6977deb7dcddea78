"""``ngdual bench`` writes one valid record per (case, level, solver): structure, not speed."""

import json

from ngdual.cli import main
from ngdual.studies.bench import CASES, SOLVERS

RECORD_KEYS = {"case", "scene", "level", "solver", "method", "ndof", "dofs", "converged",
               "iterations", "seconds_assemble", "seconds_total", "seconds_parts",
               "linear_seconds", "linear", "limit_ratio", "limit_ratio_fastest", "nnz_factor",
               "residuals", "norms", "peak_rss_mb", "peak_rss_scope", "versions"}


def test_bench_levels_1_2_3_writes_valid_json(tmp_path, capsys):
    path = tmp_path / "bench.json"
    assert main(["bench", "--levels", "1", "2", "3", "--json", str(path)]) == 0
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
    assert main(["bench", "--levels", "1", "--solvers", "newton"]) == 2
    assert "newton" in capsys.readouterr().err
