"""Algorithm 3.38: the Uzawa algorithm for contact without friction, and the linear solve.

Each step solves the fixed saddle-point system

    [[A, B], [B^T, 0]] (sigma^i, (u, eta, phi, lambda_t)^i) = (g - C_n lambda_n^{i-1}, b)

with one factorisation made before the loop, then updates
lambda_n^i = P^+(lambda_n^{i-1} + rho Phi(sigma^i)) (step 4, as the QP of
Remark 3.40). It stops on the thesis' relative increment (step 5); the
residual of the discrete variational inequality is reported alongside.

lambda_n is whatever the multiplier space of Gamma_C makes it -- the thesis' P1 hats, or
Bernstein coefficients at order k (:mod:`ngdual.boundary`) -- and P^+ is the projection
onto lambda_n >= 0 coefficient by coefficient in the metric of that space
(:func:`~ngdual.solvers.projections.metric_matrix`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as sla_sparse

from ..forms import DiscreteProblem
from ..solution import ConvergenceError, Solution
from ..tolerances import DIVERGENCE_FACTOR
from .condensed import CondensedResponse
from .linear import Factorization
from .projections import NonnegativeProjection, metric_matrix
from .settings import UzawaSettings


def contact_residuals(lam: np.ndarray, traction: np.ndarray,
                      projection: NonnegativeProjection, lam_scale: float | None = None,
                      load_scale: float = 0.0) -> dict:
    """Residuals of the discrete VI (3.103): lambda_n >= 0, C_n^T sigma <= 0, complementarity.

    ``traction`` is C_n^T sigma (the normal stress tested with the multipliers' basis
    functions, the hats or the Bernstein polynomials, less the right-hand side of their rows).
    ``lam_scale`` is the displacement scale on Gamma_C that lambda_n is measured
    against (default max |lambda_n|; pass max(|lambda_n|, |lambda_t|) when
    lambda_n may vanish, e.g. full contact at g = 0, where lambda_n itself is
    round-off). ``load_scale`` (max of the load vector b) keeps the traction
    scale meaningful when C_n^T sigma vanishes (no contact anywhere). All values
    are relative, so 0 means exact and 1e-8 is at solver tolerance;
    complementarity is max_j |lambda_j t_j| / (lam_scale max |t|).
    """
    lam_scale = lam_scale or np.max(np.abs(lam), initial=0.0) or 1.0
    tr_scale = max(np.max(np.abs(traction), initial=0.0), load_scale) or 1.0
    return {
        "lambda_n_negative": float(max(0.0, -lam.min(initial=0.0)) / lam_scale),
        "sigma_n_positive": float(max(0.0, traction.max(initial=0.0)) / tr_scale),
        "complementarity": float(np.max(np.abs(lam * traction), initial=0.0)
                                 / (lam_scale * tr_scale)),
        "natural": projection.residual(lam, traction),
    }


@dataclass
class LoopState:
    """Where the inner loop stands: the Gamma_C unknowns and what the iteration observes.

    ``z = (lambda_n, tau)`` determines y through the linear solve of step 3, tau the
    load of the lambda_t rows (Q_F^T nu of Algorithm 3.41). ``traction`` = C_n^T sigma - r_n
    (the moments t_n of the lambda_n rows of (3.62); r_n = 0 where the gap enters g),
    ``lam_t`` = lambda_t, ``extra`` = the caller's additional functionals of y.
    """

    lam: np.ndarray
    tau: np.ndarray
    traction: np.ndarray
    lam_t: np.ndarray
    extra: np.ndarray
    y: np.ndarray | None = None

    @property
    def z(self) -> np.ndarray:
        return np.concatenate([self.lam, self.tau])


class ContactLoop:
    """Steps 3-5 of Algorithm 3.38 (the inner loop, steps 4-7, of Algorithm 3.41).

    Holds what never changes during an iteration: the factorised saddle-point
    matrix, C_n, the projection P^+ and g. :meth:`run` iterates for a given load
    tau of the lambda_t rows, warm-started from lambda_n.

    With ``condensed=True`` the linear solve of step 3 is replaced by the
    Gamma_C response of :class:`~ngdual.solvers.condensed.CondensedResponse`
    (2 N_C + 1 solves once for the response; the Gram data of the stopping rule
    come from the same solves, or from 2 N_C more where the responses do not fit in
    memory; then small dense products): the same iterates and
    the same stopping rule at a fraction of the cost when there are many steps.
    ``modulus`` is E* (it scales the metric, so that rho is dimensionless);
    ``extra_outputs`` (k x saddle, sparse) are further functionals of y to observe.
    """

    def __init__(self, problem: DiscreteProblem, metric: str, modulus: float,
                 condensed: bool = False, extra_outputs: sp.spmatrix | None = None):
        self.problem = problem
        self.saddle, self.n_sigma = problem.saddle, len(problem.sigma)
        n = len(self.saddle)
        self.fact = Factorization(problem.block(self.saddle, self.saddle))
        self.C_n = problem.block(problem.sigma, problem.lam_n)
        self.projection = NonnegativeProjection(
            metric_matrix(problem.spaces.contact, modulus, metric))
        self.g = problem.rhs[problem.sigma]
        self.b0 = problem.rhs[problem.mult]
        self.r_n = problem.rhs[problem.lam_n]   # t_n = C_n^T sigma - r_n, the lambda_n rows
        i_t = problem.index("lam_t")  # the saddle unknowns are a prefix of x: also positions in y
        n_c, n_t = self.C_n.shape[1], len(i_t)
        self.E_t = sp.csr_matrix((np.ones(n_t), (i_t, np.arange(n_t))), shape=(n, n_t))
        self.n_c = n_c
        C_pad = sp.vstack([self.C_n, sp.csr_matrix((n - self.n_sigma, n_c))])
        extra = sp.csr_matrix((0, n)) if extra_outputs is None else sp.csr_matrix(extra_outputs)
        self.outputs = sp.vstack([C_pad.T, self.E_t.T, extra]).tocsr()
        self.inputs = sp.hstack([-C_pad, self.E_t]).tocsc()
        self.r0 = np.concatenate([self.g, self.b0])
        start = time.perf_counter()
        self.response = (CondensedResponse(self.fact, self.r0, self.inputs, self.outputs)
                         if condensed else None)
        self.condense_seconds = time.perf_counter() - start
        self._split = np.cumsum([n_c, n_t])

    @cached_property
    def stability_bound(self) -> float:
        """lambda_max(W^{-1} S), S the Steklov-Poincare map lambda_n -> -C_n^T sigma.

        Step 4 contracts for rho < 2 / lambda_max. The metric W carries the half-plane
        scaling of S, so lambda_max is about 1 where the ends of Gamma_C are fixed (0.82
        to 0.96 on Example 3.46, levels 2-3); where Gamma_C has free ends, its lowest
        modes feel the stiffness of the whole body (a block of height H pressed as a
        whole: S ~ E*/H per length, far above the metric's E*/2 |k| at small k), and
        lambda_max can exceed 2 (2.76 on hertz-cylinder, level 1). Computed by Lanczos
        (scipy ``eigsh``, about 20 responses: cheap beside the iteration).
        """
        n = self.n_c
        if n == 0:
            return 0.0
        tau = np.zeros(self.E_t.shape[1])
        t0 = self.respond(np.zeros(n), tau).traction
        chol = sla.cholesky(np.diag(self.projection.W) if self.projection.diagonal
                            else self.projection.W)  # W = R^T R

        def apply(v):
            w = sla.solve_triangular(chol, v)
            return sla.solve_triangular(chol, -(self.respond(w, tau).traction - t0), trans="T")
        if n <= 3:
            matrix = np.column_stack([apply(e) for e in np.eye(n)])
            return float(np.linalg.eigvalsh(0.5 * (matrix + matrix.T)).max())
        op = sla_sparse.LinearOperator((n, n), matvec=apply, dtype=float)
        return float(sla_sparse.eigsh(op, k=1, which="LA", tol=1e-3,
                                      v0=np.ones(n))[0][0])

    def step(self, rho: float) -> float:
        """The step of step 4 for the dimensionless ``rho``, as :meth:`run` takes it.

        In the H^{1/2} metric rho / max(1, lambda_max), lambda_max the
        :attr:`stability_bound`; in the Euclidean metric the plain step (:meth:`plain_step`).
        """
        if not self.projection.diagonal:
            return rho / max(1.0, self.stability_bound)
        return self.plain_step(rho, "solver.metric = \"h12\", whose step is relative to "
                                    "that bound")

    def plain_step(self, rho: float, remedy: str) -> float:
        """``rho`` itself, which contracts only for rho lambda_max < 2: a step that would not
        is refused before the iteration starts, naming the ``remedy`` besides a smaller step.
        lambda_max is near 1 for the thesis' hats in either metric; in the Euclidean metric it
        reaches 2.1 for the facet multipliers of order 0 (Example 3.46, level 3), whose edge
        indicators feel the stiffness of the jumps between them.

        Raises
        ------
        ConvergenceError
            If rho lambda_max >= 2.
        """
        bound = self.stability_bound
        if rho * bound >= 2.0:
            raise ConvergenceError(
                f"the Uzawa step rho = {rho:g} does not contract here: the bound of the "
                f"contact iteration in the {'Euclidean' if self.projection.diagonal else 'H^1/2'}"
                f" metric is lambda_max = {bound:.3g}, and rho lambda_max must stay below 2; "
                f"choose a step below {2.0 / bound:.3g} (solver.rho, or solver.rho1 with "
                f"friction) or {remedy}", [])
        return rho

    def respond(self, lam: np.ndarray, tau: np.ndarray) -> LoopState:
        """Step 3 for lambda_n = ``lam`` and the lambda_t-row load ``tau``."""
        z = np.concatenate([lam, tau])
        if self.response is not None:
            y, observed = None, self.response.observe(z)
        else:
            y = self.fact.solve(self.r0 + self.inputs @ z)
            observed = self.outputs @ y
        traction, lam_t, extra = np.split(observed, self._split)
        return LoopState(lam, tau, traction - self.r_n, lam_t, extra, y=y)

    def _distance(self, state: LoopState, prev: LoopState | None) -> tuple[float, float]:
        """(||y - y_prev||, ||y||), y_prev = 0 at the start of a run."""
        if self.response is not None:
            size = self.response.norm(state.z)
            return (size if prev is None else self.response.distance(state.z, prev.z)), size
        size = float(np.linalg.norm(state.y))
        return (size if prev is None else float(np.linalg.norm(state.y - prev.y))), size

    def solution(self, state: LoopState) -> np.ndarray:
        """y = (sigma, u, eta, phi, lambda_t) of ``state`` (one solve when condensed)."""
        if state.y is None:
            state.y = self.response.solution(state.z)
        return state.y

    def run(self, lam: np.ndarray, rho: float, eps: float, max_iter: int,
            tau: np.ndarray | None = None,
            progress: Callable[[int, float], None] | None = None):
        """Iterate until the relative increment is <= eps (step 5).

        ``rho`` is the dimensionless step (:meth:`step`). In the H^{1/2} metric, where the
        metric underestimates the body's stiffness (:attr:`stability_bound` > 1), it is taken
        relative to that bound, rho / lambda_max, so that rho in (0, 2) always contracts
        (where the bound is <= 1, e.g. on Example 3.46 with the thesis' hats, the step is
        rho itself, as in the thesis). In the Euclidean metric the bound stays near 1 while
        the smallest eigenvalue falls like h, and rho is the plain step of the thesis, to be
        chosen by the user (refused where it would not contract).
        Returns ``(state, iterations, history, converged)``; the state's y solves
        the linear system with the state's lambda_n exactly.
        """
        rho = self.step(rho)
        tau = np.zeros(self.E_t.shape[1]) if tau is None else tau
        prev, history, converged = None, [], False
        for it in range(1, max_iter + 1):
            state = self.respond(lam, tau)                                          # step 3
            lam_new = self.projection(self.projection.matvec(lam) + rho * state.traction)  # 4
            change, size = self._distance(state, prev)
            change = np.sqrt(change**2 + np.sum((lam_new - lam) ** 2))
            size = np.sqrt(size**2 + np.sum(lam_new**2)) or 1.0
            history.append(float(change / size))
            if progress:
                progress(it, history[-1])
            if not np.isfinite(history[-1]) or history[-1] > DIVERGENCE_FACTOR * history[0]:
                raise ConvergenceError(f"Uzawa diverged at step {it} (rho = {rho} too large?)",
                                       history)
            prev = state
            if history[-1] <= eps:                                                  # step 5
                converged = True
                break
            lam = lam_new
        return state, it, history, converged

    def residuals(self, state: LoopState) -> dict:
        scale = max(np.max(np.abs(state.lam), initial=0.0),
                    np.max(np.abs(state.lam_t), initial=0.0))
        return contact_residuals(state.lam, state.traction, self.projection, scale,
                                 np.max(np.abs(self.b0), initial=0.0))


def uzawa(problem: DiscreteProblem, settings: UzawaSettings,
          progress: Callable[[int, float], None] | None = None) -> Solution:
    """Algorithm 3.38 for the frictionless contact problem (3.68).

    Parameters
    ----------
    settings : UzawaSettings
        ``rho`` (dimensionless step: the metric carries the elastic modulus), ``eps``
        (tolerance on the relative increment of step 5), ``max_iter``, ``metric`` (of the
        projection P^+, :mod:`ngdual.solvers.projections`), ``condensed`` (iterate on the
        Gamma_C response, :class:`ContactLoop`: pays off when the number of steps exceeds
        about 2 N_C solves' worth), and the model (E*).
    progress : callable, optional
        Called as ``progress(iteration, increment)`` after every step.

    Raises
    ------
    ConvergenceError
        If the increments grow by ``DIVERGENCE_FACTOR`` (rho too large) or become NaN.
    """
    s = settings
    loop = ContactLoop(problem, s.metric, s.model.plane_strain_modulus, s.condensed)
    start = time.perf_counter()
    state, its, history, converged = loop.run(np.zeros(len(problem.lam_n)), s.rho, s.eps,
                                              s.max_iter, progress=progress)
    x = np.zeros(problem.n)
    x[problem.saddle], x[problem.lam_n] = loop.solution(state), state.lam
    residuals = {"increment": history[-1], **loop.residuals(state)}
    return Solution(problem, x, converged, f"uzawa-{s.metric}",
                    iterations={"outer": its, "inner": 0}, residuals=residuals,
                    history=history,
                    timings={"assemble": problem.assemble_seconds,
                             "factorize": loop.fact.seconds,
                             "condense": loop.condense_seconds,
                             "solve": time.perf_counter() - start})
