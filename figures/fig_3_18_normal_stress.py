"""Fig. 3.18: normal stress sigma_n^h on Gamma_C (constant per fine edge), both problems.

Also F_abs = int_{A_C} |sigma_n| + |sigma_t| ds (the total force on the active part).
The thesis: max |sigma_n| is larger without friction, although the contact zone is larger
with friction (kinks where the body changes between slip and stick); F_abs is larger with
friction.
"""

import numpy as np

from ngdual import plot
from ngdual.figures import PROBLEM_TITLES, curve_rows, script_main

AWAY = 3.0  # |x_1| <= AWAY: the y-range leaves out the singular corners at x_1 = +-4
THESIS = "Fig. 3.18"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    # WRITE
    data = ctx.write_csv("fig_3_18_normal_stress.csv",
                         curve_rows(fields, "edge_x", ["sigma_n", "edge_active"]),
                         "sigma_n^h at the midpoints of the fine Gamma_C edges")
    # PLOT
    panels, numbers = [], {}
    # one y-range for both panels, from the values away from the corners
    span = max(float(np.abs(a["sigma_n"][np.abs(a["edge_x"]) <= AWAY]).max())
               for _, a in fields.values()) or 1.0
    for p, (record, a) in fields.items():
        order = np.argsort(a["edge_x"])
        panels.append({"title": f"{PROBLEM_TITLES[p]}, level {ctx.plan.field_level}",
                       "ylim": (-1.25 * span, 1.25 * span),
                       "note": f"corner singularities at x_1 = +-4 off scale "
                               f"(|sigma_n| up to {np.abs(a['sigma_n']).max():.3g}; see the CSV)",
                       "xlabel": r"$x_1$ on $\Gamma_C$ [length]",
                       "ylabel": r"$\sigma_n^h$ [stress units]",
                       "curves": [{"x": a["edge_x"][order], "y": a["sigma_n"][order],
                                   "drawstyle": "steps-mid", "label": r"$\sigma_n^h$"}]})
        active = a["edge_active"].astype(bool)
        numbers[f"max |sigma_n| on A_C, {PROBLEM_TITLES[p]}"] = float(
            np.abs(a["sigma_n"][active]).max())
        numbers[f"max |sigma_n| overall (corners), {PROBLEM_TITLES[p]}"] = float(
            np.abs(a["sigma_n"]).max())
        numbers[f"F_abs, {PROBLEM_TITLES[p]}"] = record["contact"]["F_abs"]
    figs = plot.plot_curves(panels, ctx.figure_stem("fig_3_18_normal_stress"),
                            r"Fig. 3.18: normal stress $\sigma_n^h$ on $\Gamma_C$")
    ctx.entry(THESIS, "Normal stress sigma_n on Gamma_C", [*figs, data], numbers,
              thesis_says="max |sigma_n| larger without friction; F_abs larger with friction "
                          "(the values are withheld in our copy of the thesis).")


if __name__ == "__main__":
    script_main(__file__)
