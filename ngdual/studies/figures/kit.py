"""What several figure scripts share: axis labels in the thesis scenes' units, the norms of
Tables 3.2/3.3, the rho searches of Tables 3.5/3.6, the element fields of Figs. 3.11-3.14,
the Gamma_N and Gamma_C panels of Figs. 3.15-3.20, the h^ cases of Figs. 3.26-3.28, the
adaptive meshes of Figs. 4.1-4.13, and CSV rows of fields and traces.

The figure scripts (``figures/*.py``) import it as ``ngdual.studies.figures.kit``; no other
module does, so that loading the thesis scene for :data:`UNITS` costs nothing elsewhere.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from ... import plot
from ...scene import load_scene
from .index import markdown_table
from .numbers import best, outcome, require
from .output import Context
from .plan import PROBLEM_TITLES, SCENES
from .tasks import adaptive_task, gap_tasks, rho_tasks, solve

# the units the thesis scenes declare ([units]; none: labels name the quantity alone)
UNITS = load_scene(SCENES["frictionless"]).units


def length(quantity: str) -> str:
    """An axis label of a length, displacement or gap, in the thesis scenes' length unit."""
    return plot.unit_label(quantity, UNITS.length)


def stress(quantity: str) -> str:
    """An axis label of a stress or traction, in the thesis scenes' stress unit."""
    return plot.unit_label(quantity, UNITS.stress)


NORM_KEYS = ("sigma_X", "u", "eta", "phi", "lam_t", "lam_n", "nu")
NORM_LABELS = {"sigma_X": "||sigma||_X", "u": "||u||_L2", "eta": "||eta||_L2",
               "phi": "||phi||_L2(G_N)", "lam_t": "||lam_t||_L2(G_C)",
               "lam_n": "||lam_n||_L2(G_C)", "nu": "||nu||_L2(A_C)"}

HHAT_CASES = {"abs": ("(a) $g = |x_1|$", "g = |x_1|"), "3125": ("(b) $g$ of (3.125)", "g (3.125)")}
HHAT_NAMES = {1: "h^ = h~", 2: "h^ = 2h~"}
HHAT_STYLE = {1: {"color": "tab:red", "ls": "--", "label": r"$\hat h = \tilde h$"},
              2: {"color": "tab:green", "label": r"$\hat h = 2\tilde h$"}}


def hhat_solutions(ctx: Context, uzawa: bool = False
                   ) -> dict[str, dict[int, tuple[dict | None, dict]]]:
    """Figs. 3.26-3.28: ``[case][hhat_factor] = (record, arrays)`` (arrays empty if failed),
    of the default solver on the gap level or (``uzawa``) of nested Uzawa."""
    tasks = gap_tasks(ctx.plan)
    out = {}
    for case in HHAT_CASES:
        out[case] = {}
        for factor in (1, 2):
            task = tasks[f"{'uzawa-' if uzawa else ''}{case}-hhat{factor}"]
            record = ctx.record(task)
            ok = record is not None and record["status"] == "ok"
            out[case][factor] = (record, ctx.arrays(task) if ok else {})
    return out


def hhat_numbers(ctx: Context) -> dict:
    """How every h^ case ended, with the default solver and with nested Uzawa."""
    numbers = {}
    for uzawa, level in ((False, ctx.plan.gap_level), (True, ctx.plan.uzawa_gap_level)):
        solver = "nested Uzawa" if uzawa else "default solver"
        for case, by_factor in hhat_solutions(ctx, uzawa).items():
            for factor, (record, _) in by_factor.items():
                key = f"{HHAT_CASES[case][1]}, {HHAT_NAMES[factor]}, {solver}, level {level}"
                numbers[key] = outcome(record)
    return numbers


def hhat_panels(solutions: dict, ylabel: str,
                trace: Callable[[str, int, dict], tuple[list[dict], dict]],
                **panel) -> tuple[list[dict], list[dict]]:
    """Figs. 3.26-3.28: one panel per gap case, with a curve for every h^ that solved and a
    note naming those that did not.

    Parameters
    ----------
    solutions : dict
        :func:`hhat_solutions`.
    ylabel : str
        The panels' y-axis label (x is x_1 on Gamma_C).
    trace : callable
        ``trace(case, hhat_factor, arrays)``: the CSV rows and the curve of one solution.
    **panel
        Further keys of every panel of :func:`ngdual.plot.plot_curves` (such as ``ylim``).

    Returns
    -------
    rows : list of dict
        The CSV rows of every solution, case by case.
    panels : list of dict
        One panel per gap case of :data:`HHAT_CASES`.
    """
    rows, panels = [], []
    for case, by_factor in solutions.items():
        curves, notes = [], []
        for factor, (record, arrays) in by_factor.items():
            if not arrays:
                notes.append(f"{HHAT_NAMES[factor]}: {(record or {}).get('status', 'missing')}")
                continue
            case_rows, curve = trace(case, factor, arrays)
            rows += case_rows
            curves.append(curve)
        panels.append({"title": HHAT_CASES[case][0], "xlabel": length(r"$x_1$ on $\Gamma_C$"),
                       "ylabel": ylabel, "curves": curves, "note": "; ".join(notes), **panel})
    return rows, panels


def hhat_figure(ctx: Context, thesis: str, stem: str, rows: list[dict], panels: list[dict], *,
                title: str, description: str, entry: str, numbers: dict | None = None,
                thesis_says: str) -> None:
    """Figs. 3.26-3.28: write the CSV and the figure of one h^ comparison and its index entry.

    Parameters
    ----------
    thesis, stem : str
        The figure's thesis number (``"Fig. 3.26"``) and the name of its files.
    rows, panels : list of dict
        :func:`hhat_panels`, perhaps with panels added.
    title : str
        What the figure shows; the suptitle adds the thesis number, mu_f and the gap level.
    description : str
        What the CSV holds.
    entry : str
        The index entry's title, before "for h^ = h~ and h^ = 2h~".
    numbers : dict, optional
        The figure's own numbers; the entry adds how every h^ case ended
        (:func:`hhat_numbers`).
    thesis_says : str
        What the thesis states about the figure.
    """
    data = ctx.write_csv(f"{stem}.csv", rows, description)
    fig = plot.plot_curves(panels, rf"{thesis}: {title}, $\mu_f = 0.5$, level {ctx.plan.gap_level}")
    ctx.entry(thesis, f"{entry} for h^ = h~ and h^ = 2h~",
              [*plot.save_figure(fig, ctx.figure_stem(stem)), data],
              {**(numbers or {}), **hhat_numbers(ctx)}, thesis_says=thesis_says)


def centroids(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The centroid of every triangle, where the element fields are plotted and tabulated."""
    return points[triangles].mean(axis=1)


def element_rows(fields: dict[str, tuple[dict, dict]], key: str) -> list[dict]:
    """CSV rows of an element field of both problems: element, centroid, one value each."""
    first = next(iter(fields.values()))[1]
    columns = {f"{key}_{p}": arrays[key] for p, (_, arrays) in fields.items()}
    return [{"element": k, "x1": c[0], "x2": c[1], **{n: v[k] for n, v in columns.items()}}
            for k, c in enumerate(centroids(first["points"], first["triangles"]))]


def element_field(ctx: Context, fields: dict[str, tuple[dict, dict]], key: str, label: str,
                  title: str, stem: str, description: str, clip: float | None = None
                  ) -> list[Path]:
    """Figs. 3.11-3.14: write the CSV of an element field of both problems, one row per
    element, and the figure of both side by side on one colour scale.

    Parameters
    ----------
    fields : dict
        :meth:`Context.both_fields`.
    key : str
        The field among the arrays (``"u1"``, ``"eta"``, ...).
    label, title : str
        The colour bar's label and the figure's suptitle.
    stem, description : str
        The name of the files and what the CSV holds.
    clip : float, optional
        The percentile where the colour scale ends (:data:`ngdual.plot.CORNER_CLIP`).

    Returns
    -------
    list of pathlib.Path
        The files written, the figure's first.
    """
    data = ctx.write_csv(f"{stem}.csv", element_rows(fields, key), description)
    arrays = [a for _, a in fields.values()]
    fig = plot.plot_field_pair(arrays[0]["points"], arrays[0]["triangles"],
                               [a[key] for a in arrays], ctx.titles(), label, title, clip=clip,
                               units=UNITS)
    return [*plot.save_figure(fig, ctx.figure_stem(stem)), data]


def curve_rows(fields: dict[str, tuple[dict, dict]], x_key: str, keys: list[str],
               mask_key: str | None = None) -> list[dict]:
    """Long-format CSV rows of 1D traces: problem, x_1, then ``keys`` (Gamma_C / Gamma_N)."""
    rows = []
    for problem, (_, arrays) in fields.items():
        if x_key not in arrays:
            continue
        order = np.argsort(arrays[x_key], kind="stable")
        for i in order:
            if mask_key is not None and not arrays[mask_key][i]:
                continue
            rows.append({"problem": problem, "x1": arrays[x_key][i],
                         **{k: arrays[k][i] for k in keys if k in arrays}})
    return rows


def norms_table(ctx: Context, thesis: str, problem: str, name: str, keys) -> None:
    """Tables 3.2 / 3.3: the norms per uniform level and their Aitken limits (CSV + index)."""
    records = ctx.uniform(problem)
    reference = ctx.reference(problem)
    rows = []
    for level, record in zip(ctx.plan.levels, records):
        row = {"level": level, "status": record["status"] if record else "missing"}
        if record and "norms" in record:
            row.update(ndof=record["ndof"], **{k: record["norms"][k] for k in keys})
        rows.append(row)
    rows.append({"level": "Aitken", "status": f"limit of levels {ctx.plan.reference_levels}",
                 **{k: reference.get(k) for k in keys}})
    data = ctx.write_csv(f"{name}.csv", rows, f"norms per level, {SCENES[problem]}; last row: "
                                              "Aitken Delta^2 extrapolation")
    ctx.entry(thesis, f"Norms of the solutions, {PROBLEM_TITLES[problem]}", [data],
              {f"Aitken limit {NORM_LABELS[k]}": reference.get(k) for k in keys},
              table=markdown_table(rows, {"level": "level", "ndof": "Dof",
                                          **{k: NORM_LABELS[k] for k in keys}}),
              thesis_says="an asymptotic behaviour of all norms (the thesis' rows are withheld "
                          "in our copy).")


def field_summary(values: np.ndarray, points: np.ndarray, triangles: np.ndarray) -> dict:
    """min / max of an element field and where the maximum sits (for the index)."""
    k = int(np.argmax(values))
    return {"min": float(values.min()), "max": float(values.max()),
            "argmax": [round(float(c), 3) for c in centroids(points, triangles)[k]]}


def gamma_c_stress(ctx: Context, fields: dict, thesis: str, key: str, tex: str, what: str,
                   stem: str, away: float = 3.0) -> tuple[list[Path], dict]:
    """Figs. 3.18 / 3.20: ``key`` (sigma_n or sigma_t, constant per fine Gamma_C edge) for
    both problems (``fields`` = :meth:`Context.both_fields`): the CSV, one panel per
    problem, and the maxima for the index.

    The y-range comes from the values with |x_1| <= ``away``, leaving the corner
    singularities at x_1 = +-4 off scale (their size is a note on the panel and in the CSV).
    Returns the files written and the numbers, for the script's index entry.
    """
    data = ctx.write_csv(f"{stem}.csv", curve_rows(fields, "edge_x", [key, "edge_active"]),
                         f"{key}^h at the midpoints of the fine Gamma_C edges")
    panels, numbers = [], {}
    span = max(float(np.abs(a[key][np.abs(a["edge_x"]) <= away]).max())
               for _, a in fields.values()) or 1.0
    for p, (_, a) in fields.items():
        order = np.argsort(a["edge_x"])
        panels.append({"title": f"{PROBLEM_TITLES[p]}, level {ctx.plan.field_level}",
                       "ylim": (-1.25 * span, 1.25 * span),
                       "note": f"corner singularities at x_1 = +-4 off scale "
                               f"(|{key}| up to {np.abs(a[key]).max():.3g}; see the CSV)",
                       "xlabel": length(r"$x_1$ on $\Gamma_C$"),
                       "ylabel": stress(rf"${tex}^h$"),
                       "curves": [{"x": a["edge_x"][order], "y": a[key][order],
                                   "drawstyle": "steps-mid", "label": rf"${tex}^h$"}]})
        active = a["edge_active"].astype(bool)
        numbers[f"max |{key}| on A_C, {PROBLEM_TITLES[p]}"] = float(np.abs(a[key][active]).max())
        numbers[f"max |{key}| overall (corners), {PROBLEM_TITLES[p]}"] = float(
            np.abs(a[key]).max())
    fig = plot.plot_curves(panels, rf"{thesis}: {what} ${tex}^h$ on $\Gamma_C$")
    return [*plot.save_figure(fig, ctx.figure_stem(stem)), data], numbers


NEUMANN_STYLE = {"frictionless": {"color": "tab:blue"}, "coulomb": {"color": "tab:red", "ls": "--"}}


def neumann_multiplier(ctx: Context, thesis: str, component: int, stem: str) -> None:
    """Figs. 3.15 / 3.16: phi_i^h on Gamma_N for both problems (CSV, plot, index entry).

    The thesis sees no difference between the two problems (the same traction t_0) and, by
    Theorem 3.10 (phi = -u on Gamma_N), the sign of phi opposite to that of u there.
    """
    key, tex = f"phi{component}", rf"\varphi_{component}"
    fields = ctx.both_fields()
    a0, a1 = (fields[p][1] for p in ("frictionless", "coulomb"))
    data = ctx.write_csv(f"{stem}.csv", curve_rows(fields, "phi_x", [key]),
                         f"phi_{component}^h at the fine vertices of Gamma_N (x_2 = 1), "
                         "both problems")
    panels = [{"title": f"{PROBLEM_TITLES[p]}, level {ctx.plan.field_level}",
               "xlabel": length(r"$x_1$ on $\Gamma_N$"), "ylabel": length(rf"${tex}^h$"),
               "curves": [{"x": a["phi_x"], "y": a[key], "label": PROBLEM_TITLES[p],
                           **NEUMANN_STYLE[p]}]}
              for p, (_, a) in fields.items()]
    fig = plot.plot_curves(panels, rf"{thesis}: ${tex}^h$ on the Neumann boundary $\Gamma_N$")
    figs = plot.save_figure(fig, ctx.figure_stem(stem))
    name = f"phi_{component}"
    ctx.entry(thesis, f"{name} on Gamma_N", [*figs, data],
              {f"range {name}, mu_f = 0": [float(a0[key].min()), float(a0[key].max())],
               f"range {name}, mu_f = 0.5": [float(a1[key].min()), float(a1[key].max())],
               f"max |{name}(0.5) - {name}(0)|": float(np.abs(a1[key] - a0[key]).max())},
              thesis_says="no difference between the frictionless and the frictional case.")


def adaptive_meshes(ctx: Context, strategy: str, first: int) -> tuple[list[Path], dict[int, dict]]:
    """Figs. 4.1-4.13: write the meshes of an adaptive run (mu_f = 0.5) at the steps the plan
    shows, one figure each, shaded where the next step refines (marked by the indicators
    eta_{tot,T} of (4.50)), and the CSV of their sizes.

    Parameters
    ----------
    strategy : {"max", "fraction"}
        The run of :data:`~.plan.ADAPTIVE_RUNS`; its marking and theta name the figures.
    first : int
        The thesis number of the first figure (Fig. 4.``first``).

    Returns
    -------
    files : list of pathlib.Path
        The files written, the CSV first.
    steps : dict
        The run's history, by step.
    """
    task = adaptive_task(ctx.plan, "coulomb", strategy)
    record = require(ctx.record(task), task.label)
    arrays = ctx.arrays(task)
    steps = {r["step"]: r for r in record["history"]}
    shown = list(zip(range(first, first + len(task.params["snapshots"])),
                     task.params["snapshots"]))
    figures = f"Figs. 4.{first}-4.{shown[-1][0]}"
    marking = f"{task.params['marking']} marking $\\theta = {task.params['theta']}$"
    files = [ctx.write_csv(f"fig_4_{first:02d}_to_4_{shown[-1][0]:02d}_{strategy}_marking.csv",
                           [{"figure": f"4.{n}", "step": k, "elements": steps[k]["elements"],
                             "dofs": steps[k]["dofs"]["total"], "marked": steps[k]["marked"],
                             "h_min": steps[k]["h_min"]} for n, k in shown],
                           f"the meshes shown in {figures}: step, triangles, DOFs, marked")]
    for n, k in shown:
        when = "initial mesh" if k == 0 else f"after {k} step{'s' if k > 1 else ''}"
        fig = plot.plot_mesh(arrays[f"points_{k}"], arrays[f"triangles_{k}"],
                             f"Fig. 4.{n}: {marking}, {when} ({steps[k]['dofs']['total']} DOFs)",
                             arrays[f"marked_{k}"], units=UNITS)
        files += plot.save_figure(fig, ctx.figure_stem(f"fig_4_{n:02d}_{strategy}_marking_"
                                                       f"step{k:02d}"))
    return files, steps


def rho_search(ctx: Context, problem: str) -> dict[int, tuple[dict, object, dict | None]]:
    """Tables 3.5 / 3.6: the rho search on every uniform level.

    Parameters
    ----------
    problem : {"frictionless", "coulomb"}
        The search over rho of Algorithm 3.38 or over (rho_1, rho_2) of Algorithm 3.41.

    Returns
    -------
    dict
        ``level -> (records, best, active_set)``: the records keyed by rho or (rho_1, rho_2),
        the key of the best (:func:`~.numbers.best`; None if none converged) and the record
        of the default active-set solver on that level, what the search is measured against.
    """
    tasks = rho_tasks(ctx.plan)[problem]
    records = dict(zip(tasks, ctx.compute(list(tasks.values()))))
    out = {}
    for level in ctx.plan.levels:
        at = {key[1] if len(key) == 2 else key[1:]: record
              for key, record in records.items() if key[0] == level}
        out[level] = (at, best(at), ctx.record(solve(ctx.plan, problem, level)))
    return out


def solver_columns(record: dict | None, counts: dict[str, str], suffix: str = "") -> dict:
    """Tables 3.5 / 3.6: the columns of one solve.

    Parameters
    ----------
    record : dict or None
        A solve's record; one that is missing or did not converge gives no columns.
    counts : dict
        Column name -> ``"outer"`` or ``"inner"``: the iteration counts to show.
    suffix : str
        Appended to the names of the two times, ``time`` (the iteration) and ``total``
        (with meshing, assembly and factorisation).

    Returns
    -------
    dict
        The columns, counts first.
    """
    if not record or record["status"] != "ok":
        return {}
    return {**{name: record["iterations"][kind] for name, kind in counts.items()},
            f"time{suffix}": record["timings_s"]["solve"],
            f"total{suffix}": record["timings_s"]["total"]}
