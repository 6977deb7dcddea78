"""The active-set method on the conforming system K: contact and friction at every order k.

The default solver (:mod:`ngdual.solvers.active_set`) condenses the hybridised system
(:class:`~ngdual.solvers.hybrid.HybridSystem`) onto the contact multipliers. The same
problem (3.62) can be solved on the assembled K itself, with one sparse LU factorisation
(UMFPACK, :class:`~ngdual.solvers.linear.Factorization`), sharing neither the broken
spaces, the condensation nor the Cholesky factor: this solver is the default's fallback
where the hybridised system is singular, and a second solver to check it by.

The contact and friction conditions act on the Bernstein coefficients of lambda_n and
lambda_t and on their moments t = C^T sigma - r (C = K_sigma,lambda, r the lambda rows of
the right-hand side; t_n,i = d_Cn(B_i, sigma_h) - g_i): lambda_n >= 0, t_n <= 0,
lambda_n t_n = 0; without friction t_t = 0, with it the law of
:class:`ngdual.friction.MomentFriction`, |t_t,i| <= F_i on every coefficient.

Condensation onto the candidates. One factorisation of the whole K -- every multiplier
free: the linear problem in which Gamma_C carries no traction -- gives the free solution
x_0 = K^{-1} rhs with multipliers a, and the columns K^{-1} e_j of the multipliers j of a
set J of coefficients give the multipliers for tractions t_J on J (zero elsewhere):

    K x = rhs + E_J t_J,    lambda = a + H t_J,    H = (K^{-1})_{lambda, J}.

By the block inverse, H_JJ = -G^{-1} with G = C_J^T K_R^{-1} C_J (R: all unknowns but
lambda_J; G symmetric positive definite), so on J the problem is that of
:mod:`ngdual.solvers.semismooth`,

    t_J(z) = b - G z,    G = -H_JJ^{-1},    b = G a_J,

z = (lambda_n, lambda_t) on J (without friction lambda_t is free everywhere, t_t = 0: its
block is the identity), and the damped semismooth Newton method with its QP fallback
solves it; for Coulomb friction the fixed point F = mu_f (-t_n) of Remark 3.45 runs around
it (:func:`ngdual.solvers.coulomb.coulomb_fixed_point`). Off J the multipliers are free
and their moments vanish, which satisfies the conditions exactly where lambda_n >= 0 (and,
where a Tresca bound F_i > 0 holds, lambda_t,i = 0: stick). J starts with the coefficients
the free solution pushes through the obstacle by at least ``DEEPEST`` of its deepest
penetration -- with those in contact in a warm start, and every coefficient with F_i > 0
for Tresca -- and takes in the coefficients that violate a condition off J (the deepest
penetrations first, by the same rule), until none does; each column is computed once. One
more solve with the tractions t_J gives all unknowns. The cost: one factorisation and
|J| + 2 solves, 2 |J| + 2 with friction (Hertz at k = 1: 14 of 128 coefficients on
level 2, 12 of them in contact, where condensing onto every coefficient takes 128 solves;
docs/theory/order.md has the measurements).

If K is singular (a body held by Gamma_C alone has rigid motions when nothing touches),
every multiplier is eliminated instead: one factorisation of K without the multipliers
(all clamped, lambda = 0) and a solve per coefficient, G = C^T K_SS^{-1} C and
b = C^T K_SS^{-1} r_S - r on all of Gamma_C.

The primal-dual active-set method on the sparse K (one factorisation per set) cycles on
the manufactured case at k = 1 and on Example 3.46 at k = 0 with the facet multipliers
(K is no M-matrix); the damped method on the condensed problem does not.
The result is checked on K: the residuals of (3.103) (and of the friction law) are
round-off, or a :class:`ConvergenceError` names every one that is not.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla

from ..forms import DiscreteProblem
from ..friction import MomentFriction, build_friction_forms, tresca_moments
from ..solution import ConvergenceError, Solution
from ..tolerances import COULOMB_FIXED_POINT_TOL
from .contact_problem import Condensed, solve_contact
from .convergence import accepted, exceeding, moments, residuals
from .linear import Factorization
from .semismooth import EPS, SAFETY
from .settings import ActiveSetSettings
from .start import ContactStart

REGULAR = 1e-8     # the free solve of a regular K leaves relative residuals below this
CONTACT_START = 1e-8  # a warm start's lambda_n in contact: below this of its largest value
DEEPEST = 0.5      # candidates per round: penetrations of at least this share of the deepest


class WholeFactorization:
    """K factorised with every multiplier free, and the columns K^{-1} e_j of the multipliers
    on demand, each computed once (rows: lambda_n, then lambda_t)."""

    def __init__(self, problem: DiscreteProblem):
        self.problem = problem
        self.fact = Factorization(problem.K)
        self.rows = np.concatenate([problem.lam_n, problem.index("lam_t")])
        self.x0 = self.fact.solve(problem.rhs)
        self.a = self.x0[self.rows]
        self._columns: dict[int, np.ndarray] = {}
        self.solves = 1

    @property
    def regular(self) -> bool:
        """Whether the free solve is a solution (K is singular when the body floats)."""
        K, rhs, x = self.problem.K, self.problem.rhs, self.x0
        if not np.all(np.isfinite(x)):
            return False
        scale = max(float(np.max(abs(K) @ np.abs(x), initial=0.0)),
                    float(np.max(np.abs(rhs), initial=0.0))) or 1.0
        return float(np.max(np.abs(K @ x - rhs), initial=0.0)) <= REGULAR * scale

    def columns(self, unknowns: np.ndarray) -> np.ndarray:
        """(K^{-1})_{lambda, p} for the unknowns p (2 N_C x len(unknowns))."""
        e = np.zeros(self.problem.n)
        for p in unknowns:
            if p not in self._columns:
                e[p] = 1.0
                self._columns[p] = self.fact.solve(e)[self.rows]
                e[p] = 0.0
                self.solves += 1
        return np.column_stack([self._columns[p] for p in unknowns]) if len(unknowns) \
            else np.zeros((len(self.rows), 0))

    def condensed(self, J: np.ndarray, friction: bool) -> tuple[Condensed, np.ndarray]:
        """The problem on J and the columns H (all multipliers x the unknowns of J)."""
        n_c = len(self.problem.lam_n)
        own = np.concatenate([J, n_c + J]) if friction else J
        H = self.columns(self.rows[own])
        H_JJ = H[own]
        G = -sla.inv(0.5 * (H_JJ + H_JJ.T))
        G = 0.5 * (G + G.T)
        b = G @ self.a[own]
        if not friction:  # lambda_t free: the identity block of semismooth_newton
            G = sla.block_diag(G, np.eye(len(J)))
            b = np.concatenate([b, np.zeros(len(J))])
        return Condensed(G, b, J), H

    def solution(self, J: np.ndarray, t: np.ndarray, friction: bool) -> np.ndarray:
        """All unknowns for the tractions t on J (one solve with K)."""
        n_c = len(self.problem.lam_n)
        own = np.concatenate([J, n_c + J]) if friction else J
        rhs = self.problem.rhs.copy()
        rhs[self.rows[own]] += t[:len(own)]
        self.solves += 1
        return self.fact.solve(rhs)


def conforming_active_set(problem: DiscreteProblem, settings: ActiveSetSettings,
                          start: ContactStart | None = None,
                          tol: float = COULOMB_FIXED_POINT_TOL) -> Solution:
    """Solve (3.62) on ``problem.K``: condensed onto the candidates on Gamma_C, semismooth
    Newton there (module docstring).

    Parameters
    ----------
    problem : DiscreteProblem
        Any assembled problem with a contact boundary and the facet multipliers.
    settings : ActiveSetSettings
        The model (friction law, mu_f) and ``max_iter`` (bound on the Coulomb fixed-point
        steps); the method iterates to round-off.
    start : ContactStart, optional
        The multipliers of a coarser solution, at this problem's control points
        (``spaces.contact.node_points()``): the Newton method starts there.
    tol : float
        Relative change of F at which the Coulomb fixed point stops (or its round-off).

    Raises
    ------
    ConvergenceError
        If the contact problem on Gamma_C is not solved (:func:`semismooth_newton`), the
        Coulomb fixed point does not converge, or the residuals of (3.62) exceed
        ``TOLERANCE``.
    """
    model = settings.model
    begin = time.perf_counter()
    first = start.at(problem.spaces.contact.node_points()) if start is not None else None
    law = model.law
    bound = tresca_moments(problem) if law == "tresca" else None
    whole = WholeFactorization(problem)
    factor_s = whole.fact.seconds
    friction = MomentFriction()
    if whole.regular:
        x, state, F, info = _on_candidates(whole, law, model.mu_f, bound, friction, first,
                                           settings.max_iter, tol)
    else:
        x, state, F, info, factor_s = _on_every_coefficient(problem, law, model.mu_f, bound,
                                                            friction, first,
                                                            settings.max_iter, tol)
    return checked_solution(problem, x, law, model.mu_f, F, "active-set-conforming",
                            {**info["iterations"], "condensed": info["unknowns"],
                             "solves": info["solves"]}, info["history"],
                            {"assemble": problem.assemble_seconds, "factorize": factor_s,
                             "solve": time.perf_counter() - begin})


def checked_solution(problem: DiscreteProblem, x: np.ndarray, law: str, mu_f: float,
                     F: np.ndarray | None, method: str, iterations: dict, history: list,
                     seconds: dict, found: dict | None = None,
                     floors: dict | None = None) -> Solution:
    """The solution x of (3.62) with the facet multipliers, once its residuals on
    ``problem.K`` (:func:`residuals`; ``found``: those of this x, computed by the caller)
    are round-off (:func:`~ngdual.solvers.convergence.exceeding`, with the residuals' own
    ``floors``); the friction multiplier nu and the bound reported per fine edge (the h^
    edges of ``FacetFrictionForms``).

    Raises
    ------
    ConvergenceError
        Naming every residual above ``TOLERANCE`` (or its floor).
    """
    found = residuals(problem, x, law, mu_f, F) if found is None else found
    bad = exceeding(found, floors)
    if bad:
        raise ConvergenceError("the active-set solution does not satisfy (3.62) to round-off: "
                               + ", ".join(f"{k} = {v:.1e} > {accepted(k, floors):.2g}"
                                           for k, v in bad.items()), history)
    nu = forms = edge_bound = nu_l2 = None
    if F is not None:
        forms = build_friction_forms(problem)
        edge_bound = forms.edge_bound(F)
        nu = forms.edge_nu(moments(problem, x)[1], F)
        nu_l2 = forms.l2_norm_nu(nu, edge_bound > 0)
    return Solution(problem, x, True, method if law == "none" else f"{method}-{law}",
                    iterations=iterations, residuals=found, history=history, nu=nu,
                    friction_bound=edge_bound, friction_forms=forms, nu_l2=nu_l2,
                    timings=seconds)


def _on_candidates(whole: WholeFactorization, law: str, mu_f: float, bound, friction, first,
                   max_iter: int, tol: float):
    """Condense onto the candidates J from the factorisation of the whole K, enlarging J
    until no coefficient off J violates a condition (module docstring)."""
    n_c = len(whole.problem.lam_n)
    has_friction = law != "none"
    candidate = _deepest(whole.a[:n_c], 0.0)
    if first is not None:
        candidate |= first[0] <= CONTACT_START * (np.max(np.abs(first[0]), initial=0.0) or 1.0)
    if law == "tresca":
        candidate |= bound > 0.0
    inner, history, rounds = 0, [], 0
    while True:
        rounds += 1
        J = np.flatnonzero(candidate)
        cond, H = whole.condensed(J, has_friction)
        if len(J):
            state, F_J, hist, its = solve_contact(cond, law, mu_f, _on(bound, J), friction,
                                                  first, max_iter, tol)
            t = cond.traction(state)
        else:
            state, F_J, hist, its = None, None, [], {"outer": 0, "inner": 0}
            t = np.zeros(0)
        inner += its["inner"]
        history += hist
        own = 2 * len(J) if has_friction else len(J)
        lam = whole.a + H @ t[:own]
        scale = float(np.max(np.abs(lam), initial=0.0)) or 1.0
        level = SAFETY * (cond.roundoff if len(J) else EPS) * scale
        off = ~candidate
        violated = off & _deepest(np.where(off, lam[:n_c], 0.0), level)
        if law == "tresca":
            violated |= off & (bound > 0.0) & (np.abs(lam[n_c:]) > level)
        if not violated.any():
            break
        candidate |= violated
        if state is not None:
            lam_t = lam[n_c:]
            first = (lam[:n_c], lam_t)
    x = whole.solution(J, t, has_friction)
    F = None
    if has_friction:
        F = np.zeros(n_c)
        if law == "tresca":
            F = bound
        elif F_J is not None:
            F[J] = F_J
    return x, state, F, {"iterations": {"outer": its["outer"], "inner": int(inner),
                                        "candidate_rounds": rounds},
                         "history": history, "unknowns": len(J), "solves": whole.solves}


def _on(bound: np.ndarray | None, J: np.ndarray) -> np.ndarray | None:
    """A Tresca bound on every coefficient restricted to J."""
    return None if bound is None else bound[J]


def _deepest(lam_n: np.ndarray, level: float) -> np.ndarray:
    """The coefficients that penetrate (lambda_n < -``level``) by at least ``DEEPEST`` of the
    deepest penetration: contact there lifts the body elsewhere, so the shallow ones are
    taken in only if they still penetrate afterwards."""
    deepest = float(np.min(lam_n, initial=0.0))
    return (lam_n < -level) & (lam_n <= DEEPEST * deepest)


def _on_every_coefficient(problem: DiscreteProblem, law: str, mu_f: float, bound, friction,
                          first, max_iter: int, tol: float):
    """Eliminate every multiplier (all clamped) and condense onto all coefficients: for a
    singular K (module docstring)."""
    K, rhs = problem.K.tocsr(), problem.rhs
    has_friction = law != "none"
    L = np.concatenate([problem.lam_n, problem.index("lam_t")]) if has_friction \
        else problem.lam_n
    n_c = len(problem.lam_n)
    rest = np.setdiff1d(np.arange(K.shape[0]), L)
    fact = Factorization(K[rest][:, rest])
    x = np.zeros(K.shape[0])
    x[rest] = fact.solve(rhs[rest])
    C = K[rest][:, L].toarray()
    W = fact.solve_many(C)
    G = C.T @ W
    G = 0.5 * (G + G.T)
    b = C.T @ x[rest] - rhs[L]
    if not has_friction:
        G = sla.block_diag(G, np.eye(n_c))
        b = np.concatenate([b, np.zeros(n_c)])
    cond = Condensed(G, b, np.arange(n_c))
    state, F, history, its = solve_contact(cond, law, mu_f, bound, friction, first,
                                            max_iter, tol)
    z = np.concatenate([state.lam_n, state.lam_t])[:len(L)]
    x[rest] -= W @ z
    x[L] = z
    return x, state, F, {"iterations": {**its, "candidate_rounds": 0}, "history": history,
                         "unknowns": n_c, "solves": len(L) + 1}, fact.seconds
