"""The true-error studies: every method's solutions against adaptive references.

For each problem of :data:`~ngdual.studies.figures.plan.TRUTH_PROBLEMS` the uniform
solves, the adaptive runs (one per goal at order 0 and at the orders
:data:`~ngdual.studies.figures.plan.ORDERS`) and the primal peers, uniform and adaptive,
are measured as ``ngdual cost`` measures one scene's (:mod:`ngdual.studies.cost.errors`:
the references, their own errors, the targets they resolve), here on the fixed sizes of the
:class:`~ngdual.studies.figures.plan.Plan` instead of a budget of wall time; the stress
goal's steps up to a size are also solved again by PEERS_2, candidates for the sigma
reference. The errors are cached in the records folder.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import TYPE_CHECKING

from ..cost import errors
from . import hats, own_errors
from .plan import TRUTH_PROBLEMS
from .tasks import truth_tasks

if TYPE_CHECKING:
    from .output import Context

# the modules whose code measures the true errors: a change to one recomputes the cached ones
MEASURING = (errors, own_errors, hats)


def true_error_study(ctx: Context, problem: str) -> dict:
    """True errors of every method of one problem against its references
    (:func:`ngdual.studies.cost.errors.true_errors_of`, with the quadrature check of the
    sigma reference), cached in ``DIR/records`` (recomputed only when a task id or the
    measuring code changes): ``{"rows": [...], "reference": {...}, "runs": [...]}``."""
    from ...io import write_json
    from ...scene import load_scene

    tp = TRUTH_PROBLEMS[problem]
    tasks = truth_tasks(ctx.plan, problem)
    ids = [t.id for ts in tasks.values() for t in ts]
    # the errors depend on the tasks and on how the true-error modules measure them
    digest = hashlib.sha1(json.dumps(ids).encode() + b"".join(
        Path(m.__file__).read_bytes() for m in MEASURING)).hexdigest()[:12]
    cache = ctx.records_dir / f"true-errors-{problem}-{digest}.json"
    if cache.is_file():
        return json.loads(cache.read_text())
    found = errors.candidates(tasks, ctx.record, ctx.arrays)
    data = errors.true_errors_of(load_scene(tp.scene, list(tp.overrides)), found,
                                 tp.pressure_window)
    write_json(data, cache)
    return data
