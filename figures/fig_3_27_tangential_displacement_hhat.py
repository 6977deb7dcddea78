"""Fig. 3.27: lambda_t^h on Gamma_C for h^ = h~ (dashed red) and h^ = 2h~ (green):
(a) g = |x_1|, (b) g of (3.125), mu_f = 0.5."""

import numpy as np

from ngdual.studies.figures import kit, script_main

THESIS = "Fig. 3.27"
STUDIES = ("gaps",)


def tangential_displacement(case, factor, a):
    """lambda_t of one solution along Gamma_C: its CSV rows and its curve."""
    order = np.argsort(a["node_x"])
    rows = [{"gap": case, "hhat_factor": factor, "x1": a["node_x"][i], "lam_t": a["lam_t"][i]}
            for i in order]
    return rows, {"x": a["node_x"][order], "y": a["lam_t"][order], **kit.HHAT_STYLE[factor]}


def run(ctx):
    # COMPUTE: both gaps with h^ = h~ and h^ = 2h~ on the gap level (default solver)
    solutions = kit.hhat_solutions(ctx)
    rows, panels = kit.hhat_panels(solutions, kit.length(r"$\lambda_t^h$"), tangential_displacement)
    numbers = {}
    for case, by_factor in solutions.items():
        if all(arrays for _, arrays in by_factor.values()):
            t1, t2 = by_factor[1][1]["lam_t"], by_factor[2][1]["lam_t"]
            numbers[f"max |lam_t(h~) - lam_t(2h~)| / max |lam_t|, {kit.HHAT_CASES[case][1]}"] = (
                float(np.abs(t1 - t2).max() / max(np.abs(t2).max(), 1e-300)))
    # WRITE + PLOT
    kit.hhat_figure(ctx, THESIS, "fig_3_27_tangential_displacement_hhat", rows, panels,
                    title="tangential displacement", entry="Tangential displacement",
                    description="lambda_t on Gamma_C for both gaps and both h^", numbers=numbers,
                    thesis_says="(a) fits very well; (b) a bit different (complex gap, "
                                "eps_2 = 1e-6).")


if __name__ == "__main__":
    script_main(__file__)
