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
4. One back substitution gives the remaining unknowns, NGSolve's local solves sigma and u.

The result is the discrete solution of (3.62) itself (not an approximation of it): the
residuals of every row of the assembled system and of the contact and friction conditions
are computed on ``problem.K`` and reported; if they are not at round-off level a
:class:`ConvergenceError` is raised.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp
from threadpoolctl import threadpool_limits

from ..forms import DiscreteProblem
from ..friction import build_friction_forms, tresca_bound
from .cholesky import BLAS_THREADS, SchurCholesky
from .hybrid import HybridSystem
from .nested import sign_residual
from .projections import NonnegativeProjection, metric_matrix
from .result import ConvergenceError, Solution
from .semismooth import BoundarySolution, semismooth_newton
from .uzawa import contact_residuals

ROUNDOFF = 1e-12
LINEAR_TOL = 1e-9      # relative residual of the linear rows of (3.62)
CONDITION_TOL = 1e-8   # relative residuals of the contact / friction conditions


def _linear_residual(problem: DiscreteProblem, x: np.ndarray) -> float:
    """Largest blockwise relative residual of the rows sigma, u, eta, phi of K x = F.

    Each block (their units differ) is measured against the size of its own terms,
    ||K_b x - F_b|| / max(|| |K_b| |x| ||, ||F_b||) in the max norm.
    """
    worst = 0.0
    for names in (problem.sigma, problem.index("u1", "u2"), problem.index("eta"),
                  problem.index("phi1", "phi2")):
        if not len(names):
            continue
        K_b = problem.K[names]
        terms = abs(K_b) @ np.abs(x)
        scale = max(np.max(terms, initial=0.0), np.max(np.abs(problem.F[names]), initial=0.0))
        if scale > 0:
            worst = max(worst, float(np.max(np.abs(K_b @ x - problem.F[names])) / scale))
    return worst


def fast_solve(problem: DiscreteProblem, law: str | None = None, mu_f: float = 0.0,
               tol: float = 1e-12, max_iter: int = 500, ordering: str = "amd",
               metric: str = "h12",
               progress: Callable[[int, float], None] | None = None) -> Solution:
    """Solve (3.62) by condensation onto Gamma_C and semismooth Newton there.

    Parameters
    ----------
    law : {None, "none", "tresca", "coulomb"}
        Friction law (default: the scene's).
    mu_f : float
        Coulomb coefficient (default: the scene's).
    tol : float
        Relative change of F at which the Coulomb fixed point (3.123) stops.
    max_iter : int
        Bound on the Coulomb fixed-point steps.
    ordering : {"amd", "metis"}
        Fill-reducing ordering of the hybridised matrix.
    metric : str
        Metric of the natural residual of the contact condition (reporting only).

    Raises
    ------
    ConvergenceError
        If the Coulomb fixed point does not converge in ``max_iter`` steps, or the final
        residuals of (3.62) are not at round-off level.
    """
    # the dense work is small (at most a few thousand unknowns): one BLAS thread is as fast
    # and immune to the spin-waiting of threaded BLAS on busy cores
    with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
        try:
            return _fast_solve(problem, law, mu_f, tol, max_iter, ordering, metric, progress)
        except ConvergenceError as err:
            scene = problem.scene
            if (law or scene.friction.law) in ("tresca", "coulomb") \
                    and scene.contact.hhat_factor == 1:
                raise ConvergenceError(f"{err}; with h^ = h~ the inf-sup condition (3.74) "
                                       "for nu fails where the contact zone reaches the end of "
                                       "Gamma_C: try contact.hhat_factor = 2",
                                       err.history) from err
            raise


def _fast_solve(problem: DiscreteProblem, law: str | None, mu_f: float, tol: float,
                max_iter: int, ordering: str, metric: str,
                progress: Callable[[int, float], None] | None) -> Solution:
    scene = problem.scene
    law = scene.friction.law if law is None else law
    mu_f = mu_f or scene.friction.mu
    timings = {"assemble": problem.assemble_seconds}
    start_all = time.perf_counter()
    hybrid = HybridSystem(problem)                                              # step 1
    timings["hybridize"] = hybrid.assemble_seconds + hybrid.reduce_seconds
    chol = SchurCholesky(hybrid.H, hybrid.contact_index, ordering)             # step 2
    timings["cholesky"] = sum(chol.seconds.values())
    # the hybridisation (assembly and static condensation) prepares the factorisation
    timings["factorize"] = timings["hybridize"] + timings["cholesky"]
    start = time.perf_counter()
    y = chol.forward(hybrid.r)
    if not scene.has_contact:
        x = hybrid.unknowns(chol.backward(y))
        timings["solve"] = time.perf_counter() - start
        timings["total_solver"] = time.perf_counter() - start_all
        residuals = {"linear": _linear_residual(problem, x)}
        _check(residuals, [])
        return Solution(problem, x, True, "linear", residuals=residuals, timings=timings)

    boundary = BoundaryProblem(hybrid, chol, y)
    timings["boundary"] = time.perf_counter() - start
    forms = build_friction_forms(problem) if law in ("tresca", "coulomb") else None
    if law == "coulomb":                                                        # step 3
        state, F, history, iterations = _coulomb_fixed_point(boundary, forms, mu_f, tol,
                                                             max_iter, progress)
    else:
        F = tresca_bound(forms, problem) if law == "tresca" else None
        state = semismooth_newton(boundary.G, boundary.b, boundary.n_c,
                                  forms.q_matrix(F).toarray() if F is not None else None)
        history, iterations = [], {"outer": 1, "inner": state.iterations}
    ce = hybrid.contact                                                         # step 4
    zeta = np.concatenate([ce.hat_means @ state.lam_n - ce.gap,
                           ce.hat_means @ state.lam_t - ce.offset_t])
    x = hybrid.unknowns(chol.solve_with_last(y, zeta), state.lam_t, state.lam_n)
    nu = state.nu if F is not None else None
    timings["solve"] = time.perf_counter() - start

    residuals = {"boundary_kkt": max(state.residuals.values()),
                 "qp_fallback": float(state.fallback),
                 "linear": _linear_residual(problem, x),
                 **_contact_conditions(problem, x, metric, boundary.traction_scale)}
    if nu is not None:
        residuals.update(_friction_conditions(problem, forms, x, nu, F,
                                              boundary.traction_scale))
    if law == "coulomb":
        F_x = _coulomb_bound(forms, forms.T_n @ x, mu_f, boundary.stress_scale)
        residuals["coulomb_bound"] = float(np.max(np.abs(F_x - F), initial=0.0) / (
            max(np.max(F_x, initial=0.0), mu_f * boundary.stress_scale) or 1.0))
    timings["total_solver"] = time.perf_counter() - start_all
    _check(residuals, history)
    return Solution(problem, x, True, "active-set" if law == "none" else f"active-set-{law}",
                    iterations=iterations, residuals=residuals, history=history,
                    timings=timings, nu=nu, friction_bound=F,
                    nu_l2=forms.l2_norm_nu(nu, forms.per_hat_edge(F) > 0)
                    if nu is not None else None)


class BoundaryProblem:
    """The contact problem condensed onto Gamma_C from the factorisation (step 3).

    ``G``, ``b``: t(z) = b - G z for the coarse moments t = (C_n^T sigma, C_t^T sigma),
    z = (lambda_n, lambda_t); ``normal_stress(z)``: sigma_n on the fine Gamma_C edges,
    from t_f(z) = a_f - S M z. ``stress_scale`` and ``traction_scale`` are the stresses
    and moments with lambda = 0 (u_n = g): where g >> u, lambda_n = g - u_n carries u_n in
    its last digits, so these (not the load) are the scales of attainable accuracy.
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

    def normal_stress(self, state: BoundarySolution) -> np.ndarray:
        """sigma_n = t_f,n / |e| on the fine Gamma_C edges for the state's multipliers."""
        z = np.concatenate([state.lam_n, state.lam_t])
        return (self.a_f - self.B_f @ z)[:len(self.lengths)] / self.lengths


def _coulomb_fixed_point(boundary: BoundaryProblem, forms, mu_f: float, tol: float,
                         max_iter: int, progress):
    """Remark 3.45 on Gamma_C: F^0 from the frictionless solution, then F = mu_f |sigma_n|
    of (3.123) and a Tresca solve, warm-started, until F changes by <= ``tol`` (relative)."""
    G, b, n_c = boundary.G, boundary.b, boundary.n_c
    state = semismooth_newton(G, b, n_c)
    inner = state.iterations
    F = _coulomb_bound(forms, boundary.normal_stress(state), mu_f, boundary.stress_scale)
    history = []
    for outer in range(1, max_iter + 1):
        state = semismooth_newton(G, b, n_c, forms.q_matrix(F).toarray(), start=state)
        inner += state.iterations
        F_new = _coulomb_bound(forms, boundary.normal_stress(state), mu_f,
                               boundary.stress_scale)
        change = float(np.linalg.norm(F_new - F) / (np.linalg.norm(F_new) or 1.0))
        history.append(change)
        if progress:
            progress(outer, change)
        F = F_new
        if change <= tol:
            # the last F: its own Tresca solution, so that F, nu and z belong together
            state = semismooth_newton(G, b, n_c, forms.q_matrix(F).toarray(), start=state)
            inner += state.iterations
            return state, F, history, {"outer": outer, "inner": int(inner)}
    raise ConvergenceError(f"the Coulomb fixed point (3.123) did not converge in "
                           f"solver.max_iter = {max_iter} steps; try a smaller friction.mu",
                           history)


def _coulomb_bound(forms, sigma_n: np.ndarray, mu_f: float, stress_scale: float) -> np.ndarray:
    """F of (3.123) (``FrictionForms.coulomb_bound_of``), zero where it is round-off.

    On a separated part of Gamma_C the normal stress entering F vanishes up to rounding
    errors of the stress scale; a bound made of rounding errors would turn the friction
    conditions there into conditions on noise, so values below round-off count as 0.
    """
    F = forms.coulomb_bound_of(sigma_n, mu_f)
    F[F <= ROUNDOFF * mu_f * stress_scale] = 0.0
    return F


def _contact_conditions(problem: DiscreteProblem, x: np.ndarray, metric: str,
                        traction_scale: float) -> dict:
    """contact_residuals of :mod:`ngdual.solvers.uzawa` on the assembled C_n."""
    modulus = problem.scene.material.plane_strain_modulus
    projection = NonnegativeProjection(metric_matrix(problem.spaces.contact, modulus, metric))
    lam, lam_t = x[problem.lam_n], x[problem.index("lam_t")]
    traction = problem.block(problem.sigma, problem.lam_n).T @ x[problem.sigma]
    scale = max(np.max(np.abs(lam), initial=0.0), np.max(np.abs(lam_t), initial=0.0))
    b0 = problem.F[problem.mult]
    return contact_residuals(lam, traction, projection, scale,
                             max(np.max(np.abs(b0), initial=0.0), traction_scale))


def _friction_conditions(problem: DiscreteProblem, forms, x: np.ndarray, nu: np.ndarray,
                         F: np.ndarray, traction_scale: float) -> dict:
    """(3.62)_5,7 and |sigma_t| <= F tested with the h~ hats, relative to the traction scale.

    As :func:`~ngdual.solvers.nested.friction_residuals`, but the tangential residuals are
    measured against max(|C_n^T sigma|, |C_t^T sigma|, int F mu_i, ``traction_scale``)
    rather than the bound alone, which may vanish (no contact, F = mu_f |sigma_n| = 0)
    while the tractions do not.
    """
    Q = forms.q_matrix(F)
    sigma = x[problem.sigma]
    tangential = problem.block(problem.sigma, problem.index("lam_t")).T @ sigma
    normal = problem.block(problem.sigma, problem.lam_n).T @ sigma
    bound = Q.T @ np.ones(forms.n_nu)
    scale = max(np.max(np.abs(tangential), initial=0.0), np.max(np.abs(normal), initial=0.0),
                np.max(bound, initial=0.0), traction_scale) or 1.0
    return {
        "nu_sign": sign_residual(Q, nu, x[problem.index("lam_t")]),
        "nu_bound": float(max(0.0, np.abs(nu).max(initial=0.0) - 1.0)),
        "tangential": float(np.max(np.abs(tangential - Q.T @ nu), initial=0.0) / scale),
        "sigma_t_bound": float(max(0.0, np.max(np.abs(tangential) - bound, initial=0.0)) / scale),
    }


def _check(residuals: dict, history: list) -> None:
    bad = {k: v for k, v in residuals.items()
           if k not in ("qp_fallback",) and v > (LINEAR_TOL if k == "linear" else CONDITION_TOL)}
    if bad:
        raise ConvergenceError("the active-set solution does not satisfy (3.62) to round-off: "
                               + ", ".join(f"{k} = {v:.1e}" for k, v in bad.items()), history)
