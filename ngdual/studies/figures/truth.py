"""The true-error studies: every method's solutions against adaptive references.

For each problem of :data:`~ngdual.studies.figures.plan.TRUTH_PROBLEMS` the uniform
solves, the adaptive runs (one per goal at order 0 and at the orders
:data:`~ngdual.studies.figures.plan.ORDERS`) and the primal peers are compared with a
reference per measure: the last step of one of the adaptive runs.

The own error of a run's last step is estimated per measure by Richardson
(:data:`EXTRAPOLATION`: orthogonal errors for sigma, aligned ones for the pressure) from
the distances of the two steps before it, each with about 2x the unknowns of the one
before (a run that stalls, growing by less than :data:`STALLED` per step, has no
estimate). Where a run gives no such estimate, two independent solutions stand in for it
(:func:`three_cornered_hat`), whose three pairwise distances give each one's error if the
three errors are orthogonal: for sigma the last step of its :func:`partner` and the finest
uniform level, on meshes of other families; for the pressure the two solutions nearest to
it (:func:`nearest_corners`) among the other runs' last steps and the finest uniform
level. A hat that another run's Richardson estimate contradicts by the triangle
inequality is no own error (:func:`hat_bound`). The stress goal's steps up to a size are
solved again by PEERS_2 on their meshes (:func:`order_reference`): their last one is the
sigma reference where its own error, Richardson from the two before it, is smaller. The
reference of a measure is the step with the smallest own error, and it resolves the
targets at least 1 / :data:`RESOLVES` times its error. The steps of a run are nested
meshes (bisection), so their distances to its last step are exact integrals;
every other candidate's mesh crosses the reference's triangles, and the quadrature error
this costs (:mod:`ngdual.verification.overkill`) is measured by integrating the sigma
error again on the reference's triangles split in four (:func:`split_samples`). The
errors are cached in the records folder.

No error identity replaces the references: for the exact displacement, 2 (J(sigma_h) -
J(sigma)) with the complementary energy J(tau) = a(tau, tau) / 2 - <tau n, u_D> equals
||sigma - sigma_h||_A^2 only up to -2 (as sigma_h, eta - eta_h) and the weakly imposed
traction and contact conditions: PEERS' sigma_h is symmetric only against the P1
rotations, so it is not statically admissible, and these terms are of the order of the
squared error itself.
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...io import plain, versions, write_json
from ..sweep import estimator
from .numbers import aligned_richardson_check, richardson_check
from .plan import REFERENCE_ORDER, TRUTH_PROBLEMS, method_base, method_order
from .tasks import truth_tasks

if TYPE_CHECKING:
    from .output import Context


# measures of the true-error studies: key -> (what, how it is made relative), and the
# adaptive run whose last step is the reference of each
TRUE_MEASURES = {"pressure": "relative L2 error of the contact pressure on Gamma_C",
                 "sigma_energy": "relative compliance-norm error of sigma"}
# a run's own error per measure: sigma's errors are near orthogonal in the compliance norm
# (Galerkin), the pressure's need not be (worst case: aligned)
EXTRAPOLATION = {"pressure": aligned_richardson_check, "sigma_energy": richardson_check}
# a target is resolved when the reference's own error is at most this share of it
RESOLVES = 1 / 3
# an adaptive run whose steps grow the unknowns by less than this factor is stalled: its
# estimate is held by a few triangles it cannot improve, and its steps are no sequence to
# extrapolate from
STALLED = 1.3
# a Richardson estimate that bounds a three-cornered hat (hat_bound) counts at this many
# times its value: it assumes the asymptotic ratio, and where a run has both, it lies up
# to 13 % below its hat (the stress goal of order 1: the punch's 0.019 % against 0.022 %,
# Hertz's 1.39 % against 1.53 %) or far above it (the study at 0839a8a); a hat is refuted
# only by a contradiction larger than such an error, not by a remote run's (the Hertz
# stress goal's 1.39 %, 1.8 % from the pressure goal of order 1, whose hat is 0.082 %)
RICHARDSON_SAFETY = 2.0
# the P2 nodes of the four red children of the reference triangle, in barycentric
# coordinates of the parent (vertices 0, 1, 2; midpoints m01, m12, m20)
_V = np.eye(3)
_M = {(0, 1): (_V[0] + _V[1]) / 2, (1, 2): (_V[1] + _V[2]) / 2, (2, 0): (_V[2] + _V[0]) / 2}
CHILDREN = ((_V[0], _M[(0, 1)], _M[(2, 0)]), (_M[(0, 1)], _V[1], _M[(1, 2)]),
            (_M[(2, 0)], _M[(1, 2)], _V[2]), (_M[(1, 2)], _M[(2, 0)], _M[(0, 1)]))


def fastest_reduction(growth: float, order: int) -> float:
    """The least error ratio e_L / e_(L-1) a step of PEERS_``order`` that multiplies the
    unknowns by ``growth`` can attain: growth^-(k + 1), twice the best rate in the unknowns
    (h^(k+1) ~ N^-(k+1)/2) of sigma and of its normal trace. A Richardson ratio below it is
    no rate but a measure that the last step left unchanged (the stress goal refining the
    corners once the contact zone is resolved: the pressure moved by 3 % and then by
    0.006 %, r = 0.002), and gives no own error.

    >>> round(fastest_reduction(2.0, 0), 3), round(fastest_reduction(1.5, 2), 3)
    (0.5, 0.296)
    """
    return growth ** -(order + 1)


def _within_rates(check: dict, unknowns: list[int], order: int) -> dict:
    """A Richardson ``check`` without its own error where its ratio is faster than any rate
    of the method over the last step of ``unknowns`` (:func:`fastest_reduction`)."""
    if check["r"] is not None and check["r"] < fastest_reduction(unknowns[-1] / unknowns[-2],
                                                                 order):
        return {**check, "overkill_error": None}
    return check


def _measures(errors: dict) -> dict:
    """The relative errors plotted (:data:`TRUE_MEASURES`) and the absolute total error
    e = (||sigma - sigma_ref||^2 + ||u - u_ref||^2 + ||eta - eta_ref||^2)^(1/2) (L2; div sigma
    has no error when f = 0) that the estimator is compared with."""
    return {"pressure": errors.get("pressure_rel"),
            "pressure_max": errors.get("pressure_max"),
            "pressure_l2": errors.get("pressure_l2"),
            "sigma_energy": errors["sigma_energy"] / errors["sigma_energy_norm"],
            "e_true": math.sqrt(sum(errors.get(k, 0.0) ** 2 for k in ("sigma", "u", "eta")))}


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


def _run_check(run: list[tuple[dict, dict]], lam: float, mu: float, window) -> dict:
    """How accurate an adaptive run's last step is, per measure: Richardson
    (:data:`EXTRAPOLATION`) from the distances of the two steps before it (nested meshes:
    exact integrals), ``None`` where
    the run stalled (a step before the last grew the unknowns by less than
    :data:`STALLED`), the distances do not fall or fall faster than any rate of the
    method (:func:`fastest_reduction`)."""
    from ...verification.overkill import true_errors

    (last_row, last), before = run[-1], run[-3:-1]
    out = {"method": last_row["method"], "step": last_row["level_or_step"],
           "ndof": last_row["ndof"], "elements": last_row["elements"],
           "time_s": last_row["time_s"], "relative_estimate": last_row["relative_estimate"]}
    steps = [r["ndof"] for r, _ in run[-3:]]
    stalled = len(steps) < 3 or min(b / a for a, b in zip(steps, steps[1:])) < STALLED
    d = [_measures(true_errors(arrays, last, lam, mu, window)) for _, arrays in before]
    for measure in TRUE_MEASURES:
        check = ({"r": None, "rate": None, "overkill_error": None} if stalled
                 else EXTRAPOLATION[measure](*(e[measure] for e in d)))
        check = _within_rates(check, steps, last_row["order"])
        out[measure] = {"d_last-2": d[0][measure] if len(d) == 2 else None,
                        "d_last-1": d[-1][measure] if d else None, **check,
                        "estimate": None if check["overkill_error"] is None else "Richardson"}
    out["stalled"] = stalled
    return out


def three_cornered_hat(d_ab: float, d_ac: float, d_bc: float) -> float | None:
    """The error of solution a from the pairwise distances of three solutions a, b, c whose
    errors are orthogonal (d_ab^2 = e_a^2 + e_b^2, ...; the three-cornered hat of clock
    comparisons): e_a = ((d_ab^2 + d_ac^2 - d_bc^2) / 2)^(1/2); None where the distances
    contradict orthogonality (a negative square).

    >>> round(three_cornered_hat(5 ** 0.5, 10 ** 0.5, 13 ** 0.5), 12)  # e = 1, 2, 3
    1.0
    """
    square = (d_ab**2 + d_ac**2 - d_bc**2) / 2
    return math.sqrt(square) if square >= 0 else None


def partner(method: str, methods: list[str]) -> str | None:
    """The run whose last step is the second corner of ``method``'s three-cornered hat:
    the run of the other goal at the same order, else the first of ``methods`` (ordered by
    the unknowns of their last steps, largest first) of another goal; None without one. A
    run of another goal refines elsewhere: its error is the nearest to orthogonal.

    >>> partner("adaptive, pressure goal, k = 2", ["adaptive, stress goal",
    ...         "adaptive, pressure goal", "adaptive, pressure goal, k = 2"])
    'adaptive, stress goal'
    """
    others = [m for m in methods if method_base(m) != method_base(method)]
    same = [m for m in others if method_order(m) == method_order(method)]
    return (same or others or [None])[0]


def same_mesh(a: dict, b: dict) -> bool:
    """Whether two solutions' sample arrays lie on the same triangles (a run that stopped on
    the mesh of a uniform level): no quadrature error to measure between them."""
    return (np.array_equal(a["vertices"], b["vertices"])
            and np.array_equal(a["triangles"], b["triangles"]))


def pressure_distance(candidate: dict, reference: dict, window: float | None = None
                      ) -> float:
    """The relative L2 distance of two solutions' pressures on Gamma_C (on |x| <=
    ``window``; :func:`ngdual.verification.overkill.pressure_errors`)."""
    from ...verification.overkill import pressure_errors

    return pressure_errors(candidate, reference, window)["pressure_rel"]


def nearest_corners(name: str, names: list[str], distance) -> tuple[str, str] | None:
    """The two of ``names`` nearest to ``name`` by ``distance(a, b)``, nearest first: the
    other corners of its three-cornered hat. The nearest solutions are the most accurate
    ones, so that the hat subtracts squares of small distances (a corner far from the
    truth makes it the difference of two large, nearly equal squares). A solution at
    distance 0 is the same solution (two runs that stopped on the same mesh), no
    independent corner; the two corners must differ from each other too. None without
    two such corners.

    >>> at = {"a": 0.0, "b": 5.0, "c": 1.0, "d": 2.0, "e": 0.0, "f": 1.0}
    >>> nearest_corners("a", list(at), lambda x, y: abs(at[x] - at[y]))
    ('c', 'd')
    """
    others = sorted((distance(name, m), m) for m in names if m != name)
    first = next((m for d, m in others if d > 0), None)
    second = next((m for d, m in others if d > 0 and m != first
                   and distance(first, m) > 0), None)
    return (first, second) if second is not None else None


def _hat_checks(checks: list[dict], runs: dict, uniform: tuple[dict, dict] | None,
                lam: float, mu: float, window) -> None:
    """Add to every run's check, per measure, ``hat``: its last step's error by
    :func:`three_cornered_hat` (the distances under ``hat_distances``, the corners under
    ``corners``); where the run's Richardson estimate is missing, the hat's becomes its
    ``overkill_error`` (``estimate`` says which). The corners of sigma: the last step of
    its :func:`partner` run and the finest uniform solution ``uniform``; of the pressure,
    whose distances cost little: the two :func:`nearest_corners` among the other runs'
    last steps and ``uniform``.

    A hat is no own error where another solution's own Richardson estimate refutes it:
    the distances are a norm's, so e_a >= d_ab - e_b (e_b counted twice: Richardson
    estimates err too, :data:`RICHARDSON_SAFETY`), and a hat below that bound
    (``hat_bound``, the largest such bound: from the corners for sigma, from every run
    with a Richardson estimate for the pressure) rests on errors that are not orthogonal
    (:func:`hat_bound`); the run then has no own error (``hat_refuted``)."""
    from ...verification.overkill import true_errors

    if uniform is None:
        return
    by_size = sorted(runs, key=lambda m: -runs[m][-1][0]["ndof"])
    last = {**{m: runs[m][-1][1] for m in runs}, "uniform": uniform[1]}
    # the runs' own errors by Richardson, read before any hat stands in for one
    richardson = {(c["method"], m): c[m]["overkill_error"] for c in checks
                  for m in TRUE_MEASURES if c[m]["estimate"] == "Richardson"}

    # the same pairs come back in later checks (the partner, the finest uniform level)
    @functools.cache
    def sigma(a: str, b: str) -> float:
        x, y = last[a], last[b]
        if len(x["triangles"]) < len(y["triangles"]):
            x, y = y, x
        return _measures(true_errors(y, x, lam, mu, window))["sigma_energy"]

    @functools.cache
    def pressure(a: str, b: str) -> float:
        return pressure_distance(last[a], last[b], window)

    for check in checks:
        name = check["method"]
        other = partner(name, by_size)
        corners = {"sigma_energy": other and (other, "uniform"),
                   "pressure": nearest_corners(name, list(last), pressure)}
        for measure, distance in (("sigma_energy", sigma), ("pressure", pressure)):
            if corners[measure] is None:
                continue
            b, c = corners[measure]
            d_ab, d_ac, d_bc = distance(name, b), distance(name, c), distance(b, c)
            hat = three_cornered_hat(d_ab, d_ac, d_bc)
            # sigma's distances cost a field integral each: its corners bound it; the
            # pressure's cost little: every run with a Richardson estimate does
            bounding = {m: distance(name, m) for m in runs if m != name
                        and (m, measure) in richardson} if measure == "pressure" else {}
            bounding.update({b: d_ab, c: d_ac})
            bound = hat_bound(bounding, {m: richardson.get((m, measure)) for m in bounding})
            entry = check[measure]
            entry.update(hat=hat, corners=[b, c], hat_bound=bound,
                         hat_distances={"to_b": d_ab, "to_c": d_ac, "b_to_c": d_bc},
                         hat_refuted=hat is not None and hat < bound)
            if entry["overkill_error"] is None and hat is not None and hat >= bound:
                entry.update(overkill_error=hat, estimate="three-cornered hat")


def hat_bound(distances: dict[str, float], own: dict[str, float | None]) -> float:
    """The least error of a solution a that the triangle inequality allows, e_a >= d_ab -
    e_b, from its ``distances`` to other solutions b and their ``own`` errors (Richardson;
    None: unknown, no bound), each counted at :data:`RICHARDSON_SAFETY` times its value;
    0 where nothing bounds it.

    The three-cornered hat assumes orthogonal errors; the pressure goal's runs of the
    three orders refine alike and their errors share a part. On the flat punch's core (the
    study at 0839a8a) the order-2 pressure run's hat from the order-1 and order-0 pressure
    runs was 0.0070 % (distances 0.020 and 0.021 %), while the stress goal of order 1,
    Richardson 0.019 % (its own hat 0.022 %), lay 0.060 % from it: the error is at least
    0.060 - 2 x 0.019 = 0.022 %, three times the hat. (At 1925802 the same run's hat was
    0.010 %, its corner the order-0 run with Richardson 0.042 % at 0.084 %.)

    >>> hat_bound({"b": 0.75, "c": 0.5}, {"b": 0.125, "c": None})
    0.5
    >>> hat_bound({"b": 0.3}, {"b": 0.5})
    0.0
    """
    return max([0.0] + [d - RICHARDSON_SAFETY * own[m] for m, d in distances.items()
                        if own.get(m) is not None])


def distance(candidate: dict, reference: dict, lam: float, mu: float,
             window: float | None = None) -> dict:
    """:func:`ngdual.verification.overkill.true_errors` of ``candidate`` against
    ``reference``, the fields integrated on the finer of the two meshes (a candidate finer
    than the reference is exact on its own triangles, not on the reference's); the norms
    are the reference's."""
    from ...verification.overkill import field_errors, true_errors

    out = true_errors(candidate, reference, lam, mu, window)
    if len(candidate["triangles"]) > len(reference["triangles"]):
        swapped = field_errors(reference, candidate, lam, mu)
        out.update({k: v for k, v in swapped.items() if not k.endswith("_norm")})
    return out


def order_reference(run: list[tuple[dict, dict]], lam: float, mu: float
                    ) -> tuple[dict, dict] | None:
    """The sigma reference of an adaptive run's steps solved again by PEERS_k (k =
    :data:`~ngdual.studies.figures.plan.REFERENCE_ORDER`, arrays ``order_*``): the last such
    step's fields and their own error, Richardson (:data:`EXTRAPOLATION`, orthogonal) from
    the two such steps before it (nested meshes: exact distances); None with fewer than
    three such steps, and no own error where Richardson's ratio is faster than any rate
    (:func:`fastest_reduction`). Returns (its check, with the keys of :func:`_run_check`'s
    measures, and its sample arrays)."""
    steps = [(row, {"vertices": a["vertices"], "triangles": a["triangles"],
                    **{n: a[f"order_{n}"] for n in ("sigma", "u", "eta")}}, int(a["order_ndof"]))
             for row, a in run if "order_sigma" in a]
    if len(steps) < 3:
        return None
    (row, last, ndof), before = steps[-1], steps[-3:-1]
    d = [_measures(distance(arrays, last, lam, mu))["sigma_energy"] for _, arrays, _ in before]
    check = _within_rates(EXTRAPOLATION["sigma_energy"](*d), [before[-1][2], ndof],
                          REFERENCE_ORDER)
    return ({"method": f"{row['method']}, PEERS_{REFERENCE_ORDER}", "step": row["level_or_step"],
             "ndof": ndof, "elements": row["elements"], "d_last-2": d[0], "d_last-1": d[1],
             **check, "estimate": None if check["overkill_error"] is None
             else f"Richardson, PEERS_{REFERENCE_ORDER}"}, last)


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
    ``pressure_max``, ``pressure_l2``, ``sigma_energy``, ``e_true`` of :func:`_measures`; an
    adaptive step of the pressure goal whose error the reference resolves also
    ``effectivity`` = ``goal_estimate`` / ``pressure_l2``, the error the goal estimates, on
    the problem's window of Gamma_C; a reference has no error in its own measure); per
    measure
    its reference (:func:`_choose`), the sigma one with ``quadrature``, the relative change
    of the finest non-nested candidates' sigma errors when the reference's triangles are
    split in four; and the check of both runs (:func:`_run_check`, with the
    three-cornered hat of :func:`_hat_checks`).
    """
    from ...scene import load_scene
    from ...verification.overkill import field_errors, true_errors

    tp = TRUTH_PROBLEMS[problem]
    ids = [t.id for ts in truth_tasks(ctx.plan, problem).values() for t in ts]
    # the errors depend on the tasks and on how this module measures them
    digest = hashlib.sha1(json.dumps(ids).encode() + Path(__file__).read_bytes()
                          ).hexdigest()[:12]
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
    checks = [_run_check(run, lam, mu, tp.pressure_window) for run in runs.values()]
    uniform = [(row, arrays) for row, arrays in candidates
               if row["method"] == "uniform" and arrays]
    _hat_checks(checks, runs, max(uniform, key=lambda c: c[0]["ndof"], default=None),
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
            row.update(_measures(distance(arrays, reference, lam, mu, tp.pressure_window)))
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
            again = _measures(true_errors(arrays, split, lam, mu))["sigma_energy"]
        changes.append({"method": row["method"], "level_or_step": row["level_or_step"],
                        "sigma_energy": row["sigma_energy"], "sigma_energy_split": again,
                        "relative_change": abs(again / row["sigma_energy"] - 1)})
    chosen["sigma_energy"]["quadrature"] = changes
    chosen["pressure"]["analytic"] = analytic_check(scene, pressure, tp.pressure_window)
    data = plain({"rows": rows,
                  "reference": chosen, "runs": checks, "versions": versions()})
    write_json(data, cache)
    return data
