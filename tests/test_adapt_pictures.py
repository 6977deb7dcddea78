"""`ngdual adapt` writes its pictures by default: the convergence plot and the final mesh's
traces, von Mises stress, deformed body and mesh; its columns say what they are."""

import json

from ngdual.cli import main

PNG = b"\x89PNG\r\n\x1a\n"


def test_adapt_to_a_tolerance_writes_the_convergence_plot_and_the_final_pictures(tmp_path,
                                                                                 capsys):
    status = main(["adapt", "hertz-cylinder", "--level", "1", "--tol", "0.12", "--out",
                   str(tmp_path)])
    out = capsys.readouterr().out
    assert status == 0
    assert "estimate (stress, absolute)" in out and "stress (relative)" in out
    for name in ("convergence.png", "final_mesh.png", "final_von_mises.png",
                 "final_deformed.png", "final_contact_traces.png"):
        data = (tmp_path / name).read_bytes()
        assert data.startswith(PNG) and len(data) > 20_000, name
    history = json.loads((tmp_path / "history.json").read_text())["history"]
    assert history[-1]["relative_estimate"] <= 0.12 < history[0]["relative_estimate"]


def test_the_convergence_plot_has_the_tolerance_line_and_both_axes():
    from ngdual.plot import plot_convergence

    history = [{"dofs": {"total": n}, "relative_estimate": 1 / n, "goal_estimate": 2 / n,
                "goal": "stress", "elapsed_s": n / 1000, "e_tot": 1.5 / n}
               for n in (100, 400, 1600)]
    fig = plot_convergence(history, tol=0.002)
    labels = [[line.get_label() for line in ax.get_lines()] for ax in fig.axes]
    assert all("tolerance 0.002" in names for names in labels)
    assert all(any("true error" in name for name in names) for names in labels)
    assert fig.axes[1].get_lines()[0].get_xdata().tolist() == [0.1, 0.4, 1.6]


def test_a_step_without_a_finite_estimate_is_left_out_and_said():
    from ngdual.plot import figure_texts, plot_convergence

    history = [{"dofs": {"total": 100}, "relative_estimate": float("inf"),
                "goal_estimate": 1.0, "goal": "pressure", "elapsed_s": 0.5}]
    fig = plot_convergence(history)
    assert "without a finite estimate" in fig.axes[0].texts[0].get_text()
    assert figure_texts(fig)["axes"][0]["xlabel"] == "unknowns (all fields)"
