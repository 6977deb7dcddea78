"""Contact and friction at the cost of about one linear solve: condense onto Gamma_C, solve there.

1. Hybridise (:mod:`ngdual.solvers.hybrid`): the saddle-point system (3.97) becomes a
   symmetric positive definite H with the fine contact values zeta last.
2. Factorise H once with zeta eliminated last (:mod:`ngdual.solvers.cholesky`): the
   trailing block of the factor is the Schur complement S, so the traction moments on the
   fine Gamma_C edges are t_f(zeta) = t_hat - S zeta without any further solve.
3. With zeta = M z - (mean g, 0), z = (lambda_n, lambda_t) on the h~ mesh, the contact
   problem is the small dense problem t(z) = b - G z, G = M^T S M, b = M^T (t_hat + S g),
   solved by semismooth Newton (:mod:`ngdual.solvers.semismooth`). Coulomb friction is
   the fixed point F = mu_f |sigma_n| of (3.123) (Remark 3.45) on that small problem only:
   sigma_n per fine edge is t_f,n / |e|.
4. One back substitution gives the remaining unknowns, the element-local solves sigma and u.

The result is the discrete solution of (3.62) itself (not an approximation of it): the
residuals of every row of the assembled system (K x from its element matrices,
:meth:`~ngdual.forms.DiscreteProblem.apply`) and of the contact and friction conditions
are computed and reported; if they are not at round-off level a
:class:`ConvergenceError` is raised, naming each failing criterion with its value and
tolerance.

Tolerances. Every residual is relative to the size of its terms, and every tolerance is
``SAFETY`` (100) times the round-off level ``delta`` this problem can attain (reported as
``residuals["roundoff_level"]``), never a fixed number:

* ``delta_0 = eps max(kappa_1(G), dim G, (lambda + 2 mu) / mu)`` a priori. kappa_1(G)
  (LAPACK's estimate from a Cholesky factor, :func:`~ngdual.solvers.semismooth.kkt_tolerance`)
  bounds the round-off of the dense problem on Gamma_C. (lambda + 2 mu) / mu is the
  condition of the compliance: sigma is recovered from displacement traces w through a
  stiffness lambda + 2 mu, so where w is known to eps, sigma is known to
  eps (lambda + 2 mu) / mu of its size (times a mesh factor, below). For nu = 0.25 this is
  3, for nu = 0.4999 it is 5001.
* If a residual exceeds ``SAFETY delta_0``, ``delta`` is measured: a statistical condition
  estimate (Kenney and Laub's small-sample method with one sample): the rows of H w = r are
  perturbed by their unavoidable rounding, eps |H| |w| with random signs, the perturbation
  is carried through the factorisation and the recovery of sigma and u, and the residuals
  it causes in the rows of (3.62) and in the contact tractions are ``delta``. It costs one
  more solve and recovery. Measured: the residuals of the computed solution are 0.3 to 1.3
  times this estimate (Example 3.46 with nu = 0.4999, levels 2-6; a clamped block with
  nu = 0.25 and 0.4999, levels 2-5 and graded 2^12 towards a point; cattaneo-mindlin,
  levels 1-6 and 14 adaptive steps). It grows like eps (lambda + 2 mu) / mu diam / h_min:
  on level 6 1e-13 to 7e-13 for nu = 0.25 and 4e-10 for nu = 0.4999, 4e-8 after 14 adaptive
  steps of cattaneo-mindlin, which a fixed tolerance of 1e-9 would take for a failure.

The Coulomb bound is zero where :func:`ngdual.tolerances.friction_vanishes` says so: at most
1e-6 of its largest value, or below the round-off of a vanishing normal stress,
``SAFETY delta_0 mu_f`` times the stress scale (rounding errors of a separated Gamma_C are
below 1e-16 of it). The fixed point stops at
``tol`` or, once its change no longer halves per step below ``SAFETY eps kappa_1(G)`` (the
round-off of F), there; the semismooth Newton method stops at the same level.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..forms import DiscreteProblem
from ..friction import build_friction_forms, tresca_bound
from ..solution import ConvergenceError, Solution
from ..tolerances import COULOMB_FIXED_POINT_TOL
from .cholesky import SchurCholesky
from .coulomb import coulomb_bound, coulomb_fixed_point
from .hybrid import HybridSystem
from .linear import blas_threads
from .nested import friction_residuals
from .projections import NonnegativeProjection, metric_matrix
from .semismooth import EPS, SAFETY, BoundarySolution, condition_number, semismooth_newton
from .settings import ActiveSetSettings, Model
from .start import ContactStart
from .uzawa import contact_residuals

PROBE_SEED = 20110501      # the random signs of the round-off estimate (reproducible)
INFORMATIVE = ("qp_fallback", "roundoff_level")  # reported, not checked


def _linear_blocks(problem: DiscreteProblem) -> list[np.ndarray]:
    return [names for names in (problem.sigma, problem.index("u1", "u2"), problem.index("eta"),
                                problem.index("phi1", "phi2")) if len(names)]


def _linear_residual(problem: DiscreteProblem, x: np.ndarray,
                     dx: np.ndarray | None = None) -> float:
    """Largest blockwise relative residual of the rows sigma, u, eta, phi of K x = rhs.

    Each block (their units differ) is measured against the size of its own terms,
    ||(K x - rhs)_b|| / max(||t_b||, ||rhs_b||) in the max norm, t the terms of K x
    (:meth:`~ngdual.forms.DiscreteProblem.terms`, at least |K| |x|). With ``dx``: the
    residual K dx that a change dx of the solution x causes, on the same scale. K x and t
    come from the element matrices (:meth:`~ngdual.forms.DiscreteProblem.apply`): K itself
    is not formed.
    """
    terms = problem.terms(x)
    defect = problem.apply(x) - problem.rhs if dx is None else problem.apply(dx)
    worst = 0.0
    for names in _linear_blocks(problem):
        scale = max(np.max(terms[names], initial=0.0),
                    np.max(np.abs(problem.rhs[names]), initial=0.0))
        if scale > 0:
            worst = max(worst, float(np.max(np.abs(defect[names])) / scale))
    return worst


def _material_condition(model: Model) -> float:
    """(lambda + 2 mu) / mu (Lamé's): the condition of the compliance (module docstring)."""
    lam, mu = model.lame
    return (lam + 2 * mu) / mu


def _roundoff_probe(problem: DiscreteProblem, hybrid: HybridSystem, chol: SchurCholesky,
                    w: np.ndarray, x: np.ndarray, lam_t: np.ndarray | None = None,
                    lam_n: np.ndarray | None = None, traction_scale: float = 0.0) -> float:
    """The round-off level of the computed x, by a statistical condition estimate.

    The rows of H w = r cannot be satisfied better than their rounding, eps (|H| |w|)_i;
    a perturbation of that size (random signs, the contact values zeta fixed) is carried
    through the factorisation and the recovery of sigma, u (:meth:`HybridSystem.unknowns`).
    Returned: the relative residual it causes in the rows sigma, u, eta, phi of (3.62)
    (:func:`_linear_residual`) and in the traction moments C_n^T sigma, C_t^T sigma on
    Gamma_C (relative to max(|C^T sigma|, ``traction_scale``)), whichever is larger.
    """
    rng = np.random.default_rng(PROBE_SEED)
    perturbation = EPS * (abs(hybrid.H) @ np.abs(w)) * rng.choice((-1.0, 1.0), size=len(w))
    perturbation[hybrid.contact_index] = 0.0
    dw = chol.solve_with_last(chol.forward(perturbation), np.zeros(len(hybrid.contact_index)))
    dx = hybrid.unknowns(w + dw, lam_t, lam_n) - x
    level = _linear_residual(problem, x, dx)
    if lam_t is not None:  # with contact: the tractions on Gamma_C too
        sigma, d_sigma = x[problem.sigma], dx[problem.sigma]
        for rows in (problem.lam_n, problem.index("lam_t")):
            C = problem.block(problem.sigma, rows)
            scale = max(np.max(np.abs(C.T @ sigma), initial=0.0), traction_scale)
            if scale > 0:
                level = max(level, float(np.max(np.abs(C.T @ d_sigma), initial=0.0) / scale))
    return level


def _first_state(problem: DiscreteProblem, start: ContactStart | None, n_c: int,
                 n_rows: int) -> BoundarySolution | None:
    """The semismooth Newton start from ``start`` at this mesh's h~ nodes (dof order):
    the contact set of the coarser solution, prolonged (None: the cold start z = 0)."""
    if start is None:
        return None
    coarse = problem.spaces.gamma_c.coarse
    nodes = np.vstack([chain.path_points[coarse.dof_positions(c)]
                       for c, chain in enumerate(coarse.chains)])
    lam_n, lam_t = start.at(nodes)
    return BoundarySolution(np.maximum(lam_n, 0.0), lam_t, np.zeros(n_rows),
                            np.zeros(n_c, dtype=bool), np.zeros(n_rows, dtype=bool), 0, False,
                            {})


def active_set_solve(problem: DiscreteProblem, settings: ActiveSetSettings,
                     tol: float = COULOMB_FIXED_POINT_TOL, ordering: str = "amd",
                     progress: Callable[[int, float], None] | None = None,
                     start: ContactStart | None = None) -> Solution:
    """Solve (3.62) by condensation onto Gamma_C and semismooth Newton there.

    Parameters
    ----------
    settings : ActiveSetSettings
        The model (material, boundary parts, friction law, mu_f, h^), ``max_iter`` (bound
        on the Coulomb fixed-point steps) and ``metric`` (of the natural residual of the
        contact condition, reporting only).
    tol : float
        Relative change of F at which the Coulomb fixed point (3.123) stops (or at its
        round-off level, where it stagnates above ``tol``).
    ordering : {"amd", "metis"}
        Fill-reducing ordering of the hybridised matrix.
    start : ContactStart, optional
        The multipliers of a solution on a coarser mesh: the semismooth Newton method starts
        from their values at this mesh's h~ nodes (its first sets are their contact set),
        not from z = 0. The solution is the same.

    Raises
    ------
    ConvergenceError
        If the Coulomb fixed point does not converge in ``max_iter`` steps, the contact
        problem on Gamma_C is not solved, or the final residuals of (3.62) are not at
        round-off level; the message names the criterion, its value and its tolerance,
        ``history`` holds the iteration's residuals.
    """
    model = settings.model
    # the dense work is small (at most a few thousand unknowns): one BLAS thread is as fast
    # and immune to the spin-waiting of threaded BLAS on busy cores
    with blas_threads():
        try:
            return _active_set_solve(problem, settings, tol, ordering, progress, start)
        except ConvergenceError as err:
            if model.has_friction and model.hhat_factor == 1:
                raise ConvergenceError(f"{err}; with h^ = h~ the inf-sup condition (3.74) "
                                       "for nu fails where the contact zone reaches the end of "
                                       "Gamma_C: try contact.hhat_factor = 2",
                                       err.history) from err
            raise


def _active_set_solve(problem: DiscreteProblem, settings: ActiveSetSettings, tol: float,
                      ordering: str, progress: Callable[[int, float], None] | None,
                      warm: ContactStart | None) -> Solution:
    model = settings.model
    law, mu_f = model.law, model.mu_f
    timings = {"assemble": problem.assemble_seconds}
    start_all = time.perf_counter()
    hybrid = HybridSystem(problem, model)                                       # step 1
    timings["hybridize"] = hybrid.assemble_seconds + hybrid.reduce_seconds
    timings["hybrid_assemble"] = hybrid.assemble_seconds
    chol = SchurCholesky(hybrid.H, hybrid.contact_index, ordering)             # step 2
    timings["cholesky"] = sum(chol.seconds.values())
    # the hybridisation (edge coupling and static condensation) prepares the factorisation
    timings["factorize"] = timings["hybridize"] + timings["cholesky"]
    start = time.perf_counter()
    y = chol.forward(hybrid.r)
    # the forward and the final backward substitution: with the Cholesky time, the cost of
    # one linear solve of this mesh (the unit of ngdual bench adaptive)
    timings["substitute"] = time.perf_counter() - start
    if not model.has_contact:
        backward = time.perf_counter()
        w = chol.backward(y)
        timings["substitute"] += time.perf_counter() - backward
        x = hybrid.unknowns(w)
        timings["solve"] = time.perf_counter() - start
        residuals = {"linear": _linear_residual(problem, x)}
        _check(residuals, EPS * _material_condition(model),
               lambda: _roundoff_probe(problem, hybrid, chol, w, x), [])
        timings["total_solver"] = time.perf_counter() - start_all
        return Solution(problem, x, True, "linear", residuals=residuals, timings=timings)

    boundary = BoundaryProblem(hybrid, chol, y)
    timings["boundary"] = time.perf_counter() - start
    # the a priori round-off level delta_0 (module docstring)
    level = max(boundary.roundoff, EPS * _material_condition(model))
    forms = build_friction_forms(problem) if model.has_friction else None
    if law == "coulomb":                                                        # step 3
        noise = SAFETY * level * mu_f * boundary.stress_scale
        state, bound, history, iterations = coulomb_fixed_point(
            boundary, forms, mu_f, tol, settings.max_iter, progress, noise,
            _first_state(problem, warm, boundary.n_c, 0))
    else:
        bound = tresca_bound(forms, problem) if law == "tresca" else None
        Q = forms.q_matrix(bound).toarray() if bound is not None else None
        state = semismooth_newton(boundary.G, boundary.b, boundary.n_c, Q,
                                  _first_state(problem, warm, boundary.n_c,
                                               0 if Q is None else Q.shape[0]),
                                  tol=SAFETY * boundary.roundoff)
        history, iterations = [], {"outer": 1, "inner": state.iterations}
    ce = hybrid.contact                                                         # step 4
    zeta = np.concatenate([ce.hat_means @ state.lam_n - ce.gap,
                           ce.hat_means @ state.lam_t - ce.offset_t])
    backward = time.perf_counter()
    w = chol.solve_with_last(y, zeta)
    timings["substitute"] += time.perf_counter() - backward
    x = hybrid.unknowns(w, state.lam_t, state.lam_n)
    nu = state.nu if bound is not None else None
    timings["solve"] = time.perf_counter() - start

    residuals = {"boundary_kkt": max(state.residuals.values()),
                 "qp_fallback": float(state.fallback),
                 "linear": _linear_residual(problem, x),
                 **_contact_conditions(problem, x, settings.metric, model.plane_strain_modulus,
                                       boundary.traction_scale)}
    if nu is not None:
        residuals.update(friction_residuals(forms, problem, x, nu, bound,
                                            boundary.traction_scale))
    if law == "coulomb":
        bound_x = coulomb_bound(forms, forms.T_n @ x, mu_f, noise)
        residuals["coulomb_bound"] = float(np.max(np.abs(bound_x - bound), initial=0.0) / (
            max(np.max(bound_x, initial=0.0), mu_f * boundary.stress_scale) or 1.0))
    _check(residuals, level, lambda: _roundoff_probe(
        problem, hybrid, chol, w, x, state.lam_t, state.lam_n, boundary.traction_scale),
        history)
    timings["total_solver"] = time.perf_counter() - start_all
    return Solution(problem, x, True, "active-set" if law == "none" else f"active-set-{law}",
                    iterations=iterations, residuals=residuals, history=history,
                    timings=timings, nu=nu, friction_bound=bound, friction_forms=forms,
                    nu_l2=forms.l2_norm_nu(nu, forms.per_hat_edge(bound) > 0)
                    if nu is not None else None)


class BoundaryProblem:
    """The contact problem condensed onto Gamma_C from the factorisation (step 3).

    ``G``, ``b``: t(z) = b - G z for the coarse moments t = (C_n^T sigma, C_t^T sigma),
    z = (lambda_n, lambda_t); ``normal_stress(z)``: sigma_n on the fine Gamma_C edges,
    from t_f(z) = a_f - S M z. ``stress_scale`` and ``traction_scale`` are the stresses
    and moments with lambda = 0 (u_n = g): where g >> u, lambda_n = g - u_n carries u_n in
    its last digits, so these (not the load) are the scales of attainable accuracy.
    ``roundoff`` = eps max(kappa_1(G), dim G), the relative accuracy of the dense problem.
    """

    def __init__(self, hybrid: HybridSystem, chol: SchurCholesky, y: np.ndarray):
        ce = hybrid.contact
        self.lengths, self.n_c = ce.lengths, ce.hat_means.shape[1]
        M = sp.block_diag([ce.hat_means, ce.hat_means]).tocsr()  # z -> zeta (+ shift)
        S = chol.schur
        self.a_f = chol.reduced_rhs(y) + S @ np.concatenate([ce.gap, ce.offset_t])
        self.B_f = (M.T @ S).T  # S M
        G = M.T @ self.B_f
        self.G, self.b = 0.5 * (G + G.T), M.T @ self.a_f
        self.stress_scale = float(np.max(np.abs(self.a_f) / np.tile(ce.lengths, 2),
                                         initial=0.0))
        self.traction_scale = float(np.max(np.abs(self.b), initial=0.0))
        self.roundoff = EPS * max(condition_number(self.G), float(len(self.b)), 1.0)

    def normal_stress(self, state: BoundarySolution) -> np.ndarray:
        """sigma_n = t_f,n / |e| on the fine Gamma_C edges for the state's multipliers."""
        z = np.concatenate([state.lam_n, state.lam_t])
        return (self.a_f - self.B_f @ z)[:len(self.lengths)] / self.lengths


def _contact_conditions(problem: DiscreteProblem, x: np.ndarray, metric: str, modulus: float,
                        traction_scale: float) -> dict:
    """contact_residuals of :mod:`ngdual.solvers.uzawa` on the assembled C_n.

    ``natural`` = ||lambda_n - P(W lambda_n + t)||_W relative to the size of the terms of
    the projection's argument, max(||lambda_n||_W, ||W^{-1} t||_W) (t = C_n^T sigma), not
    to ||lambda_n||_W alone: where the body barely separates (lambda_n ~ 1e-6 of the
    displacement W^{-1} t), the round-off of t would otherwise count a million times.
    ``modulus`` is E*, the scale of the metric W.
    """
    projection = NonnegativeProjection(metric_matrix(problem.spaces.contact, modulus, metric))
    lam, lam_t = x[problem.lam_n], x[problem.index("lam_t")]
    traction = problem.block(problem.sigma, problem.lam_n).T @ x[problem.sigma]
    scale = max(np.max(np.abs(lam), initial=0.0), np.max(np.abs(lam_t), initial=0.0))
    b0 = problem.rhs[problem.mult]
    residuals = contact_residuals(lam, traction, projection, scale,
                                  max(np.max(np.abs(b0), initial=0.0), traction_scale))
    W = projection.W
    step = lam - projection(projection.matvec(lam) + traction)
    displacement = traction / W if projection.diagonal else sla.solve(W, traction,
                                                                      assume_a="pos")
    terms = np.sqrt(max(lam @ projection.matvec(lam), traction @ displacement, 0.0))
    residuals["natural"] = float(np.sqrt(max(step @ projection.matvec(step), 0.0))
                                 / (terms or 1.0))
    return residuals


def _check(residuals: dict, level: float, probe: Callable[[], float],
           history: list) -> None:
    """Every residual <= SAFETY delta, delta the round-off level; raise otherwise.

    ``level`` is the a priori delta_0; only if a residual exceeds SAFETY delta_0 is the
    round-off level measured (``probe()``, :func:`_roundoff_probe`), and delta is the larger
    of the two. ``residuals["roundoff_level"]`` records delta.
    """
    def failing():
        return {k: v for k, v in residuals.items()
                if k not in INFORMATIVE and not v <= SAFETY * level}

    if failing():
        level = max(level, probe())
    residuals["roundoff_level"] = level
    bad = failing()
    if bad:
        tol = SAFETY * level
        raise ConvergenceError("the active-set solution does not satisfy (3.62) to round-off: "
                               + ", ".join(f"{k} = {v:.1e} > {tol:.1e}" for k, v in bad.items())
                               + f" (tolerance {SAFETY:g} x the round-off level {level:.1e} "
                               "of this problem)", history)
