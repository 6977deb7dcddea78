"""Fig. 3.21: |sigma_t^h| / |sigma_n^h| on A_C (a) and the sign nu^h of lambda_t^h (b), mu_f = 0.5.

(a) per fine active edge (pointwise, not enforced by the discrete problem), and per h~ node
in contact mu_f |int sigma_t mu_i| / int F mu_i: the discrete Coulomb condition of (3.62)
(Proposition 3.25), at most mu_f. F of (3.123) is a mean of |sigma_n| over an h^ edge, so
where the contact zone ends inside an h^ edge the pointwise ratio may exceed mu_f.
(b) nu^h, piecewise constant on the h^ edges where F > 0; |nu| < 1 where the body
sticks (the thesis: nu = sigma_t / (mu_f |sigma_n|) on all of A_C, Remark 3.15).
"""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import length

THESIS = "Fig. 3.21"
STUDIES = ("uniform-coulomb",)
MU_F = 0.5


def run(ctx):
    # COMPUTE: the Coulomb solve on the field level (shared with Table 3.2)
    record, a = ctx.both_fields()["coulomb"]
    active = a["edge_active"].astype(bool)
    ratio = np.abs(a["sigma_t"]) / np.maximum(np.abs(a["sigma_n"]), np.finfo(float).tiny)
    in_contact = a["node_status"] > 0
    contact_x = a["hat_node_x"][in_contact]
    both = active & (a["edge_x"] > contact_x.min()) & (a["edge_x"] < contact_x.max()) \
        if in_contact.any() else np.zeros_like(active)
    support = a["F"] > 0
    # WRITE
    rows = [{"what": "fine edge", "x1": x, "ratio": r} for x, r in zip(a["edge_x"][active],
                                                                      ratio[active])]
    discrete = MU_F * a["bound_ratio"]
    rows += [{"what": "h~ node: mu_f |int sigma_t mu_i| / int F mu_i", "x1": x, "ratio": r}
             for x, r in zip(a["hat_node_x"][in_contact], discrete[in_contact])]
    data = ctx.write_csv("fig_3_21a_traction_ratio.csv", rows,
                         "|sigma_t| / |sigma_n| on the active part A_C, mu_f = 0.5")
    nu_data = ctx.write_csv("fig_3_21b_sign.csv",
                            [{"x1_start": s, "x1_end": e, "nu": n, "F": f, "status": st}
                             for s, e, n, f, st in zip(a["nu_start"], a["nu_end"], a["nu"],
                                                       a["F"], a["nu_status"])],
                            "nu^h on the h^ edges (status 0 free, 1 stick, 2 slip), F per edge")
    # PLOT
    order = np.argsort(a["edge_x"][active])
    xs = np.ravel(np.column_stack([a["nu_start"][support], a["nu_end"][support]]))
    ys = np.repeat(a["nu"][support], 2)
    panels = [
        {"title": r"(a) $|\sigma_t^h| / |\sigma_n^h|$ on $A_C$",
         "xlabel": length(r"$x_1$ on $\Gamma_C$"), "ylabel": "traction ratio [-]",
         "curves": [{"x": a["edge_x"][active][order], "y": ratio[active][order],
                     "marker": ".", "label": "per fine edge"},
                    {"x": a["hat_node_x"][in_contact], "y": discrete[in_contact],
                     "ls": "none", "marker": "s", "ms": 4,
                     "label": r"$\mu_f |\int\sigma_t\mu_i| / \int F\mu_i$ per $\tilde h$ node"}],
         "hlines": [(MU_F, r"$\mu_f = 0.5$", {"color": "k", "ls": "--", "lw": 1})]},
        {"title": r"(b) sign $\nu^h$ of $\lambda_t^h$ on $A_C$ ($\hat h$ edges)",
         "xlabel": length(r"$x_1$ on $\Gamma_C$"), "ylabel": r"$\nu^h$ [-]",
         "curves": [{"x": xs, "y": ys, "color": "tab:red", "label": r"$\nu^h$"}],
         "ylim": (-1.1, 1.1)},
    ]
    fig = plot.plot_curves(panels, rf"Fig. 3.21: Coulomb friction $\mu_f = 0.5$, level "
                           rf"{ctx.plan.field_level}")
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_21_friction_ratio_and_sign"))
    ctx.entry(THESIS, "|sigma_t| / |sigma_n| and the sign nu on A_C", [*figs, data, nu_data],
              {"max mu_f |int sigma_t mu_i| / int F mu_i on contact nodes":
                   float(discrete[in_contact].max()),
               "max pointwise ratio on active edges": float(ratio[active].max()),
               "max pointwise ratio on edges with both ends in contact": float(
                   ratio[both].max()) if both.any() else None,
               "nu range on A_C": [float(a["nu"][support].min()), float(a["nu"][support].max())],
               "h^ edges stick / slip": [int(np.sum(a["nu_status"] == 1)),
                                         int(np.sum(a["nu_status"] == 2))]},
              thesis_says="the ratio does not exceed mu_f = 0.5; nu is not zero where the body "
                          "sticks (nu = sigma_t / (mu_f |sigma_n|)).")


if __name__ == "__main__":
    script_main(__file__)
