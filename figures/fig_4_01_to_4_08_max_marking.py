"""Figs. 4.1-4.8: meshes of the adaptive algorithm with max marking (theta = 0.5), mu_f = 0.5.

A triangle is refined when eta_{tot,T} >= 0.5 max eta_{tot,T} (4.50), from the level-1 mesh;
the thesis shows the initial mesh and the meshes after 4, 8, ..., 28 steps. Shaded: the
triangles marked for the next refinement. One file per thesis figure (fig_4_01 ... fig_4_08).
"""

from ngdual import plot
from ngdual.studies.figures import adaptive_task, require, script_main
from ngdual.studies.figures.kit import UNITS

THESIS = "Figs. 4.1-4.8"
STUDIES = ("adaptive",)


def run(ctx):
    # COMPUTE: the adaptive run (shared with Tables 4.1 and 4.2)
    task = adaptive_task(ctx.plan, "coulomb", "max")
    run_record = require(ctx.record(task), task.label)
    arrays = ctx.arrays(task)
    steps = {r["step"]: r for r in run_record["history"]}
    # WRITE
    data = ctx.write_csv("fig_4_01_to_4_08_max_marking.csv",
                         [{"figure": f"4.{i + 1}", "step": k, "elements": steps[k]["elements"],
                           "dofs": steps[k]["dofs"]["total"], "marked": steps[k]["marked"],
                           "h_min": steps[k]["h_min"]}
                          for i, k in enumerate(ctx.plan.max_marking_snapshots)],
                         "the meshes shown in Figs. 4.1-4.8: step, triangles, DOFs, marked")
    # PLOT
    files = [data]
    for i, k in enumerate(ctx.plan.max_marking_snapshots):
        title = (f"Fig. 4.{i + 1}: max marking $\\theta = 0.5$, "
                 + ("initial mesh" if k == 0 else f"after {k} steps")
                 + f" ({steps[k]['dofs']['total']} DOFs)")
        fig = plot.plot_mesh(arrays[f"points_{k}"], arrays[f"triangles_{k}"], title,
                             arrays[f"marked_{k}"], units=UNITS)
        files += plot.save_figure(
            fig, ctx.figure_stem(f"fig_4_{i + 1:02d}_max_marking_step{k:02d}"))
    ctx.entry(THESIS, "Adaptive meshes, max marking theta = 0.5", files,
              {"steps shown": ctx.plan.max_marking_snapshots,
               "triangles / DOFs at the last step": [steps[k]["elements"],
                                                     steps[k]["dofs"]["total"]],
               "smallest h_T": steps[k]["h_min"]},
              thesis_says="too few triangles are refined even after 28 steps: only near the "
                          "corners, on Gamma_N and on the active part A_C.")


if __name__ == "__main__":
    script_main(__file__)
