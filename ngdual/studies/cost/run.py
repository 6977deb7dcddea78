"""``cost``: what accuracy costs on one scene, within a budget of wall time.

Step 1, COMPUTE: every method (:mod:`~.methods`) as one sweep task within its share of the
budget (:mod:`~.budget`), on dask workers or in this process. Step 2, MEASURE: every
solution against the references of :mod:`~.errors`, whose own errors say which targets they
resolve. Step 3, TABULATE: the least wall time to each target (:mod:`~.table`).
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ...accuracy import pressure_window
from ...scene import SceneError, load_scene, read_toml
from ..sweep import Runner, load_arrays, load_record
from .budget import reference_elements, reference_methods, shares
from .errors import candidates, true_errors_of
from .methods import methods
from .table import MEASURES, accuracy_rows

DEFAULT_BUDGET_S = 120.0


class NoReference(RuntimeError):
    """None of the runs the references come from finished a step: nothing to measure
    against."""


@dataclass
class CostResult:
    """What :func:`cost` measured on one scene.

    ``methods``: per method its share of the budget (s), status and solutions; ``rows``:
    every solution with its unknowns, wall time and true errors (:func:`~.errors.
    true_errors_of`); ``references``: per measure the reference, its own error and the
    targets it resolves; ``runs``: the own-error checks of every adaptive run; ``table``:
    the least wall time to each target per measure and method (:func:`~.table.
    accuracy_rows`); ``window``: the pressure's error is on lo <= x <= hi (None: all of
    Gamma_C); ``seconds``: the
    wall time of the whole study, ``phases`` its parts (``start_s``, ``compute_s``,
    ``measure_s``).
    """

    scene: str
    budget_s: float
    workers: int
    window: tuple[float, float] | None
    measures: tuple[str, ...]
    methods: list[dict]
    rows: list[dict]
    references: dict
    runs: list[dict]
    table: list[dict]
    seconds: float = 0.0
    phases: dict = field(default_factory=dict)
    machine: dict = field(default_factory=dict)

    def record(self) -> dict:
        """Everything as plain data, with the package versions (``cost.json``)."""
        from ...io import plain, versions

        return plain({**asdict(self), "versions": versions()})


def scene_source(scene: str) -> str:
    """The scene as a worker finds it: an existing TOML file by its absolute path, else the
    shipped name."""
    path = Path(scene)
    return str(path.resolve()) if path.is_file() else scene


def records_folder(out: Path, source: str, overrides) -> Path:
    """``out/records/<digest>``: the sweep records of the scene's text and ``overrides``, so
    that a scene file edited between two runs is never measured by the other's records."""
    _, data = read_toml(source)
    digest = hashlib.sha1(json.dumps([data, list(overrides)], sort_keys=True,
                                     default=str).encode()).hexdigest()[:12]
    return out / "records" / digest


def check_measurable(scene) -> None:
    """A SceneError naming the field when no error of the scene is finite or it has nothing
    to measure: the thesis' ends of Gamma_C (sigma ~ 1/r at a clamped end, not in L2), no
    Gamma_C (no pressure)."""
    if not scene.has_contact:
        raise SceneError("boundary.contact", "ngdual cost measures the contact pressure and "
                                             "the stress: the scene has no contact boundary")
    if scene.contact.ends == "thesis":
        raise SceneError("contact.ends", 'the thesis\' ends set lambda = 0 at a clamped end of '
                                         "Gamma_C, where sigma is then not in L2: no error is "
                                         "finite; use --set contact.ends='consistent'")


def cost(scene: str, budget_s: float = DEFAULT_BUDGET_S, out: str | Path = "cost-output",
         orders=(0, 1, 2), overrides=(), window: tuple[float, float] | None = None,
         workers: int | None = None, processes: bool = True,
         progress: bool | None = None) -> CostResult:
    """What accuracy costs on ``scene``: uniform and adaptive PEERS_k at ``orders`` (both
    goals), the primal peers P1 / P2 uniform and adaptive, within ``budget_s`` seconds of
    wall time, against references whose own errors it measures.

    Parameters
    ----------
    scene : str
        A shipped scene's name or the path of a TOML scene, with ``overrides``
        (``section.key=value``).
    budget_s : float
        The wall time of the whole study: start-up, the methods' runs (each stops before a
        step that would end past its share), the true errors and the outputs.
    out : str or Path
        The folder of the sweep records (``out/records/<digest of the scene>``).
    orders : sequence of int
        The orders k of PEERS_k.
    window : (float, float), optional
        The pressure's error on the part lo <= x <= hi of Gamma_C; default
        :func:`ngdual.accuracy.pressure_window`: all of it, or its middle half where its
        pressure may be singular at an end (a flat punch's core, as the work-precision
        study measures it).
    workers, processes : int, bool
        dask workers (default: one per core), or the methods one after another in this
        process (``processes=False``).
    progress : bool, optional
        Progress bars (None: on a terminal).

    Returns
    -------
    CostResult

    Raises
    ------
    NoReference
        When none of the adaptive runs of the highest order finished a step.
    """
    start = time.perf_counter()
    sc = load_scene(scene, list(overrides))
    check_measurable(sc)
    window = pressure_window(sc) if window is None else tuple(window)
    source = scene_source(scene)
    folder = records_folder(Path(out), source, overrides)
    chosen = methods(orders)
    with Runner(None, workers, processes, progress) as runner:
        runner.start()
        parallel = 1 if runner.in_process else runner.workers
        started = time.perf_counter() - start
        left = budget_s - started
        share = shares(chosen, left, parallel)
        references = reference_methods(chosen)
        largest = reference_elements(chosen, budget_s)
        tasks = {m.name: [m.task(source, list(overrides), share[m], window,
                                 largest if m in references else None)] for m in chosen}
        runner.run([t for ts in tasks.values() for t in ts], folder, desc="methods")
    computed = time.perf_counter() - start
    found = candidates(tasks, lambda t: load_record(folder, t),
                       lambda t: load_arrays(folder, t) if load_record(folder, t) else {})
    names = [m.name for m in references]
    if not any(row["method"] in names and arrays for row, arrays in found):
        failed = "; ".join(f"{row['method']}: {row.get('message') or row['status']}"
                           for row, _ in found if row["method"] in names)
        raise NoReference(f"no reference to measure against: {failed}")
    measured = true_errors_of(sc, found, window, quadrature=False, progress=progress,
                              references_from=names)
    table = accuracy_rows(measured["rows"], measured["reference"])
    summary = []
    for m in chosen:
        [task] = tasks[m.name]
        record = load_record(folder, task) or {}
        summary.append({"method": m.name, "share_s": share[m], "task": task.id,
                        "status": record.get("status", "missing"),
                        "stopped_by": record.get("stopped_by"),
                        "message": record.get("message"),
                        "solutions": sum(r["method"] == m.name and r["status"] == "ok"
                                         for r, _ in found)})
    return CostResult(sc.name, budget_s, parallel, window, tuple(MEASURES), summary,
                      measured["rows"], measured["reference"], measured["runs"], table,
                      time.perf_counter() - start,
                      {"start_s": started, "compute_s": computed - started,
                       "measure_s": time.perf_counter() - start - computed},
                      {"cpus": os.cpu_count(), "load_average": list(os.getloadavg())})
