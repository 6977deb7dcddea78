"""What several figure scripts share: axis labels in the thesis scenes' units, the norms of
Tables 3.2/3.3, the h^ cases of Figs. 3.26-3.28, CSV rows of fields and traces, and the
panels of Figs. 3.15-3.20.

The figure scripts (``figures/*.py``) import it as ``ngdual.studies.figures.kit``; no other
module does, so that loading the thesis scene for :data:`UNITS` costs nothing elsewhere.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ... import plot
from ...scene import load_scene
from .index import markdown_table
from .numbers import outcome
from .output import Context
from .plan import PROBLEM_TITLES, SCENES
from .tasks import gap_tasks

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
                key = (f"{HHAT_CASES[case][1]}, h^ = {'2' if factor == 2 else ''}h~, {solver}, "
                       f"level {level}")
                numbers[key] = outcome(record)
    return numbers


def element_rows(fields: dict[str, tuple[dict, dict]], key: str) -> list[dict]:
    """CSV rows of an element field of both problems: element, centroid, one value each."""
    first = next(iter(fields.values()))[1]
    centroids = first["points"][first["triangles"]].mean(axis=1)
    columns = {f"{key}_{p}": arrays[key] for p, (_, arrays) in fields.items()}
    return [{"element": k, "x1": c[0], "x2": c[1], **{n: v[k] for n, v in columns.items()}}
            for k, c in enumerate(centroids)]


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
    centroids = points[triangles].mean(axis=1)
    k = int(np.argmax(values))
    return {"min": float(values.min()), "max": float(values.max()),
            "argmax": [round(float(c), 3) for c in centroids[k]]}


def gamma_c_stress(ctx: Context, fields: dict, thesis: str, key: str, tex: str, what: str,
                   stem: str, away: float = 3.0) -> tuple[list, Path, dict]:
    """Figs. 3.18 / 3.20: ``key`` (sigma_n or sigma_t, constant per fine Gamma_C edge) for
    both problems (``fields`` = :meth:`Context.both_fields`): the CSV, one panel per
    problem, and the maxima for the index.

    The y-range comes from the values with |x_1| <= ``away``, leaving the corner
    singularities at x_1 = +-4 off scale (their size is a note on the panel and in the CSV).
    Returns the figure files, the CSV and the numbers, for the script's index entry.
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
    figs = plot.save_figure(fig, ctx.figure_stem(stem))
    return figs, data, numbers


NEUMANN_STYLE = {"frictionless": {"color": "tab:blue"}, "coulomb": {"color": "tab:red", "ls": "--"}}


def neumann_multiplier(ctx: Context, thesis: str, component: int, stem: str) -> None:
    """Figs. 3.15 / 3.16: phi_i^h on Gamma_N for both problems (CSV, plot, index entry)."""
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
