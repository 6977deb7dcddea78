"""Fig. 3.13: displacement u_2^h in Omega (piecewise constant), mu_f = 0 and mu_f = 0.5."""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import UNITS, element_rows, length

THESIS = "Fig. 3.13"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    a0, a1 = (fields[p][1] for p in ("frictionless", "coulomb"))
    # WRITE
    data = ctx.write_csv("fig_3_13_u2.csv", element_rows(fields, "u2"),
                         "u_2^h per element (centroid), both problems")
    # PLOT
    fig = plot.plot_field_pair(a0["points"], a0["triangles"], [a0["u2"], a1["u2"]],
                               ctx.titles(), length(r"$u_2^h$"),
                               "Fig. 3.13: vertical displacement $u_2^h$", units=UNITS)
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_13_u2"))
    ctx.entry(THESIS, "Displacement u_2 in Omega", [*figs, data],
              {"min u_2, mu_f = 0": float(a0["u2"].min()),
               "min u_2, mu_f = 0.5": float(a1["u2"].min()),
               "max |u_2(0.5) - u_2(0)|": float(np.abs(a1["u2"] - a0["u2"]).max())},
              thesis_says="the body moves down by the gap g = 0.01 and more; no visible "
                          "difference between the two cases.")


if __name__ == "__main__":
    script_main(__file__)
