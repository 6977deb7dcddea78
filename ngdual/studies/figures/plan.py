"""``ngdual figures``: every figure and table of Sections 3.4 and 4.2, and what accuracy costs.

The scripts in ``figures/`` (one per thesis figure or table) each compute, write
their data (CSV / JSON, with the package versions) and plot (PNG and PDF). They
share their solves through *studies*: named lists of :class:`~ngdual.sweep.Task`
that :func:`studies` derives from one number, the finest uniform level K
(``--max-level``); see :class:`Plan` for every size derived from it. A run first
computes all studies the selected scripts declare (``STUDIES``), as one dask
sweep (:class:`~ngdual.sweep.Runner`) whose records go to ``DIR/records`` --
re-running skips them -- then runs the scripts, which only read records, and
writes ``DIR/index.md``: every output next to its thesis counterpart, with our
numbers.

Output folder::

    DIR/index.md            the index (from figures/index_template.md)
    DIR/run.json            settings, plan, versions, script times, failed tasks
    DIR/records/            one JSON (+ NPZ) record per task
    DIR/data/               CSV / JSON data of every figure and table
    DIR/figures/            PNG and PDF (+ a JSON sidecar naming titles, labels, legends)
    DIR/entries/            one JSON per script: its thesis counterpart, files and numbers

A new solver variant for the work-precision study is one entry of
:data:`SOLVER_VARIANTS` (its ``--set`` overrides, e.g. ``solver.method="..."``). The
figures of the discrete solutions use the default solver (``solver.method = "auto"``, the
same discrete solution as the thesis' algorithms, to round-off); the studies of the
algorithms themselves (Tables 3.5, 3.6, Fig. 3.23, the eps_2 and h^ statements of
Figs. 3.24-3.28) run the thesis' Uzawa iterations (``solver.method = "uzawa"``).
"""

from __future__ import annotations

import csv
import hashlib
import importlib.util
import json
import math
import os
import re
import sys
import time
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

import numpy as np

from .bench import TUNED
from .io import write_json
from .rates import aitken_extrapolate, total_error
from .sweep import Runner, Task, load_arrays, load_record, versions

DEFAULT_MAX_LEVEL = 5
THESIS_MAX_LEVEL = 8
SOURCE_ENV = "NGDUAL_FIGURES_DIR"
SCENES = {"frictionless": "thesis-3.46-frictionless", "coulomb": "thesis-3.46-coulomb"}
PROBLEM_TITLES = {"frictionless": r"$\mu_f = 0$", "coulomb": r"$\mu_f = 0.5$"}
NORM_KEYS = ("sigma_X", "u", "eta", "phi", "lam_t", "lam_n", "nu")
NORM_LABELS = {"sigma_X": "||sigma||_X", "u": "||u||_L2", "eta": "||eta||_L2",
               "phi": "||phi||_L2(G_N)", "lam_t": "||lam_t||_L2(G_C)",
               "lam_n": "||lam_n||_L2(G_C)", "nu": "||nu||_L2(A_C)"}


@dataclass(frozen=True)
class Variant:
    """A solver variant of the work-precision study: ``--set`` overrides of the scene.

    ``problems`` lists the problems it applies to (``"frictionless"``, ``"coulomb"``).
    """

    name: str
    overrides: tuple[str, ...] = ()
    problems: tuple[str, ...] = ("frictionless", "coulomb")
    description: str = ""


UZAWA = 'solver.method="uzawa"'
SOLVER_VARIANTS: list[Variant] = [
    Variant("default", (), description="solver.method = auto: active set / semismooth Newton "
                                       "on Gamma_C after one Cholesky factorisation"),
    Variant("uzawa", (UZAWA,), description="Algorithm 3.38 / 3.41 (Remark 3.45), H^1/2 metric, "
                                           "friction outside, Jacobi metric for nu"),
    Variant("uzawa-tuned", (UZAWA, *(f"solver.{k}={v}" for k, v in TUNED.items())),
            description="Uzawa with the steps of ngdual.bench.TUNED"),
    Variant("uzawa-euclidean", (UZAWA, 'solver.metric="euclidean"'),
            description="Uzawa with P+ in the Euclidean metric (closed form)"),
    Variant("uzawa-contact-outer", (UZAWA, 'solver.loop_order="contact-outer"'), ("coulomb",),
            description="nested Uzawa with the loops exchanged (Remark 3.43)"),
    Variant("uzawa-mass-metric", (UZAWA, 'solver.friction_metric="mass"'), ("coulomb",),
            description="nested Uzawa, P^Lambda in the mass metric of Remark 3.44"),
]


@dataclass(frozen=True)
class Plan:
    """Every size of a run, derived from the finest uniform level K.

    K = 8 is the thesis scale. The adaptive runs of Section 4.2 keep the thesis'
    parameters and step counts once K is large enough (28 refinements with max
    marking, snapshots after 1, 3, 5, 7, 9 refinements with fraction marking),
    and shrink with K otherwise so that their last mesh stays about as large as
    level K; the figure titles name the steps actually shown.
    """

    max_level: int = DEFAULT_MAX_LEVEL

    def __post_init__(self):
        if not 2 <= self.max_level <= THESIS_MAX_LEVEL:
            raise ValueError(f"--max-level must lie in 2..{THESIS_MAX_LEVEL}, "
                             f"got {self.max_level}")

    @property
    def levels(self) -> list[int]:
        return list(range(1, self.max_level + 1))

    @property
    def field_level(self) -> int:
        """Level of the field plots of Figs. 3.11-3.21 (at most 6: 65 536 triangles)."""
        return min(self.max_level, 6)

    @property
    def reference_levels(self) -> list[int]:
        """The three levels whose norms give the Aitken-extrapolated reference (3.124)."""
        return self.levels[-3:]

    @property
    def work_precision_reference_levels(self) -> list[int]:
        """Levels of the Aitken reference of the work-precision study: one level beyond K
        (default solver), so that level K has an error too; the thesis' rule at K = 8."""
        if self.max_level == THESIS_MAX_LEVEL:
            return self.reference_levels
        return [self.max_level - 1, self.max_level, self.max_level + 1]

    @property
    def rho_level(self) -> int:
        """Level of the (rho_1, rho_2) grid of Fig. 3.23 (the thesis: the 4th)."""
        return min(self.max_level, 4)

    @property
    def rho_grid(self) -> tuple[float, ...]:
        """rho of Algorithm 3.38 searched on every level (Table 3.5)."""
        return (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75)

    @property
    def rho1_grid(self) -> tuple[float, ...]:
        return (0.5, 0.75, 1.0, 1.25, 1.5, 1.75) if self.max_level >= 4 else (0.5, 1.0, 1.5)

    @property
    def rho2_grid(self) -> tuple[float, ...]:
        """rho_2 is relative to the computed stability bound of the nu step: (0, 2)."""
        return ((0.25, 0.5, 1.0, 1.25, 1.5, 1.9) if self.max_level >= 4
                else (0.5, 1.0, 1.9))

    @property
    def rho_cross(self) -> tuple[tuple[float, float], ...]:
        """(rho_1, rho_2) tried on the levels above :attr:`rho_level` (besides (1, 1))."""
        return ((1.0, 1.9), (1.5, 1.9))

    @property
    def gap_level(self) -> int:
        """Level of the solutions plotted in Figs. 3.24-3.28 (default solver)."""
        return self.field_level

    @property
    def uzawa_gap_level(self) -> int:
        """Level of the nested Uzawa runs of Figs. 3.24-3.28 (the thesis: the 4th)."""
        return max(1, min(self.max_level - 1, 4))

    @property
    def max_marking_refinements(self) -> int:
        return min(28, 7 * (self.max_level - 1))

    @property
    def max_marking_snapshots(self) -> list[int]:
        """Steps shown in Figs. 4.1-4.8 (the thesis: 0, 4, ..., 28)."""
        return [int(v) for v in np.floor(np.linspace(0, self.max_marking_refinements, 8) + 0.5)]

    @property
    def fraction_refinements(self) -> int:
        """fraction marking (theta = 0.2) doubles the mesh about every step."""
        return min(9, 2 * self.max_level - 3) if self.max_level >= 4 else 4

    @property
    def fraction_snapshots(self) -> list[int]:
        """Steps shown in Figs. 4.9-4.13 (the thesis: 1, 3, 5, 7, 9; repeated if fewer)."""
        return [int(v) for v in np.floor(np.linspace(1, self.fraction_refinements, 5) + 0.5)]

    @property
    def dorfler_refinements(self) -> int:
        return 2 * self.max_level

    def truth_levels(self, problem: str) -> list[int]:
        """Uniform levels of the true-error studies (:data:`TRUTH_PROBLEMS`): up to K - 1, so
        that the overkill (two levels finer, K + 1) stays affordable."""
        return list(range(1, max(2, self.max_level - TRUTH_PROBLEMS[problem].coarser)))

    def overkill_level(self, problem: str) -> int:
        """The reference of the true errors: two uniform levels beyond the finest studied."""
        return self.truth_levels(problem)[-1] + 2

    def describe(self) -> dict:
        names = ("max_level", "levels", "field_level", "reference_levels",
                 "work_precision_reference_levels", "rho_level",
                 "rho_grid", "rho1_grid", "rho2_grid", "rho_cross", "gap_level", "uzawa_gap_level",
                 "max_marking_refinements", "max_marking_snapshots", "fraction_refinements",
                 "fraction_snapshots", "dorfler_refinements")
        return {n: getattr(self, n) for n in names}


@dataclass(frozen=True)
class TruthProblem:
    """A scene of the true-error studies: its overrides and how many levels coarser than K
    its finest uniform level is (a flat punch level has ~6x the triangles of Example 3.46's)."""

    scene: str
    overrides: tuple[str, ...] = ()
    coarser: int = 0
    title: str = ""
    level1_elements: int = 32
    pressure_window: float | None = None


# Example 3.46 with consistent end values (lambda = g - u_D.n at the clamped ends): the
# thesis' lambda = 0 there contradicts u = 0 on Gamma_D, sigma ~ 1/r at the corners is not in
# L2 and no error norm exists (see figures/effectivity.py); the peer solves this problem too
CONSISTENT = ('contact.ends="consistent"',)
TRUTH_PROBLEMS = {
    "frictionless": TruthProblem("thesis-3.46-frictionless", CONSISTENT, 0,
                                 r"Example 3.46, $\mu_f = 0$"),
    "coulomb": TruthProblem("thesis-3.46-coulomb", CONSISTENT, 0,
                            r"Example 3.46, $\mu_f = 0.5$"),
    # the punch pressure ~ (a - |x|)^(-1/2) is not in L2: its error on the core |x| < a/2
    # (as ngdual.verification.analytic); sigma (~ r^(-1/2)) is in L2 everywhere
    "flat-punch": TruthProblem("flat-punch", (), 1, "flat punch", 206, 0.125),
}
TRUTH_ADAPTIVE = {
    # key: (marking, theta); each run from level 1 until its mesh is as large as the finest
    # uniform level's
    "max 0.5": ("max", 0.5), "max 0.25": ("max", 0.25),
    "dorfler 0.5": ("dorfler", 0.5), "dorfler 0.3": ("dorfler", 0.3),
}
PEER_ORDERS = (1, 2)


# --- the tasks ----------------------------------------------------------------------------------

def _cost(level: int, friction: bool) -> float:
    return (4.0 if friction else 1.5) ** level / 50


def solve(plan: Plan, problem_or_scene: str, level: int, overrides=(), fields: bool | None = None
          ) -> Task:
    """The task solving a scene (a problem key of :data:`SCENES` or a scene name) on ``level``.

    Without overrides, the solve on :attr:`Plan.field_level` keeps the field arrays,
    so that the tables and the figures share one solve.
    """
    scene = SCENES.get(problem_or_scene, problem_or_scene)
    overrides = list(overrides)
    if fields is None:
        fields = not overrides and level == plan.field_level
    label = f"{scene} L{level}" + (" " + " ".join(overrides) if overrides else "")
    return Task("solve", {"scene": scene, "level": level, "overrides": overrides,
                          "fields": bool(fields)}, label,
                _cost(level, "frictionless" not in scene))


def _rho_overrides(rho1: float, rho2: float) -> list[str]:
    out = [UZAWA]
    if rho1 != 1.0:
        out.append(f"solver.rho1={rho1}")
    if rho2 != 1.0:
        out.append(f"solver.rho2={rho2}")
    return out


def rho_tasks(plan: Plan) -> dict[str, dict]:
    """The rho searches of the Uzawa algorithms: ``frictionless[(level, rho)]`` and
    ``coulomb[(level, rho1, rho2)]``."""
    fl = {(lv, r): solve(plan, "frictionless", lv, [UZAWA] + ([f"solver.rho={r}"] if r != 1.0
                                                                else []))
          for lv in plan.levels for r in plan.rho_grid}
    co = {}
    for lv in plan.levels:
        pairs = ([(r1, r2) for r1 in plan.rho1_grid for r2 in plan.rho2_grid]
                 if lv <= plan.rho_level else [(1.0, 1.0), *plan.rho_cross])
        for r1, r2 in pairs:
            co[(lv, r1, r2)] = solve(plan, "coulomb", lv, _rho_overrides(r1, r2))
    return {"frictionless": fl, "coulomb": co}


GAP_CASES = {
    # key: (scene, overrides); solved with the default solver on Plan.gap_level and with the
    # thesis' nested Uzawa on Plan.uzawa_gap_level ("uzawa-" + key)
    "gap0": ("thesis-3.46-coulomb-gap0", []),
    "gap0-hhat1": ("thesis-3.46-coulomb-gap0", ["contact.hhat_factor=1"]),
    "abs-hhat1": ("thesis-3.46-coulomb-gap-abs", ["contact.hhat_factor=1"]),
    "abs-hhat2": ("thesis-3.46-coulomb-gap-abs", []),
    "3125-hhat1": ("thesis-3.46-coulomb-gap-3125", ["contact.hhat_factor=1"]),
    "3125-hhat2": ("thesis-3.46-coulomb-gap-3125", []),
}


def gap_tasks(plan: Plan) -> dict[str, Task]:
    """Figs. 3.24-3.28: every case of :data:`GAP_CASES` with both solvers, and
    ``uzawa-gap0-eps8``: nested Uzawa with eps_2 = 1e-8 (Fig. 3.25)."""
    out = {}
    for key, (scene, overrides) in GAP_CASES.items():
        out[key] = solve(plan, scene, plan.gap_level, overrides, fields=True)
        out[f"uzawa-{key}"] = solve(plan, scene, plan.uzawa_gap_level, [UZAWA, *overrides],
                                    fields=True)
    out["uzawa-gap0-eps8"] = solve(plan, "thesis-3.46-coulomb-gap0", plan.uzawa_gap_level,
                                   [UZAWA, "solver.eps2=1e-08"], fields=True)
    return out


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


def outcome(record: dict | None) -> str:
    """One line on how a solve ended: iterations, or the failure and its message."""
    if record is None:
        return "missing"
    if record["status"] != "ok":
        return f"{record['status']}: {record.get('message', '')[:200]}"
    return (f"ok, outer {record['iterations']['outer']}, inner {record['iterations']['inner']}, "
            f"{record['timings_s']['total']:.1f} s")


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


ADAPTIVE_RUNS = {
    # key: (marking, theta, initial level)
    "max": ("max", 0.5, 1),
    "fraction": ("fraction", 0.2, 2),
    "dorfler": ("dorfler", 0.5, 1),
}


def adapt_task(plan: Plan, problem: str, strategy: str) -> Task:
    marking, theta, level = ADAPTIVE_RUNS[strategy]
    refinements = {"max": plan.max_marking_refinements, "fraction": plan.fraction_refinements,
                   "dorfler": plan.dorfler_refinements}[strategy]
    snapshots = {"max": plan.max_marking_snapshots,
                 "fraction": plan.fraction_snapshots}.get(strategy, [])
    scene = SCENES[problem]
    return Task("adapt", {"scene": scene, "marking": marking, "theta": theta,
                          "steps": refinements + 1, "level": level, "overrides": [],
                          "snapshots": list(snapshots)},
                f"{scene} {marking} theta={theta}", 4.0 * refinements)


def truth_solve(plan: Plan, problem: str, level: int, uzawa: bool = False) -> Task:
    """A uniform solve of a :data:`TRUTH_PROBLEMS` scene that keeps its sample arrays."""
    tp = TRUTH_PROBLEMS[problem]
    overrides = [*tp.overrides, *([UZAWA] if uzawa else [])]
    return Task("solve", {"scene": tp.scene, "level": level, "overrides": overrides,
                          "fields": False, "samples": True},
                f"{tp.scene} L{level} samples" + (" uzawa" if uzawa else ""),
                _cost(level + 1, problem == "coulomb"))


def truth_adapt(plan: Plan, problem: str, strategy: str) -> Task:
    """An adaptive run of a :data:`TRUTH_PROBLEMS` scene keeping every step's samples, up to
    the triangles of its finest uniform level."""
    tp = TRUTH_PROBLEMS[problem]
    marking, theta = TRUTH_ADAPTIVE[strategy]
    finest = plan.truth_levels(problem)[-1]
    return Task("adapt", {"scene": tp.scene, "marking": marking, "theta": theta, "steps": 60,
                          "level": 1, "overrides": list(tp.overrides), "snapshots": [],
                          "samples": True, "max_elements": tp.level1_elements * 4 ** (finest - 1)},
                f"{tp.scene} {strategy} samples", 2.0 * finest)


def peer_solve(plan: Plan, problem: str, level: int, order: int) -> Task:
    """The primal peer on a :data:`TRUTH_PROBLEMS` scene, pressure samples fine enough for
    the overkill's Gamma_C edges."""
    tp = TRUTH_PROBLEMS[problem]
    return Task("peer", {"scene": tp.scene, "level": level, "order": order,
                         "overrides": list(tp.overrides),
                         "subdivisions": 2 ** max(plan.overkill_level(problem) - level, 0)},
                f"{tp.scene} L{level} peer P{order}", _cost(level, False))


def peer_levels(plan: Plan, problem: str) -> list[int]:
    """The peer's levels: those of ngdual and one beyond (an independent check of the
    overkill)."""
    levels = plan.truth_levels(problem)
    return [*levels, levels[-1] + 1]


def truth_tasks(plan: Plan, problem: str) -> dict[str, list[Task]]:
    """Every task of the true-error study of one problem, by method."""
    levels = plan.truth_levels(problem)
    out = {"uniform, active set": [truth_solve(plan, problem, lv) for lv in levels],
           "uniform, Uzawa": [truth_solve(plan, problem, lv, True) for lv in levels]}
    for strategy in TRUTH_ADAPTIVE:
        out[f"adaptive {strategy}"] = [truth_adapt(plan, problem, strategy)]
    for order in PEER_ORDERS:
        out[f"primal P{order}"] = [peer_solve(plan, problem, lv, order)
                                   for lv in peer_levels(plan, problem)]
    return out


def reference_tasks(plan: Plan, problem: str) -> list[Task]:
    """The overkill and the level below it (the Richardson check)."""
    level = plan.overkill_level(problem)
    return [truth_solve(plan, problem, level - 1), truth_solve(plan, problem, level)]


MANUFACTURED_CASES = ("frictionless", "coulomb-nodes")


def manufactured_tasks(plan: Plan) -> dict[str, Task]:
    """Manufactured cases (exact errors) on uniform levels 1..K-1 and Doerfler theta = 0.5
    from level 1 (2K steps): the estimator against the truth."""
    levels = list(range(1, plan.max_level))
    out = {f"{case}, uniform L{lv}": Task("manufactured", {"case": case, "level": lv},
                                           f"manufactured {case} L{lv}", 1.5 ** lv / 20)
           for case in MANUFACTURED_CASES for lv in levels}
    for case in MANUFACTURED_CASES:
        out[f"{case}, adaptive"] = Task(
            "manufactured", {"case": case, "level": 1, "marking": "dorfler", "theta": 0.5,
                             "steps": 2 * plan.max_level}, f"manufactured {case} dorfler", 5.0)
    return out


def studies(plan: Plan) -> dict[str, list[Task]]:
    """Every study a script may declare in ``STUDIES``, as lists of tasks."""
    rho = rho_tasks(plan)
    out = {
        "dofs": [Task("dofs", {"scene": SCENES["coulomb"], "level": lv}, f"dofs L{lv}", 0.1)
                 for lv in plan.levels],
        "rho-frictionless": list(rho["frictionless"].values()),
        "rho-coulomb": list(rho["coulomb"].values()),
        "gaps": list(gap_tasks(plan).values()),
        "adaptive": [adapt_task(plan, p, s) for p in SCENES for s in ADAPTIVE_RUNS],
    }
    for problem in SCENES:
        out[f"uniform-{problem}"] = [solve(plan, problem, lv) for lv in plan.levels]
    out["variants"] = [solve(plan, problem, lv, v.overrides) for v in SOLVER_VARIANTS
                       for problem in v.problems for lv in plan.levels]
    out["work-precision-reference"] = [solve(plan, problem, lv) for problem in SCENES
                                       for lv in plan.work_precision_reference_levels]
    out["manufactured"] = list(manufactured_tasks(plan).values())
    out["truth"] = [t for problem in TRUTH_PROBLEMS for t in
                    [*reference_tasks(plan, problem),
                     *(t for ts in truth_tasks(plan, problem).values() for t in ts)]]
    return out


# --- numbers derived from records (pure functions) ----------------------------------------------

def require(record: dict | None, what: str) -> dict:
    """``record`` if its task finished with status ok, else a clear error naming it."""
    if record is None:
        raise RuntimeError(f"{what}: no record (the task did not finish; see run.json)")
    if record.get("status") != "ok":
        raise RuntimeError(f"{what}: {record.get('status')}: {record.get('message', '')}")
    return record


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


def reference_norms(records: list[dict]) -> dict:
    """Aitken Delta^2 limits of the norms of the last three uniform levels (Section 3.4)."""
    last = [r["norms"] for r in records[-3:]]
    if len(last) < 3:
        return dict(last[-1]) if last else {}
    return {q: (aitken_extrapolate([n[q] for n in last])
                if all(n.get(q) is not None for n in last) else None) for q in last[0]}


def errors(records: list[dict], reference: dict) -> list[dict]:
    """e_i(q) per quantity and e_tot of (3.124) for each record (None if it has no norms)."""
    out = []
    for r in records:
        if not r or "norms" not in r:
            out.append(None)
            continue
        per, tot = total_error(r["norms"], reference)
        out.append({"errors": per, "e_tot": tot})
    return out


def rates(ndofs: list[float], errs: list[float]) -> list[float | None]:
    """alpha between consecutive levels: -2 log(e_i / e_{i+1}) / log(N_i / N_{i+1}) (3.4)."""
    out: list[float | None] = [None]
    for (n0, e0), (n1, e1) in zip(zip(ndofs, errs), zip(ndofs[1:], errs[1:])):
        ok = e0 and e1 and e0 > 0 and e1 > 0
        out.append(float(-2 * math.log(e0 / e1) / math.log(n0 / n1)) if ok else None)
    return out


def iterations_key(record: dict) -> tuple:
    """The fewest iterations win: total inner then outer (nested), outer (Uzawa), then time."""
    it = record["iterations"]
    return (it.get("inner", 0) or it.get("outer", 0), it.get("outer", 0),
            record["timings_s"]["solve"])


def best(records: dict) -> tuple | None:
    """The key of the converged record with the fewest iterations (see :func:`iterations_key`)."""
    ok = {k: r for k, r in records.items() if r and r.get("status") == "ok"}
    return min(ok, key=lambda k: iterations_key(ok[k])) if ok else None


def richardson_check(d_coarse: float, d_fine: float) -> dict:
    """The overkill's own error from the distances d of the two levels below it (L-2, L-1)
    to it, for errors e_k = C r^k orthogonal between levels (Galerkin orthogonality:
    d_k^2 = e_k^2 - e_L^2): (d_{L-2} / d_{L-1})^2 = (1 + r^2) / r^2, so
    r^2 = 1 / (ratio^2 - 1) and e_L = d_{L-1} r / (1 - r^2)^(1/2). ``rate`` = -log2 r (the
    order in h); None where the distances do not decrease (ratio <= 1).

    >>> round(richardson_check(5 ** 0.5, 1.0)["overkill_error"], 12)  # r = 1/2
    0.57735026919
    """
    if not (d_coarse and d_fine) or d_coarse <= d_fine:
        return {"r": None, "rate": None, "overkill_error": None}
    r = 1 / math.sqrt((d_coarse / d_fine) ** 2 - 1)
    if r >= 1:
        return {"r": r, "rate": -math.log2(r), "overkill_error": None}
    return {"r": r, "rate": -math.log2(r), "overkill_error": d_fine * r / math.sqrt(1 - r * r)}


# measures of the true-error studies: key -> (what, how it is made relative)
TRUE_MEASURES = {"pressure": "relative L2 error of the contact pressure on Gamma_C",
                 "sigma_energy": "relative compliance-norm error of sigma"}


def _measures(errors: dict) -> dict:
    """The relative errors plotted (:data:`TRUE_MEASURES`) and the absolute total error
    e = (||sigma - sigma_ref||^2 + ||u - u_ref||^2 + ||eta - eta_ref||^2)^(1/2) (L2; div sigma
    has no error when f = 0) that the estimator is compared with."""
    out = {"pressure": errors.get("pressure_rel"),
           "pressure_max": errors.get("pressure_max"),
           "sigma_energy": errors["sigma_energy"] / errors["sigma_energy_norm"],
           "e_true": math.sqrt(sum(errors.get(k, 0.0) ** 2 for k in ("sigma", "u", "eta")))}
    return out


def _candidates(ctx: Context, problem: str) -> list[tuple[dict, dict]]:
    """(row, sample arrays) of every solution of the true-error study of ``problem``."""
    out = []
    for method, tasks in truth_tasks(ctx.plan, problem).items():
        for task, record in zip(tasks, ctx.compute(tasks)):
            if record is None or record.get("status") != "ok":
                out.append(({"method": method, "status": (record or {}).get("status",
                                                                           "missing"),
                             "message": (record or {}).get("message", "")[:200]}, {}))
                continue
            arrays = ctx.arrays(task)
            if task.kind == "adapt":
                for r in record["history"]:
                    prefix = f"s{r['step']}_"
                    out.append(({"method": method, "status": "ok", "level_or_step": r["step"],
                                 "ndof": r["dofs"]["total"], "elements": r["elements"],
                                 "time_s": r["cumulative_s"], "eta": r["eta"]},
                                {k[len(prefix):]: v for k, v in arrays.items()
                                 if k.startswith(prefix)}))
            else:
                eta = record.get("estimator", {}).get("eta")
                out.append(({"method": method, "status": "ok",
                             "level_or_step": task.params["level"], "ndof": record["ndof"],
                             "time_s": record["timings_s"]["total"], "eta": eta}, arrays))
    return out


def true_error_study(ctx: Context, problem: str) -> dict:
    """True errors of every method of one problem against its overkill, cached in
    ``DIR/records`` (the errors are recomputed only when a task id changes).

    Returns ``{"rows": [...], "reference": {...}}``: one row per solution (method,
    level or adaptive step, DOFs, wall time, estimator eta, ``pressure``, ``pressure_max``,
    ``sigma_energy``, ``e_true``, :func:`_measures`), and the overkill's level, DOFs and its
    Richardson check per measure.
    """
    from .scene import load_scene
    from .verification.reference import true_errors

    tp = TRUTH_PROBLEMS[problem]
    below, top = reference_tasks(ctx.plan, problem)
    ids = [below.id, top.id] + [t.id for ts in truth_tasks(ctx.plan, problem).values()
                                for t in ts]
    digest = hashlib.sha1(json.dumps(ids).encode()).hexdigest()[:12]
    cache = ctx.records_dir / f"true-errors-{problem}-{digest}.json"
    if cache.is_file():
        return json.loads(cache.read_text())
    lam, mu = load_scene(tp.scene, list(tp.overrides)).material.lame
    ref_record = require(ctx.record(top), top.label)
    reference = ctx.arrays(top)
    rows = []
    for row, arrays in _candidates(ctx, problem):
        if arrays:
            row.update(_measures(true_errors(arrays, reference, lam, mu, tp.pressure_window)))
        rows.append(row)
    # Richardson: the two levels below the overkill against it
    finest = next(r for r in rows if r["method"] == "uniform, active set"
                  and r.get("level_or_step") == ctx.plan.truth_levels(problem)[-1])
    below_errors = _measures(true_errors(ctx.arrays(below), reference, lam, mu,
                                         tp.pressure_window))
    check = {k: {"d_L-2": finest.get(k), "d_L-1": below_errors[k],
                 **richardson_check(finest.get(k), below_errors[k])}
             for k in ("pressure", "sigma_energy")}
    data = _plain({"rows": rows, "reference": {
        "scene": tp.scene, "overrides": list(tp.overrides), "level": top.params["level"],
        "ndof": ref_record["ndof"], "time_s": ref_record["timings_s"]["total"],
        "richardson": check}, "versions": versions()})
    write_json(data, cache)
    return data


# --- the context the scripts see ----------------------------------------------------------------

@dataclass
class Context:
    """What a figure script works with: the plan, the records, the output folders."""

    out: Path
    plan: Plan
    runner: Runner | None = None
    script: str = ""
    written: list = field(default_factory=list)

    @property
    def records_dir(self) -> Path:
        return self.out / "records"

    def studies(self) -> dict[str, list[Task]]:
        return studies(self.plan)

    def compute(self, tasks: list[Task], desc: str = "sweep") -> list[dict | None]:
        """Records of ``tasks``; missing ones are computed (needs a runner)."""
        records = [load_record(self.records_dir, t) for t in tasks]
        missing = [t for t, r in zip(tasks, records) if r is None]
        if missing and self.runner is not None:
            self.runner.run(missing, self.records_dir, desc)
            records = [load_record(self.records_dir, t) for t in tasks]
        return records

    def record(self, task: Task) -> dict | None:
        return self.compute([task])[0]

    def arrays(self, task: Task) -> dict[str, np.ndarray]:
        return load_arrays(self.records_dir, task) if self.record(task) else {}

    # shared studies
    def uniform(self, problem: str) -> list[dict | None]:
        return self.compute([solve(self.plan, problem, lv) for lv in self.plan.levels])

    def reference(self, problem: str) -> dict:
        return reference_norms([r for r in self.uniform(problem) if r])

    def fields(self, problem: str) -> tuple[dict | None, dict]:
        task = solve(self.plan, problem, self.plan.field_level)
        return self.record(task), self.arrays(task)

    def both_fields(self) -> dict[str, tuple[dict, dict]]:
        """Record and field arrays of both problems on :attr:`Plan.field_level`."""
        out = {}
        for problem in SCENES:
            record, arrays = self.fields(problem)
            out[problem] = (require(record, f"{SCENES[problem]} level "
                                            f"{self.plan.field_level}"), arrays)
        return out

    def titles(self, what: str = "") -> list[str]:
        """Panel titles: the two problems, the level and the DOFs."""
        return [f"{what}{PROBLEM_TITLES[p]}, level {self.plan.field_level}" for p in SCENES]

    # output
    def data_path(self, name: str) -> Path:
        path = self.out / "data" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        return path

    def figure_stem(self, name: str) -> Path:
        path = self.out / "figures" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        return path

    def header(self, description: str) -> dict:
        return {"description": description, "script": self.script, "plan": self.plan.describe(),
                "versions": versions()}

    def write_json(self, name: str, data: dict, description: str) -> Path:
        path = write_json({**self.header(description), **_plain(data)}, self.data_path(name))
        self.written.append(path)
        return path

    def write_csv(self, name: str, rows: list[dict], description: str) -> Path:
        """Rows as CSV; ``#`` lines first: description, plan and package versions."""
        path = self.data_path(name)
        columns = list(dict.fromkeys(k for row in rows for k in row))
        tmp = path.with_name(path.name + ".tmp")
        with open(tmp, "w", newline="") as fh:
            for key, value in self.header(description).items():
                fh.write(f"# {key}: {json.dumps(value) if not isinstance(value, str) else value}"
                         "\n")
            writer = csv.DictWriter(fh, columns)
            writer.writeheader()
            for row in rows:
                writer.writerow({k: _csv_value(row.get(k)) for k in columns})
        os.replace(tmp, path)
        self.written.append(path)
        return path

    def entry(self, thesis: str, title: str, files: list, numbers: dict | None = None,
              thesis_says: str = "", notes: str = "", table: str = "") -> Path:
        """Register this script's outputs for the index (``DIR/entries/<script>.json``).

        ``numbers``: our headline numbers; ``thesis_says``: what the thesis states
        about them; ``table``: a markdown table shown in the index.
        """
        files = [Path(f) for f in files]
        data = {"script": self.script, "thesis": thesis, "title": title,
                "files": [str(f.relative_to(self.out)) for f in files],
                "numbers": _plain(numbers or {}), "thesis_says": thesis_says, "notes": notes,
                "table": table}
        return write_json(data, self.out / "entries" / f"{self.script}.json")


def _csv_value(value):
    if isinstance(value, float):
        return repr(value) if np.isfinite(value) else ""
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        return _csv_value(value.item())
    return "" if value is None else value


def _plain(value):
    """numpy scalars / arrays as plain JSON data; NaN as None."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return _plain(value.item())
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


# --- the scripts and the run --------------------------------------------------------------------

def figures_dir(source: str | Path | None = None) -> Path:
    """``--source``, else ``NGDUAL_FIGURES_DIR``, else ``figures/`` of the source checkout."""
    folder = Path(source or os.environ.get(SOURCE_ENV)
                  or Path(__file__).resolve().parent.parent / "figures")
    if not folder.is_dir():
        raise FileNotFoundError(f"no figures folder at {folder}: the figure scripts ship with "
                                f"the source checkout (pip install -e .); point {SOURCE_ENV} or "
                                "--source at its figures/ folder")
    return folder


def figure_scripts(source: str | Path | None = None) -> list[Path]:
    """The figure scripts (``figures/*.py`` not starting with ``_``), sorted by name."""
    return sorted(p for p in figures_dir(source).glob("*.py") if not p.name.startswith("_"))


def load_script(path: Path):
    spec = importlib.util.spec_from_file_location(f"ngdual_figure_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for name in ("THESIS", "STUDIES", "run"):
        if not hasattr(module, name):
            raise AttributeError(f"figure script {path} defines no {name}")
    return module


_NUMBER = re.compile(r"(Fig|Table)s?\.\s*(\d+)\.(\d+)")


def thesis_order(label: str) -> tuple:
    """Sort key of a thesis reference: chapter, number, figures before tables."""
    match = _NUMBER.search(label)
    if not match:
        return (99, 99, 0)
    return (int(match.group(2)), int(match.group(3)), 0 if match.group(1) == "Fig" else 1)


def run_figures(max_level: int | None = None, out: str | Path = "figures-output",
                scheduler: str | None = None, workers: int | None = None,
                processes: bool = True, only: list[str] | None = None,
                source: str | Path | None = None, progress: bool | None = None) -> dict:
    """Compute the studies, run the selected scripts, write the index. Returns the run summary."""
    from tqdm import tqdm

    start = time.perf_counter()
    max_level = max_level or DEFAULT_MAX_LEVEL
    plan = Plan(max_level)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    scripts = figure_scripts(source)
    if only:
        scripts = [p for p in scripts if any(pat in p.stem for pat in only)]
        if not scripts:
            raise ValueError(f"no figure script matches {only}")
    modules = {p.stem: load_script(p) for p in scripts}
    summary = {"max_level": max_level, "plan": plan.describe(), "out": str(out),
               "scheduler": scheduler or "LocalCluster", "workers": workers,
               "processes": processes,
               "started": datetime.now().astimezone().isoformat(timespec="seconds"),
               "versions": versions(), "scripts": {}, "failed_tasks": {}}
    with Runner(scheduler, workers, processes, progress) as runner:
        ctx = Context(out, plan, runner)
        # COMPUTE: every study the selected scripts need, as one sweep (both workers busy)
        all_studies = ctx.studies()
        needed = list(dict.fromkeys(s for m in modules.values() for s in m.STUDIES))
        tasks = [t for name in needed for t in all_studies[name]]
        t0 = time.perf_counter()
        runner.run(tasks, ctx.records_dir, desc="sweeps")
        summary["sweep_s"] = time.perf_counter() - t0
        summary["tasks"] = len({t.id for t in tasks})
        summary["computed_tasks"] = runner.computed
        # WRITE + PLOT: the scripts read the records
        for stem, module in tqdm(modules.items(), desc="figures", unit="script",
                                 disable=None if progress is None else not progress):
            ctx.script = stem
            t0 = time.perf_counter()
            try:
                module.run(ctx)
                status = "ok"
            except Exception as err:  # noqa: BLE001 - one broken figure must not stop the rest
                import traceback

                status = f"error: {type(err).__name__}: {err}"
                print(f"ngdual figures: {stem} failed:\n{traceback.format_exc()}", file=sys.stderr)
            summary["scripts"][stem] = {"status": status, "seconds": time.perf_counter() - t0}
        summary["failed_tasks"] = _failed_tasks(ctx, tasks)
    summary["seconds"] = time.perf_counter() - start
    write_json(_plain(summary), out / "run.json")
    write_index(out, summary, source)
    return summary


def _failed_tasks(ctx: Context, tasks: list[Task]) -> dict:
    out = {}
    for t in {t.id: t for t in tasks}.values():
        try:
            record = json.loads((ctx.records_dir / f"{t.id}.json").read_text())
        except (OSError, ValueError):
            out[t.id] = {"label": t.label, "status": "missing", "message": ""}
            continue
        if record.get("status") != "ok":
            out[t.id] = {"label": t.label, "status": record.get("status"),
                         "message": record.get("message", "")[:500]}
    return out


def _format(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (list, tuple)) and any(isinstance(v, (list, tuple)) for v in value):
        return ", ".join("(" + _format(v) + ")" if isinstance(v, (list, tuple)) else _format(v)
                         for v in value)
    if isinstance(value, (list, tuple)):
        return ", ".join(_format(v) for v in value)
    return str(value)


def write_index(out: Path, summary: dict, source: str | Path | None = None) -> Path:
    """``DIR/index.md`` from ``figures/index_template.md`` and the entries of the scripts."""
    template = (figures_dir(source) / "index_template.md").read_text()
    entries = []
    for path in sorted((out / "entries").glob("*.json")):
        entries.append(json.loads(path.read_text()))
    entries.sort(key=lambda e: thesis_order(e["thesis"]))
    blocks = []
    for e in entries:
        status = summary["scripts"].get(e["script"], {}).get("status", "from an earlier run")
        lines = [f"### {e['thesis']}: {e['title']}", "",
                 f"Script `figures/{e['script']}.py` ({status}).", ""]
        images = [f for f in e["files"] if f.endswith(".png")]
        lines += [f"![{e['thesis']}]({f})" for f in images[:1]]
        lines += ["", "Files: " + ", ".join(f"[{Path(f).name}]({f})" for f in e["files"]), ""]
        if e["numbers"]:
            lines += ["| quantity | ours |", "|---|---|"]
            lines += [f"| {k} | {_format(v)} |" for k, v in e["numbers"].items()]
            lines.append("")
        if e.get("table"):
            lines += [e["table"], ""]
        if e["thesis_says"]:
            lines += [f"Thesis: {e['thesis_says']}", ""]
        if e["notes"]:
            lines += [f"Notes: {e['notes']}", ""]
        blocks.append("\n".join(lines))
    failed = summary.get("failed_tasks", {})
    failures = "\n".join(f"* `{k}` ({v['label']}): **{v['status']}** {v['message']}"
                         for k, v in failed.items()) or "none"
    text = (template.replace("{{max_level}}", str(summary["max_level"]))
            .replace("{{started}}", summary["started"])
            .replace("{{seconds}}", f"{summary.get('seconds', 0):.0f}")
            .replace("{{tasks}}", f"{summary.get('tasks', 0)} tasks, "
                                  f"{summary.get('computed_tasks', 0)} computed in this run")
            .replace("{{versions}}", ", ".join(f"{k} {v}" for k, v in summary["versions"].items()
                                               if v and k != "platform"))
            .replace("{{plan}}", "\n".join(f"* `{k}`: {_format(v)}"
                                           for k, v in summary["plan"].items()))
            .replace("{{entries}}", "\n".join(blocks))
            .replace("{{failures}}", failures))
    path = out / "index.md"
    path.write_text(text)
    return path


GALLERY = ("fig_3_11_von_mises", "fig_3_19_tangential_displacement", "fig_3_23_rho_grid",
           "fig_4_13_", "work_precision",
           *(f"contact_scenes_{name}" for name in ("hertz-cylinder", "flat-punch",
                                                    "cattaneo-mindlin", "wedge")))


def write_gallery(out: str | Path, dest: str | Path, width: int = 900,
                  names: tuple[str, ...] = GALLERY) -> list[Path]:
    """Small copies (``width`` pixels, 8-bit palette) of the PNGs starting with ``names``,
    for the README."""
    from PIL import Image

    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    written = []
    for name in names:
        for path in sorted((Path(out) / "figures").glob(f"{name}*.png"))[:1]:
            with Image.open(path) as img:
                img = img.convert("RGB")
                if img.width > width:
                    img = img.resize((width, round(img.height * width / img.width)),
                                     Image.LANCZOS)
                target = dest / re.sub(r"_step\d+", "", path.name)  # stable for the README
                img.quantize(colors=256, method=Image.FASTOCTREE).save(target, optimize=True)
                written.append(target)
    return written


def script_main(path: str) -> None:
    """``python figures/<script>.py [--max-level K] [--out DIR]``: run one script (and its
    studies), as ``ngdual figures --only <script>`` does."""
    import argparse

    p = argparse.ArgumentParser(description=f"regenerate {Path(path).stem}")
    p.add_argument("--max-level", type=int, default=DEFAULT_MAX_LEVEL)
    p.add_argument("--out", default="figures-output")
    p.add_argument("--threads", action="store_true", help="dask workers as threads")
    args = p.parse_args()
    summary = run_figures(args.max_level, args.out, processes=not args.threads,
                          only=[Path(path).stem], source=Path(path).parent)
    print(f"wrote {Path(args.out) / 'index.md'} ({summary['seconds']:.0f} s)")


def markdown_table(rows: list[dict], columns: dict[str, str]) -> str:
    """A markdown table of ``rows``; ``columns`` maps keys to headers (missing values: -).

    >>> print(markdown_table([{"a": 1, "b": 0.5}], {"a": "A", "b": "B"}))
    | A | B |
    |---|---|
    | 1 | 0.5 |
    """
    head = "| " + " | ".join(columns.values()) + " |"
    rule = "|" + "---|" * len(columns)
    body = ["| " + " | ".join("-" if r.get(k) is None else _format(r[k]) for k in columns) + " |"
            for r in rows]
    return "\n".join([head, rule, *body])


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
    from . import plot

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
                       "xlabel": r"$x_1$ on $\Gamma_C$ [length]",
                       "ylabel": rf"${tex}^h$ [stress units]",
                       "curves": [{"x": a["edge_x"][order], "y": a[key][order],
                                   "drawstyle": "steps-mid", "label": rf"${tex}^h$"}]})
        active = a["edge_active"].astype(bool)
        numbers[f"max |{key}| on A_C, {PROBLEM_TITLES[p]}"] = float(np.abs(a[key][active]).max())
        numbers[f"max |{key}| overall (corners), {PROBLEM_TITLES[p]}"] = float(
            np.abs(a[key]).max())
    figs = plot.plot_curves(panels, ctx.figure_stem(stem),
                            rf"{thesis}: {what} ${tex}^h$ on $\Gamma_C$")
    return figs, data, numbers


NEUMANN_STYLE = {"frictionless": {"color": "tab:blue"}, "coulomb": {"color": "tab:red", "ls": "--"}}


def neumann_multiplier(ctx: Context, thesis: str, component: int, stem: str) -> None:
    """Figs. 3.15 / 3.16: phi_i^h on Gamma_N for both problems (CSV, plot, index entry)."""
    from . import plot

    key, tex = f"phi{component}", rf"\varphi_{component}"
    fields = ctx.both_fields()
    a0, a1 = (fields[p][1] for p in ("frictionless", "coulomb"))
    data = ctx.write_csv(f"{stem}.csv", curve_rows(fields, "phi_x", [key]),
                         f"phi_{component}^h at the fine vertices of Gamma_N (x_2 = 1), "
                         "both problems")
    panels = [{"title": f"{PROBLEM_TITLES[p]}, level {ctx.plan.field_level}",
               "xlabel": r"$x_1$ on $\Gamma_N$ [length]", "ylabel": rf"${tex}^h$ [length]",
               "curves": [{"x": a["phi_x"], "y": a[key], "label": PROBLEM_TITLES[p],
                           **NEUMANN_STYLE[p]}]}
              for p, (_, a) in fields.items()]
    figs = plot.plot_curves(panels, ctx.figure_stem(stem),
                            rf"{thesis}: ${tex}^h$ on the Neumann boundary $\Gamma_N$")
    name = f"phi_{component}"
    ctx.entry(thesis, f"{name} on Gamma_N", [*figs, data],
              {f"range {name}, mu_f = 0": [float(a0[key].min()), float(a0[key].max())],
               f"range {name}, mu_f = 0.5": [float(a1[key].min()), float(a1[key].max())],
               f"max |{name}(0.5) - {name}(0)|": float(np.abs(a1[key] - a0[key]).max())},
              thesis_says="no difference between the frictionless and the frictional case.")
