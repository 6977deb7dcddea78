"""Fig. 3.22: total error e_tot (3.124) against the number of DOFs, mu_f = 0 and mu_f = 0.5.

Uniform levels 1..K-1 against the Aitken limits of the last three levels (see Table 3.4;
level K is left out: it is part of its own reference); the thesis' slope -1/5 is drawn
through the second level of the frictionless curve.
"""

from ngdual import plot
from ngdual.rates import observed_rates
from ngdual.studies.figures import PROBLEM_TITLES, errors, script_main

THESIS = "Fig. 3.22"
STUDIES = ("uniform-frictionless", "uniform-coulomb")
STYLE = {"frictionless": {"marker": "o", "color": "tab:blue"},
         "coulomb": {"marker": "s", "color": "tab:red", "ls": "--"}}


def run(ctx):
    # COMPUTE
    series = {}
    for problem in ("frictionless", "coulomb"):
        records = ctx.uniform(problem)
        errs = errors(records, ctx.reference(problem))
        series[problem] = [(r["ndof"], e["e_tot"], lv) for lv, r, e in
                           zip(ctx.plan.levels[:-1], records, errs) if r and e and e["e_tot"] > 0]
    # WRITE
    data = ctx.write_csv("fig_3_22_convergence.csv",
                         [{"problem": p, "level": lv, "ndof": n, "e_tot": e}
                          for p, pts in series.items() for n, e, lv in pts],
                         "total error (3.124) against the DOFs, uniform levels")
    # PLOT
    curves = [{"x": [n for n, _, _ in pts], "y": [e for _, e, _ in pts],
               "label": PROBLEM_TITLES[p], **STYLE[p]} for p, pts in series.items()]
    n0, e0, _ = series["frictionless"][min(1, len(series["frictionless"]) - 1)]
    n_last = series["frictionless"][-1][0]
    curves.append({"x": [n0, n_last], "y": [0.7 * e0, 0.7 * e0 * (n_last / n0) ** -0.2],
                   "color": "k", "ls": ":", "label": "slope -1/5 (thesis)"})
    fig = plot.plot_curves([{"title": "uniform refinement, Example 3.46",
                             "xlabel": "degrees of freedom N [-]",
                             "ylabel": r"$e_{tot}$ (3.124)",
                             "curves": curves, "loglog": True,
                             "note": f"reference: Aitken limit of levels "
                                     f"{ctx.plan.reference_levels}"}],
                           "Fig. 3.22: convergence of the frictionless and frictional problems",
                           ncols=1, panel_size=(6.5, 4.5))
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_22_convergence"))
    ctx.entry(THESIS, "Convergence of the total error", [*figs, data],
              {**{f"e_tot at level {lv}, {PROBLEM_TITLES[p]}": e for p, pts in series.items()
                  for _, e, lv in pts[-2:]},
               **{f"alpha (ngdual.rates) of the last two points, {PROBLEM_TITLES[p]}":
                  observed_rates([n for n, _, _ in pts[-2:]], [e for _, e, _ in pts[-2:]])[1]
                  for p, pts in series.items() if len(pts) >= 2}},
              thesis_says="slope -1/5 against the DOFs (alpha about 0.45).",
              notes="level K is left out: the reference is extrapolated from it.")


if __name__ == "__main__":
    script_main(__file__)
