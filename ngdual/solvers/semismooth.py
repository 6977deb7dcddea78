"""Contact with (given) Tresca friction on Gamma_C as a small dense problem: semismooth Newton.

Condensed onto Gamma_C (:mod:`ngdual.solvers.active_set`), (3.62) leaves the multipliers
z = (lambda_n, lambda_t) (coarse h~ P1 values) and nu (h^ values) with the traction
moments t = (C_n^T sigma, C_t^T sigma) an affine function of z,

    t(z) = b - G z,     G symmetric positive definite,

and the conditions (3.62)_5-7 with q = Q_F lambda_t ((3.95), Q_F of :mod:`ngdual.friction`)

    lambda_n >= 0,  t_n <= 0,  lambda_n t_n = 0,
    t_t = Q_F^T nu,  |nu_j| <= 1,  nu_j q_j = |q_j|.

They are the KKT conditions of the strictly convex problem
min 1/2 z^T G z - b^T z + ||Q_F lambda_t||_1 s.t. lambda_n >= 0, so z is unique; nu is
unique only where the rows of Q_F are independent (not on h^ edges with F = 0, nor for
h^ = h~ when the contact zone reaches the ends of Gamma_C, Lemma 3.29).

The semismooth Newton method of Hueber, Stadler and Wohlmuth (primal-dual active sets,
the frictionless case being the method of Hintermueller, Ito and Kunisch) writes the
inequalities as the equations

    lambda_n - max(0, lambda_n + c_n t_n) = 0,    nu - P_[-1,1](nu + c_t q) = 0,

whose Newton steps are linear systems on the current sets: separation (t_n = 0) or
contact (lambda_n = 0); stick (q_j = 0) or slip (nu_j = sign(nu_j + c_t q_j)). The method
stops as soon as a Newton iterate satisfies the conditions to round-off.

Globalisation. The full steps of this primal-dual active-set method can cycle: started from
the frictionless solution (nu = 0) with a large tangential load, the contact zone flips
between slip to the left and slip to the right (nu = +-1 on every edge, the KKT residual
stuck at 2), and on h^ = h~ meshes it can wander through dozens of sets. Full steps are
taken as long as they make progress (the plain method, which converges in a few steps on
every shipped scene, is unchanged there); once the sets repeat, or ``PATIENCE`` full steps
bring no new smallest value of the merit function ``||Phi(z, nu)||`` (:class:`Merit`: the
natural residual of the two equations above and of t_t = Q_F^T nu, dimensionless), the
iteration returns to the iterate of smallest merit and damps its steps: the Newton iterate
is taken if it reduces the merit by the Armijo factor (1 - 1e-4 alpha), otherwise the step
alpha is halved; the next sets are those of the damped iterate. The merit is piecewise
smooth, not differentiable, so there is no global convergence proof, and along a Newton
direction it can grow at once (a multiplier nu far beyond [-1, 1] on a stick edge that must
slip): then (alpha < ``MIN_STEP``) a full step is taken again, at most ``MAX_ESCAPES``
times. Failing all that (or after ``max_iter`` steps) the problem is solved as the convex QP
it is (:func:`ngdual.solvers.qp.contact_qp`), and the same iteration restarts from the
QP's solution (one or two steps to round-off). Measured on 500 random problems (200 of them
with Tresca bounds varying by 1e3 between edges, a third of those with duplicated rows of Q_F,
as for h^ = h~): the QP is needed for 5 of the 433 without duplicated rows (with full steps
and the QP alone, 27 of the 300 easy ones need it); on a Cattaneo-Mindlin block the damped
steps end in 17 steps without the QP a cycle that full steps leave only after 25 steps and
the QP.

Tolerance: the conditions are residuals relative to the size of their terms; a backward
stable solve of a Newton system attains about eps times the condition number of G
(:func:`kkt_tolerance`: SAFETY * eps * max(kappa_1(G), dim G); kappa_1(G) doubles per level,
so 4e-13 to 1.4e-11 on levels 1-6 of Example 3.46).
The result is always checked (:func:`kkt_residuals`); a :class:`ConvergenceError` names
every condition that fails, with its value and the tolerance.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.linalg.lapack as lapack
import scipy.optimize as spo

from ..solution import ConvergenceError
from ..tolerances import friction_vanishes
from .qp import contact_qp

EPS = float(np.finfo(float).eps)
SAFETY = 100.0  # a tolerance is SAFETY times the round-off level it has to accommodate
PATIENCE = 8  # full steps without a new smallest merit before damping
MAX_ESCAPES = 3  # full steps after a failed line search
ARMIJO = 1e-4
MIN_STEP = 2.0**-20


def condition_number(G: np.ndarray) -> float:
    """kappa_1(G) of a symmetric positive definite G (LAPACK's Cholesky and its estimate).

    ``inf`` if the Cholesky factorisation breaks down (G not numerically definite).
    """
    G = np.asarray(G, dtype=float)
    if G.size == 0:
        return 1.0
    factor, info = lapack.dpotrf(G, lower=0, clean=1)
    if info != 0:
        return float("inf")
    rcond, info = lapack.dpocon(factor, float(np.abs(G).sum(axis=0).max()))
    return float("inf") if info != 0 or rcond <= 0 else 1.0 / float(rcond)


def kkt_tolerance(G: np.ndarray) -> float:
    """SAFETY * eps * max(kappa_1(G), dim G): what round-off leaves of the conditions.

    The conditions are residuals relative to the size of their terms (backward errors),
    which a backward stable solve of a Newton system keeps at a small multiple of eps times
    the dimension; where a computed value must have a sign (lambda_n >= 0 next to the end
    of the contact zone), its forward error eps kappa(G) counts.
    """
    return SAFETY * EPS * max(condition_number(G), float(G.shape[0]), 1.0)


@dataclass
class BoundarySolution:
    """z = (lambda_n, lambda_t), nu and the sets of the last Newton step."""

    lam_n: np.ndarray
    lam_t: np.ndarray
    nu: np.ndarray
    contact: np.ndarray
    stick: np.ndarray
    iterations: int
    fallback: bool
    residuals: dict


def _split(z: np.ndarray, n_c: int) -> tuple[np.ndarray, np.ndarray]:
    return z[:n_c], z[n_c:]


def kkt_residuals(G: np.ndarray, b: np.ndarray, Q: np.ndarray, lam_n: np.ndarray,
                  lam_t: np.ndarray, nu: np.ndarray) -> dict:
    """Relative residuals of the conditions above (0 = exact).

    Scales: max |b| for tractions; for the multipliers max |z|, at least the displacement
    s = max |b_i| / G_ii the load produces; sum |Q| |lambda_t| (the friction work), at
    least sum |Q| s, for the sign condition. The floors matter where z vanishes (a whole
    side in contact and sticking, z = 0 up to round-off): relative to max |z| the
    round-off of a zero z would count as a violation of order one.
    """
    z = np.concatenate([lam_n, lam_t])
    t = b - G @ z
    n_c = len(lam_n)
    t_n, t_t = _split(t, n_c)
    t_scale = max(np.max(np.abs(b), initial=0.0), np.max(np.abs(G @ z), initial=0.0)) or 1.0
    s = float(np.max(np.abs(b) / np.diag(G), initial=0.0)) if G.size else 0.0
    z_scale = max(float(np.max(np.abs(z), initial=0.0)), s) or 1.0
    q = Q @ lam_t
    work = max(float(np.sum(np.abs(Q) @ np.abs(lam_t))), float(np.sum(np.abs(Q))) * s)
    return {
        "lambda_n_negative": float(max(0.0, -lam_n.min(initial=0.0)) / z_scale),
        "sigma_n_positive": float(max(0.0, t_n.max(initial=0.0)) / t_scale),
        "complementarity": float(np.max(np.abs(lam_n * t_n), initial=0.0) / (z_scale * t_scale)),
        "tangential": float(np.max(np.abs(t_t - Q.T @ nu), initial=0.0) / t_scale),
        "nu_bound": float(max(0.0, np.abs(nu).max(initial=0.0) - 1.0)),
        "nu_sign": float(np.sum(np.abs(q) - nu * q) / work) if work > 0 else 0.0,
    }


def _newton_step(G, b, Q, contact, stick, slip_sign, n_c):
    """Solve the linear system of one Newton step on the given sets.

    Unknowns: lambda_n on the separation set, all lambda_t, nu on the stick set
    (nu = slip_sign on slip edges, 0 where F = 0; lambda_n = 0 on the contact set).
    """
    n_t = G.shape[0] - n_c
    free = np.concatenate([~contact, np.ones(n_t, dtype=bool)])
    Qs = Q[stick]
    nu = np.where(stick, 0.0, slip_sign)
    rhs = b.copy()
    rhs[n_c:] -= Q.T @ nu
    G_ff = G[np.ix_(free, free)]
    k, m = int(free.sum()), int(stick.sum())
    B = np.zeros((m, k))
    B[:, k - n_t:] = Qs
    kkt = np.block([[G_ff, B.T], [B, np.zeros((m, m))]])
    sol_rhs = np.concatenate([rhs[free], np.zeros(m)])
    try:
        with np.errstate(all="raise"), warnings.catch_warnings():
            warnings.simplefilter("error", sla.LinAlgWarning)
            sol = sla.solve(kkt, sol_rhs, assume_a="sym", check_finite=False)
        if not np.all(np.isfinite(sol)) or \
                np.linalg.norm(kkt @ sol - sol_rhs) > 1e-8 * (np.linalg.norm(sol_rhs) or 1.0):
            raise sla.LinAlgError("inaccurate")
    except (sla.LinAlgError, sla.LinAlgWarning, FloatingPointError, ValueError):
        sol = _dependent_stick_rows(G_ff, B, rhs[free])
    z = np.zeros(G.shape[0])
    z[free] = sol[:k]
    nu[stick] = sol[k:]
    return z, nu


def _dependent_stick_rows(G_ff, B, rhs):
    """The step when the stick rows B of Q_F are dependent (h^ = h~, Lemma 3.29).

    z is still unique: it minimises the energy on ker B (null-space method). nu is not;
    among the nu with B^T nu = rhs - G z the one closest to [-1, 1] is taken (bounded
    least squares), so that the next sets see a feasible nu whenever there is one.
    """
    if B.shape[0] == 0:
        return sla.solve(G_ff, rhs, assume_a="pos")
    _, sv, Vt = sla.svd(B)
    rank = int(np.sum(sv > 1e-12 * sv[0])) if len(sv) else 0
    N = Vt[rank:].T
    z = N @ sla.solve(N.T @ G_ff @ N, N.T @ rhs, assume_a="pos")
    fit = spo.lsq_linear(B.T, rhs - G_ff @ z, bounds=(-1.0, 1.0), method="bvls",
                         tol=1e-14)
    return np.concatenate([z, fit.x])


def _scales(G: np.ndarray, Q: np.ndarray, n_c: int) -> tuple[np.ndarray, np.ndarray]:
    """c_n = 1 / diag(G_nn), c_t = 1 / diag(Q diag(G_tt)^{-1} Q^T): scale-free NCP functions."""
    d = np.diag(G)
    c_n = 1.0 / d[:n_c]
    qq = (Q**2) @ (1.0 / d[n_c:])
    c_t = np.where(qq > 0, 1.0 / np.where(qq > 0, qq, 1.0), 0.0)
    c_t[friction_vanishes(np.sqrt(qq))] = 0.0  # qq is quadratic in F
    return c_n, c_t


def _sets(G, b, Q, z, nu, c_n, c_t, n_c, has_friction):
    """Contact, stick and the slip signs of the next Newton step.

    On h^ edges whose F is negligible (zero, or round-off of a Coulomb bound on a
    separated edge) nu is arbitrary; it is set to sign(q_j) there, which satisfies
    (3.62)_7 exactly and keeps those edges out of the Newton system.
    """
    lam_n, lam_t = _split(z, n_c)
    t_n = (b - G @ z)[:n_c]
    contact = lam_n + c_n * t_n <= 0
    q = Q @ lam_t
    p = nu + c_t * q
    # |p| = 1 counts as slip: a nu pushed onto the bound (dependent stick rows without a
    # feasible nu, :func:`_dependent_stick_rows`) must leave the stick set
    stick = has_friction & (np.abs(p) < 1.0)
    slip_sign = np.where(has_friction, np.where(stick, 0.0, np.sign(p)), np.sign(q))
    return contact, stick, slip_sign


class Merit:
    """||Phi(z, nu)||, the natural residual of the complementarity equations, dimensionless.

    Phi = ((lambda_n - max(0, lambda_n + c_n t_n)) / s, c_tt (t_t - Q^T nu) / s,
    nu - P_[-1,1](nu + c_t q)), with s = max |b / diag G| the displacement the load
    produces (fixed for the solve, so that the merit of different iterates compares)
    and c_tt = 1 / diag G_tt. It vanishes exactly at the solutions; a Newton step on the
    sets of (z, nu) satisfies the linear rows, and so does any point between two such steps.
    """

    def __init__(self, G, b, Q, n_c, c_n, c_t, has_friction):
        self.G, self.b, self.Q, self.n_c = G, b, Q, n_c
        self.c_n, self.c_t, self.has_friction = c_n, c_t, has_friction
        d = np.diag(G)
        self.c_tt = 1.0 / d[n_c:]
        self.s = float(np.max(np.abs(b) / d, initial=0.0)) or 1.0

    def __call__(self, z: np.ndarray, nu: np.ndarray) -> float:
        n_c = self.n_c
        t = self.b - self.G @ z
        lam_n, lam_t = _split(z, n_c)
        r_n = lam_n - np.maximum(0.0, lam_n + self.c_n * t[:n_c])
        r_t = self.c_tt * (t[n_c:] - self.Q.T @ nu)
        p = nu + self.c_t * (self.Q @ lam_t)
        r_nu = np.where(self.has_friction, nu - np.clip(p, -1.0, 1.0), 0.0)
        return float(np.sqrt((r_n @ r_n + r_t @ r_t) / self.s**2 + r_nu @ r_nu))


def semismooth_newton(G: np.ndarray, b: np.ndarray, n_c: int, Q: np.ndarray | None = None,
                      start: BoundarySolution | None = None, max_iter: int = 100,
                      tol: float | None = None) -> BoundarySolution:
    """Solve the contact problem above (Tresca bound in Q = Q_F; none: frictionless).

    Parameters
    ----------
    G, b : numpy.ndarray
        t(z) = b - G z, z = (lambda_n, lambda_t), each of length ``n_c``.
    Q : numpy.ndarray, optional
        Q_F (N_A x N_C); on rows that vanish (F = 0 on the h^ edge) nu_j = sign(q_j).
        Without Q, lambda_t is free and t_t = 0 (no friction).
    start : BoundarySolution, optional
        Warm start (the previous fixed-point step of Coulomb friction).
    max_iter : int
        Newton steps before the QP fallback (and again after it).
    tol : float, optional
        Bound on every relative residual of :func:`kkt_residuals` (default
        :func:`kkt_tolerance` of G).

    Raises
    ------
    ConvergenceError
        If neither the damped Newton iteration nor the QP fallback satisfies the
        conditions to ``tol``; the message names each failing condition with its value,
        ``history`` holds the largest residual of every Newton iterate.
    """
    Q = np.zeros((0, n_c)) if Q is None else np.asarray(Q, dtype=float)
    tol = kkt_tolerance(G) if tol is None else tol
    has_friction = ~friction_vanishes(np.abs(Q).sum(axis=1))  # the rows of Q_F scale with F
    if start is not None and len(start.nu) == Q.shape[0]:
        z, nu = np.concatenate([start.lam_n, start.lam_t]), start.nu.copy()
    else:
        z, nu = np.zeros(2 * n_c), np.zeros(Q.shape[0])
    history: list[float] = []
    best: dict = {}
    _remember(best, G, b, Q, z, nu, n_c)
    found = _iterate(G, b, Q, z, nu, n_c, has_friction, max_iter, tol, history, best)
    if found is not None:
        return found
    # no convergence (the line search stalled, or max_iter): the convex QP gives the
    # sets, the damped Newton iteration polishes from there
    qp = contact_qp(G, b, Q, n_c)
    if qp is not None:
        z, nu = qp
        found = _iterate(G, b, Q, z, nu, n_c, has_friction, max_iter, tol, history, best)
        if found is not None:
            found.fallback = True
            return found
        if _remember(best, G, b, Q, z, nu, n_c) <= tol:  # the QP's own solution
            contact, stick, _ = _sets(G, b, Q, z, nu, *_scales(G, Q, n_c), n_c, has_friction)
            return BoundarySolution(*_split(z, n_c), nu, contact, stick, len(history), True,
                                    best["residuals"])
    res = best["residuals"]
    failed = {k: v for k, v in res.items() if v > tol} or res
    raise ConvergenceError(
        "the contact problem on Gamma_C was not solved by semismooth Newton (damped, "
        f"{len(history)} steps) nor by the QP fallback"
        + ("" if qp is not None else " (which returned no solution)") + ": "
        + ", ".join(f"{k} = {v:.1e} > {tol:.1e}" for k, v in failed.items()), history)


def _remember(best: dict, G, b, Q, z, nu, n_c) -> float:
    """Keep the iterate with the smallest largest KKT residual (for the error message)."""
    res = kkt_residuals(G, b, Q, *_split(z, n_c), nu)
    worst = max(res.values(), default=0.0)
    if worst < best.get("worst", np.inf):
        best.update(worst=worst, residuals=res)
    return worst


def _iterate(G, b, Q, z, nu, n_c, has_friction, max_iter, tol, history, best):
    """Newton steps from (z, nu) until a Newton iterate satisfies the conditions (result),
    or the damped steps stall or ``max_iter`` steps pass (None).

    Full steps while they make progress; once the sets repeat (a cycle) or ``PATIENCE``
    full steps pass without a new smallest merit, the iteration returns to the iterate of
    smallest merit and continues with damped steps, monotone in the merit.
    """
    c_n, c_t = _scales(G, Q, n_c)
    merit = Merit(G, b, Q, n_c, c_n, c_t, has_friction)
    value = merit(z, nu)
    lowest, since_lowest = (value, z, nu), 0
    seen, damped, escapes = set(), False, 0
    for _ in range(max_iter):
        contact, stick, slip_sign = _sets(G, b, Q, z, nu, c_n, c_t, n_c, has_friction)
        key = (contact.tobytes(), stick.tobytes(), slip_sign[has_friction].tobytes())
        if not damped and (key in seen or since_lowest >= PATIENCE):
            damped, since_lowest = True, 0
            value, z, nu = lowest
            contact, stick, slip_sign = _sets(G, b, Q, z, nu, c_n, c_t, n_c, has_friction)
            key = (contact.tobytes(), stick.tobytes(), slip_sign[has_friction].tobytes())
        seen.add(key)
        z_new, nu_new = _newton_step(G, b, Q, contact, stick, slip_sign, n_c)
        worst = _remember(best, G, b, Q, z_new, nu_new, n_c)
        history.append(worst)
        if worst <= tol:
            res = kkt_residuals(G, b, Q, *_split(z_new, n_c), nu_new)
            return BoundarySolution(*_split(z_new, n_c), nu_new, contact, stick, len(history),
                                    False, res)
        if damped:
            alpha, reference = 1.0, value
            while True:
                z_try, nu_try = z + alpha * (z_new - z), nu + alpha * (nu_new - nu)
                value = merit(z_try, nu_try)
                if value <= (1.0 - ARMIJO * alpha) * reference:
                    break
                alpha *= 0.5
                if alpha < MIN_STEP:
                    break
            if alpha >= MIN_STEP:
                z, nu = z_try, nu_try
                if value < lowest[0]:
                    lowest = (value, z, nu)
                continue
            # the merit does not decrease along the Newton direction (it is not smooth):
            # a full step again (watchdog); a repeated cycle ends in the QP fallback
            damped = False
            escapes += 1
            if escapes > MAX_ESCAPES:
                return None
        z, nu, value = z_new, nu_new, merit(z_new, nu_new)
        since_lowest += 1
        if value < lowest[0]:
            lowest, since_lowest = (value, z, nu), 0
    return None
