"""Algorithm 3.38: the Uzawa algorithm for contact without friction, and the linear solve.

Each step solves the fixed saddle-point system

    [[A, B], [B^T, 0]] (sigma^i, (u, eta, phi, lambda_t)^i) = (g - C_n lambda_n^{i-1}, b)

with one factorisation made before the loop, then updates
lambda_n^i = P^+(lambda_n^{i-1} + rho Phi(sigma^i)) (step 4, as the QP of
Remark 3.40). It stops on the thesis' relative increment (step 5); the
residual of the discrete variational inequality is reported alongside.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from ..forms import DiscreteProblem
from .linear import Factorization
from .projections import NonnegativeProjection, metric_matrix
from .result import ConvergenceError, Solution

DIVERGENCE_FACTOR = 1e6


def solve_linear(problem: DiscreteProblem, backend: str = "umfpack") -> Solution:
    """One saddle-point solve: the whole problem when there is no contact boundary."""
    saddle = problem.saddle
    fact = Factorization(problem.block(saddle, saddle), backend)
    start = time.perf_counter()
    x = np.zeros(problem.K.shape[0])
    x[saddle] = fact.solve(problem.F[saddle])
    solve_s = time.perf_counter() - start
    return Solution(problem, x, True, "linear",
                    timings={"assemble": problem.assemble_seconds, "factorize": fact.seconds,
                             "solve": solve_s})


def contact_residuals(lam: np.ndarray, traction: np.ndarray,
                      projection: NonnegativeProjection) -> dict:
    """Residuals of the discrete VI (3.103): lambda_n >= 0, C_n^T sigma <= 0, complementarity.

    ``traction`` is C_n^T sigma (the normal stress tested with the coarse hats).
    All values are relative, so 0 means exact and 1e-8 is at solver tolerance.
    """
    lam_scale = np.max(np.abs(lam)) or 1.0
    tr_scale = np.max(np.abs(traction)) or 1.0
    return {
        "lambda_n_negative": float(max(0.0, -lam.min(initial=0.0)) / lam_scale),
        "sigma_n_positive": float(max(0.0, traction.max(initial=0.0)) / tr_scale),
        "complementarity": float(abs(lam @ traction)
                                 / ((np.linalg.norm(lam) * np.linalg.norm(traction)) or 1.0)),
        "natural": projection.residual(lam, traction),
    }


class ContactLoop:
    """Steps 3-5 of Algorithm 3.38 (the inner loop, steps 4-7, of Algorithm 3.41).

    Holds what never changes during an iteration: the factorised saddle-point
    matrix, C_n, the projection P^+ and g. :meth:`run` iterates for a given
    right-hand side of the (u, eta, phi, lambda_t) rows, warm-started from lambda_n.
    """

    def __init__(self, problem: DiscreteProblem, metric: str, backend: str = "umfpack"):
        self.problem = problem
        self.saddle, self.n_sigma = problem.saddle, len(problem.sigma)
        self.fact = Factorization(problem.block(self.saddle, self.saddle), backend)
        self.C_n = problem.block(problem.sigma, problem.lam_n)
        modulus = problem.scene.material.plane_strain_modulus
        self.projection = NonnegativeProjection(
            metric_matrix(problem.spaces.contact, modulus, metric))
        self.g = problem.F[problem.sigma]

    def run(self, b: np.ndarray, lam: np.ndarray, rho: float, eps: float, max_iter: int,
            progress: Callable[[int, float], None] | None = None):
        """Iterate until the relative increment is <= eps.

        Returns ``(y, lam, iterations, history, converged)`` where y = (sigma,
        u, eta, phi, lambda_t) solves the linear system with ``lam`` exactly.
        """
        rhs = np.concatenate([self.g, b])
        y_prev = np.zeros(len(self.saddle))
        history, converged = [], False
        for it in range(1, max_iter + 1):
            rhs[:self.n_sigma] = self.g - self.C_n @ lam
            y = self.fact.solve(rhs)                                            # step 3
            traction = self.C_n.T @ y[:self.n_sigma]
            lam_new = self.projection(self.projection.matvec(lam) + rho * traction)  # step 4
            change = np.sqrt(np.sum((y - y_prev) ** 2) + np.sum((lam_new - lam) ** 2))
            size = np.sqrt(np.sum(y**2) + np.sum(lam_new**2)) or 1.0
            history.append(float(change / size))
            if progress:
                progress(it, history[-1])
            if not np.isfinite(history[-1]) or history[-1] > DIVERGENCE_FACTOR * history[0]:
                raise ConvergenceError(f"Uzawa diverged at step {it} (rho = {rho} too large?)",
                                       history)
            y_prev = y
            if history[-1] <= eps:                                              # step 5
                converged = True
                break
            lam = lam_new
        return y, lam, it, history, converged

    def residuals(self, y: np.ndarray, lam: np.ndarray) -> dict:
        return contact_residuals(lam, self.C_n.T @ y[:self.n_sigma], self.projection)


def uzawa(problem: DiscreteProblem, rho: float = 1.0, eps: float = 1e-8, max_iter: int = 2000,
          metric: str = "h12", backend: str = "umfpack",
          progress: Callable[[int, float], None] | None = None) -> Solution:
    """Algorithm 3.38 for the frictionless contact problem (3.68).

    Parameters
    ----------
    rho : float
        Dimensionless step length (the metric carries the elastic modulus).
    eps : float
        Tolerance on the relative increment of step 5.
    metric : {"h12", "euclidean"}
        Metric W of the projection P^+ (see :mod:`ngdual.solvers.projections`).
    progress : callable, optional
        Called as ``progress(iteration, increment)`` after every step.

    Raises
    ------
    ConvergenceError
        If the increments grow by a factor 1e6 (rho too large) or become NaN.
    """
    loop = ContactLoop(problem, metric, backend)
    start = time.perf_counter()
    lam0 = np.zeros(len(problem.lam_n))
    y, lam, its, history, converged = loop.run(problem.F[problem.mult], lam0, rho, eps,
                                               max_iter, progress)
    x = np.zeros(problem.K.shape[0])
    x[problem.saddle], x[problem.lam_n] = y, lam
    residuals = {"increment": history[-1], **loop.residuals(y, lam)}
    return Solution(problem, x, converged, f"uzawa-{metric}",
                    iterations={"outer": its, "inner": 0}, residuals=residuals,
                    history=history,
                    timings={"assemble": problem.assemble_seconds,
                             "factorize": loop.fact.seconds,
                             "solve": time.perf_counter() - start})
