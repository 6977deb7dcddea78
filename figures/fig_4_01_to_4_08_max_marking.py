"""Figs. 4.1-4.8: meshes of the adaptive algorithm with max marking (theta = 0.5), mu_f = 0.5.

A triangle is refined when eta_{tot,T} >= 0.5 max eta_{tot,T} (4.50), from the level-1 mesh;
the thesis shows the initial mesh and the meshes after 4, 8, ..., 28 steps. Shaded: the
triangles marked for the next refinement. One file per thesis figure (fig_4_01 ... fig_4_08).
"""

from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import adaptive_meshes

THESIS = "Figs. 4.1-4.8"
STUDIES = ("adaptive",)


def run(ctx):
    # COMPUTE: the adaptive run (shared with Tables 4.1 and 4.2)
    # WRITE, PLOT: the CSV of the meshes shown and one figure each
    files, steps = adaptive_meshes(ctx, "max", first=1)
    last = steps[ctx.plan.max_marking_snapshots[-1]]
    ctx.entry(THESIS, "Adaptive meshes, max marking theta = 0.5", files,
              {"steps shown": ctx.plan.max_marking_snapshots,
               "triangles / DOFs at the last step": [last["elements"], last["dofs"]["total"]],
               "smallest h_T": last["h_min"]},
              thesis_says="too few triangles are refined even after 28 steps: only near the "
                          "corners, on Gamma_N and on the active part A_C.")


if __name__ == "__main__":
    script_main(__file__)
