"""Fig. 3.19: tangential displacement lambda_t^h on Gamma_C (lambda_t = -u_t), both problems.

With friction, the h~ nodes in contact are marked stick (green) or slip (red) as in
:func:`ngdual.trace.friction_diagnostics`. The thesis: a sticking zone around x_1 in (-0.5, 0.5).
"""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import PROBLEM_TITLES, script_main
from ngdual.studies.figures.kit import curve_rows, length

THESIS = "Fig. 3.19"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    # WRITE
    data = ctx.write_csv("fig_3_19_tangential_displacement.csv",
                         curve_rows(fields, "node_x", ["lam_t"]),
                         "lambda_t^h at the fine vertices of Gamma_C")
    status = ctx.write_csv("fig_3_19_stick_slip.csv",
                           curve_rows({"coulomb": fields["coulomb"]}, "hat_node_x",
                                      ["node_status", "hat_ratio"]),
                           "h~ nodes, mu_f = 0.5: 0 separation, 1 stick, 2 slip")
    # PLOT
    panels, numbers = [], {}
    for p, (record, a) in fields.items():
        order = np.argsort(a["node_x"])
        x, y = a["node_x"][order], a["lam_t"][order]
        curves = [{"x": x, "y": y, "label": r"$\lambda_t^h$"}]
        if "node_status" in a:
            for code, name, colour in ((1, "stick", "green"), (2, "slip", "red")):
                xs = a["hat_node_x"][a["node_status"] == code]
                curves.append({"x": xs, "y": np.interp(xs, x, y), "ls": "none", "marker": "o",
                               "ms": 3, "color": colour, "label": f"{name} node"})
                if code == 1 and len(xs):
                    numbers["stick zone (h~ nodes), mu_f = 0.5"] = [float(xs.min()),
                                                                    float(xs.max())]
            numbers["stick / slip nodes, mu_f = 0.5"] = [record["contact"]["stick_nodes"],
                                                         record["contact"]["slip_nodes"]]
        panels.append({"title": f"{PROBLEM_TITLES[p]}, level {ctx.plan.field_level}",
                       "xlabel": length(r"$x_1$ on $\Gamma_C$"),
                       "ylabel": length(r"$\lambda_t^h$"), "curves": curves})
    fig = plot.plot_curves(panels,
                           r"Fig. 3.19: tangential displacement $\lambda_t^h$ on $\Gamma_C$")
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_19_tangential_displacement"))
    ctx.entry(THESIS, "Tangential displacement lambda_t on Gamma_C", [*figs, data, status],
              numbers, thesis_says="with friction a sticking zone around x_1 in (-0.5, 0.5).")


if __name__ == "__main__":
    script_main(__file__)
