"""The true-error studies: every method's solutions against an overkill solution.

For each problem of :data:`~ngdual.studies.figures.plan.TRUTH_PROBLEMS`, the uniform
solves (active set and Uzawa), the adaptive runs and the primal peer are compared with a
solve two uniform levels finer than the finest studied (the overkill), whose own error is
estimated from the two levels below it (:func:`~ngdual.studies.figures.numbers.
richardson_check`). The errors are cached in the records folder.
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import TYPE_CHECKING

from ...io import plain, versions, write_json
from ..sweep import estimator
from .numbers import require, richardson_check
from .plan import TRUTH_PROBLEMS
from .tasks import reference_tasks, truth_tasks

if TYPE_CHECKING:
    from .output import Context


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
                                 "time_s": r["cumulative_s"], "estimator": estimator(r)},
                                {k[len(prefix):]: v for k, v in arrays.items()
                                 if k.startswith(prefix)}))
            else:
                out.append(({"method": method, "status": "ok",
                             "level_or_step": task.params["level"], "ndof": record["ndof"],
                             "time_s": record["timings_s"]["total"],
                             "estimator": estimator(record)}, arrays))
    return out


def true_error_study(ctx: Context, problem: str) -> dict:
    """True errors of every method of one problem against its overkill, cached in
    ``DIR/records`` (the errors are recomputed only when a task id changes).

    Returns ``{"rows": [...], "reference": {...}}``: one row per solution (method,
    level or adaptive step, DOFs, wall time, ``estimator``, ``pressure``, ``pressure_max``,
    ``sigma_energy``, ``e_true``, :func:`_measures`), and the overkill's level, DOFs and its
    Richardson check per measure.
    """
    from ...scene import load_scene
    from ...verification.overkill import true_errors

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
    data = plain({"rows": rows, "reference": {
        "scene": tp.scene, "overrides": list(tp.overrides), "level": top.params["level"],
        "ndof": ref_record["ndof"], "time_s": ref_record["timings_s"]["total"],
        "richardson": check}, "versions": versions()})
    write_json(data, cache)
    return data
