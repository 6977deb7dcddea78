"""What accuracy costs in time: true errors against wall time and unknowns, every method.

Problems (ngdual.studies.figures.TRUTH_PROBLEMS): Example 3.46 without friction and with
Coulomb friction mu_f = 0.5, both with consistent end values at the clamped sides (the
thesis' lambda = 0 there leaves sigma ~ 1/r, not in L2: no error is finite), the rigid flat
punch, the Hertz cylinder, Cattaneo-Mindlin (the cylinder with Coulomb friction, shifted
sideways) and the wedge (a kink in Gamma_C at the apex).

Methods: uniform refinement (active set) up to the budget level K minus the problem's
``coarser`` (``--max-level`` K); the adaptive loop as a tolerance run (ngdual.afem.adapt:
Doerfler theta = 0.9 from level 1) with goal "stress" ((4.50)) and goal "pressure"
(ngdual.goal; on the flat punch its core |x| < a/2), each run to a relative estimate of
0.1 % (the flat punch 0.03 %, whose sigma references converge slowest, with twice the
budget at order k >= 1: TruthProblem.reference_tol) or the budget
Plan.reference_elements; these are k = 0 with the thesis' coarse
multipliers. At the orders k = 1, 2 (PEERS_k with the facet P_k multipliers on the fine
edges, ", k = 1" in the method's name): uniform refinement to k levels fewer and both
goals' tolerance runs to the budget Plan.order_elements; on the frictionless problems also
uniform refinement of PEERS_k with the thesis' coarse multipliers of degree k + 1 (", k = 1,
coarse"; they solve frictionless contact only). A method that fails on a problem is a row
"failed: <reason>" of the table. The primal peer
ngdual.studies.primal_peer (P1 and P2 displacements, Nitsche contact, semismooth Newton)
on the uniform meshes, and adapting as a primal user would: Kelly's indicator (the jumps of
sigma(u_h) n, h-weighted, as deal.II's step-42) driving the same Doerfler marking (theta =
0.9) and netgen bisection from level 1 ("primal P2, adaptive"); "primal P2" in the verdicts
is the faster of the two. Left out, as they add run time and change no verdict: the thesis'
Uzawa iterations (the same discrete problems as the active set, slower: README, "Solvers")
and max marking or Doerfler theta = 0.5 (the unknowns grow by 1.3-1.5x per step, so more
steps pay for the same mesh: ngdual.afem.THETA_TOL).

References: no analytic solution is exact for these finite bodies (the Hertz, Sadowsky and
Cattaneo-Mindlin pressures are half-space formulas), and a uniform overkill two levels
beyond the budget would not fit. Each adaptive run's last step is the reference of its
goal's measure (ngdual.studies.figures.truth): per measure the run's last step with the
smallest own error. A reference's own error is Richardson-estimated from the two steps
before it (nested meshes, exact distances); where the steps give no converging sequence,
by the three-cornered hat: the pairwise distances of three solutions whose errors are
taken as orthogonal (the JSON's ``estimate`` says which) -- for sigma the run's last step,
the last step of a run of the other goal (of the same order, else of order 0) and the
finest uniform level; for the pressure the run's last step and the two solutions nearest
to it among the other runs' last steps and the finest uniform level (corners far from the
truth would make the hat a difference of large squares). A hat below the error that
another run's own Richardson estimate and the triangle inequality force (e_a >= d_ab -
2 e_b, the estimate counted twice; for sigma the corners', for the pressure every run's;
the JSON's ``hat_bound``) is refuted and gives no own error (``hat_refuted``): the
corners' errors are then not orthogonal (runs of one goal refine alike). The runs of order
1 and 2 are candidates too: their pressure and sigma converge faster than those of order 0.
A target
is resolved when that error is at most a third of it (the JSON's ``resolves``).
Candidates whose meshes are not nested in the reference's (uniform, the peers, the other
runs' steps) carry a quadrature error; it is measured by integrating again on the
reference's triangles split in four (``quadrature``).

Measures: the relative L2 error of the contact pressure on Gamma_C (ngdual: -sigma_n^h
projected onto the h~ hats at k = 0, the traces -sigma_nn^h at k >= 1; the peer: its
Nitsche pressure; the flat punch: on the core |x| < a/2, its pressure is not in L2 at the
punch edges) and the relative error of sigma in the compliance norm (int A tau : tau)^(1/2).

Time: uniform and peer -- the wall time of one solve (mesh, assembly, solve; not the
estimator); adaptive -- to that mesh's solution: the SOLVE-ESTIMATE-MARK-REFINE of every
step before and its SOLVE (the estimate on the mesh, which decides whether to go on, is left
out as uniform's is; ngdual.studies.sweep.adaptive_tasks.adapt_task).
From the default K on, every time is the median of three runs (an adaptive step's: the
median of its step's times, summed over the steps), runs beyond the first only while they
take under 5 s (``ngdual.studies.sweep.timing.REPEAT_BELOW_S``): one run's time of a fraction
of a second varies by about 10 % with the load, enough to decide a verdict. A task's runs
follow each other, so one slow period of the machine (10-25 % on a shared VM, invisible to
the guest) can fall on all runs of one method: a verdict whose two times lie within
CLOSE (1.3x) of each other is timed again after the sweep, the uniform solve and the
adaptive run to its step in turn, seven runs of each after one not counted
(ngdual.studies.sweep.adaptive_tasks.paired_task), and decided by their medians (the table's
"adaptive first" gives them). A verdict whose fastest adaptive run reaches the target with
its first solve, the very solve of the fastest uniform level (same order, multipliers and
unknowns), is a tie by construction: "tie: the same solve", no win, not timed again
(same_solve). Every task
runs NGSolve and BLAS on one thread (``ngdual.studies.sweep.timing.one_thread``): one task per
core, the same for every method.
The table gives the least time to reach 5 %, 2 % and 1 % per method and measure, the
verdicts adaptive against uniform (at order 0, and the fastest of each at any order), the
ratio of the fastest ngdual method to the primal P2
peer, and the pressure goal's effectivity (its estimate / the true pressure error on
Gamma_C) per adaptive step.
"""

import os

from ngdual import plot
from ngdual.io import versions
from ngdual.studies.cost.methods import is_peer, method_base, method_order, order_method
from ngdual.studies.cost.output import curve_style, seconds_and_unknowns
from ngdual.studies.cost.table import MEASURES, TARGETS, accuracy_rows
from ngdual.studies.figures import TRUTH_PROBLEMS, markdown_table, script_main, true_error_study
from ngdual.studies.figures.plan import COARSE_ORDERS, ORDERS
from ngdual.studies.figures.tasks import paired_timing, truth_tasks
from ngdual.studies.sweep.timing import REPEAT_BELOW_S

THESIS = "Work-precision (beyond the thesis)"
STUDIES = ("truth",)
UNIFORM, P2 = "uniform", "primal P2"
# A verdict whose adaptive and uniform times lie within this factor of each other (both
# under REPEAT_BELOW_S) is timed again in pairs, the two methods in turn (paired_timing):
# one slow period of the machine moves a task's back-to-back repeats by 10-25 %.
CLOSE = 1.3
# the problems' names in the summary tables (the README's)
SUMMARY_NAMES = {"frictionless": "3.46, μ_f = 0", "coulomb": "3.46, μ_f = 0.5",
                 "flat-punch": "punch core", "hertz-cylinder": "Hertz",
                 "cattaneo-mindlin": "Cattaneo–Mindlin", "wedge": "wedge"}
def accuracy_table(rows: list[dict], references: dict) -> list[dict]:
    """Least time (and its unknowns) to each target per problem, measure and method
    (:func:`ngdual.studies.cost.table.accuracy_rows` of each problem, the table of
    ``ngdual cost``)."""
    return [{"problem": problem, **r} for problem in TRUTH_PROBLEMS
            for r in accuracy_rows([r for r in rows if r["problem"] == problem],
                                   references[problem])]


def is_p2(method: str) -> bool:
    """Whether ``method`` is the primal P2 peer, uniform or adaptive."""
    return method.startswith(P2)


def _fastest(table: list[dict], problem: str, measure: str, target: float, which
             ) -> dict | None:
    rows = [r for r in table if (r["problem"], r["measure"], r["target"])
            == (problem, measure, target) and r["time_s"] is not None and which(r["method"])]
    return min(rows, key=lambda r: r["time_s"], default=None)


def same_solve(adaptive: dict | None, uniform: dict | None) -> bool:
    """Whether ``adaptive`` reaches its target with its first solve and that solve is
    ``uniform``'s: step 0 with the same order, multipliers and unknowns (an adaptive run
    starts on a uniform level of the same scene). The two times then measure one
    computation: a tie by construction, which no timing decides (the punch core's pressure,
    where PEERS_1 on the initial mesh is at 0.92 %).

    >>> first = {"level_or_step": 0, "order": 1, "multipliers": "facet", "ndof": 5205}
    >>> same_solve(first, {**first, "level_or_step": 1}), same_solve(first, {**first, "ndof": 9})
    (True, False)
    """
    return (adaptive is not None and uniform is not None and adaptive["level_or_step"] == 0
            and all(adaptive[k] == uniform[k] for k in ("order", "multipliers", "ndof")))


def _wins(adaptive: dict | None, uniform: dict | None) -> bool | None:
    """Whether ``adaptive`` reaches the target before ``uniform`` (or uniform does not within
    its budget); None where adaptive does not reach it, False where it is the same solve
    (:func:`same_solve`: not less time)."""
    if adaptive is None:
        return None
    return uniform is None or (not same_solve(adaptive, uniform)
                               and adaptive["time_s"] < uniform["time_s"])


def verdicts(table: list[dict]) -> list[dict]:
    """Per problem, measure and target: the fastest adaptive run of order 0 against uniform
    refinement of order 0 (``adaptive_wins``: it reaches the target first, or uniform does
    not within its budget), the fastest adaptive run of any order against the fastest
    uniform refinement of any order (``adaptive_any_wins``), and the fastest ngdual method
    against the primal P2 peer, uniform or adaptive (``ratio`` = ngdual time / P2 time), also
    among the methods
    of order k >= 1 (``ratio_order_p2``)."""
    out = []
    for problem in TRUTH_PROBLEMS:
        for measure in MEASURES:
            for target in TARGETS:
                key = (problem, measure, target)
                uniform = _fastest(table, *key, lambda m: m == UNIFORM)
                adaptive = _fastest(table, *key, lambda m: m.startswith("adaptive")
                                    and method_order(m)[0] == 0)
                uniform_any = _fastest(table, *key, lambda m: method_base(m) == UNIFORM)
                adaptive_any = _fastest(table, *key, lambda m: m.startswith("adaptive"))
                ngdual = _fastest(table, *key, lambda m: not is_peer(m))
                higher = _fastest(table, *key,
                                  lambda m: not is_peer(m) and method_order(m)[0] >= 1)
                p2 = _fastest(table, *key, is_p2)
                resolved = next(r["resolved"] for r in table if (r["problem"], r["measure"],
                                                                 r["target"]) == key)
                out.append({
                    "problem": problem, "measure": measure, "target": target,
                    "resolved": resolved,
                    "uniform_s": uniform and uniform["time_s"],
                    "uniform_ndof": uniform and uniform["ndof"],
                    "adaptive_s": adaptive and adaptive["time_s"],
                    "adaptive_ndof": adaptive and adaptive["ndof"],
                    "adaptive_method": adaptive and adaptive["method"],
                    "adaptive_wins": _wins(adaptive, uniform),
                    "adaptive_same_solve": same_solve(adaptive, uniform),
                    "uniform_any_s": uniform_any and uniform_any["time_s"],
                    "uniform_any_method": uniform_any and uniform_any["method"],
                    "uniform_any_level": uniform_any and uniform_any["level_or_step"],
                    "adaptive_any_s": adaptive_any and adaptive_any["time_s"],
                    "adaptive_any_method": adaptive_any and adaptive_any["method"],
                    "adaptive_any_step": adaptive_any and adaptive_any["level_or_step"],
                    "adaptive_any_wins": _wins(adaptive_any, uniform_any),
                    "adaptive_any_same_solve": same_solve(adaptive_any, uniform_any),
                    "paired_uniform_s": None, "paired_adaptive_s": None,
                    "fastest_ngdual": ngdual and ngdual["method"],
                    "ngdual_s": ngdual and ngdual["time_s"], "p2_s": p2 and p2["time_s"],
                    "ratio_ngdual_p2": (ngdual["time_s"] / p2["time_s"]
                                        if ngdual and p2 else None),
                    "fastest_order": higher and higher["method"],
                    "order_s": higher and higher["time_s"],
                    "ratio_order_p2": (higher["time_s"] / p2["time_s"]
                                       if higher and p2 else None)})
    return out


def is_close(v: dict) -> bool:
    """Whether the fastest adaptive and uniform times of a verdict lie within
    :data:`CLOSE` of each other, both under REPEAT_BELOW_S (longer runs vary less), and
    are two computations (not :func:`same_solve`)."""
    a, u = v["adaptive_any_s"], v["uniform_any_s"]
    return (a is not None and u is not None and max(a / u, u / a) <= CLOSE
            and max(a, u) < REPEAT_BELOW_S and not v.get("adaptive_any_same_solve"))


def paired_tasks(plan, verdict: list[dict], rows: list[dict]) -> dict[int, object]:
    """The paired timing (:func:`paired_timing`) of every close verdict (:func:`is_close`),
    by its index: the fastest uniform solve and the fastest adaptive run to its step."""
    out = {}
    for i, v in enumerate(verdict):
        if not is_close(v):
            continue
        tasks = truth_tasks(plan, v["problem"])
        [uniform] = [t for t in tasks[v["uniform_any_method"]]
                     if t.params["level"] == v["uniform_any_level"]]
        [adaptive] = tasks[v["adaptive_any_method"]]
        steps = sorted((r["level_or_step"], r["ndof"]) for r in rows
                       if (r["problem"], r["method"]) == (v["problem"], v["adaptive_any_method"])
                       and r["status"] == "ok" and r["level_or_step"] <= v["adaptive_any_step"])
        out[i] = paired_timing(plan, uniform, adaptive, [n for _, n in steps])
    return out


def apply_paired(verdict: list[dict], paired: dict[int, dict | None]) -> None:
    """The close verdicts decided by their paired timing (records by verdict index): the
    medians of the runs in turn (``paired_uniform_s``, ``paired_adaptive_s``) decide
    ``adaptive_any_wins``; a paired timing that failed leaves the verdict as it was."""
    for i, record in paired.items():
        if record is None or record.get("status") != "ok":
            continue
        v = verdict[i]
        v["paired_uniform_s"], v["paired_adaptive_s"] = record["uniform_s"], record["adaptive_s"]
        v["adaptive_any_wins"] = record["adaptive_s"] < record["uniform_s"]


def effectivities(rows: list[dict]) -> list[dict]:
    """The pressure goal's estimate / the true pressure error on Gamma_C (the flat punch: on
    its core) per adaptive step (a step that is the pressure reference has none)."""
    return [{"problem": r["problem"], "method": r["method"], "step": r["level_or_step"],
             "ndof": r["ndof"],
             "goal_estimate": r["goal_estimate"], "pressure_l2": r["pressure_l2"],
             "effectivity": r["effectivity"]}
            for r in rows if r.get("effectivity") is not None]


def budgets(rows: list[dict], references: dict) -> list[dict]:
    """Per problem: the finest uniform level (the budget), its unknowns and time, whether it
    reached 1 % on both measures, and each reference's size and own error."""
    out = []
    for problem in TRUTH_PROBLEMS:
        uniform = [r for r in rows if r["problem"] == problem and r["method"] == UNIFORM
                   and r["status"] == "ok"]
        finest = max(uniform, key=lambda r: r["level_or_step"])
        first = {m: next((r["level_or_step"] for r in sorted(uniform, key=lambda r: r["ndof"])
                          if r.get(m) is not None and r[m] <= 0.01), None) for m in MEASURES}
        ref = references[problem]
        out.append({"problem": problem, "uniform_budget_level": finest["level_or_step"],
                    "uniform_budget_ndof": finest["ndof"],
                    "uniform_budget_s": finest["time_s"],
                    **{f"uniform_1%_{m}_level": first[m] for m in MEASURES},
                    "stopped_by": ("1 % on both measures" if None not in first.values()
                                   else "budget"),
                    **{f"reference_{m}_{k}": ref[m][k] for m in MEASURES
                       for k in ("method", "ndof", "overkill_error", "estimate")},
                    "analytic_pressure_difference": (ref["pressure"]["analytic"] or {}).get(
                        "relative_l2"),
                    "quadrature_max": max((q["relative_change"]
                                           for q in ref["sigma_energy"]["quadrature"]),
                                          default=None)})
    return out


def pivot(table: list[dict], verdict: list[dict]) -> list[dict]:
    """One row per problem, measure and target: per method "time s (unknowns)", "-" or
    "failed: <reason>", the ratios fastest ngdual / primal P2 (all orders, k >= 1) and
    whether the reference resolves the target."""
    out = []
    for v in verdict:
        key = (v["problem"], v["measure"], v["target"])
        row = {"problem": v["problem"], "measure": v["measure"], "target": v["target"]}
        for r in table:
            if (r["problem"], r["measure"], r["target"]) == key:
                row[r["method"]] = (f"{r['time_s']:.3g} s ({r['ndof']})" if r["time_s"]
                                    else r["failed"] and r["failed"][:80])
        row.update(ratio=v["ratio_ngdual_p2"], ratio_order=v["ratio_order_p2"],
                   resolved=v["resolved"])
        out.append(row)
    return out


def method_letters(method: str) -> str:
    """u (uniform), s / p (adaptive, stress / pressure goal), with c for the coarse
    multipliers of order k; a peer: none uniform, a adaptive.

    >>> method_letters("adaptive, pressure goal, k = 2"), method_letters("uniform, k = 1, coarse")
    ('p', 'uc')
    >>> method_letters("primal P2"), method_letters("primal P2, adaptive")
    ('', 'a')
    """
    if is_peer(method):
        return "a" if method.endswith("adaptive") else ""
    base = {UNIFORM: "u", "adaptive, stress goal": "s", "adaptive, pressure goal": "p"}
    order, family = method_order(method)
    return base[method_base(method)] + ("c" if order and family == "coarse" else "")


def first_cell(v: dict) -> str | None:
    """"yes" / "no": the fastest adaptive method of any order comes first; with the medians
    of a paired timing (adaptive / uniform) where there is one; "tie: the same solve" where
    the two are one computation (:func:`same_solve`).

    >>> first_cell({"adaptive_any_wins": True, "paired_adaptive_s": 0.378,
    ...             "paired_uniform_s": 0.4512})
    'yes (in turn: 0.38 / 0.45 s)'
    """
    if v["adaptive_any_wins"] is None:
        return None
    if v.get("adaptive_any_same_solve"):
        return "tie: the same solve"
    verdict = "yes" if v["adaptive_any_wins"] else "no"
    if v.get("paired_adaptive_s") is None:
        return verdict
    return f"{verdict} (in turn: {v['paired_adaptive_s']:.2g} / {v['paired_uniform_s']:.2g} s)"


def summary_rows(table: list[dict], verdict: list[dict], measure: str) -> list[dict]:
    """The README's time-to-accuracy table of ``measure``: per problem and target the least
    time (unknowns) of uniform and adaptive refinement at k = 0, of the fastest method of
    each order k >= 1 and of the primal P2 peer, the ratios to P2, whether the fastest
    adaptive method of any order comes first and whether the reference resolves the target."""
    def cell(rows: list[dict], letters: bool = True) -> str | None:
        hits = [r for r in rows if r["time_s"] is not None]
        if not hits:
            return None
        best = min(hits, key=lambda r: r["time_s"])
        text = seconds_and_unknowns(best["time_s"], best["ndof"])
        return f"{text} {method_letters(best['method'])}".rstrip() if letters else text

    def ratio(value: float | None) -> str | None:
        return None if value is None else f"{value:.2g}"

    out = []
    for v in verdict:
        if v["measure"] != measure:
            continue
        mine = [r for r in table if (r["problem"], r["measure"], r["target"])
                == (v["problem"], measure, v["target"])]
        ngdual = [r for r in mine if not is_peer(r["method"])]
        row = {"case": f"{SUMMARY_NAMES[v['problem']]}, {v['target']:.0%}".replace("%", " %"),
               "uniform": cell([r for r in mine if r["method"] == UNIFORM], letters=False),
               "adaptive": cell([r for r in ngdual if r["method"].startswith("adaptive")
                                 and r["order"] == 0]),
               **{f"k{k}": cell([r for r in ngdual if r["order"] == k]) for k in ORDERS},
               "p2": cell([r for r in mine if is_p2(r["method"])]),
               "ratio": ratio(v["ratio_ngdual_p2"]), "ratio_order": ratio(v["ratio_order_p2"]),
               "first": first_cell(v),
               "resolved": "yes" if v["resolved"] else "no"}
        out.append(row)
    return out


def summary_markdown(table: list[dict], verdict: list[dict]) -> str:
    """Both measures' :func:`summary_rows` as the two markdown tables of the README."""
    what = {"pressure": "problem, pressure", "sigma_energy": "problem, σ"}
    return "\n\n".join(markdown_table(
        summary_rows(table, verdict, measure),
        {"case": header, "uniform": "uniform, k = 0", "adaptive": "adaptive, k = 0",
         **{f"k{k}": f"k = {k}" for k in ORDERS}, "p2": "primal P2", "ratio": "ngdual / P2",
         "ratio_order": "k ≥ 1 / P2", "first": "adaptive first", "resolved": "resolved"},
        missing="–") for measure, header in what.items()) + "\n"


# the figures' file names per measure (work_precision_pressure.png, ..._sigma.png)
SHORT = {"pressure": "pressure", "sigma_energy": "sigma"}
ERROR_AXIS = {"pressure": "rel. $L^2$ error on $\\Gamma_C$ [-]",
              "sigma_energy": "rel. error, compliance norm [-]"}
WHAT_SHORT = {"pressure": "contact pressure", "sigma_energy": "stress $\\sigma$"}


def _panels(rows: list[dict], references: dict, measure: str, xkey: str) -> list[dict]:
    """One panel per problem: the true error ``measure`` of every solution against wall time
    (``xkey`` "time_s") or unknowns ("ndof"), one curve per method, the targets as thin
    lines and the reference's own error."""
    methods = list(dict.fromkeys(r["method"] for r in rows))
    style = {m: curve_style(m) for m in methods}
    xlabel = "wall time [s]" if xkey == "time_s" else "unknowns [-]"
    panels = []
    for problem, tp in TRUTH_PROBLEMS.items():
        floor = references[problem][measure]["overkill_error"]
        curves = []
        for m in methods:
            # in refinement order: the measured times carry noise
            pts = sorted((r for r in rows if r["problem"] == problem and r["method"] == m
                          and r.get(measure)), key=lambda r: r["ndof"])
            if pts:
                curves.append({"x": [r[xkey] for r in pts], "y": [r[measure] for r in pts],
                               "label": m, **style[m]})
        panels.append({
            "title": tp.title, "xlabel": xlabel, "ylabel": MEASURES[measure], "loglog": True,
            "curves": curves,
            "hlines": [(t, None, {"color": "0.7", "lw": 0.8}) for t in TARGETS]
            + ([(floor, "reference's own error", {"color": "k", "ls": "-.", "lw": 1.0})]
               if floor else [])})
    return panels


def frontier_panels(table: list[dict], measure: str) -> list[dict]:
    """One panel per problem: per method the least wall time to reach each target of
    ``measure`` (the rows of ``work_precision_table.csv``), the targets on the error axis;
    a target the reference does not resolve is named in the panel."""
    methods = list(dict.fromkeys(r["method"] for r in table))
    panels = []
    for problem, tp in TRUTH_PROBLEMS.items():
        mine = [r for r in table if (r["problem"], r["measure"]) == (problem, measure)]
        curves = []
        for m in methods:
            hits = sorted((r for r in mine if r["method"] == m and r["time_s"] is not None),
                          key=lambda r: -r["target"])
            if hits:
                curves.append({"x": [r["time_s"] for r in hits],
                               "y": [r["target"] for r in hits], "label": m, **curve_style(m)})
        unresolved = sorted({r["target"] for r in mine if not r["resolved"]})
        panels.append({
            "title": tp.title, "xlabel": "wall time [s]",
            "ylabel": ERROR_AXIS[measure], "loglog": True, "curves": curves,
            "ylim": (min(TARGETS) / 1.4, max(TARGETS) * 1.4),
            **({"note": "reference does not resolve "
                        + ", ".join(f"{t:.0%}" for t in unresolved)} if unresolved else {})})
    return panels


def measure_figures(panels: list[dict], title: str, percent: bool = False):
    """Six problem panels (2 x 3) with one legend beside them (a 16:9 slide); ``percent``:
    the error axis labelled at the targets in %."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter

    fig = plot.plot_curves(panels, title, ncols=3, panel_size=(3.4, 3.2), figure_legend=True,
                           legend_loc="outside right center")
    for ax in fig.axes:
        # plain numbers on the log axes; within a decade also at 2 and 5
        low, high = ax.get_xlim()
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:g}")
                                     if high / low < 10 else NullFormatter())
        if high / low < 10:
            ax.xaxis.set_minor_locator(FixedLocator(
                [m * 10.0 ** e for e in range(-4, 6) for m in (2, 5)]))
        if percent:
            ax.yaxis.set_major_locator(FixedLocator(TARGETS))
            ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{100 * v:g} %"))
            ax.yaxis.set_minor_formatter(NullFormatter())
    return fig


def plot_frontiers(table: list[dict], stem) -> list:
    """``<stem>``: the summary (:func:`plot_summary`); ``<stem>_pressure`` and
    ``<stem>_sigma``: the time to each target, one figure per measure
    (:func:`frontier_panels`)."""
    files = plot.save_figure(plot_summary(table), stem)
    for measure, short in SHORT.items():
        fig = measure_figures(frontier_panels(table, measure),
                              f"What accuracy costs: least wall time to reach 5, 2, 1 % error "
                              f"in the {WHAT_SHORT[measure]}", percent=True)
        files += plot.save_figure(fig, f"{stem}_{short}")
    return files


SUMMARY_TARGET = 0.01
SUMMARY_KINDS = {  # the summary's markers: which methods each takes the fastest of
    "uniform, k = 0": (lambda r: r["method"] == UNIFORM, "C0", "o"),
    "adaptive, k = 0": (lambda r: r["method"].startswith("adaptive") and r["order"] == 0,
                        "C0", "D"),
    "fastest ngdual, k ≥ 1": (lambda r: not is_peer(r["method"]) and r["order"] >= 1,
                              "C2", "s"),
    "primal P2": (lambda r: is_p2(r["method"]), "k", "^")}


def plot_summary(table: list[dict]):
    """The study on one slide: per measure and problem the least wall time to
    :data:`SUMMARY_TARGET` of uniform and adaptive refinement at k = 0, the fastest ngdual
    method of order k >= 1 and the primal P2 peer (no marker: not reached)."""
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.ticker import FuncFormatter

    fig, axes = plt.subplots(1, 2, figsize=(12.8, 7.2), sharey=True, constrained_layout=True)
    names = list(TRUTH_PROBLEMS)
    for ax, measure in zip(axes, MEASURES):
        for i, (kind, (which, colour, marker)) in enumerate(SUMMARY_KINDS.items()):
            xs, ys = [], []
            for j, problem in enumerate(names):
                hits = [r for r in table if (r["problem"], r["measure"], r["target"])
                        == (problem, measure, SUMMARY_TARGET) and r["time_s"] is not None
                        and which(r)]
                if hits:
                    xs.append(j + 0.16 * (i - 1.5))
                    ys.append(min(r["time_s"] for r in hits))
            ax.plot(xs, ys, ls="none", marker=marker, ms=10, color=colour,
                    mfc="none" if kind.startswith("uniform") else colour, label=kind)
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.set_xticks(np.arange(len(names)),
                      [TRUTH_PROBLEMS[n].title + (" (core)" if n == "flat-punch"
                                                  and measure == "pressure" else "")
                       for n in names], rotation=25, ha="right", rotation_mode="anchor")
        ax.set_xlabel("problem")
        ax.set_ylabel(f"least wall time to {SUMMARY_TARGET:.0%} error [s]".replace("%", " %"))
        ax.set_title(f"error in the {WHAT_SHORT[measure]}")
        ax.grid(alpha=0.3, which="both", axis="y")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=4)
    fig.suptitle(f"What accuracy costs: least wall time to {SUMMARY_TARGET:.0%} true error "
                 "(no marker: not reached)".replace("%", " %"))
    return fig


def read_table(path) -> list[dict]:
    """``work_precision_table.csv`` (a run's, or the gallery's copy) as :func:`accuracy_table`
    rows: numbers as numbers, an empty time as None."""
    import csv
    from pathlib import Path

    lines = [line for line in Path(path).read_text().splitlines() if not line.startswith("#")]
    rows = []
    for r in csv.DictReader(lines):
        rows.append({**r, "target": float(r["target"]), "order": int(r["order"]),
                     "time_s": float(r["time_s"]) if r["time_s"] else None,
                     "ndof": int(r["ndof"]) if r["ndof"] else None,
                     "resolved": r["resolved"] == "True", "failed": r["failed"] or None})
    return rows


def replot(table_csv, out) -> list:
    """The time-to-accuracy figures again from a saved ``work_precision_table.csv`` (the
    study takes an hour; its table is enough for them), into ``out/figures``."""
    from pathlib import Path

    with plot.slides():
        return plot_frontiers(read_table(table_csv), Path(out) / "figures" / "work_precision")


def _numbers(verdict: list[dict], effectivity: list[dict], budget: list[dict]) -> dict:
    numbers = {}
    for v in verdict:
        what = f"{v['problem']}: {v['target']:.0%} {v['measure']}"
        if v["adaptive_wins"] is None:
            numbers[f"{what}, adaptive beats uniform"] = "adaptive does not reach it"
        else:
            uniform = ("not reached" if v["uniform_s"] is None
                       else f"{v['uniform_s']:.2f} s")
            tie = "tie, the same solve: " if v["adaptive_same_solve"] else ""
            numbers[f"{what}, adaptive beats uniform"] = (
                f"{tie}{v['adaptive_wins']} ({v['adaptive_s']:.2f} s {v['adaptive_method']} vs "
                f"uniform {uniform}){'' if v['resolved'] else ', not resolved'}")
        if v["adaptive_any_wins"] is None:
            numbers[f"{what}, adaptive beats uniform, any order"] = \
                "adaptive does not reach it"
        else:
            uniform = ("not reached" if v["uniform_any_s"] is None
                       else f"{v['uniform_any_s']:.2f} s {v['uniform_any_method']}")
            paired = ("" if v["paired_adaptive_s"] is None else
                      f"; timed in turn {v['paired_adaptive_s']:.3f} s vs "
                      f"{v['paired_uniform_s']:.3f} s")
            tie = "tie, the same solve: " if v["adaptive_any_same_solve"] else ""
            numbers[f"{what}, adaptive beats uniform, any order"] = (
                f"{tie}{v['adaptive_any_wins']} ({v['adaptive_any_s']:.2f} s "
                f"{v['adaptive_any_method']} vs {uniform}{paired})"
                f"{'' if v['resolved'] else ', not resolved'}")
        if v["measure"] == "pressure":
            numbers[f"{what}, fastest ngdual / primal P2"] = (
                f"{v['ratio_ngdual_p2']:.2f} ({v['fastest_ngdual']})"
                if v["ratio_ngdual_p2"] else "not both reached")
            numbers[f"{what}, fastest ngdual of order k >= 1 / primal P2"] = (
                f"{v['ratio_order_p2']:.2f} ({v['fastest_order']}, {v['order_s']:.2f} s)"
                if v["ratio_order_p2"] else "not both reached")
    for problem in TRUTH_PROBLEMS:
        for method in dict.fromkeys(e["method"] for e in effectivity):
            eff = [e["effectivity"] for e in effectivity
                   if (e["problem"], e["method"]) == (problem, method)]
            if eff:
                numbers[f"{problem}: {method} effectivity range"] = [min(eff), max(eff)]
    for b in budget:
        numbers[f"{b['problem']}: uniform stopped by"] = (
            f"{b['stopped_by']} (level {b['uniform_budget_level']}, "
            f"{b['uniform_budget_ndof']} unknowns)")
        for m in MEASURES:
            numbers[f"{b['problem']}: reference of {m}, own error"] = (
                f"{b[f'reference_{m}_overkill_error']} ({b[f'reference_{m}_estimate']})")
        numbers[f"{b['problem']}: quadrature error of non-nested sigma errors"] = \
            b["quadrature_max"]
        if b["analytic_pressure_difference"] is not None:
            numbers[f"{b['problem']}: reference pressure against the half-plane formula "
                    "(rel. L2)"] = b["analytic_pressure_difference"]
    return numbers


def run(ctx):
    # COMPUTE: the true errors of every solution (cached with the records)
    rows, references = [], {}
    for problem in TRUTH_PROBLEMS:
        study = true_error_study(ctx, problem)
        references[problem] = study["reference"]
        rows += [{"problem": problem, **r} for r in study["rows"]]
    table = accuracy_table(rows, references)
    verdict = verdicts(table)
    # COMPUTE: the close verdicts timed again, uniform and adaptive in turn
    paired = paired_tasks(ctx.plan, verdict, rows)
    apply_paired(verdict, dict(zip(paired, ctx.compute(list(paired.values()), "paired"))))
    effectivity = effectivities(rows)
    budget = budgets(rows, references)
    machine = {"cpus": os.cpu_count(), "load_average": os.getloadavg(), "versions": versions()}
    # WRITE
    data = ctx.write_csv("work_precision.csv", rows, "true errors (pressure, sigma), wall "
                         "time, DOFs, estimator and goal estimate of every solution")
    least = ctx.write_csv("work_precision_table.csv", table,
                          "least wall time to 5 %, 2 %, 1 % true error per method")
    verdicts_csv = ctx.write_csv("work_precision_verdict.csv", verdict,
                                 "adaptive against uniform, fastest ngdual against primal P2")
    js = ctx.write_json("work_precision.json",
                        {"targets": TARGETS, "time_to_accuracy": table, "verdicts": verdict,
                         "effectivity": effectivity, "budgets": budget,
                         "references": references, "machine": machine},
                        "time to accuracy on true errors, adaptive references with their "
                        "Richardson and quadrature checks, adaptive against uniform, the "
                        "pressure goal's effectivity")
    summary = ctx.write_markdown("work_precision_summary.md", summary_markdown(table, verdict),
                                 "least wall time to 5 %, 2 %, 1 % per order, the README's "
                                 "tables (u = uniform, s / p = adaptive with the stress / "
                                 "pressure goal, c = the coarse multipliers)")
    # PLOT: per measure, the time to each target (the gallery's), and every solution's error
    # against wall time and against unknowns; six problem panels each
    figs = plot_frontiers(table, ctx.figure_stem("work_precision"))
    for measure, short in SHORT.items():
        for xkey, stem, against in (("time_s", "work_precision_curves", "wall time"),
                                    ("ndof", "work_precision_unknowns", "unknowns")):
            fig = measure_figures(_panels(rows, references, measure, xkey),
                                  f"True error in the {WHAT_SHORT[measure]} against {against}")
            figs += plot.save_figure(fig, ctx.figure_stem(f"{stem}_{short}"))
    ctx.entry(THESIS, "Work-precision: true errors against wall time and unknowns",
              [*figs, data, least, verdicts_csv, js, summary],
              _numbers(verdict, effectivity, budget),
              table=markdown_table(
                  pivot(table, verdict),
                  {"problem": "problem", "measure": "measure", "target": "target",
                   UNIFORM: "uniform", "adaptive, stress goal": "adaptive, stress goal",
                   "adaptive, pressure goal": "adaptive, pressure goal",
                   **{order_method(m, k): f"{m}, k = {k} (facet)" for k in ORDERS
                      for m in (UNIFORM, "adaptive, stress goal",
                                "adaptive, pressure goal")},
                   **{order_method(UNIFORM, k, "coarse"): f"uniform, k = {k} (coarse)"
                      for k in COARSE_ORDERS},
                   **{f"primal P{k}{a}": f"primal P{k}{a}" for k in (1, 2)
                      for a in ("", ", adaptive")},
                   "ratio": "fastest ngdual / P2",
                   "ratio_order": "fastest k >= 1 / P2", "resolved": "reference resolves"}),
              notes=f"Machine: {machine['cpus']} cores, load average "
                    f"{machine['load_average'][0]:.1f} at the end; sweep tasks run side by "
                    "side, so times carry that noise. Errors against the adaptive references "
                    "named above; adaptive times are cumulative.")


if __name__ == "__main__":
    import sys

    if "--from-table" in sys.argv:  # python figures/work_precision.py --from-table CSV OUT
        i = sys.argv.index("--from-table")
        for path in replot(sys.argv[i + 1], sys.argv[i + 2]):
            print(path)
    else:
        script_main(__file__)
