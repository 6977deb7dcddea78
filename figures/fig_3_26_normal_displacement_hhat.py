"""Fig. 3.26: lambda_n^h - g on Gamma_C for h^ = h~ (dashed red) and h^ = 2h~ (green), with the
rigid foundation -g (dashed blue): (a) g = |x_1|, (b) g of (3.125), mu_f = 0.5.

lambda_n - g = u_2 on Gamma_C, so the curves show where the bottom of the body goes; they
touch the foundation where the body is in contact. Top: all of it (near the ends lambda_n
falls to 0, where the multiplier space C_h~ prescribes it); bottom: zoomed. The solutions
are those of the default solver; how the thesis' nested Uzawa fares on each case (on
Plan.uzawa_gap_level) is listed in the index. A case that did not converge is named in the panel.
"""

import numpy as np

from ngdual.studies.figures import kit, script_main

THESIS = "Fig. 3.26"
STUDIES = ("gaps",)


def normal_displacement(case, factor, a):
    """lambda_n - g of one solution, with g, along Gamma_C: its CSV rows and its curve."""
    order = np.argsort(a["node_x"])
    x, y = a["node_x"][order], (a["lam_n"] - a["gap"])[order]
    rows = [{"gap": case, "hhat_factor": factor, "x1": xi, "lam_n_minus_g": yi, "gap_value": gi}
            for xi, yi, gi in zip(x, y, a["gap"][order])]
    return rows, {"x": x, "y": y, **kit.HHAT_STYLE[factor]}


def run(ctx):
    # COMPUTE: both gaps with h^ = h~ and h^ = 2h~ on the gap level (default solver)
    solutions = kit.hhat_solutions(ctx)
    rows, panels = kit.hhat_panels(solutions, kit.length(r"$\lambda_n^h - g$"), normal_displacement)
    # the displacements away from the ends, where lambda_n = 0 is prescribed (C_h~ of (3.61))
    lows = [min((c["y"][np.abs(c["x"]) <= 3].min() for c in panel["curves"]), default=-0.01)
            for panel in panels]
    for panel, by_factor in zip(panels, solutions.values()):
        solved = [a for _, a in by_factor.values() if a]
        if solved:
            a = solved[-1]
            order = np.argsort(a["node_x"])
            panel["curves"].append({"x": a["node_x"][order], "y": -a["gap"][order],
                                    "color": "tab:blue", "ls": ":",
                                    "label": "rigid foundation $-g$"})
    # second row: the same, zoomed to the displacements (the foundation dips out of view)
    for panel, low in zip(list(panels), lows):
        panels.append({**panel, "title": panel["title"] + " (zoom)",
                       "ylim": (1.6 * low, -0.4 * low)})
    # WRITE + PLOT
    kit.hhat_figure(ctx, THESIS, "fig_3_26_normal_displacement_hhat", rows, panels,
                    title="normal displacement", entry="Normal displacement",
                    description="lambda_n - g and g on Gamma_C for both gaps and both h^",
                    thesis_says="the normal displacements for the two h^ fit very well.")


if __name__ == "__main__":
    script_main(__file__)
