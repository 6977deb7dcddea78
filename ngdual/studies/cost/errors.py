"""True errors of every solution of one scene against references that measure their own error.

:func:`candidates` reads the solutions of a cost study from their sweep records (a uniform
level, an adaptive step, a solve of the primal peer); :func:`true_errors_of` measures each
against a reference per measure (:data:`~ngdual.studies.figures.own_errors.TRUE_MEASURES`:
the pressure on Gamma_C, sigma in the compliance norm), which is the last step of one of the
adaptive runs of ngdual.

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
stress goal's steps up to a size may be solved again by PEERS_2 on their meshes
(:func:`~ngdual.studies.figures.own_errors.order_reference`): their last one is the sigma
reference where its own error, Richardson from the two before it, is smaller. The reference of
a measure is the step with the smallest own error, and it resolves the targets at least 1 /
:data:`RESOLVES` times its error: a target finer than that is not reported. The steps of a
run are nested meshes (bisection), so their distances to its last step are exact integrals;
every other candidate's mesh crosses the reference's triangles, and the quadrature error this
costs (:mod:`ngdual.verification.overkill`) can be measured by integrating the sigma error
again on the reference's triangles split in four (:func:`split_samples`).

No error identity replaces the references: for the exact displacement, 2 (J(sigma_h) -
J(sigma)) with the complementary energy J(tau) = a(tau, tau) / 2 - <tau n, u_D> equals
||sigma - sigma_h||_A^2 only up to -2 (as sigma_h, eta - eta_h) and the weakly imposed
traction and contact conditions: PEERS' sigma_h is symmetric only against the P1
rotations, so it is not statically admissible, and these terms are of the order of the
squared error itself.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...io import plain, versions
from ..figures.hats import hat_checks
from ..figures.own_errors import TRUE_MEASURES, distance, measures, order_reference, run_check
from ..sweep import Task, estimator
from .methods import method_base, method_order
from .table import TARGETS

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


def _steps(arrays: dict, key) -> dict:
    prefix = f"s{key}_"
    return {k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)}


def candidates(tasks: dict[str, list[Task]], record_of: Callable[[Task], dict | None],
               arrays_of: Callable[[Task], dict]) -> list[tuple[dict, dict]]:
    """(row, sample arrays) of every solution of the sweep ``tasks`` (by method), read by
    ``record_of`` and ``arrays_of``: a ``solve`` or ``peer`` task is one row, a ``uniform``
    task one per level (its time that level's solve), an ``adapt`` or ``peer_adapt`` task one
    per step (its time to that step's solution, every step before included); an adaptive
    step of ngdual carries its goal's ``goal_estimate`` and ``relative_estimate``. A task
    that did not finish is one row with its ``status`` and ``message`` and no arrays."""
    out = []
    for method, method_tasks in tasks.items():
        order, family = method_order(method)
        head = {"method": method, "order": order, "multipliers": family}
        for task in method_tasks:
            record = record_of(task)
            if record is None or record.get("status") != "ok":
                out.append(({**head, "status": (record or {}).get("status", "missing"),
                             "message": (record or {}).get("message", "")[:200]}, {}))
                continue
            arrays = arrays_of(task)
            if task.kind == "adapt":
                out += [({**head, "status": "ok", "level_or_step": r["step"],
                          "ndof": r["dofs"]["total"], "elements": r["elements"],
                          "time_s": r["cumulative_s"], "estimator": estimator(r),
                          "goal_estimate": r["goal_estimate"],
                          "relative_estimate": r["relative_estimate"]},
                         _steps(arrays, r["step"])) for r in record["history"]]
            elif task.kind == "peer_adapt":
                out += [({**head, "status": "ok", "level_or_step": r["step"], "ndof": r["ndof"],
                          "elements": r["elements"], "time_s": r["cumulative_s"],
                          "estimator": None}, _steps(arrays, r["step"]))
                        for r in record["history"]]
            elif task.kind == "uniform":
                out += [({**head, "status": "ok", "level_or_step": r["level"], "ndof": r["ndof"],
                          "elements": r["elements"], "time_s": r["time_s"], "estimator": None},
                         _steps(arrays, r["level"])) for r in record["history"]]
            else:
                out.append(({**head, "status": "ok", "level_or_step": task.params["level"],
                             "ndof": record["ndof"],
                             "time_s": record.get("time_s", record["timings_s"]["total"]),
                             "estimator": estimator(record)}, arrays))
    return out


def same_mesh(a: dict, b: dict) -> bool:
    """Whether two solutions' sample arrays lie on the same triangles (a run that stopped on
    the mesh of a uniform level): no quadrature error to measure between them."""
    return (np.array_equal(a["vertices"], b["vertices"])
            and np.array_equal(a["triangles"], b["triangles"]))


def resolved_targets(error: float | None) -> list[float]:
    """The targets (:data:`~.table.TARGETS`) a reference of own error ``error`` resolves:
    those at least 1 / :data:`RESOLVES` times it; none where its error is unknown.

    >>> resolved_targets(0.004), resolved_targets(None)
    ([0.05, 0.02], [])
    """
    return [t for t in TARGETS if error is not None and error <= RESOLVES * t]


def _choose(checks: list[dict], measure: str) -> dict:
    """The reference of ``measure``: the run's last step whose own error (Richardson, or
    the three-cornered hat where Richardson has none) is smallest, or without any such
    estimate the largest last step; the targets it resolves."""
    known = [c for c in checks if c[measure]["overkill_error"] is not None]
    best = (min(known, key=lambda c: c[measure]["overkill_error"]) if known
            else max(checks, key=lambda c: c["ndof"]))
    return {**{k: v for k, v in best.items() if k not in TRUE_MEASURES}, **best[measure],
            "resolves": resolved_targets(best[measure]["overkill_error"])}


def analytic_check(scene, pressure: dict, window=None) -> dict | None:
    """The half-plane formula of the scene's benchmark (:mod:`ngdual.verification.analytic`:
    Hertz, Sadowsky's flat punch, the wedge; Cattaneo-Mindlin's pressure is Hertz's) with
    the force and about the centroid of the reference pressure ``pressure`` (P1 in x, ds
    taken as dx), against it: the relative L2 difference on Gamma_C (on its part ``window``,
    :func:`ngdual.verification.overkill.in_window`),
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


def _finest_uniform(found: list[tuple[dict, dict]]) -> tuple[dict, dict] | None:
    """The finest uniform solution of order 0, else of any order: a corner of the
    three-cornered hats."""
    uniform = [c for c in found if method_base(c[0]["method"]) == "uniform" and c[1]]
    thesis = [c for c in uniform if c[0]["method"] == "uniform"]
    return max(thesis or uniform, key=lambda c: c[0]["ndof"], default=None)


def true_errors_of(scene, found: list[tuple[dict, dict]], window=None,
                   quadrature: bool = True, progress: bool | None = False,
                   references_from: list[str] | None = None) -> dict:
    """True errors of every solution ``found`` (:func:`candidates`) of ``scene`` against its
    references.

    Returns ``{"rows": [...], "reference": {...}, "runs": [...]}``: one row per solution
    (method, level or adaptive step, DOFs, wall time, ``estimator``, ``pressure``,
    ``pressure_max``, ``pressure_l2``, ``sigma_energy``, ``e_true`` of
    :func:`~ngdual.studies.figures.own_errors.measures`; an adaptive step of the pressure goal
    whose error the reference resolves also ``effectivity`` = ``goal_estimate`` /
    ``pressure_l2``, the error the goal estimates, on the part ``window`` of Gamma_C (|x| <=
    window for a number, lo <= x <= hi for a pair: :func:`ngdual.verification.overkill.
    in_window`);
    a reference has no error in its own measure); per measure its reference (:func:`_choose`)
    with the targets it resolves, the pressure one with ``analytic`` (:func:`analytic_check`),
    with ``quadrature`` the sigma one with the relative change of the finest non-nested
    candidates' sigma errors when the reference's triangles are split in four; and the check
    of every adaptive run (:func:`~ngdual.studies.figures.own_errors.run_check`, with the
    three-cornered hat of :func:`~ngdual.studies.figures.hats.hat_checks`). The references
    are the last steps of the runs ``references_from`` (default: of every adaptive run of
    ngdual). ``progress``: a progress bar over the solutions (None: on a terminal).
    """
    from tqdm import tqdm

    from ...verification.overkill import field_errors, true_errors

    lam, mu = scene.material.lame
    runs = {}
    for row, arrays in found:
        if row["method"].startswith("adaptive") and arrays:
            runs.setdefault(row["method"], []).append((row, arrays))
    checks = [run_check(run, lam, mu, window) for run in runs.values()]
    hat_checks(checks, runs, _finest_uniform(found), lam, mu, window)
    eligible = [c for c in checks if references_from is None
                or c["method"] in references_from]
    chosen = {m: _choose(eligible, m) for m in TRUE_MEASURES}
    last = {m: runs[c["method"]][-1] for m, c in chosen.items()}
    # a run's steps solved again at order k are a better sigma reference where their own
    # error is smaller: no row is that reference
    for found_order in filter(None, (order_reference(run, lam, mu) for run in runs.values())):
        check, arrays = found_order
        own = chosen["sigma_energy"]["overkill_error"]
        if check["overkill_error"] is not None and (own is None or check["overkill_error"] < own):
            chosen["sigma_energy"] = {**check,
                                      "resolves": resolved_targets(check["overkill_error"])}
            last["sigma_energy"] = ({}, arrays)
    # sigma, u and the rotation from one run's last step, the pressure from one's
    pressure = {k: last["pressure"][1][k] for k in ("p_nodes", "p")}
    reference = {**{k: v for k, v in last["sigma_energy"][1].items()
                    if k in ("vertices", "triangles", "sigma", "u", "eta")}, **pressure}
    rows, crossing = [], {}
    floor = chosen["pressure"]["overkill_error"]
    for row, arrays in tqdm(found, desc="true errors", unit="solution",
                            disable=None if progress is None else not progress):
        if arrays:
            row.update(measures(distance(arrays, reference, lam, mu, window)))
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
    if quadrature:
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
    chosen["pressure"]["analytic"] = analytic_check(scene, pressure, window)
    return plain({"rows": rows, "reference": chosen, "runs": checks, "versions": versions()})
