"""Every tutorial runs top to bottom, headless and in quick mode, and its numbers are right.

Each tutorial (``tutorials/NN_*.py``, jupytext percent format) is executed as a
script in a fresh process with ``NGDUAL_QUICK=1`` and ``MPLBACKEND=Agg`` in a
temporary folder, within two minutes. It writes the numbers it computed to
``results.json``; the check registered for its number in ``CHECKS`` asserts the
mathematics behind them (Table 3.1, a bounded inf-sup constant, locking of P1 but
not of PEERS, Uzawa = QP, validation errors naming their field...). A new tutorial
fails ``test_every_tutorial_has_a_check`` until it gets a check here.

The notebooks written by ``ngdual tutorials --notebooks DIR`` are executed with
``jupyter nbconvert --execute`` and must produce no error and the same numbers.
The exercise solutions (``tutorials/solutions/``) run in quick mode as well.
"""

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ngdual.cli import main
from ngdual.studies.tutorials import (
    Tutorial,
    in_notebook,
    list_tutorials,
    quick_mode,
    tutorials_dir,
    write_notebooks,
)

TIME_LIMIT_S = 120
TUTORIALS = list_tutorials()
SOLUTIONS = list_tutorials(solutions=True)
TABLE_3_1 = {1: (180, 64, 27), 2: (680, 256, 85), 3: (2640, 1024, 297), 4: (10400, 4096, 1105),
             5: (41280, 16384, 4257)}


def quick_env(out: Path) -> dict:
    """The environment of a headless quick run: no display, Agg backend, output in ``out``."""
    env = dict(os.environ, NGDUAL_QUICK="1", MPLBACKEND="Agg", NGDUAL_TUTORIAL_OUT=str(out))
    env.pop("DISPLAY", None)
    return env


def run_script(item: Tutorial, tmp_path: Path) -> dict:
    """Run one tutorial or solution as a script; return its results.json."""
    out = tmp_path / "out"
    result = subprocess.run([sys.executable, str(item.path)], cwd=tmp_path, env=quick_env(out),
                            capture_output=True, text=True, timeout=TIME_LIMIT_S)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "Traceback" not in result.stderr, result.stderr[-3000:]
    return json.loads((out / item.name / "results.json").read_text())


# --- what each tutorial must have computed ---------------------------------------------------

def check_peers_spaces(r: dict) -> None:
    """Table 3.1 and a bounded inf-sup constant (zero without bubbles)."""
    for row in r["dofs"]:
        assert (row["X"], row["M"], row["S"]) == TABLE_3_1[row["level"]]
    betas = [row["peers"][0] for row in r["inf_sup"]]
    assert 0.35 < min(betas) and max(betas) / min(betas) < 1.05, betas
    for row in r["inf_sup"]:
        assert max(row["rt0_only"][:2]) < 1e-6          # two spurious modes without bubbles
    third = [row["rt0_only"][2] for row in r["inf_sup"]]
    assert all(1.7 < a / b < 2.3 for a, b in zip(third, third[1:])), third   # decays like h


def check_locking(r: dict) -> None:
    """Locking of P1 but not of PEERS; PEERS converges; the P1 mean stress is spurious."""
    ratios = r["ratios"]
    assert ratios["peers_sigma"] < 1.5 and ratios["peers_u"] < 1.5, ratios
    assert ratios["p1_sigma"] > 2 and ratios["p1_u"] > 2, ratios
    for nu in {row["nu"] for row in r["convergence"]}:
        errors = [row["peers_sigma"] for row in r["convergence"] if row["nu"] == nu]
        assert all(b < a for a, b in zip(errors, errors[1:])), errors
    assert r["mean_stress_max"]["P1"] > 20 * r["mean_stress_max"]["PEERS"], r["mean_stress_max"]


def check_signorini_uzawa(r: dict) -> None:
    """P+ as a QP, iteration counts vs rho and metric, Uzawa = independent QP."""
    p = r["projection"]
    assert p["cvxpy_vs_ngdual"] < 1e-6 and p["kkt_complementarity"] < 1e-10, p
    assert p["kkt_gradient_min"] > -1e-10 and p["clipping_differs_by"] > 1e-3, p
    assert all(all(runs.values()) for runs in r["converged"].values())
    assert not r["overshoot"]["converged"]
    assert set(r["iterations"]["h12"]) == {"0.25", "0.5", "1.0", "1.5"}   # no long divergent runs
    for counts in r["iterations"].values():               # small rho: contraction ~ 1 - c rho
        assert 1.7 < counts["0.25"] / counts["0.5"] < 2.3, counts
    h12, euclidean = (r["iterations_per_level"][m] for m in ("h12", "euclidean"))
    assert h12[-1] <= h12[0] + 2, h12                     # mesh independent (Remark 3.40)
    assert euclidean[-1] > euclidean[-2] and euclidean[-1] > h12[-1], (euclidean, h12)
    a = r["agreement"]
    assert a["sigma"] < 1e-8 and a["lam_n"] < 1e-8, a
    assert a["nodes_in_contact"][0] == a["nodes_in_contact"][1] > 0, a
    assert r["residuals"]["sigma_n_positive"] < 1e-8 and r["residuals"]["lambda_n_negative"] == 0


def check_friction(r: dict) -> None:
    """(3.62) holds tested with the hats; nested Uzawa = QP = the default solver, both loop
    orders; Coulomb's bound is a fixed point."""
    assert r["converged"]["tresca"] and r["converged"]["coulomb"]
    for law, c in r["conditions"].items():
        assert c["lam_n_min"] >= 0 and c["sigma_n_max"] < 1e-8, (law, c)      # lambda_n, sigma_n
        assert c["complementarity"] < 1e-8, (law, c)
        assert c["cone_excess"] < 1e-10 and c["tangential"] < 1e-8, (law, c)  # |sigma_t| <= F
        assert c["nu_max"] <= 1 and c["slipping_edges"] > 0, (law, c)
        assert c["nu_sign_mismatch"] < 1e-6, (law, c)                         # nu = sign lam_t
    for law, a in r["agreement"].items():
        assert max(a.values()) < 1e-5, (law, a)
        assert r["loop_order_difference"][law] < 1e-5
    assert max(r["active_set_difference"].values()) < 1e-5
    assert r["fixed_point_residual"] < 1e-5
    assert r["qp_fixed_point_history"][-1] < r["qp_fixed_point_history"][0]


def check_friction_inf_sup(r: dict) -> None:
    """A checkerboard kernel for h^ = h~, a bounded inf-sup constant for h^ = 2h~."""
    for row in r["inf_sup"]:                      # a kernel for h^ = h~ (checkerboard), none else
        assert row["hhat_h"]["N_A"] == row["hhat_h"]["N_C"] + 1 and row["hhat_h"]["beta"] == 0
        assert np.allclose(np.abs(row["kernel_hhat_h"]), 1)
        assert np.allclose(row["kernel_hhat_h"][1:], -np.array(row["kernel_hhat_h"][:-1]))
        assert row["hhat_2h"]["N_A"] < row["hhat_2h"]["N_C"] and row["hhat_2h"]["beta"] > 0.1
    betas = [row["hhat_2h"]["beta"] for row in r["inf_sup"]]
    assert max(betas) / min(betas) < 1.5, betas                               # Lemma 3.29
    assert r["inf_sup_inner"]["beta"] > 0.01                                  # Lemma 3.31
    coarse, fine = r["gap0"]["hhat_2h"], r["gap0"]["hhat_h"]
    assert all(row["converged"] for row in coarse)
    both = [(a["outer"], b["outer"]) for a, b in zip(fine, coarse) if a["converged"]]
    assert both and all(f > c for f, c in both), both
    assert all("hhat_factor" in message for message in r["failure_messages"])


def check_estimator(r: dict) -> None:
    """Terms add up, live where they should; effectivity band, rates, the H(div) variant."""
    t = r["thesis"]
    assert t["sum_of_terms_is_eta2"]
    assert math.isclose(math.sqrt(sum(t["summed"].values())), t["eta"], rel_tol=1e-10)
    assert t["summed"]["residual"] < 1e-12 * t["eta"] ** 2                   # f = 0 = div sigma_h
    assert 0 < t["friction_elements"] < t["elements"] and 0 < t["neumann_elements"]
    effectivity = r["effectivity"]
    assert 0.2 <= min(effectivity) and max(effectivity) <= 5
    assert max(effectivity) / min(effectivity) <= 1.5, effectivity
    rows = r["smooth"]
    for row in rows[1:]:
        assert row["rate_error"] > 0.8 and abs(row["rate_eta"] - row["rate_error"]) <= 0.15, row
    hdiv = r["hdiv_effectivity"]
    assert all(b > 1.5 * a for a, b in zip(hdiv, hdiv[1:])), hdiv           # grows like 1/h
    assert rows[-1]["as_hdiv"] > 0.5 * rows[0]["as_hdiv"]                   # does not decay
    assert rows[-1]["as_l2"] < 0.5 * rows[0]["as_l2"]


def check_adaptivity(r: dict) -> None:
    """The MARK step as specified, REFINE adds triangles; Dörfler beats uniform on the
    L-shape; every run reduces error and eta."""
    assert r["marking_share"]["dorfler"] >= 0.5
    assert r["marking_example"]["fraction"] >= math.ceil(0.2 * r["elements"])  # + ties
    assert 1 <= r["marking_example"]["max"] < r["elements"] < r["refined_elements"]
    runs = r["l_shape"]
    assert runs["uniform"]["rates"]["error"] <= 0.7        # ngdual.rates: e ~ N^(-rate/2)
    assert runs["dorfler"]["rates"]["error"] >= runs["uniform"]["rates"]["error"] + 0.3
    for name, run in runs.items():
        assert run["errors"][-1] < run["errors"][0] and run["etas"][-1] < run["etas"][0], name
        assert all(b > a for a, b in zip(run["ndofs"], run["ndofs"][1:])), name
    dorfler = runs["dorfler"]["effectivity"]
    assert max(dorfler) / min(dorfler) <= 3, dorfler


def check_your_own_scene(r: dict) -> None:
    """Each mistake caught with the right field, the record of result.json, a convergent
    contact solve."""
    assert r["caught"] == r["expected_fields"]
    assert {"converged", "dofs", "norms", "contact", "residuals"} <= set(r["record_sections"])
    levels = r["levels"]
    for row in levels:
        assert row["converged"] and row["nodes_in_contact"] >= 1, row
        assert row["sigma_n_positive"] < 1e-7, row
    dims = [row["dofs"]["X"] for row in levels]
    assert all(3.5 < b / a < 4.5 for a, b in zip(dims, dims[1:])), dims


def check_order_against_mesh_size(r: dict) -> None:
    """The stress of PEERS_k converges at order k + 1 against the exact solution; a higher
    order reaches the target error with fewer unknowns; the adaptive loop runs at every
    order and reduces the error."""
    for k, observed in r["observed_order"].items():
        assert abs(observed - (int(k) + 1)) <= 0.2, r["observed_order"]
    unknowns = [r["costs"][k]["ndof"] for k in ("0", "1", "2")]
    assert unknowns[0] > unknowns[1] > unknowns[2], unknowns
    for k, kept in r["adaptive"].items():
        assert kept["sigma"][-1] < kept["sigma"][0] and kept["ndof"][-1] > kept["ndof"][0], k


def check_goal_and_tolerance(r: dict) -> None:
    """Both goals stop by the tolerance; the pressure goal refines along Gamma_C, reaches a
    smaller true pressure error than uniform refinement with fewer unknowns, and its
    estimate is within a factor 4 of the true error on the steps above the reference's
    accuracy."""
    runs, uniform = r["runs"], r["uniform"]
    assert all(run["stopped_by"] == "tol" for run in runs.values()), runs
    pressure, stress = runs["pressure"], runs["stress"]
    assert r["near_contact"]["pressure"] > 1.5 * r["near_contact"]["stress"], r["near_contact"]
    assert pressure["error"][-1] < 3 * r["tol"], pressure["error"]
    assert pressure["error"][-1] < stress["error"][-1]
    finest = uniform[-1]
    assert pressure["error"][-1] < finest["error"] and pressure["ndof"][-1] < 2 * finest["ndof"]
    assert all(0.25 <= e <= 4 for e in r["effectivity"]), r["effectivity"]


CHECKS = {1: check_peers_spaces, 2: check_locking, 3: check_signorini_uzawa,
          4: check_friction, 5: check_friction_inf_sup, 6: check_estimator,
          7: check_adaptivity, 8: check_your_own_scene, 9: check_order_against_mesh_size,
          10: check_goal_and_tolerance}


def check_solutions(number: int, r: dict) -> None:
    if number == 1:
        assert 1.8 < r["growth_of_largest"]["l2"] < 2.2          # ~1/h in L2
        assert abs(r["growth_of_largest"]["hdiv"] - 1) < 0.05    # bounded in H(div)
    elif number == 2:
        assert r["primal_ratios"]["P1"] > r["primal_ratios"]["P2"] > 2
        assert all(row["kernel"] == 0 and row["count"] < 0 for row in r["divergence_free"])
    elif number == 3:
        assert all(uzawa == qp for uzawa, qp in r["gaps"].values()), r["gaps"]
        assert r["mass_metric_iterations"][-1] > r["mass_metric_iterations"][0]
        assert all(abs(hand - ngdual) <= 1 for hand, ngdual in r["hand_vs_ngdual"])
    elif number == 4:
        sweep = r["sweep"]
        assert all(converged for _, _, converged in sweep.values()), sweep
        for rho1 in r["rho1s"]:                   # outer steps ~ 1 / rho2 with nu outside
            outer = [sweep[f"friction-outer {rho1} {rho2}"][0] for rho2 in r["rho2s"]]
            assert all(b < a for a, b in zip(outer, outer[1:])), outer
        assert not r["large_rho2"]["8.0"][2]      # far beyond the bound: stalls
        by_mu = r["by_mu"]
        assert by_mu["0.0"]["sigma_vs_frictionless"] < 1e-8
        assert by_mu["0.5"]["F_abs"] > by_mu["0.0"]["F_abs"]
        assert by_mu["1.0"]["stick_nodes"] >= by_mu["0.1"]["stick_nodes"]
    elif number == 5:
        assert all(r["gap_abs_converged"]) and max(r["gap_abs_difference"].values()) < 1e-2
        assert r["kernel_alternates"] and r["kernel_spread"] > 1.5   # a weighted checkerboard
    elif number == 6:
        assert r["patch_sigma"] < 1e-20 * r["patch_u"] and r["patch_u"] > 0.1
        l2 = [row["l2"]["max"] for row in r["table_4_2"]]
        hdiv = [row["hdiv"]["max"] for row in r["table_4_2"]]
        assert max(l2) / min(l2) < 1.5 and hdiv[-1] > 3 * hdiv[0], (l2, hdiv)
        assert all(abs(row["l2"]["argmax_xy"][0]) > 3.5 and row["l2"]["argmax_xy"][1] < 0
                   for row in r["table_4_2"])                      # a lower corner
        assert r["table_4_2"][-1]["l2"]["q_as"] < r["table_4_2"][0]["l2"]["q_as"]
        square = r["sum_ratios"]["square"]
        assert all(0.8 < row["ratio"] / math.sqrt(row["elements"]) <= 1 for row in square)
        assert all(row["ratio"] <= math.sqrt(row["elements"]) for row in r["sum_ratios"]["thesis"])
    elif number == 7:
        d = r["dorfler"]
        assert d["0.5"]["rate"] > d["0.8"]["rate"] and d["0.5"]["rate"] > 0.9, d
        assert d["0.2"]["steps"] > d["0.5"]["steps"] > d["0.8"]["steps"], d
        eta, sigma = r["by_indicator"]["indicators"], r["by_indicator"]["eta_sigma"]
        assert eta["top_edges"] > sigma["top_edges"], (eta, sigma)
        incompatible, compatible = r["corners"]["0.01"], r["corners"]["0"]
        assert incompatible["uniform_as_max"][-1] > 0.8 * incompatible["uniform_as_max"][0]
        assert compatible["uniform_as_max"][-1] < 0.5 * compatible["uniform_as_max"][0]
        assert compatible["uniform_eta"][-1] < 0.3 * compatible["uniform_eta"][0]
    elif number == 8:
        assert r["touching"]["0.95"] == 0 and r["touching"]["1.05"] >= 1, r["touching"]
        assert sorted(r["arch_errors"].values()) == ["contact.ends", "geometry.points"]
        assert r["arch_contact"] >= 1
    elif number == 10:
        assert r["window"]["stopped_by"] == "tol" and r["window"]["core_share"] >= 0.5
        assert min(r["no_window_estimates"]) > 0.05                 # not in L2: no decay
        assert r["no_window_stopped_by"] == "singular"
        assert all(o["stopped_by"] == "tol" for o in r["orders"].values()), r["orders"]
        assert r["orders"]["2"]["ndof"] < r["orders"]["0"]["ndof"]
        growth = r["growth"]
        assert growth["0.5"]["solves"] > growth["0.8"]["solves"] >= growth["0.95"]["solves"]
        assert growth["0.5"]["growth"] < growth["0.8"]["growth"] < growth["0.95"]["growth"]
    elif number == 9:
        for k, observed in r["orders"].items():
            assert abs(observed["u"] - (int(k) + 1)) <= 0.2, r["orders"]
        coarse, facet = r["pairings"]["coarse"], r["pairings"]["facet"]
        assert abs(facet["sigma_order"] - 1) <= 0.2 and abs(coarse["sigma_order"] - 1) <= 0.2


# --- the tests ---------------------------------------------------------------------------------

def test_tutorials_are_found_and_numbered():
    numbers = [t.number for t in TUTORIALS]
    assert set(numbers) == set(range(1, 11)) and numbers == sorted(set(numbers))


def test_every_tutorial_has_a_check_and_solutions():
    assert {t.number for t in TUTORIALS} == set(CHECKS)
    assert {s.number for s in SOLUTIONS} == set(CHECKS)


@pytest.mark.parametrize("tutorial", TUTORIALS, ids=lambda t: t.name)
def test_tutorial_opens_with_header_and_ends_with_exercises(tutorial):
    """STYLE.md: the idea in words first, then problem, discretisation, learning goals,
    references; 2-3 exercises at the end."""
    text = tutorial.path.read_text(encoding="utf-8")
    header = text.split("# %%\n", 1)[0]
    for words in ("**The idea in words.**", "**Problem.**", "**Discretisation.**",
                  "**What you will learn.**", "**References.**"):
        assert words in header, words
    # the mathematics in words before its first equation number, e.g. (3.62)
    words = header.index("**The idea in words.**")
    assert words < header.index("**Problem.**"), tutorial.name
    assert not re.search(r"\(\d\.\d+\)", header[:words]), tutorial.name
    assert "Leibniz Universität Hannover, 2011" in header        # the thesis, cited in full
    first_code = text.split("# %%\n", 2)[1]
    assert f'Lesson("{tutorial.name}")' in first_code            # parameters come first
    assert "QUICK = lesson.quick" in first_code
    exercises = text.rsplit("## Exercises", 1)[1]
    assert 2 <= len(re.findall(r"^# \d\. ", exercises, flags=re.M)) <= 3
    assert f"solutions/{tutorial.name}_solutions.py" in exercises
    assert "input(" not in text


@pytest.mark.slow
@pytest.mark.parametrize("tutorial", TUTORIALS, ids=lambda t: t.name)
def test_tutorial_runs_headless_in_quick_mode(tutorial, tmp_path):
    results = run_script(tutorial, tmp_path)
    assert results["quick"] is True
    CHECKS[tutorial.number](results)
    pictures = list((tmp_path / "out" / tutorial.name).glob("*.png"))
    assert pictures and all(p.stat().st_size > 0 for p in pictures)
    assert (tmp_path / "out" / tutorial.name / "geometry.png").is_file()   # Γ_D, Γ_N, Γ_C, mesh


@pytest.mark.slow
@pytest.mark.parametrize("solution", SOLUTIONS, ids=lambda t: t.name)
def test_solutions_run_in_quick_mode_and_show_their_answers(solution, tmp_path):
    check_solutions(solution.number, run_script(solution, tmp_path))
    pictures = list((tmp_path / "out" / solution.name).glob("*.png"))
    assert pictures and all(p.stat().st_size > 10_000 for p in pictures), pictures


@pytest.mark.slow
def test_notebooks_execute_cleanly_with_nbconvert(tmp_path):
    """`ngdual tutorials --notebooks DIR`, then `jupyter nbconvert --execute` on every notebook."""
    import nbformat

    folder = tmp_path / "notebooks"
    assert main(["tutorials", "--notebooks", str(folder)]) == 0
    notebooks = sorted(folder.glob("*.ipynb"))
    assert [p.stem for p in notebooks] == [t.name for t in TUTORIALS]
    out = tmp_path / "out"
    command = [sys.executable, "-m", "jupyter", "nbconvert", "--to", "notebook", "--execute",
               "--ExecutePreprocessor.kernel_name=python3",
               f"--ExecutePreprocessor.startup_timeout={TIME_LIMIT_S}",
               f"--ExecutePreprocessor.timeout={TIME_LIMIT_S}",
               "--output-dir", str(tmp_path / "executed"), *map(str, notebooks)]
    result = subprocess.run(command, cwd=folder, env=quick_env(out), capture_output=True,
                            text=True, timeout=TIME_LIMIT_S * len(notebooks))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-6000:]
    for tutorial in TUTORIALS:
        executed = nbformat.read(tmp_path / "executed" / f"{tutorial.name}.ipynb", as_version=4)
        outputs = [o for cell in executed.cells for o in cell.get("outputs", [])]
        assert not [o for o in outputs if o["output_type"] == "error"], tutorial.name
        assert any("image/png" in o.get("data", {}) for o in outputs), tutorial.name
        CHECKS[tutorial.number](json.loads((out / tutorial.name / "results.json").read_text()))


def test_solution_notebooks_are_written_on_request(tmp_path, capsys):
    assert main(["tutorials", "--notebooks", str(tmp_path), "--solutions"]) == 0
    assert len(list((tmp_path / "solutions").glob("*.ipynb"))) == len(SOLUTIONS)
    assert "wrote" in capsys.readouterr().out


def test_notebook_cells_follow_the_percent_markers(tmp_path):
    import nbformat

    path = write_notebooks(tmp_path)[0]
    notebook = nbformat.read(path, as_version=4)
    kinds = [cell.cell_type for cell in notebook.cells]
    assert kinds[0] == "markdown" and "code" in kinds
    assert notebook.metadata["kernelspec"]["name"] == "python3"


def test_cli_lists_the_tutorials(capsys):
    assert main(["tutorials"]) == 0
    out = capsys.readouterr().out
    for tutorial in TUTORIALS:
        assert tutorial.title in out


def test_missing_tutorials_folder_is_a_clear_error(tmp_path, capsys):
    assert main(["tutorials", "--source", str(tmp_path / "nowhere")]) == 2
    assert "no tutorials folder" in capsys.readouterr().err


def test_quick_mode_and_source_folder_come_from_the_environment(monkeypatch, tmp_path):
    monkeypatch.delenv("NGDUAL_QUICK", raising=False)
    assert not quick_mode()
    for value, expected in (("1", True), ("yes", True), ("0", False), ("", False)):
        monkeypatch.setenv("NGDUAL_QUICK", value)
        assert quick_mode() is expected
    monkeypatch.setenv("NGDUAL_TUTORIALS_DIR", str(tmp_path))
    assert tutorials_dir() == tmp_path
    assert not in_notebook()
