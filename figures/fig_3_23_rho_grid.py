"""Fig. 3.23: outer (a) and total inner (b) iterations of the Coulomb problem over (rho_1, rho_2).

On the level Plan.rho_level (the thesis: the 4th level). Blue: few iterations, red: many;
crossed cells did not converge (ConvergenceError or max_iter).
"""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import best, rho_tasks, script_main

THESIS = "Fig. 3.23"
STUDIES = ("rho-coulomb",)


def run(ctx):
    # COMPUTE: the (rho_1, rho_2) grid on the level of the figure
    plan = ctx.plan
    tasks = {(r1, r2): t for (lv, r1, r2), t in rho_tasks(plan)["coulomb"].items()
             if lv == plan.rho_level}
    records = dict(zip(tasks, ctx.compute(list(tasks.values()))))
    grids = {k: np.full((len(plan.rho1_grid), len(plan.rho2_grid)), np.nan)
             for k in ("outer", "inner")}
    rows = []
    for i, r1 in enumerate(plan.rho1_grid):
        for j, r2 in enumerate(plan.rho2_grid):
            r = records[(r1, r2)]
            ok = r is not None and r["status"] == "ok"
            for k in grids:
                grids[k][i, j] = r["iterations"][k] if ok else np.nan
            rows.append({"rho1": r1, "rho2": r2, "status": r["status"] if r else "missing",
                         "outer": grids["outer"][i, j], "inner": grids["inner"][i, j],
                         "solve_s": r["timings_s"]["solve"] if ok else None,
                         "message": (r or {}).get("message", "")[:200]})
    # WRITE
    data = ctx.write_csv("fig_3_23_rho_grid.csv", rows,
                         f"nested Uzawa iterations over (rho_1, rho_2), level {plan.rho_level}")
    # PLOT
    fig = plot.plot_heatmaps(plan.rho1_grid, plan.rho2_grid, [grids["outer"], grids["inner"]],
                             ["(a) outer iterations", "(b) inner iterations (total)"],
                             r"$\rho_1$ [-]", r"$\rho_2$ (relative to the stability bound) [-]",
                             ["outer iterations [count]", "inner iterations [count]"],
                             rf"Fig. 3.23: Coulomb $\mu_f = 0.5$, level {plan.rho_level}")
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_23_rho_grid"))
    opt = best(records)
    ctx.entry(THESIS, "Iteration numbers over (rho_1, rho_2)", [*figs, data],
              {"optimal (rho_1, rho_2)": opt,
               "outer / inner there": [records[opt]["iterations"]["outer"],
                                       records[opt]["iterations"]["inner"]] if opt else None,
               "outer / inner at (1, 1)": [records[(1.0, 1.0)]["iterations"]["outer"],
                                           records[(1.0, 1.0)]["iterations"]["inner"]]
               if (1.0, 1.0) in records and records[(1.0, 1.0)] else None,
               "did not converge": sum(1 for r in rows if r["status"] != "ok")},
              thesis_says="the number of outer iterations depends mostly on rho_2, the inner "
                          "ones on both; blue (few) to red (many).")


if __name__ == "__main__":
    script_main(__file__)
