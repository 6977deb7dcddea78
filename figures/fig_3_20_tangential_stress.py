"""Fig. 3.20: tangential stress sigma_t^h on Gamma_C (constant per fine edge), both problems.

The thesis: zero without friction (free sliding); with friction the friction forces act
tangentially, with the sign of lambda_t.
"""

import numpy as np

from ngdual import plot
from ngdual.figures import PROBLEM_TITLES, curve_rows, script_main

AWAY = 3.0  # |x_1| <= AWAY: the y-range leaves out the singular corners at x_1 = +-4
THESIS = "Fig. 3.20"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    # WRITE
    data = ctx.write_csv("fig_3_20_tangential_stress.csv",
                         curve_rows(fields, "edge_x", ["sigma_t", "edge_active"]),
                         "sigma_t^h at the midpoints of the fine Gamma_C edges")
    # PLOT
    panels, numbers = [], {}
    # one y-range for both panels, from the values away from the corners
    span = max(float(np.abs(a["sigma_t"][np.abs(a["edge_x"]) <= AWAY]).max())
               for _, a in fields.values()) or 1.0
    for p, (_, a) in fields.items():
        order = np.argsort(a["edge_x"])
        panels.append({"title": f"{PROBLEM_TITLES[p]}, level {ctx.plan.field_level}",
                       "ylim": (-1.25 * span, 1.25 * span),
                       "note": f"corner singularities at x_1 = +-4 off scale "
                               f"(|sigma_t| up to {np.abs(a['sigma_t']).max():.3g}; see the CSV)",
                       "xlabel": r"$x_1$ on $\Gamma_C$ [length]",
                       "ylabel": r"$\sigma_t^h$ [stress units]",
                       "curves": [{"x": a["edge_x"][order], "y": a["sigma_t"][order],
                                   "drawstyle": "steps-mid", "label": r"$\sigma_t^h$"}]})
        active = a["edge_active"].astype(bool)
        numbers[f"max |sigma_t| on A_C, {PROBLEM_TITLES[p]}"] = float(
            np.abs(a["sigma_t"][active]).max())
        numbers[f"max |sigma_t| overall (corners), {PROBLEM_TITLES[p]}"] = float(
            np.abs(a["sigma_t"]).max())
    figs = plot.plot_curves(panels, ctx.figure_stem("fig_3_20_tangential_stress"),
                            r"Fig. 3.20: tangential stress $\sigma_t^h$ on $\Gamma_C$")
    ctx.entry(THESIS, "Tangential stress sigma_t on Gamma_C", [*figs, data], numbers,
              thesis_says="sigma_t = 0 without friction; friction forces with friction.")


if __name__ == "__main__":
    script_main(__file__)
