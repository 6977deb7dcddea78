"""Fig. 3.28: the sign nu^h of lambda_t^h for h^ = h~ (red) and h^ = 2h~ (dashed blue):
(a) g = |x_1|, (b) g of (3.125), mu_f = 0.5 (piecewise constant on the h^ edges where F > 0)."""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import HHAT_CASES, hhat_numbers, hhat_solutions, length

THESIS = "Fig. 3.28"
STUDIES = ("gaps",)
STYLE = {1: {"color": "tab:red", "label": r"$\hat h = \tilde h$"},
         2: {"color": "tab:blue", "ls": "--", "label": r"$\hat h = 2\tilde h$"}}


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
            support = a["F"] > 0
            rows += [{"gap": case, "hhat_factor": factor, "x1_start": s, "x1_end": e, "nu": n}
                     for s, e, n in zip(a["nu_start"][support], a["nu_end"][support],
                                        a["nu"][support])]
            xs = np.ravel(np.column_stack([a["nu_start"][support], a["nu_end"][support]]))
            curves.append({"x": xs, "y": np.repeat(a["nu"][support], 2), **STYLE[factor]})
            numbers[f"width of A_C (F > 0), {HHAT_CASES[case][1]}, h^ = "
                    f"{'2' if factor == 2 else ''}h~"] = float(
                np.sum(a["nu_end"][support] - a["nu_start"][support]))
        panels.append({"title": HHAT_CASES[case][0], "xlabel": length(r"$x_1$ on $\Gamma_C$"),
                       "ylabel": r"$\nu^h$ [-]", "curves": curves, "note": "; ".join(notes),
                       "ylim": (-1.1, 1.1)})
    data = ctx.write_csv("fig_3_28_sign_hhat.csv", rows,
                         "nu on the h^ edges with F > 0, both gaps and both h^")
    fig = plot.plot_curves(panels, rf"Fig. 3.28: sign $\nu^h$ of $\lambda_t^h$, $\mu_f = 0.5$, "
                           rf"level {ctx.plan.gap_level}")
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_28_sign_hhat"))
    ctx.entry(THESIS, "Sign nu for h^ = h~ and h^ = 2h~", [*figs, data],
              {**numbers, **hhat_numbers(ctx)},
              thesis_says="the signs agree; the width of A_C differs with the edge length.")


if __name__ == "__main__":
    script_main(__file__)
