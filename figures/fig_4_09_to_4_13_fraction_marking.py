"""Figs. 4.9-4.13: meshes of the adaptive algorithm with fraction marking (theta = 0.2), mu_f = 0.5.

The 20 % of the triangles with the largest eta_{tot,T} (4.50) are refined, from the level-2
mesh; the thesis shows the meshes after 1, 3, 5, 7 and 9 steps. Shaded: the triangles marked
for the next refinement. One file per thesis figure (fig_4_09 ... fig_4_13).
"""

from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import adaptive_meshes

THESIS = "Figs. 4.9-4.13"
STUDIES = ("adaptive",)


def run(ctx):
    # COMPUTE: the adaptive run (shared with Tables 4.3 and 4.4)
    # WRITE, PLOT: the CSV of the meshes shown and one figure each
    files, steps = adaptive_meshes(ctx, "fraction", first=9)
    last = steps[ctx.plan.fraction_snapshots[-1]]
    ctx.entry(THESIS, "Adaptive meshes, fraction marking theta = 0.2", files,
              {"steps shown": ctx.plan.fraction_snapshots,
               "triangles / DOFs at the last step shown": [last["elements"],
                                                           last["dofs"]["total"]]},
              thesis_says="starting from a finer mesh, the algorithm also refines inside the "
                          "domain; local refinement on the active part A_C.")


if __name__ == "__main__":
    script_main(__file__)
