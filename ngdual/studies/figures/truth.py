"""The true-error studies: every method's solutions against adaptive references.

For each problem of :data:`~ngdual.studies.figures.plan.TRUTH_PROBLEMS` the uniform
solves, the adaptive runs (one per goal at order 0 and at the orders
:data:`~ngdual.studies.figures.plan.ORDERS`) and the primal peers are compared with a
reference per measure: the last step of one of the adaptive runs.

The own error of a run's last step is estimated per measure by Richardson
(:data:`~ngdual.studies.figures.own_errors.EXTRAPOLATION`: orthogonal errors for sigma,
aligned ones for the pressure) from the distances of the two steps before it, each with about
2x the unknowns of the one before (a run that stalls, growing by less than
:data:`~ngdual.studies.figures.own_errors.STALLED` per step, has no estimate). Where a run
gives no such estimate, two independent solutions stand in for it
(:func:`~ngdual.studies.figures.hats.three_cornered_hat`), whose three pairwise distances give
each one's error if the three errors are orthogonal: for sigma the last step of its
:func:`~ngdual.studies.figures.hats.partner` and the finest uniform level, on meshes of other
families; for the pressure the two solutions nearest to it
(:func:`~ngdual.studies.figures.hats.nearest_corners`) among the other runs' last steps and
the finest uniform level. A hat that another run's Richardson estimate contradicts by the
triangle inequality is no own error (:func:`~ngdual.studies.figures.hats.hat_bound`). The
stress goal's steps up to a size are solved again by PEERS_2 on their meshes
(:func:`~ngdual.studies.figures.own_errors.order_reference`): their last one is the sigma
reference where its own error, Richardson from the two before it, is smaller. The reference of
a measure is the step with the smallest own error, and it resolves the targets at least 1 /
:data:`RESOLVES` times its error. The steps of a run are nested meshes (bisection), so their
distances to its last step are exact integrals; every other candidate's mesh crosses the
reference's triangles, and the quadrature error this costs
(:mod:`ngdual.verification.overkill`) is measured by integrating the sigma error again on the
reference's triangles split in four (:func:`split_samples`). The errors are cached in the
records folder.

No error identity replaces the references: for the exact displacement, 2 (J(sigma_h) -
J(sigma)) with the complementary energy J(tau) = a(tau, tau) / 2 - <tau n, u_D> equals
||sigma - sigma_h||_A^2 only up to -2 (as sigma_h, eta - eta_h) and the weakly imposed
traction and contact conditions: PEERS' sigma_h is symmetric only against the P1
rotations, so it is not statically admissible, and these terms are of the order of the
squared error itself.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...io import plain, versions, write_json
from ..sweep import estimator
from .hats import hat_checks
from .own_errors import TRUE_MEASURES, distance, measures, order_reference, run_check
from .plan import TRUTH_PROBLEMS, method_order
from .tasks import truth_tasks

if TYPE_CHECKING:
    from .output import Context

# the modules whose code measures the true errors: a change to one recomputes the cached ones
MEASURING = ("truth.py", "own_errors.py", "hats.py")
# a target is resolved when the reference's own error is at most this share of it
RESOLVES = 1 / 3
# the P2 nodes of the four red children of the reference triangle, in barycentric
# coordinates of the parent (vertices 0, 1, 2; midpoints m01, m12, m20)
_V = np.eye(3)
_M = {(0, 1): (_V[0] + _V[1]) / 2, (1, 2): (_V[1] + _V[2]) / 2, (2, 0): (_V[2] + _V[0]) / 2}
CHILDREN = ((_V[0], _M[(0, 1)], _M[(2, 0)]), (_M[(0, 1)], _V[1], _M[(1, 2)]),
            (_M[(2, 0)], _M[(1, 2)], _V[2]), (_M[(1, 2)], _M[(2, 0)], _M[(0, 1)]))


def split_samples(samples: dict) -> dict:
    """The same P2 fields on every triangle split into its four red children (midpoints):
    a reference with four times the quadrature points, to measure the quadrature error of
    a candidate whose edges cross the reference's triangles."""
    from ...verification.overkill import P2_NODES, p2_basis

    tri_xy = samples["vertices"][samples["triangles"]]                 # (ne, 3, 2)
    ne = len(tri_xy)
    # barycentric coordinates (child, P2 node, parent vertex) of the children's P2 nodes
    nodes = np.array([[a * x + b * y + (1 - x - y) * c for x, y in P2_NODES]
                      for a, b, c in CHILDREN])
    basis = p2_basis(nodes.reshape(-1, 3)).reshape(4, 6, 6)
    xy = np.einsum("knv,evd->eknd", nodes, tri_xy)                     # (ne, 4, 6, 2)
    vertices = xy[:, :, :3].reshape(-1, 2)
    out = {"vertices": vertices, "triangles": np.arange(len(vertices)).reshape(-1, 3)}
    for name in ("sigma", "u", "eta"):
        if name in samples:
            out[name] = np.einsum("knj,ejd->eknd", basis, samples[name]).reshape(
                4 * ne, 6, -1)
    return out


def _candidates(ctx: Context, problem: str) -> list[tuple[dict, dict]]:
    """(row, sample arrays) of every solution of the true-error study of ``problem``;
    an adaptive step's row carries its goal's ``goal_estimate`` and ``relative_estimate``
    and ``nested`` (its run's last step is the reference of its goal's measure)."""
    out = []
    for method, tasks in truth_tasks(ctx.plan, problem).items():
        order, family = method_order(method)
        for task, record in zip(tasks, ctx.compute(tasks)):
            if record is None or record.get("status") != "ok":
                out.append(({"method": method, "order": order, "multipliers": family,
                             "status": (record or {}).get("status", "missing"),
                             "message": (record or {}).get("message", "")[:200]}, {}))
                continue
            arrays = ctx.arrays(task)
            if task.kind == "adapt":
                for r in record["history"]:
                    prefix = f"s{r['step']}_"
                    out.append(({"method": method, "order": order, "multipliers": family,
                                 "status": "ok", "level_or_step": r["step"],
                                 "ndof": r["dofs"]["total"], "elements": r["elements"],
                                 "time_s": r["cumulative_s"], "estimator": estimator(r),
                                 "goal_estimate": r["goal_estimate"],
                                 "relative_estimate": r["relative_estimate"]},
                                {k[len(prefix):]: v for k, v in arrays.items()
                                 if k.startswith(prefix)}))
            else:
                out.append(({"method": method, "order": order, "multipliers": family,
                             "status": "ok",
                             "level_or_step": task.params["level"], "ndof": record["ndof"],
                             "time_s": record.get("time_s", record["timings_s"]["total"]),
                             "estimator": estimator(record)}, arrays))
    return out


def same_mesh(a: dict, b: dict) -> bool:
    """Whether two solutions' sample arrays lie on the same triangles (a run that stopped on
    the mesh of a uniform level): no quadrature error to measure between them."""
    return (np.array_equal(a["vertices"], b["vertices"])
            and np.array_equal(a["triangles"], b["triangles"]))


def _resolves(error: float | None) -> list[float]:
    return [t for t in (0.05, 0.02, 0.01) if error is not None and error <= RESOLVES * t]


def _choose(checks: list[dict], measure: str) -> dict:
    """The reference of ``measure``: the run's last step whose own error (Richardson, or
    the three-cornered hat where Richardson has none) is smallest, or without any such
    estimate the largest last step; the targets it resolves."""
    known = [c for c in checks if c[measure]["overkill_error"] is not None]
    best = (min(known, key=lambda c: c[measure]["overkill_error"]) if known
            else max(checks, key=lambda c: c["ndof"]))
    return {**{k: v for k, v in best.items() if k not in TRUE_MEASURES}, **best[measure],
            "resolves": _resolves(best[measure]["overkill_error"])}


def analytic_check(scene, pressure: dict, window: float | None) -> dict | None:
    """The half-plane formula of the scene's benchmark (:mod:`ngdual.verification.analytic`:
    Hertz, Sadowsky's flat punch, the wedge; Cattaneo-Mindlin's pressure is Hertz's) with
    the force and about the centroid of the reference pressure ``pressure`` (P1 in x, ds
    taken as dx), against it: the relative L2 difference on Gamma_C (on |x| <= ``window``),
    a cross-check of a reference on a finite body, not its error. None without a benchmark."""
    from ...verification import analytic
    from ...verification.overkill import gauss_samples, pressure_error

    bench, mat = scene.benchmark, scene.material
    x, p = np.asarray(pressure["p_nodes"]), np.asarray(pressure["p"])
    force = float(np.trapezoid(p, x))
    centre = float(np.trapezoid(x * p, x)) / force
    exact = {"hertz": lambda: analytic.hertz(force, bench.radius, mat.E, mat.nu),
             "cattaneo-mindlin": lambda: analytic.hertz(force, bench.radius, mat.E, mat.nu),
             "flat-punch": lambda: analytic.flat_punch(force, bench.half_width),
             "wedge": lambda: analytic.wedge(force, bench.slope, mat.E, mat.nu)}
    if bench is None or bench.kind not in exact:
        return None
    formula = exact[bench.kind]()
    points, weights = gauss_samples(x[:-1], x[1:])
    diff = pressure_error(points, weights, formula.pressure(points - centre),
                          {"x": x, "p": p}, window)
    return {"kind": bench.kind, "force": force, "centre": centre, "relative_l2": diff["rel"]}


def true_error_study(ctx: Context, problem: str) -> dict:
    """True errors of every method of one problem against its references, cached in
    ``DIR/records`` (recomputed only when a task id changes).

    Returns ``{"rows": [...], "reference": {...}, "runs": [...]}``: one row per solution
    (method, level or adaptive step, DOFs, wall time, ``estimator``, ``pressure``,
    ``pressure_max``, ``pressure_l2``, ``sigma_energy``, ``e_true`` of
    :func:`~ngdual.studies.figures.own_errors.measures`; an adaptive step of the pressure goal
    whose error the reference resolves also ``effectivity`` = ``goal_estimate`` /
    ``pressure_l2``, the error the goal estimates, on the problem's window of Gamma_C; a
    reference has no error in its own measure); per measure its reference (:func:`_choose`),
    the sigma one with ``quadrature``, the relative change of the finest non-nested
    candidates' sigma errors when the reference's triangles are split in four; and the check
    of both runs (:func:`~ngdual.studies.figures.own_errors.run_check`, with the
    three-cornered hat of :func:`~ngdual.studies.figures.hats.hat_checks`).
    """
    from ...scene import load_scene
    from ...verification.overkill import field_errors, true_errors

    tp = TRUTH_PROBLEMS[problem]
    ids = [t.id for ts in truth_tasks(ctx.plan, problem).values() for t in ts]
    # the errors depend on the tasks and on how the true-error modules measure them
    digest = hashlib.sha1(json.dumps(ids).encode() + b"".join(
        Path(__file__).with_name(name).read_bytes() for name in MEASURING)).hexdigest()[:12]
    cache = ctx.records_dir / f"true-errors-{problem}-{digest}.json"
    if cache.is_file():
        return json.loads(cache.read_text())
    scene = load_scene(tp.scene, list(tp.overrides))
    lam, mu = scene.material.lame
    candidates = _candidates(ctx, problem)
    runs = {}
    for row, arrays in candidates:
        if row["method"].startswith("adaptive") and arrays:
            runs.setdefault(row["method"], []).append((row, arrays))
    checks = [run_check(run, lam, mu, tp.pressure_window) for run in runs.values()]
    uniform = [(row, arrays) for row, arrays in candidates
               if row["method"] == "uniform" and arrays]
    hat_checks(checks, runs, max(uniform, key=lambda c: c[0]["ndof"], default=None),
                lam, mu, tp.pressure_window)
    chosen = {m: _choose(checks, m) for m in TRUE_MEASURES}
    last = {m: runs[c["method"]][-1] for m, c in chosen.items()}
    # a run's steps solved again at order k are a better sigma reference where their own
    # error is smaller: no row is that reference
    for found in filter(None, (order_reference(run, lam, mu) for run in runs.values())):
        check, arrays = found
        own = chosen["sigma_energy"]["overkill_error"]
        if check["overkill_error"] is not None and (own is None or check["overkill_error"] < own):
            chosen["sigma_energy"] = {**check, "resolves": _resolves(check["overkill_error"])}
            last["sigma_energy"] = ({}, arrays)
    # sigma, u and the rotation from one run's last step, the pressure from one's
    pressure = {k: last["pressure"][1][k] for k in ("p_nodes", "p")}
    reference = {**{k: v for k, v in last["sigma_energy"][1].items()
                    if k in ("vertices", "triangles", "sigma", "u", "eta")}, **pressure}
    rows, crossing = [], {}
    floor = chosen["pressure"]["overkill_error"]
    for row, arrays in candidates:
        if arrays:
            row.update(measures(distance(arrays, reference, lam, mu, tp.pressure_window)))
            if (row["method"].startswith("adaptive, pressure goal") and floor
                    and row["pressure"] >= floor / RESOLVES):
                row["effectivity"] = row["goal_estimate"] / row["pressure_l2"]
            if (row["method"] != chosen["sigma_energy"]["method"]
                    and not same_mesh(arrays, reference)):
                crossing[row["method"]] = (row, arrays)     # the finest of each method
        for measure, (ref_row, _) in last.items():
            if row is ref_row:
                row[measure] = None
        rows.append(row)
    # the quadrature error of non-nested candidates: their sigma errors again, on the
    # triangles of the finer of the two split in four
    split, norm = None, None
    changes = []
    for row, arrays in crossing.values():
        if len(arrays["triangles"]) > len(reference["triangles"]):
            norm = norm or field_errors(reference, reference, lam, mu, ("sigma",))[
                "sigma_energy_norm"]
            again = field_errors(reference, split_samples(arrays), lam, mu, ("sigma",))[
                "sigma_energy"] / norm
        else:
            split = split or {**split_samples(reference), **pressure}
            again = measures(true_errors(arrays, split, lam, mu))["sigma_energy"]
        changes.append({"method": row["method"], "level_or_step": row["level_or_step"],
                        "sigma_energy": row["sigma_energy"], "sigma_energy_split": again,
                        "relative_change": abs(again / row["sigma_energy"] - 1)})
    chosen["sigma_energy"]["quadrature"] = changes
    chosen["pressure"]["analytic"] = analytic_check(scene, pressure, tp.pressure_window)
    data = plain({"rows": rows,
                  "reference": chosen, "runs": checks, "versions": versions()})
    write_json(data, cache)
    return data
