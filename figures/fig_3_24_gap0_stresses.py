"""Fig. 3.24: normal (a) and tangential (b) stress on Gamma_C for g = 0 with h^ = 2h~.

With g = 0 the whole of Gamma_C is in contact, assumption (3.73) fails and nu needs the
coarser mesh h^ = 2h~ (Lemma 3.29). The thesis: the end-point singularities vanish; the
kinks of sigma_t mark the change between slip and stick.
"""

import numpy as np

from ngdual import plot
from ngdual.studies.figures import gap_tasks, outcome, require, script_main
from ngdual.studies.figures.kit import length, stress

THESIS = "Fig. 3.24"
STUDIES = ("gaps",)


def run(ctx):
    # COMPUTE: g = 0 on the gap level (default solver), and nested Uzawa for both h^
    tasks = gap_tasks(ctx.plan)
    task = tasks["gap0"]
    record = require(ctx.record(task), task.label)
    uzawa = {key: ctx.record(tasks[f"uzawa-{key}"]) for key in ("gap0", "gap0-hhat1")}
    same = ctx.record(tasks["gap0-hhat1"])  # h^ = h~: no inf-sup condition for nu
    a = ctx.arrays(task)
    order = np.argsort(a["edge_x"])
    # WRITE
    data = ctx.write_csv("fig_3_24_gap0_stresses.csv",
                         [{"x1": a["edge_x"][i], "sigma_n": a["sigma_n"][i],
                           "sigma_t": a["sigma_t"][i]} for i in order],
                         "sigma_n, sigma_t per fine Gamma_C edge, g = 0, h^ = 2h~, mu_f = 0.5")
    # PLOT
    level = task.params["level"]
    panels = [{"title": f"(a) normal stress, level {level}",
               "xlabel": length(r"$x_1$ on $\Gamma_C$"),
               "ylabel": stress(r"$\sigma_n^h$"),
               "curves": [{"x": a["edge_x"][order], "y": a["sigma_n"][order],
                           "drawstyle": "steps-mid", "label": r"$\sigma_n^h$"}]},
              {"title": f"(b) tangential stress, level {level}",
               "xlabel": length(r"$x_1$ on $\Gamma_C$"),
               "ylabel": stress(r"$\sigma_t^h$"),
               "curves": [{"x": a["edge_x"][order], "y": a["sigma_t"][order],
                           "drawstyle": "steps-mid", "label": r"$\sigma_t^h$"},
                          {"x": a["edge_x"][order], "y": 0.5 * np.abs(a["sigma_n"][order]),
                           "ls": ":", "color": "k", "label": r"$\pm\mu_f|\sigma_n^h|$"},
                          {"x": a["edge_x"][order], "y": -0.5 * np.abs(a["sigma_n"][order]),
                           "ls": ":", "color": "k"}]}]
    fig = plot.plot_curves(panels, r"Fig. 3.24: stresses on $\Gamma_C$, $g = 0$, "
                           r"$\hat h = 2\tilde h$, $\mu_f = 0.5$")
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_24_gap0_stresses"))
    end = np.argsort(np.abs(a["edge_x"]))[-2:]
    ctx.entry(THESIS, "Stresses on Gamma_C with g = 0, h^ = 2h~", [*figs, data],
              {"iterations outer / inner": [record["iterations"]["outer"],
                                            record["iterations"]["inner"]],
               "nodes in contact / all h~ nodes": [record["contact"]["nodes_in_contact"],
                                                   len(a["coarse_x"])],
               "max |sigma_n|": float(np.abs(a["sigma_n"]).max()),
               "|sigma_n| on the two end edges": [float(abs(a["sigma_n"][i])) for i in end],
               "h^ = h~, default solver": outcome(same),
               f"nested Uzawa, level {ctx.plan.uzawa_gap_level}, h^ = 2h~": outcome(
                   uzawa["gap0"]),
               f"nested Uzawa, level {ctx.plan.uzawa_gap_level}, h^ = h~": outcome(
                   uzawa["gap0-hhat1"])},
              thesis_says="the singularities at the end points vanish; sigma_n tends to zero "
                          "very fast at the ends of Gamma_C; kinks in sigma_t at slip/stick. "
                          "With h^ = h~ the algorithm does not converge (no discrete inf-sup "
                          "condition for q).",
              notes="with h^ = h~ and g = 0, nu is not unique (Lemma 3.29): the discrete "
                    "inf-sup condition for q fails where the contact zone reaches the ends of "
                    "Gamma_C.")


if __name__ == "__main__":
    script_main(__file__)
