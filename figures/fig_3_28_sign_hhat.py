"""Fig. 3.28: the sign nu^h of lambda_t^h for h^ = h~ (red) and h^ = 2h~ (dashed blue):
(a) g = |x_1|, (b) g of (3.125), mu_f = 0.5 (piecewise constant on the h^ edges where F > 0)."""

import numpy as np

from ngdual.studies.figures import kit, script_main

THESIS = "Fig. 3.28"
STUDIES = ("gaps",)
STYLE = {1: {"color": "tab:red", "label": r"$\hat h = \tilde h$"},
         2: {"color": "tab:blue", "ls": "--", "label": r"$\hat h = 2\tilde h$"}}


def sign(case, factor, a):
    """nu of one solution on the h^ edges where F > 0: its CSV rows and its step curve."""
    support = a["F"] > 0
    rows = [{"gap": case, "hhat_factor": factor, "x1_start": s, "x1_end": e, "nu": n}
            for s, e, n in zip(a["nu_start"][support], a["nu_end"][support], a["nu"][support])]
    xs = np.ravel(np.column_stack([a["nu_start"][support], a["nu_end"][support]]))
    return rows, {"x": xs, "y": np.repeat(a["nu"][support], 2), **STYLE[factor]}


def run(ctx):
    # COMPUTE: both gaps with h^ = h~ and h^ = 2h~ on the gap level (default solver)
    solutions = kit.hhat_solutions(ctx)
    rows, panels = kit.hhat_panels(solutions, r"$\nu^h$ [-]", sign, ylim=(-1.1, 1.1))
    numbers = {f"width of A_C (F > 0), {kit.HHAT_CASES[case][1]}, {kit.HHAT_NAMES[factor]}":
               float(np.sum(a["nu_end"][a["F"] > 0] - a["nu_start"][a["F"] > 0]))
               for case, by_factor in solutions.items()
               for factor, (_, a) in by_factor.items() if a}
    # WRITE + PLOT
    kit.hhat_figure(ctx, THESIS, "fig_3_28_sign_hhat", rows, panels,
                    title=r"sign $\nu^h$ of $\lambda_t^h$", entry="Sign nu", numbers=numbers,
                    description="nu on the h^ edges with F > 0, both gaps and both h^",
                    thesis_says="the signs agree; the width of A_C differs with the edge length.")


if __name__ == "__main__":
    script_main(__file__)
