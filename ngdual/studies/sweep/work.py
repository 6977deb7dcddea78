"""Sweeps: many independent solves as dask tasks, each leaving its own record on disk.

A :class:`Task` is a kind (``"solve"``, ``"dofs"``, ``"adapt"``: the functions in
:data:`TASKS`) and JSON parameters; its id is a hash of both, so the same
computation always has the same id. :func:`run_task` computes a task and writes
``FOLDER/<id>.npz`` (arrays, if any) and then ``FOLDER/<id>.json`` (the record,
the commit marker), each to a temporary file that is renamed into place, so a
killed run never leaves a half-written record. :class:`Runner` submits the
tasks whose record is missing to a ``dask.distributed`` cluster (a
``LocalCluster`` by default, any running scheduler by address) and shows a
progress bar; re-running a sweep skips every finished task.

Statuses: ``"ok"``; ``"not-converged"`` (the solver returned without reaching its
tolerance, e.g. at ``solver.max_iter``); ``"failed"`` (it raised a
:class:`~ngdual.solvers.result.ConvergenceError`, whose message is kept) -- all
three are final. ``"error"`` (any other exception, with its traceback) is kept
for inspection but counts as unfinished, so the next run tries again.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import socket
import tempfile
import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .io import write_json

FINISHED = ("ok", "not-converged", "failed")
# part of every task id: raise it when what a task writes changes, so old records are not reused
RECORD_FORMAT = 2
WORKER_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "MPLBACKEND": "Agg"}


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


# --- the task kinds -----------------------------------------------------------------------------

def _scene(scene: str, overrides: list[str]):
    from .scene import load_scene

    return load_scene(scene, overrides)


def _status_of(solution) -> str:
    return "ok" if solution.converged else "not-converged"


def solve_task(scene: str, level: int, overrides: list[str] = (), fields: bool = False,
               samples: bool = False) -> tuple[dict, dict]:
    """Solve one scene on one level: the result record of ``ngdual solve`` (and field arrays).

    The record also holds the a posteriori estimator (4.50) of the solution
    (``estimator``: eta = (sum_T eta_T^2)^(1/2), eta_sum = sum_T eta_T, its time;
    not part of ``timings_s``). With ``fields=True`` the arrays hold what the
    figures of Section 3.4 plot (:func:`field_arrays`); with ``samples=True`` the solution
    as the arrays of :func:`ngdual.verification.reference.solution_samples` (true errors).
    """
    from .estimator import estimate
    from .post import result_record
    from .solvers import solve_scene

    solution = solve_scene(_scene(scene, list(overrides)), level)
    record = result_record(solution)
    record["status"] = _status_of(solution)
    record["ndof"] = int(sum(record["dofs"].values()))
    indicators = estimate(solution)
    record["estimator"] = {"eta": indicators.total, "eta_sum": indicators.total_sum,
                           "seconds": indicators.seconds}
    arrays = field_arrays(solution) if fields else {}
    if samples:
        from .verification.reference import solution_samples

        arrays.update(solution_samples(solution))
    return record, arrays


def field_arrays(solution) -> dict[str, np.ndarray]:
    """Everything Figs. 3.11-3.28 plot, as plain arrays (no NGSolve objects).

    Element values at the centroids of the fine mesh (``points``, ``triangles``):
    ``von_mises`` (plane strain, Section 3.4), ``u1``, ``u2``, ``eta``. On
    Gamma_N at the fine vertices: ``phi_x``, ``phi1``, ``phi2``. On Gamma_C
    (:func:`ngdual.post.contact_traces`): per fine edge ``edge_x``,
    ``sigma_n``, ``sigma_t``, ``edge_active``; per fine vertex ``node_x``,
    ``lam_n``, ``lam_t``, ``gap``; per h~ node ``coarse_x``, ``in_contact`` and the
    pressure and shear traction the contact conditions see, ``hat_x`` (coordinate along the
    foundation), ``hat_pressure``, ``hat_shear``
    (:func:`ngdual.verification.analytic.traction_profile`).
    With friction (:func:`ngdual.post.friction_diagnostics`): per h~ node
    ``hat_ratio`` (|int sigma_t mu_i| / |int sigma_n mu_i|), ``bound_ratio``
    (|int sigma_t mu_i| / int F mu_i, at most 1 by (3.62): the discrete Coulomb
    condition) and ``node_status`` (0 separation, 1 stick, 2 slip); per h^ edge
    ``nu``, ``nu_start``, ``nu_end`` (x-interval), ``F`` and ``nu_status``
    (0 free, 1 stick, 2 slip).
    """
    import ngsolve as ngs

    from . import post

    pb = solution.problem
    mesh = pb.fes.mesh
    f = post.fields(solution)
    out = {}
    cfs = {"von_mises": post.von_mises(f.sigma, pb.scene.material.nu), "u1": f.u[0],
           "u2": f.u[1], "eta": f.eta}
    for name, cf in cfs.items():
        out["points"], out["triangles"], out[name] = post.element_values(mesh, cf)
    if f.phi is not None:
        xy = []
        for chain in pb.spaces.neumann.chains:
            xy.append(chain.path_points)
        xy = np.vstack(xy)
        xy = xy[np.argsort(xy[:, 0])]
        values = np.asarray(f.phi(mesh(xy[:, 0], xy[:, 1], VOL_or_BND=ngs.BND)))
        out.update(phi_x=xy[:, 0], phi1=values[:, 0], phi2=values[:, 1])
    if pb.spaces.contact is not None:
        tr = post.contact_traces(solution)
        out.update(edge_x=tr.edge_xy[:, 0], edge_length=tr.edge_length, sigma_n=tr.sigma_n,
                   sigma_t=tr.sigma_t, edge_active=tr.edge_active, node_x=tr.node_xy[:, 0],
                   lam_n=tr.lam_n, lam_t=tr.lam_t, gap=tr.gap, coarse_x=tr.coarse_xy[:, 0],
                   in_contact=tr.coarse_in_contact)
        from .verification.analytic import traction_profile

        profile = traction_profile(solution)
        out.update(hat_x=profile.x, hat_pressure=profile.pressure, hat_shear=profile.shear)
    if solution.nu is not None:
        from .friction import build_friction_forms

        diag = post.friction_diagnostics(solution)
        bound = build_friction_forms(pb).q_matrix(solution.friction_bound).T @ np.ones(
            len(solution.nu))
        out["bound_ratio"] = np.where(bound > 0, np.abs(diag.t_t) / np.where(bound > 0, bound,
                                                                            1.0), 0.0)
        codes = {"separation": 0, "free": 0, "stick": 1, "slip": 2}
        hat = pb.spaces.friction
        start = np.concatenate([ch.path_points[n[:-1], 0] for ch, n in zip(hat.chains,
                                                                            hat.nodes)])
        end = np.concatenate([ch.path_points[n[1:], 0] for ch, n in zip(hat.chains, hat.nodes)])
        out.update(hat_node_x=diag.node_xy[:, 0], hat_ratio=diag.traction_ratio,
                   node_status=np.array([codes[s] for s in diag.node_status]),
                   nu=diag.nu, nu_start=np.minimum(start, end), nu_end=np.maximum(start, end),
                   F=diag.F, nu_status=np.array([codes[s] for s in diag.edge_status]))
    return out


def dofs_task(scene: str, level: int, overrides: list[str] = ()) -> tuple[dict, dict]:
    """The DOF counts of Table 3.1 and the mesh size h on one level (no assembly)."""
    from .forms import Spaces
    from .mesh import build_mesh, mesh_size

    sc = _scene(scene, list(overrides))
    mesh = build_mesh(sc.geometry, level)
    dofs = Spaces.build(sc, mesh).dofs()
    return {"status": "ok", "scene": scene, "level": level, "dofs": dofs,
            "ndof": int(sum(dofs.values())), "h": mesh_size(mesh), "elements": mesh.ne}, {}


class _Budget(Exception):
    """An adaptive run reached its element budget."""


def adapt_task(scene: str, marking: str, theta: float, steps: int, level: int,
               overrides: list[str] = (), snapshots: list[int] = (), samples: bool = False,
               max_elements: int | None = None) -> tuple[dict, dict]:
    """An adaptive run (:func:`ngdual.afem.adapt`): its history, with extras for Section 4.2.

    Every step record of :func:`ngdual.afem.step_record` gets ``eta_as`` (the
    largest eta_{as,T} with as(sigma_h) in L^2 and in H(div), and the share
    q_as of triangles with eta_{as,T} >= 0.1 max, Table 4.2) and ``cumulative_s``
    (the wall time from the start to this step's marks, all solves, estimates and
    refinements before included; not the extra H(div) estimate). The
    meshes of the steps in ``snapshots`` are kept as arrays ``points_<k>``,
    ``triangles_<k>`` and ``marked_<k>``. A ConvergenceError keeps the steps done.
    With ``samples=True`` every step's solution is kept as the arrays of
    :func:`ngdual.verification.reference.solution_samples`, prefixed ``s<k>_``; the run stops
    after the first step whose mesh has at least ``max_elements`` triangles.
    """
    from .afem import adapt
    from .estimator import estimate
    from .mesh import mesh_arrays
    from .solvers.result import ConvergenceError

    history, arrays = [], {}
    start, extra = time.perf_counter(), [0.0]

    def on_step(record, solution, indicators, marked):
        # wall time up to this solution, its estimate and marks (refine of the step before
        # included; step_record's "solve" leaves out the Gamma_C condensation)
        record["cumulative_s"] = time.perf_counter() - start - extra[0]
        t0 = time.perf_counter()
        hdiv = estimate(solution, "hdiv")
        record["eta_as"] = {}
        for norm, est in (("l2", indicators), ("hdiv", hdiv)):
            eta_as = np.sqrt(est.terms["asymmetry"])
            record["eta_as"][norm] = {"max": float(eta_as.max()),
                                      "q": float(np.mean(eta_as >= 0.1 * eta_as.max()))}
        k = record["step"]
        if k in snapshots:
            mesh = solution.problem.fes.mesh
            arrays[f"points_{k}"], arrays[f"triangles_{k}"] = mesh_arrays(mesh)
            arrays[f"marked_{k}"] = (np.zeros(mesh.ne, bool) if marked is None
                                     else np.asarray(marked, bool))
        if samples:
            from .verification.reference import solution_samples

            arrays.update({f"s{k}_{n}": v for n, v in solution_samples(solution).items()})
        history.append(record)
        extra[0] += time.perf_counter() - t0
        if max_elements is not None and record["elements"] >= max_elements:
            raise _Budget

    run = {"scene": scene, "marking": marking, "theta": theta, "steps": steps, "level": level,
           "overrides": list(overrides)}
    try:
        adapt(_scene(scene, list(overrides)), marking, theta, steps, level, on_step=on_step)
        status = "ok" if all(r["converged"] for r in history) else "not-converged"
    except ConvergenceError as err:
        run.update(message=str(err))
        status = "failed"
    except _Budget:
        status = "ok" if all(r["converged"] for r in history) else "not-converged"
    run.update(status=status, history=history)
    return run, arrays


def peer_task(scene: str, level: int, order: int, overrides: list[str] = (),
              subdivisions: int = 1) -> tuple[dict, dict]:
    """The scene solved by the primal peer (``benchmarks/primal_peer.py``: P``order``
    displacements, Nitsche contact, semismooth Newton) on the scene's mesh of ``level``:
    DOFs, Newton steps, wall time (meshing included) and the arrays of
    :func:`benchmarks.primal_peer.primal_samples` (pressure samples on Gamma_C edges split
    into ``subdivisions`` parts). Needs the source checkout (benchmarks/ is not installed)."""
    import sys

    root = str(Path(__file__).resolve().parent.parent)
    if root not in sys.path:
        sys.path.insert(0, root)
    from benchmarks.primal_peer import NewtonError, primal_samples, solve_scene_primal

    sc = _scene(scene, list(overrides))
    try:
        result, seconds = solve_scene_primal(sc, level, order)
    except NewtonError as err:
        return {"status": "failed", "message": str(err)}, {}
    record = {"status": "ok", "scene": scene, "level": level, "order": order,
              "ndof": int(result.ndof), "newton_iterations": result.newton_iterations,
              "timings_s": {**{k: float(v) for k, v in result.times.items()},
                            "total": seconds}}
    return record, primal_samples(sc, result, subdivisions)


def manufactured_task(case: str, level: int, marking: str | None = None, theta: float = 0.5,
                      steps: int = 1) -> tuple[dict, dict]:
    """A manufactured case (:mod:`ngdual.verification.manufactured`) on uniform ``level``
    (``marking=None``) or adaptively from it: per step the DOFs, the estimator eta of (4.50)
    and the exact errors (:func:`~ngdual.verification.manufactured.volume_errors`)."""
    from .afem import adapt
    from .verification.manufactured import manufactured_case, volume_errors

    mc = manufactured_case(case)
    history = []

    def on_step(record, solution, indicators, marked):
        history.append({"step": record["step"], "ndof": record["dofs"]["total"],
                        "elements": record["elements"], "eta": record["eta"],
                        "converged": record["converged"],
                        "errors": volume_errors(mc, solution)})

    adapt(mc.scene(), marking or "max", theta if marking else 0.0,
          steps if marking else 1, level, on_step=on_step)
    return {"status": "ok" if all(r["converged"] for r in history) else "not-converged",
            "case": case, "history": history}, {}


TASKS: dict[str, Callable[..., tuple[dict, dict]]] = {
    "solve": solve_task, "dofs": dofs_task, "adapt": adapt_task, "peer": peer_task,
    "manufactured": manufactured_task}


# --- records on disk ----------------------------------------------------------------------------

def versions() -> dict:
    """:func:`ngdual.post.versions` plus dask and distributed."""
    from importlib import metadata

    from .post import versions as package_versions

    out = package_versions()
    for pkg in ("dask", "distributed"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def execute(task: Task) -> tuple[dict, dict]:
    """Compute ``task`` (no files): its record and arrays, failures included."""
    from threadpoolctl import threadpool_limits

    from .solvers.result import ConvergenceError

    started = time.time()
    start = time.perf_counter()
    arrays: dict = {}
    try:
        # one BLAS thread per task, one task per core: fair timings (see ngdual.bench)
        with threadpool_limits(limits=1):
            record, arrays = TASKS[task.kind](**task.params)
    except ConvergenceError as err:
        record = {"status": "failed", "message": str(err), "history_length": len(err.history)}
    except Exception as err:  # noqa: BLE001 - a sweep never dies of one task
        record = {"status": "error", "message": f"{type(err).__name__}: {err}",
                  "traceback": traceback.format_exc()}
    header = {"id": task.id, "kind": task.kind, "params": task.params, "label": task.label,
              "started": started, "wall_s": time.perf_counter() - start,
              "host": socket.gethostname(), "pid": os.getpid(),
              "load_average": list(os.getloadavg()),  # at the end: wall times depend on it
              "python": platform.python_version(), "arrays": sorted(arrays),
              "versions": versions()}
    return {**header, **record, "status": record.get("status", "ok")}, arrays


def record_path(folder: str | Path, task: Task) -> Path:
    return Path(folder) / f"{task.id}.json"


def arrays_path(folder: str | Path, task: Task) -> Path:
    return Path(folder) / f"{task.id}.npz"


def _write_npz(arrays: dict, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez_compressed(fh, **arrays)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_record(folder: str | Path, task: Task, record: dict, arrays: dict) -> Path:
    """Arrays first, then the record (the marker of a finished task), each atomically."""
    if arrays:
        _write_npz(arrays, arrays_path(folder, task))
    return write_json(_finite(record), record_path(folder, task))


def _finite(value):
    """JSON has no NaN / inf: write them as None (the record stays readable everywhere)."""
    if isinstance(value, float) and not np.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, np.generic):
        return _finite(value.item())
    return value


def run_task(task: Task, folder: str) -> tuple[dict, dict]:
    """Compute ``task`` and write its record into ``folder`` (the function dask runs)."""
    record, arrays = execute(task)
    write_record(folder, task, record, arrays)
    return record, arrays


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


# --- running on a dask cluster ------------------------------------------------------------------

def warm_up() -> None:
    """Solve a tiny scene with each solver once, so that the first timed task of a worker does
    not pay for imports and NGSolve's first-call set-up."""
    from .solvers import solve_scene

    for method in ("auto", "uzawa"):
        solve_scene(_scene("thesis-3.46-coulomb", [f'solver.method="{method}"']), 1)


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
        Worker processes (default), or one worker thread in this process
        (quick to start, what the tests use; one task at a time: netgen and
        NGSolve must not mesh or assemble in two threads at once).
    """

    def __init__(self, scheduler: str | None = None, workers: int | None = None,
                 processes: bool = True, progress: bool | None = None):
        self.scheduler, self.processes = scheduler, processes
        self.workers = workers or os.cpu_count() or 1
        self.progress = progress
        self._client = self._cluster = None
        self.failed: dict[str, dict] = {}
        self.computed = 0

    def client(self):
        if self._client is None:
            from dask.distributed import Client, LocalCluster

            if self.scheduler:
                self._client = Client(self.scheduler)
            else:
                self._cluster = LocalCluster(
                    n_workers=self.workers if self.processes else 1, threads_per_worker=1,
                    processes=self.processes, dashboard_address=None, memory_limit=0,
                    **({"env": WORKER_ENV} if self.processes else {}))
                self._client = Client(self._cluster)
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

    def run(self, tasks: Iterable[Task], folder: str | Path, desc: str = "sweep"
            ) -> list[dict | None]:
        """Records of ``tasks`` (None where a task could not finish), computing the missing."""
        from dask.distributed import as_completed
        from tqdm import tqdm

        tasks = list(tasks)
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(folder)
        unique = {t.id: t for t in tasks}
        todo = [t for t in unique.values() if load_record(folder, t) is None]
        if todo:
            client = self.client()
            todo.sort(key=lambda t: -t.cost)
            futures = {client.submit(run_task, t, str(folder), pure=False,
                                     priority=len(todo) - i): t for i, t in enumerate(todo)}
            disable = None if self.progress is None else not self.progress
            with tqdm(total=len(todo), desc=desc, unit="task", disable=disable) as bar:
                for future in as_completed(futures):
                    task = futures[future]
                    try:
                        record, arrays = future.result()
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
