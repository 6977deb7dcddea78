"""How a benchmark measures: the machine, peak memory, median wall times, one record in a
fresh process, and the header of every benchmark's JSON."""

from __future__ import annotations

import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
import warnings
from collections.abc import Callable
from importlib import import_module

from ...io import versions


def machine() -> dict:
    """What the timings were measured on (the load average shows other processes)."""
    return {"processor": platform.processor() or platform.machine(),
            "cpu_count": os.cpu_count(), "load_average": list(os.getloadavg()),
            "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS")}


def peak_rss_mb() -> float:
    """The peak resident memory of this process so far, in MB."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def median_seconds(fn: Callable[[], object], repeat: int) -> float:
    """The median wall time of ``repeat`` calls of ``fn``."""
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - start)
    return statistics.median(runs)


def solve_quietly(scene, level: int):
    """:func:`ngdual.solvers.solve_scene` without printing the physics checks' warnings: a
    benchmark records them (``solution.warnings``) rather than interleaving them with its
    table."""
    from ...solution import PhysicsWarning
    from ...solvers import solve_scene

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        return solve_scene(scene, level)


def warning_messages(solution) -> list[str]:
    """The physics checks that failed on ``solution``, one message each."""
    return [w.message for w in solution.warnings]


def header(benchmark: str, **settings) -> dict:
    """The start of a benchmark's JSON: its name, package versions, the machine, its
    settings and (filled by the caller) its ``records``."""
    return {"benchmark": benchmark, "versions": versions(), "machine": machine(), **settings,
            "records": []}


def in_fresh_process(function: str, timeout: float | None = None, **params) -> dict:
    """The record of ``function`` (``"module:name"`` of :mod:`ngdual.studies.bench`) called
    with ``params`` in a fresh Python process, so that its peak memory is its own.

    Raises :class:`subprocess.TimeoutExpired` after ``timeout`` seconds and
    :class:`subprocess.CalledProcessError` (its ``stderr`` holds the message) on a failure.
    """
    cmd = [sys.executable, "-m", __name__, function, json.dumps(params)]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, timeout=timeout)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _call(function: str, params: dict) -> dict:
    module, name = function.split(":")
    return getattr(import_module(f"{__package__}.{module}"), name)(**params)


if __name__ == "__main__":  # the child process of in_fresh_process
    print(json.dumps(_call(sys.argv[1], json.loads(sys.argv[2]))))
