"""The active-set method on the conforming system K: frictionless contact at every order k.

The hybridised solver of :mod:`ngdual.solvers.active_set` eliminates broken RT_0 rows and
P1 traces on the h~ mesh (:class:`~ngdual.solvers.hybrid.HybridSystem`); at order k >= 1,
or with the facet multipliers (:mod:`ngdual.boundary.facet`), there is no such system, and
the problem (3.103) is solved on the assembled K itself, with one sparse LU factorisation
(UMFPACK, :class:`~ngdual.solvers.linear.Factorization`).

The contact conditions of (3.103) act on the unknowns of lambda_n (the Bernstein
coefficients of the facet multipliers, the hat values of the coarse ones) and on their
moments t_n = C_n^T sigma; without friction lambda_t is free, and its moments t_t = 0 are
one more equation of the sparse system.
The problem is condensed onto lambda_n, as in :mod:`ngdual.solvers.active_set`: with S all
other unknowns (sigma, u, eta, phi, lambda_t), one factorisation of K_SS and N_C solves give

    t_n(lambda_n) = b - G lambda_n,   G = C^T K_SS^{-1} C,   b = C^T K_SS^{-1} r_S - r_n,

C = K_S,lambda_n (G is symmetric positive semidefinite: the sigma block of the inverse of a
saddle-point matrix), and the damped semismooth Newton method of
:mod:`ngdual.solvers.semismooth`, with its QP fallback, solves lambda_n >= 0, t_n <= 0,
lambda_n . t_n = 0 (it is posed for z = (lambda_n, lambda_t), here with lambda_t = 0 and the
identity as its block). One back substitution gives the rest. The primal-dual active-set
method on the sparse K, one factorisation per set and no dense G, cycles on the
manufactured case at k = 1 and on Example 3.46 at k = 0 with the facet multipliers (K is no
M-matrix), so it is not used. The N_C solves dominate (manufactured case at k = 1, level 4,
50 000 unknowns, 128 solves: about 15 s against 2 s for the factorisation).
"""

from __future__ import annotations

import time

import numpy as np

from ..forms import DiscreteProblem
from .active_set import ContactStart
from .linear import Factorization
from .qp import contact_problem_residuals
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
    first = None
    if start is not None:
        first = start.at(problem.spaces.contact.node_points())
    x, iterations, factor_s = _condensed(problem, first)
    i_sigma, i_mult, i_lam, rhs = problem.sigma, problem.mult, problem.lam_n, problem.rhs
    residuals = contact_problem_residuals(problem.block(i_sigma, i_sigma),
                                          problem.block(i_sigma, i_mult),
                                          problem.block(i_sigma, i_lam), rhs[i_sigma],
                                          rhs[i_mult], x[i_sigma], x[i_mult], x[i_lam])
    bad = {k: v for k, v in residuals.items() if not v <= TOLERANCE}
    if bad:
        raise ConvergenceError("the active-set solution does not satisfy (3.103) to round-off: "
                               + ", ".join(f"{k} = {v:.1e} > {TOLERANCE:.0e}"
                                           for k, v in bad.items()), [])
    return Solution(problem, x, True, "active-set-conforming", iterations=iterations,
                    residuals=residuals,
                    timings={"assemble": problem.assemble_seconds, "factorize": factor_s,
                             "solve": time.perf_counter() - begin})


def _condensed(problem: DiscreteProblem, first) -> tuple:
    """Semismooth Newton on the condensed problem t_n = b - G lambda_n (module docstring):
    (x, iterations, seconds of the factorisation). ``first``: (lambda_n, lambda_t) of a
    coarser solution at the control points."""
    K, rhs = problem.K.tocsr(), problem.rhs
    contact = problem.lam_n
    rest = np.setdiff1d(np.arange(K.shape[0]), contact)
    fact = Factorization(K[rest][:, rest])
    x = np.zeros(K.shape[0])
    x[rest] = fact.solve(rhs[rest])
    n_c = len(contact)
    if not n_c:
        return x, {"outer": 0, "inner": 0}, fact.seconds
    C = K[rest][:, contact].toarray()
    W = fact.solve_many(C)
    G = C.T @ W
    G = np.block([[0.5 * (G + G.T), np.zeros((n_c, n_c))], [np.zeros((n_c, n_c)), np.eye(n_c)]])
    b = np.concatenate([C.T @ x[rest] - rhs[contact], np.zeros(n_c)])
    state = None
    if first is not None:
        state = BoundarySolution(np.maximum(first[0], 0.0), np.zeros(n_c), np.zeros(0),
                                 np.zeros(n_c, dtype=bool), np.zeros(0, dtype=bool), 0, False,
                                 {})
    state = semismooth_newton(G, b, n_c, start=state)
    x[rest] -= W @ state.lam_n
    x[contact] = state.lam_n
    return x, {"outer": 0, "inner": int(state.iterations)}, fact.seconds
