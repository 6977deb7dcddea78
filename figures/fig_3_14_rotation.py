"""Fig. 3.14: rotation eta^h (the skew part of grad u, continuous P1) in Omega, both problems.

Plotted at the element centroids. The thesis: without friction eta is nearly zero on the
active part of Gamma_C (x_1 in (-1.3, 1.3)); with friction it has local extrema where the
body starts to slide; the extrema lie on the boundary.
"""

import numpy as np

from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import centroids, element_field

THESIS = "Fig. 3.14"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    a0, a1 = (fields[p][1] for p in ("frictionless", "coulomb"))
    centre = centroids(a0["points"], a0["triangles"])
    h = float(np.ptp(a0["points"][a0["triangles"][0]][:, 0]))
    # the bottom row of triangles under the central part of the contact zone
    contact_row = (centre[:, 1] < -1 + h) & (np.abs(centre[:, 0]) < 1.0)
    # WRITE, PLOT: the CSV and both problems side by side
    files = element_field(ctx, fields, "eta", r"$\eta^h$ [rad]", r"Fig. 3.14: rotation $\eta^h$",
                          "fig_3_14_rotation",
                          "rotation eta^h at the element centroids, both problems")
    ctx.entry(THESIS, "Rotation eta in Omega", files,
              {"max |eta| on the bottom row, |x_1| < 1, mu_f = 0":
                   float(np.abs(a0["eta"][contact_row]).max()),
               "max |eta| on the bottom row, |x_1| < 1, mu_f = 0.5":
                   float(np.abs(a1["eta"][contact_row]).max()),
               "max |eta| overall, mu_f = 0 / 0.5": [float(np.abs(a0["eta"]).max()),
                                                     float(np.abs(a1["eta"]).max())]},
              thesis_says="frictionless: eta nearly zero on A_C; with friction local extrema "
                          "where sliding starts; extrema on the boundaries.")


if __name__ == "__main__":
    script_main(__file__)
