"""``ngdual figures`` regenerates every figure and table of Sections 3.4 and 4.2, and a sweep
that is killed half way loses nothing.

* Smoke test, ``ngdual figures --max-level 3`` (one worker thread, ~1 min): every thesis
  figure and table has an entry, every file an entry or the index names exists and is not
  empty, every number in the CSV files is finite, every data file records the package
  versions, Table 3.1 matches the thesis, and the norms and DOFs of Tables 3.1-3.3 are
  those of ``ngdual solve`` on the same scene and level.
* Figures are readable without the thesis: the JSON sidecar of every figure shows a
  title, axis labels (with the units the scenes declare, none made up), a legend where
  curves are labelled, and a colour bar with a label where a field is coloured; the
  von Mises colour scales say where they are clipped.
* A sweep run in a subprocess is killed (SIGKILL) after some records exist; the re-run
  completes, recomputes only the missing tasks and leaves the finished records untouched
  (same file modification time and start stamp).
* The pieces: plan sizes (the thesis' step counts at K = 8), task ids, failed and
  not-converged tasks recorded with their message, the Aitken / e_tot / rate helpers.
"""

import csv
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from ngdual.afem import adapt
from ngdual.cli import main
from ngdual.rates import extrapolated_norms, observed_rates
from ngdual.scene import load_scene
from ngdual.studies.figures import Plan, best, errors, markdown_table
from ngdual.studies.figures.plan import COARSE_ORDER_PROBLEMS
from ngdual.studies.sweep import Task, estimator, execute, load_record, run_task

SMOKE = "3"     # the smoke run of every script
COARSE = "2"    # the sweep that is killed and resumed
EXPECTED = ([f"Fig. 3.{n}" for n in range(10, 29)] + [f"Table 3.{n}" for n in range(1, 7)]
            + ["Figs. 4.1-4.8", "Figs. 4.9-4.13"] + [f"Table 4.{n}" for n in range(1, 5)]
            + ["Work-precision (beyond the thesis)", "Beyond the thesis: contact scenes"])
# the thesis scenes declare no [units]: a label names the quantity, never a made-up unit
MADE_UP_UNIT = re.compile(r"\[(length|stress units|norm units)\]")


@pytest.fixture(scope="module")
def coarse_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("figures")
    start = time.perf_counter()
    code = main(["figures", "--max-level", SMOKE, "--threads", "--out", str(out)])
    print(f"\nngdual figures --max-level {SMOKE}: {time.perf_counter() - start:.0f} s")
    assert code == 0
    return out


def entries(out: Path) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted((out / "entries").glob("*.json"))]


def read_csv(path: Path) -> list[dict]:
    lines = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    return list(csv.DictReader(lines))


@pytest.mark.slow
def test_every_figure_and_table_has_its_files(coarse_run):
    run = json.loads((coarse_run / "run.json").read_text())
    assert all(s["status"] == "ok" for s in run["scripts"].values()), run["scripts"]
    found = {e["thesis"] for e in entries(coarse_run)}
    assert set(EXPECTED) <= found
    for e in entries(coarse_run):
        assert e["files"], e["script"]
        for name in e["files"]:
            assert (coarse_run / name).stat().st_size > 0, name
        if any(name.endswith(".png") for name in e["files"]):
            assert any(name.endswith(".pdf") for name in e["files"])
    index = (coarse_run / "index.md").read_text()
    for link in re.findall(r"\]\(([^)]+)\)", index):
        assert (coarse_run / link).stat().st_size > 0, link
    for thesis in EXPECTED:
        assert f"### {thesis}" in index
    # one file per thesis figure of the adaptive sequences
    assert len(list((coarse_run / "figures").glob("fig_4_*.png"))) == 13


@pytest.mark.slow
def test_tabulated_numbers_are_finite_and_carry_versions(coarse_run):
    data = sorted((coarse_run / "data").iterdir())
    assert len(data) >= 30
    for path in data:
        text = path.read_text()
        assert "versions" in text and "ngsolve" in text, path.name
        if path.suffix != ".csv":
            continue
        rows = read_csv(path)
        assert rows, path.name
        for row in rows:
            for key, value in row.items():
                assert value.lower() not in ("nan", "inf", "-inf"), (path.name, key)
                try:
                    number = float(value)
                except ValueError:
                    continue
                assert math.isfinite(number), (path.name, key)
    for record in (coarse_run / "records").glob("*.json"):
        assert "ngsolve" in json.loads(record.read_text())["versions"]


@pytest.mark.parametrize("problem, table", [("frictionless", "tab_3_3_norms_frictionless"),
                                            ("coulomb", "tab_3_2_norms_coulomb")])
@pytest.mark.slow
def test_tables_agree_with_ngdual_solve(coarse_run, tmp_path, problem, table, capsys):
    level = int(SMOKE)
    assert main(["solve", f"thesis-3.46-{problem}", "--level", str(level), "--out",
                 str(tmp_path), "--no-plots"]) == 0
    capsys.readouterr()
    solved = json.loads((tmp_path / "result.json").read_text())
    row = next(r for r in read_csv(coarse_run / "data" / f"{table}.csv")
               if r["level"] == str(level))
    for key, value in solved["norms"].items():
        if value is not None and key in row:
            assert float(row[key]) == pytest.approx(value, rel=1e-9), key
    assert int(row["ndof"]) == sum(solved["dofs"].values())
    dofs = next(r for r in read_csv(coarse_run / "data" / "tab_3_1_dofs.csv")
                if r["level"] == str(level))
    # Table 3.1 counts the frictional spaces (nu: L); the frictionless problem has no nu
    assert all(int(dofs[k]) == v for k, v in solved["dofs"].items() if v)


@pytest.mark.slow
def test_table_3_1_matches_the_thesis(coarse_run):
    rows = read_csv(coarse_run / "data" / "tab_3_1_dofs.csv")
    assert len(rows) == int(SMOKE) and all(r["matches_thesis"] == "True" for r in rows)


@pytest.mark.slow
def test_figures_are_readable_without_the_thesis(coarse_run):
    sidecars = sorted((coarse_run / "figures").glob("*.json"))
    assert len(sidecars) >= 30
    for path in sidecars:
        texts = json.loads(path.read_text())
        assert texts["suptitle"] or all(a.get("title") for a in texts["axes"]), path.name
        plots = [a for a in texts["axes"] if not a["colorbar"]]
        colorbars = [a for a in texts["axes"] if a["colorbar"]]
        assert plots, path.name
        for ax in plots:
            assert ax["title"], path.name
            assert ax["xlabel"] and ax["ylabel"], (path.name, ax)
            for label in (ax["xlabel"], ax["ylabel"]):
                assert not MADE_UP_UNIT.search(label), (path.name, label)
            if ax["labelled_lines"]:
                assert ax["legend"] or texts["figure_legend"], (path.name, ax["title"])
            if ax["filled"]:
                assert colorbars or ax["legend"], (path.name, ax["title"])
        for bar in colorbars:
            assert bar["label"] and not MADE_UP_UNIT.search(bar["label"]), (path.name, bar)
        if "von_mises" in path.name or "contact_scenes" in path.name:
            assert any("percentile" in bar["label"] for bar in colorbars), path.name


@pytest.mark.slow
def test_a_rerun_computes_nothing(coarse_run, capsys):
    assert main(["figures", "--max-level", SMOKE, "--threads", "--out", str(coarse_run),
                 "--only", "tab_3_1", "tab_3_3"]) == 0
    run = json.loads((coarse_run / "run.json").read_text())
    assert run["computed_tasks"] == 0 and run["tasks"] > 0
    assert "0 computed" in capsys.readouterr().out


@pytest.mark.slow
def test_work_precision_measures_true_errors_against_references_it_checks(coarse_run):
    """Every solution of the six problems carries a finite true error against the adaptive
    references (a reference none in its own measure), uniform, both adaptive goals and the
    primal P1 / P2 peer, uniform and adaptive, are there, uniform and both goals at orders 1
    and 2 too, on the frictionless problems uniform refinement at orders 1 and 2 with the
    coarse multipliers (a solve of order k that fails is a row with its reason, and so is its
    table entry), the table names every method's order and multiplier family, the uniform
    stress error falls from level to level, a
    reference resolves only targets at least three times its own (Richardson, or the
    three-cornered hat where Richardson has none) error, the
    quadrature of non-nested candidates changes their errors by under 5 % or by less than
    the reference's own error, and the pressure
    goal's effectivity is recorded on Hertz, the flat punch and Cattaneo-Mindlin for every
    adaptive step whose error the reference resolves."""
    every = read_csv(coarse_run / "data" / "work_precision.csv")
    assert "e_tot" not in every[0]
    rows = [r for r in every if r["status"] == "ok"]
    failed = [r for r in every if r["status"] != "ok"]
    assert all(", k = " in r["method"] and r["message"] for r in failed), failed
    result = json.loads((coarse_run / "data" / "work_precision.json").read_text())
    problems = {"frictionless", "coulomb", "flat-punch", "hertz-cylinder", "cattaneo-mindlin",
                "wedge"}
    assert {r["problem"] for r in rows} == problems
    for r in rows:
        for key in ("time_s", "ndof"):
            assert math.isfinite(float(r[key])) and float(r[key]) > 0, (r["method"], key)
        for key in ("pressure", "sigma_energy"):
            assert r[key] == "" or math.isfinite(float(r[key])) and float(r[key]) > 0, (
                r["problem"], r["method"], r["level_or_step"], key)
    for problem in problems:
        mine = [r for r in rows if r["problem"] == problem]
        coarse = ({"uniform, k = 1, coarse", "uniform, k = 2, coarse"}
                  if problem in COARSE_ORDER_PROBLEMS else set())
        assert {r["method"] for r in every if r["problem"] == problem} == {
            "uniform", "adaptive, stress goal", "adaptive, pressure goal", "primal P1",
            "primal P2", "primal P1, adaptive", "primal P2, adaptive", "uniform, k = 1",
            "adaptive, stress goal, k = 1", "adaptive, pressure goal, k = 1", "uniform, k = 2",
            "adaptive, stress goal, k = 2", "adaptive, pressure goal, k = 2", *coarse}
        uniform = [float(r["sigma_energy"]) for r in mine if r["method"] == "uniform"]
        assert len(uniform) >= 2 and all(b < a for a, b in zip(uniform, uniform[1:]))
        for measure in ("pressure", "sigma_energy"):
            ref = result["references"][problem][measure]
            # the reference itself, unless it is a run's steps solved again at order 2
            assert sum(r[measure] == "" for r in mine) == (0 if "PEERS_2" in ref["method"]
                                                           else 1)
            for target in ref["resolves"]:
                assert ref["overkill_error"] <= target / 3
            if ref["estimate"] == "three-cornered hat":
                assert ref["overkill_error"] == ref["hat"]
        # a non-nested candidate's error integrated again on triangles split in four
        # changes by under 5 %, or by less than the reference's own error (two coarse
        # meshes, each finer where its goal refines: the punch's pressure goal of order 2
        # against the stress goal's reference of 427 triangles, 2.75 % -> 3.14 %)
        own = result["references"][problem]["sigma_energy"]["overkill_error"]
        for q in result["references"][problem]["sigma_energy"]["quadrature"]:
            assert q["relative_change"] < 0.05 or (
                own is not None and abs(q["sigma_energy_split"] - q["sigma_energy"]) < own), (
                problem, q)
    for problem in ("hertz-cylinder", "flat-punch", "cattaneo-mindlin"):
        floor = result["references"][problem]["pressure"]["overkill_error"]
        resolved = [r for r in rows if r["problem"] == problem and r["pressure"]
                    and r["method"] == "adaptive, pressure goal" and floor is not None
                    and float(r["pressure"]) >= 3 * floor]
        assert [float(r["effectivity"]) for r in resolved] == [
            e["effectivity"] for e in result["effectivity"]
            if (e["problem"], e["method"]) == (problem, "adaptive, pressure goal")]
        assert all(math.isfinite(float(r["effectivity"])) and float(r["effectivity"]) > 0
                   for r in resolved)
    assert any(e["problem"] == "hertz-cylinder" for e in result["effectivity"])
    assert any("PEERS_2" in result["references"][p]["sigma_energy"]["method"] for p in problems)
    # a summary (both measures), then one figure per measure and idea: the time to each
    # target (a method that reaches none has no curve), the errors against wall time and
    # against unknowns; six problem panels and one legend each
    summary_fig = json.loads((coarse_run / "figures" / "work_precision.json").read_text())
    assert len(summary_fig["axes"]) == 2 and summary_fig["figure_legend"]
    table_rows = read_csv(coarse_run / "data" / "work_precision_table.csv")
    for stem in ("work_precision", "work_precision_curves", "work_precision_unknowns"):
        for measure, key in (("pressure", "pressure"), ("sigma", "sigma_energy")):
            sidecar = json.loads((coarse_run / "figures" / f"{stem}_{measure}.json").read_text())
            assert len(sidecar["axes"]) == 6, (stem, measure)
            labels = set(sidecar["figure_legend"])
            if stem == "work_precision":
                assert labels == {r["method"] for r in table_rows
                                  if r["measure"] == key and r["time_s"]}, labels
            else:
                assert {"primal P1", "primal P2", "uniform", "adaptive, pressure goal",
                        "uniform, k = 2", "adaptive, pressure goal, k = 1"} <= labels, labels
    table = read_csv(coarse_run / "data" / "work_precision_table.csv")
    assert {(r["order"], r["multipliers"]) for r in table if "primal" not in r["method"]} == {
        ("0", "coarse"), ("1", "facet"), ("2", "facet"), ("1", "coarse"), ("2", "coarse")}
    for r in table:
        assert bool(r["failed"]) == any(s["status"] != "ok" for s in every if (
            s["problem"], s["method"]) == (r["problem"], r["method"])), r
    assert not any(r["failed"] for r in table if ", k = " not in r["method"])
    assert any(r["time_s"] != "" and r["order"] == "2" for r in table)
    assert {v["target"] for v in result["verdicts"]} == {0.05, 0.02, 0.01}
    # the README's two tables: a row per problem and target, its verdict in "adaptive first"
    summary = (coarse_run / "data" / "work_precision_summary.md").read_text()
    rows = [line.split(" | ") for line in summary.splitlines() if line.startswith("| ")
            and not line.startswith("| problem")]
    assert len(rows) == len(result["verdicts"])
    ordered = [v for measure in ("pressure", "sigma_energy") for v in result["verdicts"]
               if v["measure"] == measure]
    assert [r[-2].split(" (in turn")[0] for r in rows] == [
        "tie: the same solve" if v["adaptive_any_same_solve"]
        else {None: "–", True: "yes", False: "no"}[v["adaptive_any_wins"]] for v in ordered]
    for v in result["verdicts"]:
        # a close verdict is the paired timing's (when it ran), a tie no win and not timed
        # again, any other the table's
        if v["adaptive_any_same_solve"]:
            assert v["adaptive_any_wins"] is False and v["paired_adaptive_s"] is None
        elif v["paired_adaptive_s"] is not None:
            a, u = v["adaptive_any_s"], v["uniform_any_s"]
            assert max(a / u, u / a) <= 1.3, v
            assert v["adaptive_any_wins"] == (v["paired_adaptive_s"] < v["paired_uniform_s"])
        elif v["adaptive_any_wins"] is not None:
            assert v["adaptive_any_wins"] == (v["uniform_any_s"] is None
                                              or v["adaptive_any_s"] < v["uniform_any_s"])
    for v in result["verdicts"]:
        # the fastest adaptive run of any order is at least as fast as that of order 0
        if v["adaptive_s"] is not None:
            assert v["adaptive_any_s"] <= v["adaptive_s"]


@pytest.mark.slow
def test_the_estimator_tracks_the_exact_error_of_the_manufactured_cases(coarse_run):
    """eta / e on the manufactured cases (exact errors) stays within a factor 2 over the
    uniform levels: the estimator is efficient and reliable there."""
    rows = read_csv(coarse_run / "data" / "effectivity.csv")
    for case in ("manufactured frictionless", "manufactured coulomb-nodes"):
        eff = [float(r["effectivity"]) for r in rows
               if r["problem"] == case and r["method"] == "uniform"]
        assert len(eff) >= 2 and max(eff) / min(eff) < 2 and 0.2 < min(eff), (case, eff)


# --- killing a sweep --------------------------------------------------------------------------

@pytest.mark.slow
def test_a_killed_sweep_resumes_without_recomputing(tmp_path):
    """tab_3_6 at level 2: the (rho_1, rho_2) grid on levels 1 and 2 (20 nested Uzawa solves)."""
    out = tmp_path / "out"
    command = [sys.executable, "-m", "ngdual", "figures", "--max-level", COARSE, "--threads",
               "--only", "tab_3_6", "--out", str(out)]
    env = dict(os.environ, MPLBACKEND="Agg")
    records = out / "records"
    proc = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while len(list(records.glob("*.json"))) < 4:
            assert proc.poll() is None, "the sweep ended before it could be killed"
            assert time.monotonic() < deadline
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    before = {p.name: (p.stat().st_mtime_ns, json.loads(p.read_text())["started"])
              for p in records.glob("*.json")}
    assert not (out / "run.json").exists()
    subprocess.run(command, env=env, check=True, capture_output=True, timeout=300)
    run = json.loads((out / "run.json").read_text())
    after = {p.name: (p.stat().st_mtime_ns, json.loads(p.read_text())["started"])
             for p in records.glob("*.json")}
    assert len(before) < run["tasks"] == len(after)
    assert run["computed_tasks"] == run["tasks"] - len(before)
    for name, stamp in before.items():
        assert after[name] == stamp, name
    assert not list(records.glob("*.tmp"))
    assert json.loads((out / "entries" / "tab_3_6_iterations_coulomb.json").read_text())


# --- the pieces ------------------------------------------------------------------------------

def test_the_thesis_scale_plan_uses_the_thesis_steps():
    plan = Plan(8)
    assert plan.levels == list(range(1, 9)) and plan.reference_levels == [6, 7, 8]
    assert plan.max_marking_snapshots == [0, 4, 8, 12, 16, 20, 24, 28]
    assert plan.fraction_snapshots == [1, 3, 5, 7, 9]
    assert plan.rho_level == 4
    small = Plan(2)
    assert len(small.max_marking_snapshots) == 8 and len(small.fraction_snapshots) == 5
    with pytest.raises(ValueError, match="max-level"):
        Plan(9)
    assert main(["figures", "--max-level", "1", "--out", "unused"]) == 2


def test_the_flat_punchs_reference_runs_go_further_than_the_others():
    """The true-error studies' adaptive runs stop at their problem's tolerance: the flat
    punch's at a third of the others' (its sigma references converge slowest), with twice
    the budget at order k >= 1; the others at REFERENCE_TOL with the budget / 4^k."""
    from ngdual.studies.figures.plan import REFERENCE_TOL, TRUTH_PROBLEMS
    from ngdual.studies.figures.tasks import truth_adapt

    plan = Plan(7)
    for problem, tp in TRUTH_PROBLEMS.items():
        punch = problem == "flat-punch"
        for order in (0, 1, 2):
            params = truth_adapt(plan, problem, "stress", order).params
            assert params["tol"] == tp.reference_tol
            assert (params["tol"] <= REFERENCE_TOL / 3) if punch else (
                params["tol"] == REFERENCE_TOL)
            budget = plan.reference_elements(problem) // 4 ** order * (2 if punch and order else 1)
            assert params["max_elements"] == budget, (problem, order)


def test_the_readme_summary_takes_the_fastest_method_of_each_order():
    """work_precision's summary tables (the README's): per order the least time of any of
    its methods with its letters, uniform and P2 without, the verdict's ratios and "adaptive
    first", a dash where nothing reaches the target; and the script's doctests pass."""
    import doctest

    from ngdual.studies.figures.run import load_script

    wp = load_script(Path(__file__).parents[1] / "figures" / "work_precision.py")
    assert doctest.testmod(wp).failed == 0

    def hit(method, order, time_s, ndof, family="facet"):
        return {"problem": "hertz-cylinder", "measure": "pressure", "target": 0.02,
                "method": method, "order": order, "multipliers": family, "time_s": time_s,
                "ndof": ndof}
    table = [hit("uniform", 0, None, None, "coarse"),
             hit("adaptive, stress goal", 0, 4.2, 250813, "coarse"),
             hit("adaptive, pressure goal", 0, 0.89, 30079, "coarse"),
             hit("uniform, k = 1", 1, 0.59, 87857), hit("adaptive, pressure goal, k = 1", 1,
                                                         0.71, 15139),
             hit("uniform, k = 2, coarse", 2, 0.43, 43034, "coarse"),
             hit("adaptive, stress goal, k = 2", 2, 0.81, 15533),
             hit("primal P2", 2, 3.6, 58690, "Nitsche")]
    verdict = [{"problem": "hertz-cylinder", "measure": "pressure", "target": 0.02,
                "resolved": True, "adaptive_any_wins": False, "ratio_ngdual_p2": 0.43 / 3.6,
                "ratio_order_p2": 0.43 / 3.6},
               {"problem": "hertz-cylinder", "measure": "sigma_energy", "target": 0.02,
                "resolved": False, "adaptive_any_wins": None, "ratio_ngdual_p2": None,
                "ratio_order_p2": None}]
    [row] = wp.summary_rows(table, verdict, "pressure")
    assert row == {"case": "Hertz, 2 %", "uniform": None, "adaptive": "0.89 s (30 079) p",
                   "k1": "0.59 s (87 857) u", "k2": "0.43 s (43 034) uc",
                   "p2": "3.6 s (58 690)", "ratio": "0.12", "ratio_order": "0.12",
                   "first": "no", "resolved": "yes"}
    markdown = wp.summary_markdown(table, verdict)
    assert "| Hertz, 2 % | – | 0.89 s (30 079) p |" in markdown
    assert "| Hertz, 2 % | – | – | – | – | – | – | – | – | no |" in markdown


def test_task_ids_are_stable_and_distinguish_parameters():
    a = Task("solve", {"scene": "thesis-3.46-coulomb", "level": 2, "overrides": []}, "x", 1.0)
    b = Task("solve", {"level": 2, "overrides": [], "scene": "thesis-3.46-coulomb"}, "y", 9.0)
    c = Task("solve", {"scene": "thesis-3.46-coulomb", "level": 3, "overrides": []})
    assert a.id == b.id != c.id and a.id.startswith("solve-thesis-3.46-coulomb-L2-")


def test_failed_and_unconverged_solves_are_records_with_their_message(tmp_path):
    failing = Task("solve", {"scene": "thesis-3.46-coulomb", "level": 1,
                             "overrides": ['solver.method="uzawa"', "solver.max_iter=2"]})
    record, arrays = execute(failing)
    assert record["status"] == "failed" and "max_iter" in record["message"]
    assert arrays == {} and record["versions"]["ngdual"]
    stopped = Task("solve", {"scene": "thesis-3.46-frictionless", "level": 1,
                             "overrides": ['solver.method="uzawa"', "solver.max_iter=2"]})
    run_task(stopped, str(tmp_path))
    assert load_record(tmp_path, stopped)["status"] == "not-converged"
    broken = Task("solve", {"scene": "no-such-scene", "level": 1})
    record, _ = execute(broken)
    assert record["status"] == "error" and "no-such-scene" in record["message"]
    run_task(broken, str(tmp_path))
    assert load_record(tmp_path, broken) is None  # retried by the next run


def test_error_helpers():
    records = [{"norms": {"u": 1.5, "nu": None}, "ndof": 10},
               {"norms": {"u": 1.25, "nu": None}, "ndof": 40},
               {"norms": {"u": 1.125, "nu": None}, "ndof": 160}]
    reference = extrapolated_norms([r["norms"] for r in records])
    assert reference["u"] == pytest.approx(1.0) and reference["nu"] is None
    e = [r["e_tot"] for r in errors(records, reference)]
    assert e[0] == pytest.approx(math.sqrt(1.5**2 - 1))
    alpha = observed_rates([10, 40, 160], e)
    assert alpha[0] is None and alpha[1] == pytest.approx(
        -2 * math.log(e[0] / e[1]) / math.log(10 / 40))
    ok = {"a": {"status": "ok", "iterations": {"outer": 9, "inner": 50},
                "timings_s": {"solve": 1.0}},
          "b": {"status": "ok", "iterations": {"outer": 5, "inner": 80},
                "timings_s": {"solve": 0.5}},
          "c": {"status": "failed"}}
    assert best(ok) == "a"
    assert "| 1 | - |" in markdown_table([{"a": 1}], {"a": "A", "b": "B"})


def test_the_three_cornered_hat_recovers_three_orthogonal_errors_and_refuses_others():
    """Three solutions of one truth whose errors live on disjoint parts (orthogonal): the
    pairwise distances give each error exactly; distances no orthogonal errors can have
    (one longer than the other two together in squares) give no estimate."""
    from ngdual.studies.figures.hats import three_cornered_hat

    truth = np.sin(np.linspace(0, 3, 30))
    errors = [np.zeros(30) for _ in range(3)]
    for k, size in enumerate((0.01, 0.002, 0.03)):
        errors[k][10 * k:10 * k + 10] = size * np.cos(np.arange(10))
    a, b, c = (truth + e for e in errors)
    d = np.linalg.norm
    assert three_cornered_hat(d(a - b), d(a - c), d(b - c)) == pytest.approx(d(errors[0]))
    assert three_cornered_hat(d(b - c), d(b - a), d(a - c)) == pytest.approx(d(errors[1]))
    assert three_cornered_hat(1.0, 1.0, 2.0) is None


def test_a_hat_that_a_corners_richardson_estimate_refutes_is_no_own_error(monkeypatch):
    """Errors that are not orthogonal: a's and b's aligned (2 v and 1.5 v), c's (w)
    orthogonal to both. The hat puts a at 1, half its true error 2; c's Richardson
    estimate 0.5 (counted twice: 1, its true error) and the distance sqrt(5) bound a's
    from below by sqrt(5) - 1 (triangle inequality), which refutes the hat: a keeps no own
    error, and is no reference. With orthogonal errors (a's 0.5 w') the same corners give
    the hat, exact, as its error. The pressure's hat is bounded by every run with a
    Richardson estimate, corner or not."""
    from ngdual.studies.figures import hats
    from ngdual.verification import overkill

    v, w, w2 = np.eye(3)
    solutions = {"a": 2 * v, "b": 1.5 * v, "c": w, "a2": 0.5 * w2, "uniform": 3 * w}

    def dist(x, y):
        return float(np.linalg.norm(x["e"] - y["e"]))

    monkeypatch.setattr(hats, "pressure_distance", lambda x, y, window=None: dist(x, y))
    monkeypatch.setattr(overkill, "true_errors", lambda x, y, lam, mu, window=None: {
        "sigma_energy": dist(x, y), "sigma_energy_norm": 1.0})

    def check(name, own):
        entry = {"overkill_error": own, "estimate": own and "Richardson"}
        return {"method": name, "pressure": dict(entry), "sigma_energy": dict(entry)}

    def samples(name):   # a one-triangle solution whose error is solutions[name]
        return {"e": solutions[name], "triangles": [0]}

    def runs_of(names):  # one step each, the first name's the largest
        return {m: [({"ndof": 10 - k}, samples(m))] for k, m in enumerate(names)}

    uniform = ({}, samples("uniform"))
    for name, truth_a in (("a", 2.0), ("a2", 0.5)):
        checks = [check(name, None), check("b", None), check("c", 0.5)]
        hats.hat_checks(checks, runs_of([name, "b", "c"]), uniform, 1.0, 1.0, None)
        entry = checks[0]["pressure"]
        assert sorted(entry["corners"]) == ["b", "c"]
        if name == "a":
            assert entry["hat"] == pytest.approx(1.0)
            assert entry["hat_bound"] == pytest.approx(5 ** 0.5 - 1)
            assert entry["hat_bound"] <= truth_a
            assert entry["hat_refuted"] and entry["overkill_error"] is None
        else:
            assert not entry["hat_refuted"] and entry["hat_bound"] <= truth_a
            assert entry["overkill_error"] == pytest.approx(truth_a)
            assert entry["estimate"] == "three-cornered hat"

    # a run that is no corner bounds the pressure's hat too (its distance costs little):
    # d = 5 v lies 3 from a, farther than a's corners b (0.5) and c (sqrt 5); the hat of
    # a, b, c puts a at 1 (true 2). d's Richardson estimate 5 gives no bound, 1.25 the
    # bound 3 - 2 x 1.25 = 0.5 (the hat stands), 0.75 the bound 1.5, which refutes it
    solutions.update(d=5 * v)
    for own_d, bound in ((5.0, 0.0), (1.25, 0.5), (0.75, 1.5)):
        checks = [check("a", None), check("b", None), check("c", None), check("d", own_d)]
        hats.hat_checks(checks, runs_of(["a", "b", "c", "d"]), uniform, 1.0, 1.0, None)
        entry = checks[0]["pressure"]
        assert sorted(entry["corners"]) == ["b", "c"] and entry["hat"] == pytest.approx(1.0)
        assert entry["hat_bound"] == pytest.approx(bound) and entry["hat_bound"] <= 2.0
        assert entry["hat_refuted"] == (bound > 1.0)
        assert entry["overkill_error"] == (None if bound > 1.0 else pytest.approx(1.0))


def test_a_solve_record_and_an_adaptive_step_hold_the_estimate_under_the_same_keys():
    """``estimator`` is (sum_T eta_T^2)^(1/2) and ``estimator_sum`` sum_T eta_T in every
    record; ``eta`` is the rotation's norm."""
    solve, _ = execute(Task("solve", {"scene": "thesis-3.46-coulomb", "level": 1}))
    steps = adapt(load_scene("thesis-3.46-coulomb"), steps=1, level=1)
    for record in (solve, steps[0]):
        assert isinstance(record["estimator"], float), record
        assert 0 < estimator(record) <= estimator(record, "sum"), record
    assert estimator(solve) == estimator(steps[0]) and "eta" in solve["norms"]
    assert estimator({"status": "ok", "ndof": 3}) is None  # the primal peer has none


def test_a_task_runs_on_one_thread_and_leaves_the_threads_as_they_were():
    """execute() runs NGSolve's task manager (and BLAS) on one thread: one task per core,
    so that a large mesh's parallel assembly does not take a second core the other
    methods' timings do not get; the setting is restored afterwards."""
    from ngdual.studies.sweep import timing

    before = timing._ngsolve_threads()
    record, _ = execute(Task("dofs", {"scene": "thesis-3.46-coulomb", "level": 1}))
    assert record["status"] == "ok" and record["threads"] == 1
    assert timing._ngsolve_threads() == before


def _worker_environment() -> dict:
    return {name: os.environ.get(name) for name in ("MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS")}


@pytest.mark.slow
def test_a_sweep_worker_keeps_glibcs_own_memory_trimming_and_one_blas_thread():
    """The workers of a sweep's LocalCluster run with glibc's own memory trimming (dask's
    nanny would set MALLOC_TRIM_THRESHOLD_=65536, under which the timed solves of a study
    ran 1.3-1.5 times slower than in a plain process) and one BLAS thread each; this
    process's environment is left as it was (the nanny writes its pre-spawn variables into
    it, and then OPENBLAS_NUM_THREADS here no longer said what BLAS runs on)."""
    from ngdual.studies.sweep.runner import Runner

    before = dict(os.environ)
    with Runner(workers=1, progress=False) as runner:
        environments = list(runner.client().run(_worker_environment).values())
        assert dict(os.environ) == before
    assert environments == [{"MALLOC_TRIM_THRESHOLD_": None, "OMP_NUM_THREADS": "1"}]


def test_a_true_error_task_times_the_median_of_its_runs(monkeypatch):
    """With ``repeat`` the wall time of a solve, a peer solve and an adaptive run is the
    median of its runs (an adaptive run's: its steps' median times summed); runs beyond
    the first only below REPEAT_BELOW_S, and a plan below the default K times once."""
    from ngdual.studies.sweep import adaptive_tasks, solve_tasks, timing

    solve, _ = solve_tasks.solve_task("thesis-3.46-frictionless", 1, repeat=3)
    assert len(solve["time_runs_s"]) == 3
    assert solve["time_s"] == pytest.approx(np.median(solve["time_runs_s"]))
    assert solve["time_runs_s"][0] == solve["timings_s"]["total"]
    peer, _ = solve_tasks.peer_task("hertz-cylinder", 1, 1, repeat=2)
    assert len(peer["time_runs_s"]) == 2 and peer["time_s"] == np.median(peer["time_runs_s"])
    run, _ = adaptive_tasks.adapt_task("thesis-3.46-frictionless", "dorfler", 0.8, 3, 1, repeat=3)
    cumulative = [r["cumulative_s"] for r in run["history"]]
    assert len(cumulative) == 3 and np.all(np.diff(cumulative) > 0)
    for r in run["history"]:   # the same meshes in every run: three times per step
        assert len(r["cumulative_runs_s"]) == 3, r["cumulative_runs_s"]
        # the time to the step's solution, its estimate and marks not counted
        assert r["cumulative_runs_s"][0] == r["solved_s"] < r["elapsed_s"]
    runs = np.array([r["cumulative_runs_s"] for r in run["history"]]).T
    steps = np.median(np.diff(runs, axis=1, prepend=0.0), axis=0)
    assert cumulative == pytest.approx(np.cumsum(steps), rel=1e-12)
    # a rerun that keeps no step (its first mesh differs) leaves the first run's times
    with monkeypatch.context() as m:
        m.setattr(adaptive_tasks, "_loop_times", lambda *args: [])
        alone, _ = adaptive_tasks.adapt_task("thesis-3.46-frictionless", "dorfler", 0.8, 2, 1,
                                             repeat=3)
    assert alone["status"] == "ok"
    assert [r["cumulative_s"] for r in alone["history"]] == pytest.approx(
        [r["cumulative_runs_s"][0] for r in alone["history"]], rel=1e-12)
    monkeypatch.setattr(timing, "REPEAT_BELOW_S", 0.0)
    monkeypatch.setattr(adaptive_tasks, "REPEAT_BELOW_S", 0.0)
    once, _ = adaptive_tasks.adapt_task("thesis-3.46-frictionless", "dorfler", 0.8, 2, 1, repeat=3)
    assert [len(r["cumulative_runs_s"]) for r in once["history"]] == [1, 1]
    solve, _ = solve_tasks.solve_task("thesis-3.46-frictionless", 1, repeat=3)
    assert len(solve["time_runs_s"]) == 1
    assert Plan(3).timing_repeats == 1 and Plan(5).timing_repeats == Plan(7).timing_repeats == 3


def test_a_paired_timing_runs_uniform_and_adaptive_in_turn(monkeypatch):
    """paired_task times the uniform solve and the adaptive run to its step alternately
    (uniform first in the odd rounds, adaptive first in the even ones), the adaptive run
    only to the step asked for, and its medians are those of its runs; a run on other
    meshes is not counted, and none counted is a failed record."""
    from ngdual.studies.sweep import adaptive_tasks

    uniform = {"scene": "thesis-3.46-frictionless", "level": 1, "overrides": []}
    adaptive = {"scene": "thesis-3.46-frictionless", "overrides": [], "marking": "dorfler",
                "theta": 0.8, "steps": 5, "level": 1, "goal": "stress", "tol": None,
                "window": None}
    run, _ = adaptive_tasks.adapt_task("thesis-3.46-frictionless", "dorfler", 0.8, 5, 1)
    unknowns = [r["dofs"]["total"] for r in run["history"]][:2]
    record, arrays = adaptive_tasks.paired_task(uniform, adaptive, unknowns, rounds=3)
    assert record["status"] == "ok" and arrays == {}
    assert len(record["uniform_runs_s"]) == len(record["adaptive_runs_s"]) == 3
    assert record["uniform_s"] == np.median(record["uniform_runs_s"])
    assert record["adaptive_s"] == np.median(record["adaptive_runs_s"])
    calls = []
    monkeypatch.setattr(adaptive_tasks, "solve_quietly", lambda sc, level: calls.append(
        "u") or type("S", (), {"timings": {"total": 1.0}})())

    def loop_times(scene, overrides, loop, steps, max_elements):
        calls.append("a")
        assert loop["steps"] == 5 and steps == unknowns and max_elements is None
        return [0.1, 0.2]
    monkeypatch.setattr(adaptive_tasks, "_loop_times", loop_times)
    record, _ = adaptive_tasks.paired_task(uniform, adaptive, unknowns, rounds=4)
    assert "".join(calls) == "ua" + "uaauuaau"
    assert record["adaptive_runs_s"] == [0.2] * 4 and record["uniform_s"] == 1.0
    monkeypatch.setattr(adaptive_tasks, "_loop_times", lambda *args: [0.1])   # the meshes differ
    record, _ = adaptive_tasks.paired_task(uniform, adaptive, unknowns, rounds=2)
    assert record["status"] == "failed" and "step's mesh" in record["message"]


@pytest.mark.slow
def test_close_verdicts_are_decided_by_their_paired_timing():
    """work_precision times a verdict again in pairs only when its adaptive and uniform
    times lie within CLOSE of each other, both under REPEAT_BELOW_S; the paired medians then
    decide "adaptive first" (a failed pairing leaves the table's verdict), and the README's
    cell gives them."""
    from ngdual.studies.figures.run import load_script
    from ngdual.studies.sweep.timing import REPEAT_BELOW_S

    wp = load_script(Path(__file__).parents[1] / "figures" / "work_precision.py")

    def row(time_s, ndof):   # a row of the table: a level or step of 100 or 400 unknowns
        return time_s and {"time_s": time_s, "level_or_step": 2, "order": 0,
                           "multipliers": "coarse", "ndof": ndof}

    def verdict(adaptive_s, uniform_s):
        return {"adaptive_any_s": adaptive_s, "uniform_any_s": uniform_s,
                "adaptive_any_wins": wp._wins(row(adaptive_s, 100), row(uniform_s, 400)),
                "paired_adaptive_s": None, "paired_uniform_s": None}
    assert wp.is_close(verdict(0.52, 0.42)) and wp.is_close(verdict(0.42, 0.52))
    assert not wp.is_close(verdict(0.56, 0.42)) and not wp.is_close(verdict(0.3, 0.42))
    assert not wp.is_close(verdict(REPEAT_BELOW_S, 0.9 * REPEAT_BELOW_S))
    assert not wp.is_close(verdict(0.5, None)) and not wp.is_close(verdict(None, 0.5))
    cells = [verdict(0.52, 0.42), verdict(0.44, 0.42), verdict(0.40, 0.42)]
    wp.apply_paired(cells, {0: {"status": "ok", "adaptive_s": 0.38, "uniform_s": 0.45},
                            1: {"status": "failed"}, 2: None})
    assert [c["adaptive_any_wins"] for c in cells] == [True, False, True]
    assert wp.first_cell(cells[0]) == "yes (in turn: 0.38 / 0.45 s)"
    assert [wp.first_cell(c) for c in cells[1:]] == ["no", "yes"]
    assert wp.first_cell(verdict(None, 0.4)) is None
    # the adaptive run's first solve is the uniform solve: a tie whatever the two times say
    first = {"level_or_step": 0, "order": 1, "multipliers": "facet", "ndof": 5205}
    for adaptive_s, uniform_s in ((0.0766, 0.0768), (0.0768, 0.0766)):
        adaptive, uniform = {**first, "time_s": adaptive_s}, {**first, "time_s": uniform_s}
        tie = {**verdict(adaptive_s, uniform_s), "adaptive_any_wins": wp._wins(adaptive, uniform),
               "adaptive_any_same_solve": wp.same_solve(adaptive, uniform)}
        assert tie["adaptive_any_wins"] is False and not wp.is_close(tie)
        assert wp.first_cell(tie) == "tie: the same solve"
    # the same unknowns on a later step, or another order, are two computations
    later = {**first, "level_or_step": 1, "time_s": 0.0766}
    assert wp._wins(later, {**first, "time_s": 0.0768}) is True
    assert not wp.same_solve({**first, "order": 2}, first)
