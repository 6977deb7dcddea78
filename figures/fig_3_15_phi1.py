"""Fig. 3.15: phi_1^h on Gamma_N (coarse h~ P1 multiplier, phi = -u on Gamma_N), both problems.

The thesis: no difference between the two cases (same traction t_0); by Theorem 3.10 the
sign of phi is opposite to that of u on Gamma_N.
"""

import numpy as np

from ngdual import plot
from ngdual.figures import PROBLEM_TITLES, curve_rows, script_main

THESIS = "Fig. 3.15"
STUDIES = ("uniform-frictionless", "uniform-coulomb")
STYLE = {"frictionless": {"color": "tab:blue"}, "coulomb": {"color": "tab:red", "ls": "--"}}


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    a0, a1 = (fields[p][1] for p in ("frictionless", "coulomb"))
    # WRITE
    data = ctx.write_csv("fig_3_15_phi1.csv", curve_rows(fields, "phi_x", ["phi1"]),
                         "phi_1^h at the fine vertices of Gamma_N (x_2 = 1), both problems")
    # PLOT
    panels = [{"title": f"{PROBLEM_TITLES[p]}, level {ctx.plan.field_level}",
               "xlabel": r"$x_1$ on $\Gamma_N$ [length]", "ylabel": r"$\varphi_1^h$ [length]",
               "curves": [{"x": a["phi_x"], "y": a["phi1"], "label": PROBLEM_TITLES[p],
                           **STYLE[p]}]}
              for p, (_, a) in fields.items()]
    figs = plot.plot_curves(panels, ctx.figure_stem("fig_3_15_phi1"),
                            r"Fig. 3.15: $\varphi_1^h$ on the Neumann boundary $\Gamma_N$")
    ctx.entry(THESIS, "phi_1 on Gamma_N", [*figs, data],
              {"range phi_1, mu_f = 0": [float(a0["phi1"].min()), float(a0["phi1"].max())],
               "range phi_1, mu_f = 0.5": [float(a1["phi1"].min()), float(a1["phi1"].max())],
               "max |phi_1(0.5) - phi_1(0)|": float(np.abs(a1["phi1"] - a0["phi1"]).max())},
              thesis_says="no difference between the frictionless and the frictional case.")


if __name__ == "__main__":
    script_main(__file__)
