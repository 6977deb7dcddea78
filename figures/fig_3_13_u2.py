"""Fig. 3.13: displacement u_2^h in Omega (piecewise constant), mu_f = 0 and mu_f = 0.5."""

import numpy as np

from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import element_field, length

THESIS = "Fig. 3.13"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    a0, a1 = (fields[p][1] for p in ("frictionless", "coulomb"))
    # WRITE, PLOT: the CSV and both problems side by side
    files = element_field(ctx, fields, "u2", length(r"$u_2^h$"),
                          "Fig. 3.13: vertical displacement $u_2^h$", "fig_3_13_u2",
                          "u_2^h per element (centroid), both problems")
    ctx.entry(THESIS, "Displacement u_2 in Omega", files,
              {"min u_2, mu_f = 0": float(a0["u2"].min()),
               "min u_2, mu_f = 0.5": float(a1["u2"].min()),
               "max |u_2(0.5) - u_2(0)|": float(np.abs(a1["u2"] - a0["u2"]).max())},
              thesis_says="the body moves down by the gap g = 0.01 and more; no visible "
                          "difference between the two cases.")


if __name__ == "__main__":
    script_main(__file__)
