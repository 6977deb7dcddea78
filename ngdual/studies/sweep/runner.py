"""Running sweeps on a dask.distributed cluster, each task leaving its record on disk.

:class:`Runner` submits the tasks whose record is missing (:func:`~ngdual.studies.sweep.
records.load_record`) to a ``dask.distributed`` cluster (a ``LocalCluster`` by default,
any running scheduler by address), longest first, and shows a progress bar; re-running a
sweep skips every finished task. A worker runs :func:`run_task`: it computes the task
(:func:`~ngdual.studies.sweep.work.execute`) and writes its record.
"""

from __future__ import annotations

import contextlib
import os
import warnings
from collections.abc import Iterable
from pathlib import Path

from ...extras import require
from ..variants import VARIANTS
from .records import Task, load_record, record_path, remove_stale_temporaries, write_record
from .solve_tasks import load_scene_with
from .work import execute

WORKER_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "MPLBACKEND": "Agg"}
# Environment variables dask's nanny sets in a worker and the workers here must not have:
# MALLOC_TRIM_THRESHOLD_=65536 makes glibc hand freed memory back to the system at once,
# so every large array is page-faulted in again; the timed solves of a study (a sweep's
# wall times) ran 1.3-1.5 times slower in a worker than in a plain process (adaptive runs
# of order 2 on Example 3.46: 0.66 s against 0.43 s to the same mesh; 200 inversions of a
# 300 x 300 matrix: 0.90 s against 0.68 s), and no machine here is short of memory.
UNSET_IN_WORKERS = ("MALLOC_TRIM_THRESHOLD_",)
# dask's statistical profiler wakes every 10 ms in a worker, takes the GIL and walks the
# stack of the running task: code that spends its time in many short Python calls pays for
# it, code in long C calls hardly does. The adaptive run of order 2 on Example 3.46 to
# 11 264 unknowns takes 0.44-0.50 s in a worker against 0.39-0.41 s with the profiler off
# or in a plain process, while the uniform PEERS_1 solve of level 4 takes the same time
# (0.39-0.46 s) either way: the profiler would bias the study's wall times against the
# adaptive loop. Its samples are not used here.
WORKER_CONFIG = {"distributed.worker.profile.enabled": False}


@contextlib.contextmanager
def _environment_kept():
    """This process's environment as it was on entry, on exit. dask's nanny writes its
    pre-spawn environment (OMP_NUM_THREADS=1, OPENBLAS_NUM_THREADS=1, MKL_NUM_THREADS=1,
    PYTHONHASHSEED) into the parent's os.environ before it spawns a worker: without the
    restore the parent's variables would no longer say how many threads its own BLAS runs
    on, and a process that compares the two would find them differ once a sweep has
    started a cluster in it."""
    saved = dict(os.environ)
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


def run_task(task: Task, folder: str) -> tuple[dict, dict]:
    """Compute ``task`` and write its record into ``folder`` (the function dask runs)."""
    record, arrays = execute(task)
    write_record(folder, task, record, arrays)
    return record, arrays


def warm_up() -> None:
    """Solve a tiny scene with each solver once, so that the first timed task of a worker does
    not pay for imports and NGSolve's first-call set-up."""
    from ...solution import PhysicsWarning
    from ...solvers import solve_scene

    with warnings.catch_warnings():  # the thesis ends warn; this solve is thrown away
        warnings.simplefilter("ignore", PhysicsWarning)
        for variant in ("default", "uzawa"):
            solve_scene(load_scene_with("thesis-3.46-coulomb", VARIANTS[variant].overrides), 1)


class Runner:
    """Runs sweeps on a dask.distributed cluster, skipping the tasks already on disk.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running scheduler (``tcp://host:8786``); its workers must
        see the output folder (a shared file system) -- if they do not, the
        records come back with the results and are written here.
    workers : int, optional
        Workers of the LocalCluster started otherwise (default: the CPU count).
    processes : bool
        Worker processes (default), or the tasks one after another in this process
        (quick to start, what the tests use, and without dask: netgen and NGSolve must
        not mesh or assemble in two threads at once, so a thread pool would gain nothing).
    """

    def __init__(self, scheduler: str | None = None, workers: int | None = None,
                 processes: bool = True, progress: bool | None = None):
        self.scheduler, self.processes = scheduler, processes
        self.workers = workers or os.cpu_count() or 1
        self.progress = progress
        self._client = self._cluster = None
        self._warm = False
        self.failed: dict[str, dict] = {}
        self.computed = 0

    def start(self) -> None:
        """Start the workers and warm them up (:func:`warm_up`), or warm up this process when
        the tasks run here: what the first timed task should not pay for."""
        if self.in_process:
            if not self._warm:
                warm_up()
                self._warm = True
        else:
            self.client()

    def client(self):
        if self._client is None:
            distributed = require("dask.distributed", "studies")

            if self.scheduler:
                self._client = distributed.Client(self.scheduler)
            else:
                dask = require("dask", "studies")
                unset = {f"distributed.nanny.pre-spawn-environ.{name}": None
                         for name in UNSET_IN_WORKERS}
                with dask.config.set({**unset, **WORKER_CONFIG}), _environment_kept():
                    self._cluster = distributed.LocalCluster(
                        n_workers=self.workers if self.processes else 1, threads_per_worker=1,
                        processes=self.processes, dashboard_address=None, memory_limit=0,
                        **({"env": WORKER_ENV} if self.processes else {}))
                self._client = distributed.Client(self._cluster)
            self._client.run(warm_up)
        return self._client

    def close(self) -> None:
        """Close the client and stop our LocalCluster (a cluster given by address keeps
        running); connection noise of the shutdown is not logged."""
        import logging

        quiet = logging.getLogger("distributed")
        level = quiet.level
        quiet.setLevel(logging.CRITICAL)
        try:
            if self._client is not None:
                self._client.close()
            if self._cluster is not None:
                self._cluster.close()
        finally:
            quiet.setLevel(level)
        self._client = self._cluster = None

    def __enter__(self) -> Runner:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def in_process(self) -> bool:
        """The tasks run here, one after another (no scheduler given, no worker processes)."""
        return not self.scheduler and not self.processes

    def run(self, tasks: Iterable[Task], folder: str | Path, desc: str = "sweep"
            ) -> list[dict | None]:
        """Records of ``tasks`` (None where a task could not finish), computing the missing."""
        from tqdm import tqdm

        tasks = list(tasks)
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(folder)
        unique = {t.id: t for t in tasks}
        todo = [t for t in unique.values() if load_record(folder, t) is None]
        if todo:
            todo.sort(key=lambda t: -t.cost)
            disable = None if self.progress is None else not self.progress
            with tqdm(total=len(todo), desc=desc, unit="task", disable=disable) as bar:
                for task, outcome in self._outcomes(todo, folder):
                    try:
                        record, arrays = outcome()
                    except Exception as err:  # noqa: BLE001 - e.g. a worker killed by the OS
                        record, arrays = {"status": "error", "message": repr(err)}, {}
                    else:
                        if not record_path(folder, task).is_file():
                            write_record(folder, task, record, arrays)
                    self.computed += 1
                    if record.get("status") not in ("ok",):
                        self.failed[task.id] = {"label": task.label, "status": record["status"],
                                                "message": record.get("message", "")}
                    bar.set_postfix_str(task.label[:40])
                    bar.update()
        return [load_record(folder, t) for t in tasks]

    def _outcomes(self, todo: list[Task], folder: Path):
        """(task, a function returning its (record, arrays) or raising) as tasks finish."""
        if self.in_process:
            self.start()
            for task in todo:
                yield task, (lambda t=task: run_task(t, str(folder)))
            return
        client = self.client()
        futures = {client.submit(run_task, t, str(folder), pure=False,
                                 priority=len(todo) - i): t for i, t in enumerate(todo)}
        as_completed = require("dask.distributed", "studies").as_completed
        for future in as_completed(futures):
            yield futures[future], future.result
