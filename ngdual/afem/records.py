"""The history of the adaptive loop: one plain record per step, and the reference norms.

:func:`step_record` holds DOFs, the estimate and its terms, the norms of Tables 3.2/3.3,
iterations and the wall time of every phase; given the norms of the exact solution
(e.g. Aitken-extrapolated from uniform levels, :func:`reference_norms`), also the total
error (3.124) and the effectivity index estimate / e_tot (Table 4.4).
:func:`relative_estimate` is what a tolerance is compared with.
"""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from ..estimator import Estimate
from ..quantities import norms
from ..rates import extrapolated_norms, total_error
from ..scene import Scene, SceneError, SceneTypeError, check_level, ensure_valid
from ..solution import Solution
from ..solvers import solve_scene


def relative_estimate(record: dict) -> float:
    """The goal's estimate relative to the size of the solution it measures.

    ``goal_estimate`` over ``goal_size`` (:meth:`ngdual.goal.Goal.measure`): for the stress
    goal the estimate (sum_T eta_{tot,T}^2)^{1/2} of (4.50) over ||sigma_h||_{H(div)}, the
    leading part of the total error (3.124) that (4.50) bounds; for the pressure goal the
    estimate of ||p - p_h||_{L2(W)} over ||p_h||_{L2(W)}. A zero size gives infinity (no tol
    is reached: :class:`~ngdual.afem.stops.Stalled` says why), unless the estimate is zero
    too (a solution that is zero everywhere the goal measures, and estimated to be exact
    there).

    >>> relative_estimate({"goal_estimate": 1.0, "goal_size": 4.0})
    0.25
    """
    size, total = record["goal_size"], record["goal_estimate"]
    if size > 0:
        return total / size
    return 0.0 if total == 0 else float("inf")


def step_record(step: int, solution: Solution, estimated: Estimate,
                reference: dict | None = None) -> dict:
    """The history entry of one adaptive step (plain JSON-serialisable data).

    ``estimator`` is the estimate (sum_T eta_{tot,T}^2)^{1/2} of (4.50);
    ``estimator_terms[k]`` is (sum_T term_k,T)^{1/2}, so ``estimator``^2 is the sum of their
    squares; ``estimator_sum`` is sum_T eta_{tot,T} (the eta_tot of Table 4.4) and
    ``estimator_max`` the largest indicator. ``norms`` are those of Tables 3.2/3.3, where
    ``eta`` is the rotation. ``warnings`` lists the physics checks the step's solution
    fails (:mod:`ngdual.checks`). With ``reference`` (the norms of the exact solution):
    ``errors``, ``e_tot`` of (3.124) and the effectivity indices ``estimator`` / e_tot and
    ``estimator_sum`` / e_tot.
    """
    pb = solution.problem
    mesh = pb.fes.mesh
    dofs = pb.spaces.dofs()
    timings = solution.timings
    record = {
        "step": step,
        "elements": mesh.ne,
        "h_min": float(estimated.h.min()),
        "h_max": float(estimated.h.max()),
        "dofs": {**dofs, "total": int(sum(dofs.values()))},
        "converged": bool(solution.converged),
        "iterations": {k: int(v) for k, v in solution.iterations.items()},
        "estimator": estimated.total,
        "estimator_sum": estimated.total_sum,
        "estimator_max": float(estimated.indicators.max()),
        "estimator_terms": {k: float(np.sqrt(v)) for k, v in estimated.summed().items()},
        "asymmetry_norm": estimated.asymmetry,
        "norms": norms(solution),
        "warnings": [asdict(w) for w in solution.warnings],
        "marked": 0,
        "timings_s": {"assemble": float(timings.get("assemble", pb.assemble_seconds)),
                      "solve": float(timings.get("factorize", 0.0) + timings.get("condense", 0.0)
                                       + timings.get("solve", 0.0)),
                      "estimate": estimated.seconds, "mark": 0.0, "refine": 0.0},
    }
    if reference is not None:
        errors, e_tot = total_error(record["norms"], reference)
        record.update(errors=errors, e_tot=e_tot,
                      effectivity=estimated.total / e_tot if e_tot > 0 else None,
                      effectivity_sum=estimated.total_sum / e_tot if e_tot > 0 else None)
    return record


def reference_norms(scene: Scene, levels: list[int]) -> dict:
    """Norms of the exact solution, Aitken-extrapolated from uniform levels (Section 3.4).

    Uses the last three of ``levels`` (at least three, consecutive uniform
    refinements); see :func:`ngdual.rates.aitken_extrapolate` for its safeguard.
    """
    ensure_valid(scene)
    if not isinstance(levels, (list, tuple)):
        raise SceneTypeError("levels", f"must be a list of levels, got {levels!r}")
    for level in levels:
        check_level(level, "levels")
    if len(levels) < 3:
        raise SceneError("levels", f"Aitken extrapolation needs at least three levels, got "
                                   f"{list(levels)}")
    return extrapolated_norms([norms(solve_scene(scene, level)) for level in levels[-3:]])
