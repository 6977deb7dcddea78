"""Fig. 3.27: lambda_t^h on Gamma_C for h^ = h~ (dashed red) and h^ = 2h~ (green):
(a) g = |x_1|, (b) g of (3.125), mu_f = 0.5."""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import HHAT_CASES, HHAT_STYLE, hhat_numbers, hhat_solutions, length

THESIS = "Fig. 3.27"
STUDIES = ("gaps",)


def run(ctx):
    # COMPUTE: both gaps with h^ = h~ and h^ = 2h~ on the gap level (default solver)
    solutions = hhat_solutions(ctx)
    # WRITE + PLOT
    rows, panels, numbers = [], [], {}
    for case, by_factor in solutions.items():
        curves, notes = [], []
        for factor, (record, a) in by_factor.items():
            if not a:
                notes.append(f"h^ = {'2' if factor == 2 else ''}h~: "
                             f"{(record or {}).get('status', 'missing')}")
                continue
            order = np.argsort(a["node_x"])
            rows += [{"gap": case, "hhat_factor": factor, "x1": a["node_x"][i],
                      "lam_t": a["lam_t"][i]} for i in order]
            curves.append({"x": a["node_x"][order], "y": a["lam_t"][order], **HHAT_STYLE[factor]})
        if all(by_factor[f][1] for f in (1, 2)):
            t1, t2 = by_factor[1][1]["lam_t"], by_factor[2][1]["lam_t"]
            numbers[f"max |lam_t(h~) - lam_t(2h~)| / max |lam_t|, {HHAT_CASES[case][1]}"] = (
                float(np.abs(t1 - t2).max() / max(np.abs(t2).max(), 1e-300)))
        panels.append({"title": HHAT_CASES[case][0], "xlabel": length(r"$x_1$ on $\Gamma_C$"),
                       "ylabel": length(r"$\lambda_t^h$"), "curves": curves,
                       "note": "; ".join(notes)})
    data = ctx.write_csv("fig_3_27_tangential_displacement_hhat.csv", rows,
                         "lambda_t on Gamma_C for both gaps and both h^")
    fig = plot.plot_curves(panels, rf"Fig. 3.27: tangential displacement, $\mu_f = 0.5$, level "
                           rf"{ctx.plan.gap_level}")
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_27_tangential_displacement_hhat"))
    ctx.entry(THESIS, "Tangential displacement for h^ = h~ and h^ = 2h~", [*figs, data],
              {**numbers, **hhat_numbers(ctx)},
              thesis_says="(a) fits very well; (b) a bit different (complex gap, eps_2 = 1e-6).")


if __name__ == "__main__":
    script_main(__file__)
