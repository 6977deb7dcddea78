"""Figs. 4.9-4.13: meshes of the adaptive algorithm with fraction marking (theta = 0.2), mu_f = 0.5.

The 20 % of the triangles with the largest eta_{tot,T} (4.50) are refined, from the level-2
mesh; the thesis shows the meshes after 1, 3, 5, 7 and 9 steps. Shaded: the triangles marked
for the next refinement. One file per thesis figure (fig_4_09 ... fig_4_13).
"""

from ngdual import plot
from ngdual.studies.figures import adaptive_task, require, script_main
from ngdual.studies.figures.kit import UNITS

THESIS = "Figs. 4.9-4.13"
STUDIES = ("adaptive",)


def run(ctx):
    # COMPUTE: the adaptive run (shared with Tables 4.3 and 4.4)
    task = adaptive_task(ctx.plan, "coulomb", "fraction")
    run_record = require(ctx.record(task), task.label)
    arrays = ctx.arrays(task)
    steps = {r["step"]: r for r in run_record["history"]}
    # WRITE
    data = ctx.write_csv("fig_4_09_to_4_13_fraction_marking.csv",
                         [{"figure": f"4.{i + 9}", "step": k, "elements": steps[k]["elements"],
                           "dofs": steps[k]["dofs"]["total"], "marked": steps[k]["marked"],
                           "h_min": steps[k]["h_min"]}
                          for i, k in enumerate(ctx.plan.fraction_snapshots)],
                         "the meshes shown in Figs. 4.9-4.13: step, triangles, DOFs, marked")
    # PLOT
    files = [data]
    for i, k in enumerate(ctx.plan.fraction_snapshots):
        title = (f"Fig. 4.{i + 9}: fraction marking $\\theta = 0.2$, after {k} "
                 f"step{'s' if k > 1 else ''} ({steps[k]['dofs']['total']} DOFs)")
        fig = plot.plot_mesh(arrays[f"points_{k}"], arrays[f"triangles_{k}"], title,
                             arrays[f"marked_{k}"], units=UNITS)
        files += plot.save_figure(
            fig, ctx.figure_stem(f"fig_4_{i + 9:02d}_fraction_marking_step{k:02d}"))
    last = ctx.plan.fraction_snapshots[-1]
    ctx.entry(THESIS, "Adaptive meshes, fraction marking theta = 0.2", files,
              {"steps shown": ctx.plan.fraction_snapshots,
               "triangles / DOFs at the last step shown": [steps[last]["elements"],
                                                           steps[last]["dofs"]["total"]]},
              thesis_says="starting from a finer mesh, the algorithm also refines inside the "
                          "domain; local refinement on the active part A_C.")


if __name__ == "__main__":
    script_main(__file__)
