"""Fig. 3.25: tangential displacement (a) and its sign nu^h (b) on Gamma_C, g = 0, h^ = 2h~.

(b) shows nu^h of the thesis' nested Uzawa with eps_2 = 1e-6 (red) and eps_2 = 1e-8 (dashed
blue), on Plan.uzawa_gap_level, and nu^h of the default (active-set) solver, which solves
the discrete problem to round-off, on the gap level (green). The thesis needed 22 872 outer
steps (3471 s) for eps_2 = 1e-8 on level 4 with its increment-based stopping rule; ours
also requires the residual of nu lambda_t = |lambda_t| to be below eps_2.
"""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import gap_tasks, outcome, require, script_main
from ngdual.studies.figures.kit import length

THESIS = "Fig. 3.25"
STUDIES = ("gaps",)


def _steps(a):
    support = a["F"] > 0
    xs = np.ravel(np.column_stack([a["nu_start"][support], a["nu_end"][support]]))
    return xs, np.repeat(a["nu"][support], 2)


def run(ctx):
    # COMPUTE: g = 0 with the default solver, and nested Uzawa with eps_2 = 1e-6 and 1e-8
    tasks = gap_tasks(ctx.plan)
    exact = require(ctx.record(tasks["gap0"]), tasks["gap0"].label)
    a = ctx.arrays(tasks["gap0"])
    uzawa = {}
    for key, eps in (("uzawa-gap0", 1e-6), ("uzawa-gap0-eps8", 1e-8)):
        record = ctx.record(tasks[key])
        ok = record is not None and record["status"] == "ok"
        uzawa[eps] = (record, ctx.arrays(tasks[key]) if ok else None)
    # WRITE
    order = np.argsort(a["node_x"])
    data = ctx.write_csv("fig_3_25_gap0_lambda_t.csv",
                         [{"x1": a["node_x"][i], "lam_t": a["lam_t"][i]} for i in order],
                         "lambda_t^h at the fine Gamma_C vertices, g = 0, h^ = 2h~")
    runs = [("default solver", tasks["gap0"], a)] + [
        (f"nested Uzawa eps_2 = {eps:g}", tasks[key], u[1])
        for (eps, u), key in zip(uzawa.items(), ("uzawa-gap0", "uzawa-gap0-eps8")) if u[1]]
    rows = [{"solver": name, "level": task.params["level"], "x1_start": s, "x1_end": e, "nu": n}
            for name, task, b in runs for s, e, n in zip(b["nu_start"], b["nu_end"], b["nu"])]
    nu_data = ctx.write_csv("fig_3_25_gap0_sign.csv", rows, "nu^h on the h^ edges, g = 0")
    # PLOT
    styles = [{"color": "tab:green", "lw": 2.5, "alpha": 0.6}, {"color": "tab:red"},
              {"color": "tab:blue", "ls": "--"}]
    curves = []
    for (name, task, b), style in zip(runs, styles):
        xs, ys = _steps(b)
        curves.append({"x": xs, "y": ys, "label": f"{name}, level {task.params['level']}",
                       **style})
    panels = [{"title": f"(a) tangential displacement, level {tasks['gap0'].params['level']}",
               "xlabel": length(r"$x_1$ on $\Gamma_C$"), "ylabel": length(r"$\lambda_t^h$"),
               "curves": [{"x": a["node_x"][order], "y": a["lam_t"][order],
                           "label": r"$\lambda_t^h$"}]},
              {"title": r"(b) sign $\nu^h$ of $\lambda_t^h$",
               "xlabel": length(r"$x_1$ on $\Gamma_C$"), "ylabel": r"$\nu^h$ [-]",
               "curves": curves, "ylim": (-1.15, 1.15)}]
    fig = plot.plot_curves(panels, r"Fig. 3.25: $g = 0$, $\hat h = 2\tilde h$, $\mu_f = 0.5$")
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_25_gap0_sign"))
    numbers = {"default solver: |nu| on the two end h^ edges": [float(abs(a["nu"][0])),
                                                                 float(abs(a["nu"][-1]))],
               "default solver": outcome(exact)}
    for eps, (record, b) in uzawa.items():
        numbers[f"nested Uzawa eps_2 = {eps:g}"] = outcome(record)
        if b is not None:
            numbers[f"nested Uzawa eps_2 = {eps:g}: |nu| on the end h^ edges"] = [
                float(abs(b["nu"][0])), float(abs(b["nu"][-1]))]
    ctx.entry(THESIS, "Tangential displacement and its sign with g = 0, h^ = 2h~",
              [*figs, data, nu_data], numbers,
              thesis_says="with eps_2 = 1e-6 nu tends to zero at the ends of Gamma_C (stopped "
                          "too early where F is small); eps_2 = 1e-8 on level 4 needed 22 872 "
                          "outer and 45 743 inner iterations, 3471 s.")


if __name__ == "__main__":
    script_main(__file__)
