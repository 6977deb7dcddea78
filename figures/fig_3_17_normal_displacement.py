"""Fig. 3.17: lambda_n^h - g on Gamma_C (= u_2 there: lambda_n = g - u_n), both problems.

Red triangles: the h~ nodes in contact (lambda_n = 0). The thesis: the curves look equal,
but with friction the contact zone is larger (ten more vertices in contact on level 8).
"""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import PROBLEM_TITLES, script_main
from ngdual.studies.figures.kit import curve_rows, length

THESIS = "Fig. 3.17"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    # WRITE
    rows = curve_rows(fields, "node_x", ["lam_n", "gap"])
    for r in rows:
        r["lam_n_minus_g"] = r["lam_n"] - r["gap"]
    data = ctx.write_csv("fig_3_17_normal_displacement.csv", rows,
                         "lambda_n^h (fine vertices of Gamma_C), g and lambda_n - g")
    contact = ctx.write_csv("fig_3_17_contact_nodes.csv",
                            curve_rows(fields, "coarse_x", ["in_contact"], "in_contact"),
                            "the h~ nodes in contact (lambda_n = 0)")
    # PLOT
    panels, numbers = [], {}
    for p, (_, a) in fields.items():
        order = np.argsort(a["node_x"])
        x, y = a["node_x"][order], (a["lam_n"] - a["gap"])[order]
        xc = a["coarse_x"][a["in_contact"]]
        panels.append({"title": f"{PROBLEM_TITLES[p]}, level {ctx.plan.field_level}",
                       "xlabel": length(r"$x_1$ on $\Gamma_C$"),
                       "ylabel": length(r"$\lambda_n^h - g$"),
                       "curves": [{"x": x, "y": y, "label": r"$\lambda_n^h - g$"},
                                  {"x": xc, "y": np.interp(xc, x, y), "ls": "none",
                                   "marker": "v", "color": "red", "ms": 4,
                                   "label": r"$\tilde h$-node in contact"}],
                       "hlines": [(-a["gap"].max(), "foundation $-g$",
                                   {"color": "k", "ls": ":", "lw": 1})]})
        numbers[f"nodes in contact, {PROBLEM_TITLES[p]}"] = int(a["in_contact"].sum())
        if len(xc):
            numbers[f"contact zone (h~ nodes), {PROBLEM_TITLES[p]}"] = [float(xc.min()),
                                                                        float(xc.max())]
    fig = plot.plot_curves(panels,
                           r"Fig. 3.17: normal displacement $\lambda_n^h - g$ on $\Gamma_C$")
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_17_normal_displacement"))
    ctx.entry(THESIS, "Normal displacement lambda_n - g on Gamma_C", [*figs, data, contact],
              numbers, thesis_says="frictional case: ten more vertices in contact than "
              "frictionless on the finest level (level 8); active zone about x_1 in (-1.3, 1.3).")


if __name__ == "__main__":
    script_main(__file__)
