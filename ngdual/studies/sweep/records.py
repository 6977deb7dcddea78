"""Sweep records on disk: one JSON record (+ NPZ arrays) per task, named by the task's id.

A :class:`Task` is a kind (one of :data:`ngdual.studies.sweep.work.TASKS`) and JSON
parameters; its id is a hash of both, so the same computation always has the same id.
A finished task leaves ``FOLDER/<id>.npz`` (arrays, if any) and then ``FOLDER/<id>.json``
(the record, the commit marker), each written atomically (:func:`ngdual.io.atomic`), so a
killed run never leaves a half-written record.

Statuses: ``"ok"``; ``"not-converged"`` (the solver returned without reaching its
tolerance, e.g. at ``solver.max_iter``); ``"failed"`` (it raised a
:class:`~ngdual.solution.ConvergenceError`, whose message is kept) -- all
three are final. ``"error"`` (any other exception, with its traceback) is kept
for inspection but counts as unfinished, so the next run tries again.

Record keys: the a posteriori estimate (4.50) is ``estimator`` (sum_T eta_T^2)^(1/2) and
``estimator_sum`` sum_T eta_T, in a solve record and in an adaptive step alike (``eta`` is
the rotation, as in the norms); ``warnings`` (in a solve record and in every adaptive or
manufactured step) lists the physics checks the solution fails (:mod:`ngdual.checks`).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...io import write_json, write_npz

FINISHED = ("ok", "not-converged", "failed")
# part of every task id: raise it when what a task writes changes, so old records are not reused
RECORD_FORMAT = 4


@dataclass(frozen=True)
class Task:
    """One unit of a sweep: ``TASKS[kind](**params)``.

    ``label`` names the task in progress bars and ``cost`` (seconds, a rough
    guess) orders the submission, longest first; neither enters the id.

    >>> Task("dofs", {"scene": "thesis-3.46-frictionless", "level": 2}).id[:-12]
    'dofs-thesis-3.46-frictionless-L2-'
    """

    kind: str
    params: dict = field(hash=False)
    label: str = ""
    cost: float = 1.0

    @property
    def id(self) -> str:
        canonical = json.dumps({"kind": self.kind, "params": self.params,
                                "format": RECORD_FORMAT}, sort_keys=True)
        digest = hashlib.sha1(canonical.encode()).hexdigest()[:12]
        parts = [self.kind, str(self.params.get("scene", ""))]
        if self.params.get("level") is not None:
            parts.append(f"L{self.params['level']}")
        return "-".join(p for p in parts if p) + "-" + digest


ESTIMATOR_KEYS = {"total": "estimator", "sum": "estimator_sum"}


def estimator(record: dict, key: str = "total") -> float | None:
    """The estimate (4.50) of a solve record or of an adaptive step: ``key`` ``"total"``
    is (sum_T eta_T^2)^(1/2), ``"sum"`` is sum_T eta_T; None for a record without one
    (the primal peer's)."""
    return record.get(ESTIMATOR_KEYS[key])


def record_path(folder: str | Path, task: Task) -> Path:
    return Path(folder) / f"{task.id}.json"


def arrays_path(folder: str | Path, task: Task) -> Path:
    return Path(folder) / f"{task.id}.npz"


def write_record(folder: str | Path, task: Task, record: dict, arrays: dict) -> Path:
    """Arrays first, then the record (the marker of a finished task), each atomically."""
    if arrays:
        write_npz(arrays, arrays_path(folder, task))
    return write_json(record, record_path(folder, task))


def load_record(folder: str | Path, task: Task) -> dict | None:
    """The record of ``task`` if it is finished (see :data:`FINISHED`), else None."""
    path = record_path(folder, task)
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if record.get("status") not in FINISHED:
        return None
    if record.get("arrays") and not arrays_path(folder, task).is_file():
        return None
    return record


def load_arrays(folder: str | Path, task: Task) -> dict[str, np.ndarray]:
    with np.load(arrays_path(folder, task)) as data:
        return {k: data[k] for k in data.files}


def remove_stale_temporaries(folder: str | Path) -> int:
    """Delete ``*.tmp`` files left by a killed run (one runner per folder at a time)."""
    n = 0
    for tmp in Path(folder).glob("*.tmp"):
        tmp.unlink(missing_ok=True)
        n += 1
    return n
