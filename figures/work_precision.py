"""What accuracy costs in time: error against wall time and DOFs, every method and solver.

For Example 3.46 without friction and with Coulomb friction mu_f = 0.5: uniform refinement
(levels 1..K) with every solver variant of ngdual.figures.SOLVER_VARIANTS (the default
active-set solver and the thesis' Uzawa iterations), and the default solver with the three
adaptive strategies (max theta = 0.5, fraction theta = 0.2, Doerfler theta = 0.5).

Two measures of the error. e_tot of (3.124): norms against Aitken limits, here of the
uniform levels K-1, K, K+1 (K+1 only for this reference, default solver), so that level K
has an error too. It compares norms, not functions: the adaptive meshes resolve the corner
singularities of sigma that the uniform levels do not, their ||sigma||_X exceeds the
uniform estimate of its limit, and (3.124) then reports a large error for them. Second
row: the a posteriori estimator eta = (sum_T eta_{tot,T}^2)^(1/2) of (4.50), the measure
the adaptive algorithms reduce.

Time: uniform -- the wall time of one solve on that level (mesh, assembly, factorisation,
condensation, iteration; not the estimator); adaptive -- the cumulative wall time of all
SOLVE-ESTIMATE-MARK-REFINE steps up to that mesh. Sweep tasks run two at a time on this
machine, so the times carry that noise. The table gives, for the errors of the uniform
levels 2..K (default solver), the least time (and its DOFs) each method needs to reach them.
"""

from ngdual import plot
from ngdual.figures import (
    ADAPTIVE_RUNS,
    PROBLEM_TITLES,
    SOLVER_VARIANTS,
    adapt_task,
    errors,
    markdown_table,
    reference_norms,
    script_main,
    solve,
)

THESIS = "Work-precision (beyond the thesis)"
STUDIES = ("uniform-frictionless", "uniform-coulomb", "variants", "adaptive",
           "work-precision-reference")
MARKERS = "osD^vP*X"
MEASURES = {"e_tot": r"estimated $e_{tot}$ (3.124) [norm units]",
            "eta": r"estimator $\eta$ (4.50) [norm units]"}
ROUND_OFF = 1e-3  # solvers agree to their tolerance, not to the last digit


def cheapest(points: list[dict], key: str, target: float) -> dict | None:
    """The point of least time whose error ``key`` is at most ``target`` (up to round-off)."""
    hits = [p for p in points if p[key] is not None and p[key] <= target * (1 + ROUND_OFF)]
    return min(hits, key=lambda p: p["time_s"]) if hits else None


def run(ctx):
    # COMPUTE: every curve's points (DOFs, time, e_tot, eta)
    rows = []
    for problem in ("frictionless", "coulomb"):
        reference = reference_norms(ctx.compute(
            [solve(ctx.plan, problem, lv) for lv in ctx.plan.work_precision_reference_levels]))
        for variant in SOLVER_VARIANTS:
            if problem not in variant.problems:
                continue
            records = ctx.compute([solve(ctx.plan, problem, lv, variant.overrides)
                                   for lv in ctx.plan.levels])
            for lv, r, e in zip(ctx.plan.levels, records, errors(records, reference)):
                ok = r is not None and r["status"] == "ok"
                rows.append({"problem": problem, "method": f"uniform, {variant.name} solver",
                             "level_or_step": lv, "status": r["status"] if r else "missing",
                             "ndof": r["ndof"] if ok else None,
                             "time_s": r["timings_s"]["total"] if ok else None,
                             "e_tot": e["e_tot"] if ok and e else None,
                             "eta": r["estimator"]["eta"] if ok else None,
                             "iterations": r["iterations"] if ok else None})
        for strategy in ADAPTIVE_RUNS:
            task = adapt_task(ctx.plan, problem, strategy)
            history = (ctx.record(task) or {}).get("history", [])
            for r, e in zip(history, errors(history, reference)):
                rows.append({"problem": problem, "method": f"{strategy} marking theta = "
                             f"{task.params['theta']}, default solver",
                             "level_or_step": r["step"],
                             "status": "ok" if r["converged"] else "not-converged",
                             "ndof": r["dofs"]["total"], "time_s": r["cumulative_s"],
                             "e_tot": e["e_tot"] if e else None, "eta": r["eta"],
                             "iterations": r["iterations"]})
    curves = {}
    for r in rows:
        if r["time_s"] is not None and r["ndof"] is not None:
            curves.setdefault((r["problem"], r["method"]), []).append(r)
    # WRITE
    data = ctx.write_csv("work_precision.csv", rows, "error (3.124), estimator (4.50), wall "
                         "time and DOFs of every method")
    table = []
    for (problem, method), pts in curves.items():
        base = [r for r in rows if r["problem"] == problem and r["status"] == "ok"
                and r["method"] == "uniform, default solver" and r["level_or_step"] >= 2]
        for key in MEASURES:
            for target in base:
                hit = cheapest(pts, key, target[key])
                table.append({"problem": problem, "measure": key,
                              "target": f"{key}(level {target['level_or_step']}) = "
                                        f"{target[key]:.3g}",
                              "method": method, "time_s": hit["time_s"] if hit else None,
                              "ndof": hit["ndof"] if hit else None,
                              "level_or_step": hit["level_or_step"] if hit else None})
    summary = ctx.write_csv("work_precision_table.csv", table,
                            "least wall time (and DOFs) to reach the error of uniform level k")
    # PLOT: one colour and marker per method, the same in every panel
    methods = list(dict.fromkeys(m for _, m in curves))
    style = {m: {"color": f"C{i % 10}", "marker": MARKERS[i % len(MARKERS)], "ms": 4,
                 "ls": "-" if m.startswith("uniform") else "--"} for i, m in enumerate(methods)}
    panels = []
    for problem in ("frictionless", "coulomb"):
        mine = [(m, pts) for (p, m), pts in curves.items() if p == problem]
        for key, ylabel in MEASURES.items():
            for xkey, xlabel in (("time_s", "wall time [s]"), ("ndof", "degrees of freedom [-]")):
                panels.append({
                    "title": f"{PROBLEM_TITLES[problem]}: {key} vs "
                             + ("time" if xkey == "time_s" else "DOFs"),
                    "xlabel": xlabel, "ylabel": ylabel, "loglog": True,
                    "curves": [{"x": [r[xkey] for r in pts if r[key]],
                                "y": [r[key] for r in pts if r[key]], "label": m, **style[m]}
                               for m, pts in mine]})
    figs = plot.plot_curves(panels, ctx.figure_stem("work_precision"),
                            "What accuracy costs: Example 3.46, uniform and adaptive "
                            "refinement, every solver variant", panel_size=(5.6, 3.3),
                            figure_legend=True)
    fastest = {}
    for row in table:
        key = f"fastest to {row['target']}, {PROBLEM_TITLES[row['problem']]}"
        if row["time_s"] is not None and (key not in fastest
                                          or row["time_s"] < fastest[key][1]):
            fastest[key] = (row["method"], row["time_s"])
    ctx.entry(THESIS, "Work-precision: error against wall time and DOFs", [*figs, data, summary],
              {k: f"{m} ({t:.2f} s)" for k, (m, t) in fastest.items()},
              table=markdown_table([r for r in table if r["measure"] == "e_tot"],
                                   {"problem": "problem", "target": "target error",
                                    "method": "method", "time_s": "time [s]", "ndof": "DOFs",
                                    "level_or_step": "level / step"}),
              notes=f"e_tot against the Aitken limit of uniform levels "
                    f"{ctx.plan.work_precision_reference_levels}; it compares norms, so it "
                    "overstates the error of adaptive meshes that resolve the corner "
                    "singularities better than any uniform level (see the eta panels). Times "
                    "measured with two sweep tasks running at once; adaptive times are "
                    "cumulative over all steps. The eta targets are in the CSV table.")


if __name__ == "__main__":
    script_main(__file__)
