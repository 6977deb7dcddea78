"""The active-set method on the conforming system K: frictionless contact at every order k.

The hybridised solver of :mod:`ngdual.solvers.active_set` eliminates broken RT_0 rows and
P1 traces on the h~ mesh (:class:`~ngdual.solvers.hybrid.HybridSystem`); at order k >= 1,
or with the facet multipliers (:mod:`ngdual.boundary.facet`), there is no such system, and
the problem (3.103) is solved on the assembled K itself, with one sparse LU factorisation
(UMFPACK, :class:`~ngdual.solvers.linear.Factorization`).

The contact conditions of (3.103) act on the unknowns of lambda_n (the Bernstein
coefficients of the facet multipliers, the hat values of the coarse ones) and on their
moments t_n = C_n^T sigma; without friction lambda_t is free and its moments t_t vanish.
As in :mod:`ngdual.solvers.active_set`, the problem is condensed onto z = (lambda_n,
lambda_t): with S the other unknowns (sigma, u, eta, phi), one factorisation of K_SS and
2 N_C solves give

    t(z) = b - G z,   G = K_ZS K_SS^{-1} K_SZ,   b = K_ZS K_SS^{-1} r_S - r_Z,

(G is symmetric positive semidefinite: the sigma block of the inverse of the saddle-point
matrix), and the semismooth Newton method of :mod:`ngdual.solvers.semismooth` solves
lambda_n >= 0, t_n <= 0, lambda_n . t_n = 0, t_t = 0 on Gamma_C, with its QP fallback where
the active sets cycle (the primal-dual active-set method alone cycles on Example 3.46 at
k = 0 with the facet multipliers: G is no M-matrix). One back substitution gives the rest.
"""

from __future__ import annotations

import time

import numpy as np

from ..forms import DiscreteProblem
from .active_set import ContactStart
from .linear import Factorization
from .qp import _residuals
from .result import ConvergenceError, Solution
from .semismooth import BoundarySolution, semismooth_newton
from .settings import ActiveSetSettings

TOLERANCE = 1e-9   # relative residuals of (3.103) accepted as round-off


def conforming_active_set(problem: DiscreteProblem, settings: ActiveSetSettings,
                          start: ContactStart | None = None) -> Solution:
    """Solve (3.103) on ``problem.K``: condensed onto Gamma_C, semismooth Newton there
    (module docstring).

    Parameters
    ----------
    problem : DiscreteProblem
        Any assembled problem without friction (the scene's validation refuses friction
        with the facet multipliers).
    settings : ActiveSetSettings
        Read for its model only: the method iterates to round-off.
    start : ContactStart, optional
        The multipliers of a coarser solution, at this problem's control points
        (``spaces.contact.node_points()``): the Newton method starts there.

    Raises
    ------
    ConvergenceError
        If the contact problem on Gamma_C is not solved (:func:`semismooth_newton`), or
        the residuals of (3.103) exceed ``TOLERANCE``.
    """
    if settings.model.has_friction:
        raise ValueError("the conforming active-set method solves frictionless contact")
    begin = time.perf_counter()
    K, rhs = problem.K.tocsr(), problem.rhs
    contact = np.concatenate([problem.lam_n, problem.index("lam_t")])
    rest = np.setdiff1d(np.arange(K.shape[0]), contact)
    fact = Factorization(K[rest][:, rest])
    x = np.zeros(K.shape[0])
    x[rest] = fact.solve(rhs[rest])
    iterations = {"outer": 0, "inner": 0}
    if len(contact):
        n_c = len(problem.lam_n)
        K_sz = K[rest][:, contact].toarray()
        W = fact.solve_many(K_sz)
        G = K_sz.T @ W
        b = K_sz.T @ x[rest] - rhs[contact]
        state = semismooth_newton(0.5 * (G + G.T), b, n_c, start=_first_state(problem, start))
        z = np.concatenate([state.lam_n, state.lam_t])
        x[rest] -= W @ z
        x[contact] = z
        iterations = {"outer": 1, "inner": int(state.iterations)}
    i_sigma, i_mult, i_lam = problem.sigma, problem.mult, problem.lam_n
    residuals = _residuals(problem.block(i_sigma, i_sigma), problem.block(i_sigma, i_mult),
                           problem.block(i_sigma, i_lam), rhs[i_sigma], rhs[i_mult],
                           x[i_sigma], x[i_mult], x[i_lam])
    bad = {k: v for k, v in residuals.items() if not v <= TOLERANCE}
    if bad:
        raise ConvergenceError("the active-set solution does not satisfy (3.103) to round-off: "
                               + ", ".join(f"{k} = {v:.1e} > {TOLERANCE:.0e}"
                                           for k, v in bad.items()), [])
    return Solution(problem, x, True, "active-set-conforming", iterations=iterations,
                    residuals=residuals,
                    timings={"assemble": problem.assemble_seconds, "factorize": fact.seconds,
                             "solve": time.perf_counter() - begin})


def _first_state(problem: DiscreteProblem, start: ContactStart | None
                 ) -> BoundarySolution | None:
    """The Newton start from ``start`` at this problem's control points (None: z = 0)."""
    if start is None:
        return None
    lam_n, lam_t = start.at(problem.spaces.contact.node_points())
    n_c = len(lam_n)
    return BoundarySolution(np.maximum(lam_n, 0.0), lam_t, np.zeros(0),
                            np.zeros(n_c, dtype=bool), np.zeros(0, dtype=bool), 0, False, {})
