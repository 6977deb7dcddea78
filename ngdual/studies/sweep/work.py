"""The work of a sweep task: the functions of :data:`TASKS`, each returning a record and arrays.

``solve`` (one scene on one level, with the estimator and optionally the field arrays or
the solution samples of the true-error studies), ``dofs`` (Table 3.1), ``adapt`` (an
adaptive run with the extras of Section 4.2), ``peer`` (the primal peer,
:mod:`ngdual.studies.primal_peer`), ``manufactured`` (exact errors and the estimator),
``paired`` (a uniform solve and an adaptive run timed in turn), and the methods of
``ngdual cost`` within a wall-time share: ``uniform`` (uniform refinement, ngdual or the
peer) and ``peer_adapt`` (the peer adapting).
:func:`execute` runs one task and adds the header every record carries; writing it is
:mod:`~ngdual.studies.sweep.records`' business, scheduling :mod:`~ngdual.studies.sweep.runner`'s.
The tasks live in :mod:`~ngdual.studies.sweep.solve_tasks` and
:mod:`~ngdual.studies.sweep.adaptive_tasks`, how they are timed in
:mod:`~ngdual.studies.sweep.timing`.
"""

from __future__ import annotations

import os
import platform
import socket
import time
import traceback
from collections.abc import Callable

from ...io import versions
from .adaptive_tasks import adapt_task, paired_task, peer_adapt_task
from .records import Task
from .solve_tasks import dofs_task, manufactured_task, peer_task, solve_task, uniform_task
from .timing import one_thread

TASKS: dict[str, Callable[..., tuple[dict, dict]]] = {
    "solve": solve_task, "dofs": dofs_task, "adapt": adapt_task, "peer": peer_task,
    "manufactured": manufactured_task, "paired": paired_task, "uniform": uniform_task,
    "peer_adapt": peer_adapt_task}


def execute(task: Task) -> tuple[dict, dict]:
    """Compute ``task`` (no files) on one thread (:func:`one_thread`): its record and
    arrays, failures included; the record's ``threads`` are NGSolve's during the task."""
    from ...solution import ConvergenceError

    started = time.time()
    start = time.perf_counter()
    arrays: dict = {}
    threads = None
    try:
        with one_thread() as threads:
            record, arrays = TASKS[task.kind](**task.params)
    except ConvergenceError as err:
        record = {"status": "failed", "message": str(err), "history_length": len(err.history)}
    except Exception as err:  # noqa: BLE001 - a sweep never dies of one task
        record = {"status": "error", "message": f"{type(err).__name__}: {err}",
                  "traceback": traceback.format_exc()}
    header = {"id": task.id, "kind": task.kind, "params": task.params, "label": task.label,
              "started": started, "wall_s": time.perf_counter() - start,
              "host": socket.gethostname(), "pid": os.getpid(), "threads": threads,
              "load_average": list(os.getloadavg()),  # at the end: wall times depend on it
              "python": platform.python_version(), "arrays": sorted(arrays),
              "versions": versions()}
    return {**header, **record, "status": record.get("status", "ok")}, arrays
