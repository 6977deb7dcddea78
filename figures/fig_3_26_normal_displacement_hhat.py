"""Fig. 3.26: lambda_n^h - g on Gamma_C for h^ = h~ (dashed red) and h^ = 2h~ (green), with the
rigid foundation -g (dashed blue): (a) g = |x_1|, (b) g of (3.125), mu_f = 0.5.

lambda_n - g = u_2 on Gamma_C, so the curves show where the bottom of the body goes; they
touch the foundation where the body is in contact. Top: all of it (near the ends lambda_n
falls to 0, where the multiplier space C_h~ prescribes it); bottom: zoomed. The solutions
are those of the default solver; how the thesis' nested Uzawa fares on each case (on
Plan.uzawa_gap_level) is listed in the index. A case that did not converge is named in the panel.
"""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import HHAT_CASES, HHAT_STYLE, hhat_numbers, hhat_solutions, length

THESIS = "Fig. 3.26"
STUDIES = ("gaps",)


def run(ctx):
    # COMPUTE: both gaps with h^ = h~ and h^ = 2h~ on the gap level (default solver)
    solutions = hhat_solutions(ctx)
    # WRITE + PLOT
    rows, panels, lows = [], [], []
    for case, by_factor in solutions.items():
        curves, notes = [], []
        for factor, (record, a) in by_factor.items():
            if not a:
                notes.append(f"h^ = {'2' if factor == 2 else ''}h~: "
                             f"{(record or {}).get('status', 'missing')}")
                continue
            order = np.argsort(a["node_x"])
            x, y = a["node_x"][order], (a["lam_n"] - a["gap"])[order]
            rows += [{"gap": case, "hhat_factor": factor, "x1": xi, "lam_n_minus_g": yi,
                      "gap_value": gi} for xi, yi, gi in zip(x, y, a["gap"][order])]
            curves.append({"x": x, "y": y, **HHAT_STYLE[factor]})
            foundation = (x, -a["gap"][order])
        if curves:
            curves.append({"x": foundation[0], "y": foundation[1], "color": "tab:blue",
                           "ls": ":", "label": "rigid foundation $-g$"})
        panels.append({"title": HHAT_CASES[case][0], "xlabel": length(r"$x_1$ on $\Gamma_C$"),
                       "ylabel": length(r"$\lambda_n^h - g$"), "curves": curves,
                       "note": "; ".join(notes)})
        # the displacements away from the ends, where lambda_n = 0 is prescribed (C_h~ of (3.61))
        lows.append(min((c["y"][np.abs(c["x"]) <= 3].min() for c in curves[:-1]), default=-0.01))
    # second row: the same, zoomed to the displacements (the foundation dips out of view)
    for panel, low in zip(list(panels), lows):
        panels.append({**panel, "title": panel["title"] + " (zoom)",
                       "ylim": (1.6 * low, -0.4 * low)})
    data = ctx.write_csv("fig_3_26_normal_displacement_hhat.csv", rows,
                         "lambda_n - g and g on Gamma_C for both gaps and both h^")
    fig = plot.plot_curves(panels, rf"Fig. 3.26: normal displacement, $\mu_f = 0.5$, level "
                           rf"{ctx.plan.gap_level}")
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_26_normal_displacement_hhat"))
    ctx.entry(THESIS, "Normal displacement for h^ = h~ and h^ = 2h~", [*figs, data],
              hhat_numbers(ctx),
              thesis_says="the normal displacements for the two h^ fit very well.")


if __name__ == "__main__":
    script_main(__file__)
