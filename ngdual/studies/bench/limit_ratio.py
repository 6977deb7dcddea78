"""How far each contact solver is from the cost of one linear solve (``ngdual bench
limit-ratio``).

For Example 3.46 without friction (``thesis-3.46``) and with Coulomb friction
(``thesis-3.46-coulomb``), per level and solver variant, one record with the DOFs, the
assembly time, the contact-solve time and its parts, iterations, peak memory and the
**limit ratio**

    limit_ratio = seconds_total / linear_seconds,

seconds_total being everything the solver does after assembly (factorisation,
condensation, iterations, recovery of all unknowns, the final residual checks) and
linear_seconds one factorisation plus one solve of the same saddle-point matrix with the
solver's own linear algebra, measured in the same run: NGSolve's UMFPACK on
[[A, B], [B^T, 0]] for the Uzawa variants, the hybridised system with its Cholesky
factorisation (:mod:`ngdual.solvers.hybrid`, :mod:`ngdual.solvers.cholesky`) for the
active-set solver. ``limit_ratio_fastest`` divides by the fastest linear solve measured
in the run instead (the Uzawa records measure both), so that the variants are compared on
one scale.

Solver variants: ``uzawa`` (Algorithm 3.38 / nested Uzawa 3.41 with Remark 3.45, the
scene's default steps rho = rho1 = rho2 = 1), ``uzawa-tuned`` (the steps of ``TUNED``),
``active-set`` (:mod:`ngdual.solvers.active_set`), as spelled in
:data:`ngdual.studies.variants.VARIANTS`. Every solver runs with ``BLAS_THREADS`` BLAS
threads (:mod:`ngdual.tolerances`): UMFPACK and CHOLMOD call the first OpenBLAS in the
process (NGSolve's, threaded), whose spin-waiting threads on cores shared with other
processes made the same UMFPACK factorisation take 0.8 s or 34 s. Functions return
records; printing and file writing are in :mod:`ngdual.cli`.
"""

from __future__ import annotations

import os
import subprocess
import time

from threadpoolctl import threadpool_limits

from ...tolerances import BLAS_THREADS
from ..variants import TUNED, VARIANTS
from .measure import header, in_fresh_process, peak_rss_mb

CASES = {"thesis-3.46": "thesis-3.46-frictionless", "thesis-3.46-coulomb": "thesis-3.46-coulomb"}
SOLVERS = ("uzawa", "uzawa-tuned", "active-set")
ISOLATE_FROM_LEVEL = 4
# the table ngdual bench limit-ratio prints: (title, key of a record, format)
COLUMNS = (("case", "case", "20s"), ("lvl", "level", "3d"), ("solver", "solver", "12s"),
           ("unknowns", "ndof", "9d"), ("assemble", "seconds_assemble", "8.2f"),
           ("linear", "linear_seconds", "8.2f"), ("contact", "seconds_total", "8.2f"),
           ("ratio", "limit_ratio", "6.2f"), ("r_fast", "limit_ratio_fastest", "6.2f"),
           ("outer", "iterations.outer", "6d"), ("inner", "iterations.inner", "6d"),
           ("RSS MB", "peak_rss_mb", "7.0f"))
_WARM: set = set()


def _overrides(solver: str) -> list[str]:
    if solver not in SOLVERS:
        raise ValueError(f"unknown solver {solver!r}; use one of {SOLVERS}")
    return list(VARIANTS[solver].overrides)


def linear_seconds(problem, backend: str) -> dict:
    """One factorisation and one solve of the saddle-point system of ``problem``.

    ``backend``: ``"umfpack"`` ([[A, B], [B^T, 0]] by NGSolve's UMFPACK) or
    ``"hybrid-cholesky"`` (hybridisation, static condensation, CHOLMOD, one solve and the
    recovery of sigma and u). Returns the times and, for Cholesky, the factor's nonzeros.
    """
    from ...solvers.cholesky import SchurCholesky
    from ...solvers.hybrid import HybridSystem
    from ...solvers.linear import Factorization

    start = time.perf_counter()
    if backend == "umfpack":
        saddle = problem.saddle
        fact = Factorization(problem.block(saddle, saddle))
        factorized = time.perf_counter()
        fact.solve(problem.rhs[saddle])
        nnz = None
    elif backend == "hybrid-cholesky":
        hybrid = HybridSystem(problem, friction=problem.scene.has_friction)
        chol = SchurCholesky(hybrid.H, hybrid.contact_index)
        factorized = time.perf_counter()
        hybrid.unknowns(chol.solve(hybrid.rhs(problem.rhs)), problem.rhs)
        nnz = chol.nnz
    else:
        raise ValueError(f"unknown backend {backend!r}")
    end = time.perf_counter()
    return {"backend": backend, "factorize": factorized - start, "solve": end - factorized,
            "total": end - start, "nnz_factor": nnz}


def run_one(case: str, level: int, solver: str, blas_threads: int | None = BLAS_THREADS,
            warm_up: bool = True) -> dict:
    """Assemble ``case`` on ``level``, time the linear solves and the contact solver.

    All of it runs with ``blas_threads`` BLAS threads (None: the libraries' defaults); with
    ``warm_up`` the same record is computed on level 1 first, so that one-time costs
    (imports, code generation) fall on no measurement (once per process).
    """
    from ... import forms, solvers  # noqa: F401  (loads NGSolve and its BLAS before the limit)

    with threadpool_limits(limits=blas_threads, user_api="blas"):
        if warm_up and (case, solver) not in _WARM:
            _measure(case, 1, solver)
            _WARM.add((case, solver))
        load = list(os.getloadavg())
        record = _measure(case, level, solver)
    record.update(blas_threads=blas_threads, load_average=load)
    return record


def _measure(case: str, level: int, solver: str) -> dict:
    from ...forms import assemble
    from ...mesh import build_mesh
    from ...quantities import norms
    from ...scene import load_scene
    from ...solution import ConvergenceError
    from ...solvers import solve_problem

    scene = load_scene(CASES[case], _overrides(solver))
    start = time.perf_counter()
    problem = assemble(scene, build_mesh(scene.geometry, level))
    problem.level = level
    assemble_s = time.perf_counter() - start
    # the active-set records skip UMFPACK (minutes from level 7 on); the Uzawa records
    # measure both, the Cholesky of the hybridised system costing little
    backends = ("hybrid-cholesky",) if solver == "active-set" else ("umfpack", "hybrid-cholesky")
    linear = {b: linear_seconds(problem, b) for b in backends}
    own = linear[backends[0]]
    start, cpu = time.perf_counter(), time.process_time()
    error = None
    try:
        solution = solve_problem(problem)
    except ConvergenceError as err:
        solution, error = None, str(err)
    total, cpu = time.perf_counter() - start, time.process_time() - cpu
    fastest = min(v["total"] for v in linear.values())
    record = {
        "case": case, "scene": scene.name, "level": level, "solver": solver,
        "method": solution.method if solution else None,
        "ndof": problem.n, "dofs": problem.spaces.dofs(),
        "converged": bool(solution and solution.converged), "error": error,
        "iterations": {k: int(v) for k, v in solution.iterations.items()} if solution else None,
        "seconds_assemble": assemble_s,
        "seconds_total": total,
        "cpu_seconds_total": cpu,
        "seconds_parts": {k: float(v) for k, v in solution.timings.items()
                          if k != "assemble"} if solution else {},
        "linear_seconds": own["total"],
        "linear": linear,
        "limit_ratio": total / own["total"],
        "limit_ratio_fastest": total / fastest,
        "nnz_factor": own["nnz_factor"],
        "residuals": {k: float(v) for k, v in solution.residuals.items()} if solution else {},
        "norms": norms(solution) if solution else None,
        "peak_rss_mb": peak_rss_mb(),
    }
    return record


def _run_isolated(case: str, level: int, solver: str, timeout: float | None,
                  blas_threads: int | None) -> dict:
    """:func:`run_one` in a fresh process, so that its peak memory is its own."""
    try:
        return in_fresh_process("limit_ratio:run_one", timeout, case=case, level=level,
                                solver=solver, blas_threads=blas_threads)
    except subprocess.TimeoutExpired:
        error = f"timed out after {timeout} s"
    except subprocess.CalledProcessError as err:
        error = err.stderr.strip().splitlines()[-1:]
    return {"case": case, "scene": CASES[case], "level": level, "solver": solver,
            "converged": False, "error": error, "seconds_total": None, "limit_ratio": None,
            "iterations": None, "peak_rss_mb": None}


def run(levels, cases=tuple(CASES), solvers=SOLVERS, isolate: str = "auto",
        timeout: float | None = None, on_record=None,
        blas_threads: int | None = BLAS_THREADS) -> dict:
    """All records for ``cases`` x ``levels`` x ``solvers``, with versions and machine.

    ``isolate``: ``"always"`` runs every record in its own process (its own peak memory;
    ``peak_rss_scope = "run"``), ``"never"`` runs all in this process (peak memory of the
    process so far, ``"process"``), ``"auto"`` isolates from level ``ISOLATE_FROM_LEVEL``
    on. ``timeout`` bounds an isolated run. ``on_record(study)`` is called after each record
    with everything so far (for progress and atomic partial output).
    """
    for case in cases:
        if case not in CASES:
            raise ValueError(f"unknown case {case!r}; use one of {tuple(CASES)}")
    for solver in solvers:
        _overrides(solver)
    study = header("limit-ratio", tuned=TUNED)
    study["machine"]["blas_threads"] = blas_threads
    for case in cases:
        for level in levels:
            for solver in solvers:
                isolated = isolate == "always" or (isolate == "auto"
                                                   and level >= ISOLATE_FROM_LEVEL)
                if isolated:
                    record = _run_isolated(case, level, solver, timeout, blas_threads)
                else:
                    record = run_one(case, level, solver, blas_threads)
                record["peak_rss_scope"] = "run" if isolated else "process"
                record["versions"] = study["versions"]
                study["records"].append(record)
                if on_record:
                    on_record(study)
    study["machine"]["load_average_end"] = list(os.getloadavg())
    return study
