"""What accuracy costs in time: true errors against wall time and unknowns, every method.

Problems (ngdual.studies.figures.TRUTH_PROBLEMS): Example 3.46 without friction and with Coulomb
friction mu_f = 0.5, both with consistent end values at the clamped sides (the thesis'
lambda = 0 there contradicts u = 0 on Gamma_D and leaves sigma ~ 1/r, not in L2: no error
is finite), and the rigid flat punch.

The error of every point is a true error (ngdual.verification.overkill) against an
overkill: ngdual's solution two uniform levels beyond the finest studied, checked by
Richardson from the two levels below it (the overkill's own error is in the JSON and the
index; a target below about twice it is not resolved). Two measures: the relative L2 error
of the contact pressure on Gamma_C (ngdual: -sigma_n^h projected onto the h~ hats, as in
ngdual.verification.analytic; the peer: its Nitsche pressure), and the relative error of
sigma in the compliance norm (int A tau : tau)^(1/2) -- for the flat punch the pressure is
not in L2 at the punch edges, so its pressure errors converge only logarithmically and the
sigma panel is the one to read.

Methods: uniform refinement with the default active-set solver and with the thesis' Uzawa
iterations; adaptive refinement (default solver) with max marking (theta = 0.5, 0.25) and
Doerfler marking (theta = 0.5, 0.3) from level 1 up to the triangles of the finest uniform
level; the primal peer ngdual.studies.primal_peer (P1 and P2 displacements, Nitsche
contact, semismooth Newton) on the same uniform meshes and one level beyond.

Time: uniform and peer -- the wall time of one solve (mesh, assembly, solve; not the
estimator); adaptive -- cumulative over all SOLVE-ESTIMATE-MARK-REFINE steps to that mesh.
The table gives the least time to reach 5 %, 2 % and 1 % error per method, and the ratio
of the fastest ngdual method to the fastest peer.
"""

import os

from ngdual import plot
from ngdual.studies.figures import TRUTH_PROBLEMS, markdown_table, script_main, true_error_study

THESIS = "Work-precision (beyond the thesis)"
STUDIES = ("truth",)
TARGETS = (0.05, 0.02, 0.01)
MEASURES = {"pressure": "pressure error on $\\Gamma_C$ (rel. $L^2$) [-]",
            "sigma_energy": "error of $\\sigma$ (rel. compliance norm) [-]"}
MARKERS = "osD^vP*X"


def is_peer(method: str) -> bool:
    return method.startswith("primal")


def time_to_accuracy(points: list[dict], measure: str, target: float) -> dict | None:
    """The point of least time whose error ``measure`` is at most ``target``."""
    hits = [p for p in points if p.get(measure) is not None and p[measure] <= target]
    return min(hits, key=lambda p: p["time_s"]) if hits else None


def accuracy_table(rows: list[dict]) -> list[dict]:
    """Least time to each target per problem, measure and method, and per problem the
    fastest ngdual method against the fastest peer (``ratio`` = ngdual time / peer time)."""
    table = []
    for problem in TRUTH_PROBLEMS:
        mine = [r for r in rows if r["problem"] == problem and r["status"] == "ok"]
        methods = list(dict.fromkeys(r["method"] for r in mine))
        for measure in MEASURES:
            for target in TARGETS:
                best = {}
                for method in methods:
                    hit = time_to_accuracy([r for r in mine if r["method"] == method],
                                           measure, target)
                    table.append({"problem": problem, "measure": measure, "target": target,
                                  "method": method, "time_s": hit and hit["time_s"],
                                  "ndof": hit and hit["ndof"],
                                  "level_or_step": hit and hit["level_or_step"]})
                    if hit:
                        side = "peer" if is_peer(method) else "ngdual"
                        if side not in best or hit["time_s"] < best[side][1]:
                            best[side] = (method, hit["time_s"])
                ng, peer = best.get("ngdual"), best.get("peer")
                table.append({"problem": problem, "measure": measure, "target": target,
                              "method": "fastest ngdual / fastest peer",
                              "fastest_ngdual": ng and ng[0], "fastest_peer": peer and peer[0],
                              "ratio": ng[1] / peer[1] if ng and peer else None})
    return table


def adaptive_verdict(table: list[dict]) -> list[dict]:
    """Per problem, measure and target: the fastest adaptive run against uniform refinement
    (active set), by time to accuracy."""
    out = []
    keys = {(r["problem"], r["measure"], r["target"]) for r in table}
    for problem, measure, target in sorted(keys):
        same = [r for r in table if (r["problem"], r["measure"], r["target"])
                == (problem, measure, target) and r.get("time_s") is not None]
        uniform = next((r for r in same if r["method"] == "uniform, active set"), None)
        adaptive = min((r for r in same if r["method"].startswith("adaptive")),
                       key=lambda r: r["time_s"], default=None)
        out.append({"problem": problem, "measure": measure, "target": target,
                    "uniform_s": uniform and uniform["time_s"],
                    "adaptive_s": adaptive and adaptive["time_s"],
                    "adaptive_method": adaptive and adaptive["method"],
                    "adaptive_wins": (None if not (uniform and adaptive)
                                      else adaptive["time_s"] < uniform["time_s"])})
    return out


def run(ctx):
    # COMPUTE: the true errors of every solution (cached with the records)
    rows, references = [], {}
    for problem in TRUTH_PROBLEMS:
        study = true_error_study(ctx, problem)
        references[problem] = study["reference"]
        rows += [{"problem": problem, **r} for r in study["rows"]]
    table = accuracy_table(rows)
    verdict = adaptive_verdict(table)
    machine = {"cpus": os.cpu_count(), "load_average": os.getloadavg()}
    # WRITE
    data = ctx.write_csv("work_precision.csv", rows, "true errors (pressure, sigma), wall "
                         "time, DOFs and estimator of every solution")
    summary = ctx.write_csv("work_precision_table.csv", table,
                            "least wall time to 5 %, 2 %, 1 % true error; ngdual / peer")
    js = ctx.write_json("work_precision.json",
                        {"targets": TARGETS, "time_to_accuracy": table,
                         "adaptive_vs_uniform": verdict, "references": references,
                         "machine": machine},
                        "time to accuracy on true errors, overkill references with their "
                        "Richardson checks, adaptive against uniform")
    # PLOT: one row per problem, pressure and sigma against time and DOFs
    methods = list(dict.fromkeys(r["method"] for r in rows))
    style = {m: {"color": f"C{i % 10}", "marker": MARKERS[i % len(MARKERS)], "ms": 4,
                 "ls": ":" if is_peer(m) else ("-" if m.startswith("uniform") else "--")}
             for i, m in enumerate(methods)}
    panels = []
    for problem, tp in TRUTH_PROBLEMS.items():
        ref = references[problem]
        for measure, ylabel in MEASURES.items():
            floor = ref["richardson"][measure]["overkill_error"]
            for xkey, xlabel in (("time_s", "wall time [s]"), ("ndof", "unknowns [-]")):
                curves = []
                for m in methods:
                    # in refinement order: the measured times carry noise
                    pts = sorted((r for r in rows if r["problem"] == problem
                                  and r["method"] == m and r.get(measure)),
                                 key=lambda r: r["ndof"])
                    if pts:
                        curves.append({"x": [r[xkey] for r in pts],
                                       "y": [r[measure] for r in pts], "label": m, **style[m]})
                panels.append({
                    "title": f"{tp.title}: {measure.replace('_', ' ')} vs "
                             + ("time" if xkey == "time_s" else "unknowns"),
                    "xlabel": xlabel, "ylabel": ylabel, "loglog": True, "curves": curves,
                    "hlines": [(t, None, {"color": "0.7", "lw": 0.6}) for t in TARGETS]
                    + ([(floor, "overkill's own error (Richardson)",
                         {"color": "k", "ls": "-.", "lw": 0.8})] if floor else [])})
    fig = plot.plot_curves(panels, "What accuracy costs: true errors against an overkill, ngdual "
                           "(uniform, adaptive, Uzawa) and a primal P1/P2 Nitsche peer",
                           ncols=4, panel_size=(4.4, 3.2), figure_legend=True)
    figs = plot.save_figure(fig, ctx.figure_stem("work_precision"))
    numbers = {}
    for r in table:
        if r["method"] == "fastest ngdual / fastest peer" and r["measure"] == "pressure":
            numbers[f"{r['problem']}: time ngdual / peer to {r['target']:.0%} pressure "
                    "error"] = (f"{r['ratio']:.2f} ({r['fastest_ngdual']} / "
                                f"{r['fastest_peer']})" if r["ratio"] else "not reached")
    for v in verdict:
        numbers[f"{v['problem']}: adaptive beats uniform to {v['target']:.0%} "
                f"{v['measure']}"] = ("not both reached" if v["adaptive_wins"] is None else
                                      f"{v['adaptive_wins']} ({v['adaptive_s']:.2f} s "
                                      f"{v['adaptive_method']} vs {v['uniform_s']:.2f} s)")
    for p, ref in references.items():
        for measure, check in ref["richardson"].items():
            numbers[f"{p}: overkill level {ref['level']}, its {measure} error "
                    "(Richardson)"] = check["overkill_error"]
    ctx.entry(THESIS, "Work-precision: true errors against wall time and unknowns",
              [*figs, data, summary, js], numbers,
              table=markdown_table([r for r in table if r.get("time_s") is not None
                                    and r["measure"] == "pressure"],
                                   {"problem": "problem", "target": "target", "method": "method",
                                    "time_s": "time [s]", "ndof": "unknowns",
                                    "level_or_step": "level / step"}),
              notes=f"Machine: {machine['cpus']} cores, load average "
                    f"{machine['load_average'][0]:.1f} at the end; sweep tasks run side by "
                    "side, so times carry that noise. Errors against the overkill solutions "
                    "named above; adaptive times are cumulative.")


if __name__ == "__main__":
    script_main(__file__)
