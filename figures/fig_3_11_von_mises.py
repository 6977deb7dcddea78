"""Fig. 3.11: plane-strain von Mises equivalent stress in Omega, mu_f = 0 and mu_f = 0.5.

sigma_0 = ((nu^2 - nu + 1)(s11^2 + s22^2) + (2nu^2 - 2nu - 1) s11 s22 + 3 s12^2)^(1/2) with
s12 the symmetrised shear stress (Section 3.4). The colour scale ends at the 99th percentile
of both fields (plot.CORNER_CLIP, stated on the colour bar): the corner singularities would
wash out the rest. The numbers give the largest values away from the corners and overall.
"""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import centroids, element_field, field_summary, stress

THESIS = "Fig. 3.11"
STUDIES = ("uniform-frictionless", "uniform-coulomb")
AWAY = 3.0  # |x_1| <= AWAY: away from the corner singularities at x_1 = +-4


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    a0, a1 = (fields[p][1] for p in ("frictionless", "coulomb"))
    away = np.abs(centroids(a0["points"], a0["triangles"])[:, 0]) <= AWAY
    numbers = {}
    for name, a in (("mu_f = 0", a0), ("mu_f = 0.5", a1)):
        s = field_summary(a["von_mises"][away], a["points"], a["triangles"][away])
        numbers[f"max sigma_0 for |x_1| <= {AWAY}, {name}"] = s["max"]
        numbers[f"  at (x_1, x_2), {name}"] = s["argmax"]
        numbers[f"max sigma_0 overall (corners), {name}"] = float(a["von_mises"].max())
    # WRITE, PLOT: the CSV and both problems side by side
    files = element_field(ctx, fields, "von_mises", stress(r"von Mises stress $\sigma_0$"),
                          "Fig. 3.11: von Mises equivalent stress (plane strain)",
                          "fig_3_11_von_mises",
                          "plane-strain von Mises stress per element (centroid), both problems",
                          clip=plot.CORNER_CLIP)
    ctx.entry(THESIS, "Von Mises equivalent stress in Omega", files, numbers,
              thesis_says="singularities in the corners; with friction the maximal value is "
                          "smaller and its zone moves to where the body slides.")


if __name__ == "__main__":
    script_main(__file__)
