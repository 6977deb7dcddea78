"""Fig. 3.12: displacement u_1^h in Omega (piecewise constant), mu_f = 0 and mu_f = 0.5."""

import numpy as np

from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import centroids, element_field, length

THESIS = "Fig. 3.12"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    a0, a1 = (fields[p][1] for p in ("frictionless", "coulomb"))
    diff = np.abs(a1["u1"] - a0["u1"])
    k = int(np.argmax(diff))
    # WRITE, PLOT: the CSV and both problems side by side
    files = element_field(ctx, fields, "u1", length(r"$u_1^h$"),
                          "Fig. 3.12: horizontal displacement $u_1^h$", "fig_3_12_u1",
                          "u_1^h per element (centroid), both problems")
    ctx.entry(THESIS, "Displacement u_1 in Omega", files,
              {"range u_1, mu_f = 0": [float(a0["u1"].min()), float(a0["u1"].max())],
               "range u_1, mu_f = 0.5": [float(a1["u1"].min()), float(a1["u1"].max())],
               "max |u_1(0.5) - u_1(0)|": float(diff[k]),
               "  at (x_1, x_2)": [round(float(c), 3)
                                   for c in centroids(a0["points"], a0["triangles"])[k]]},
              thesis_says="the only difference between the two cases is at the contact "
                          "boundary, in u_1 (the tangential direction on Gamma_C).")


if __name__ == "__main__":
    script_main(__file__)
