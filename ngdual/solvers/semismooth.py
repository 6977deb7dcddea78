"""Contact with (given) Tresca friction on Gamma_C as a small dense problem: semismooth Newton.

Condensed onto Gamma_C (:mod:`ngdual.solvers.fast`), (3.62) leaves the multipliers
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
contact (lambda_n = 0); stick (q_j = 0) or slip (nu_j = sign(nu_j + c_t q_j)). The sets
of the next step are those of the new iterate; the method stops as soon as the conditions
hold to round-off. If the sets repeat first (cycling), the problem is solved as a convex
QP (Clarabel through cvxpy) and Newton restarts from the QP's solution. The result is
always checked (:func:`kkt_residuals`); a :class:`ConvergenceError` says when neither
path satisfies the conditions.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import cvxpy as cp
import numpy as np
import scipy.linalg as sla
import scipy.optimize as spo
import scipy.sparse as sp

from .result import ConvergenceError

KKT_TOL = 1e-10
NEGLIGIBLE_F = 1e-10  # rows of Q_F this small relative to the largest carry no friction


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

    Scales: max |b| for tractions, max |z| for the multipliers, sum |Q| |lambda_t|
    (the friction work) for the sign condition.
    """
    z = np.concatenate([lam_n, lam_t])
    t = b - G @ z
    n_c = len(lam_n)
    t_n, t_t = _split(t, n_c)
    t_scale = max(np.max(np.abs(b), initial=0.0), np.max(np.abs(G @ z), initial=0.0)) or 1.0
    z_scale = np.max(np.abs(z), initial=0.0) or 1.0
    q = Q @ lam_t
    work = float(np.sum(np.abs(Q) @ np.abs(lam_t)))
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
    c_t[qq <= NEGLIGIBLE_F**2 * np.max(qq, initial=0.0)] = 0.0
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


def semismooth_newton(G: np.ndarray, b: np.ndarray, n_c: int, Q: np.ndarray | None = None,
                      start: BoundarySolution | None = None, max_iter: int = 100,
                      tol: float = KKT_TOL) -> BoundarySolution:
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

    Raises
    ------
    ConvergenceError
        If neither the Newton iteration nor the QP fallback satisfies the conditions to
        ``tol`` (relative).
    """
    Q = np.zeros((0, n_c)) if Q is None else np.asarray(Q, dtype=float)
    weight = np.abs(Q).sum(axis=1)
    has_friction = weight > NEGLIGIBLE_F * np.max(weight, initial=0.0)
    if start is not None and len(start.nu) == Q.shape[0]:
        z, nu = np.concatenate([start.lam_n, start.lam_t]), start.nu.copy()
    else:
        z, nu = np.zeros(2 * n_c), np.zeros(Q.shape[0])
    history: list[float] = []
    found = _iterate(G, b, Q, z, nu, n_c, has_friction, max_iter, tol, history)
    if found is not None:
        return found
    # cycling or no convergence: the convex QP gives the sets, Newton polishes from there
    z, nu = _qp_fallback(G, b, Q, n_c)
    found = _iterate(G, b, Q, z, nu, n_c, has_friction, max_iter, tol, history)
    if found is not None:
        found.fallback = True
        return found
    res = kkt_residuals(G, b, Q, *_split(z, n_c), nu)
    if max(res.values()) <= tol:
        contact, stick, _ = _sets(G, b, Q, z, nu, *_scales(G, Q, n_c), n_c, has_friction)
        return BoundarySolution(*_split(z, n_c), nu, contact, stick, len(history), True, res)
    raise ConvergenceError("the contact problem on Gamma_C was not solved: semismooth "
                           f"Newton and the QP fallback leave a KKT residual "
                           f"{max(res.values()):.1e} > {tol:.0e} ({res})", history)


def _iterate(G, b, Q, z, nu, n_c, has_friction, max_iter, tol, history):
    """Newton steps from (z, nu) until the conditions hold (result) or the sets repeat (None)."""
    c_n, c_t = _scales(G, Q, n_c)
    seen = set()
    for _ in range(max_iter):
        contact, stick, slip_sign = _sets(G, b, Q, z, nu, c_n, c_t, n_c, has_friction)
        key = (contact.tobytes(), stick.tobytes(), slip_sign[has_friction].tobytes())
        if key in seen:
            return None
        seen.add(key)
        z, nu = _newton_step(G, b, Q, contact, stick, slip_sign, n_c)
        res = kkt_residuals(G, b, Q, *_split(z, n_c), nu)
        history.append(max(res.values()))
        if history[-1] <= tol:
            return BoundarySolution(*_split(z, n_c), nu, contact, stick, len(history), False,
                                    res)
    return None


def _qp_fallback(G, b, Q, n_c):
    """min 1/2 z^T G z - b^T z + ||Q lambda_t||_1, lambda_n >= 0, by Clarabel: (z, nu)."""
    scale_t = np.max(np.abs(b), initial=0.0) or 1.0
    d = np.sqrt(np.diag(G))
    Gs = G / np.outer(d, d)  # z = y / d: unit diagonal
    R = sla.cholesky(0.5 * (Gs + Gs.T) + 1e-15 * np.eye(len(d)), lower=False)
    y = cp.Variable(len(d))
    s = cp.Variable(Q.shape[0])
    Qs = sp.csr_matrix(Q / d[n_c:][None, :] / scale_t)
    upper, lower = Qs @ y[n_c:] <= s, -Qs @ y[n_c:] <= s
    positive = y[:n_c] >= 0
    objective = 0.5 * cp.sum_squares(R @ y) - (b / d / scale_t) @ y + cp.sum(s) if Q.shape[0] \
        else 0.5 * cp.sum_squares(R @ y) - (b / d / scale_t) @ y
    constraints = [positive, upper, lower] if Q.shape[0] else [positive]
    cp.Problem(cp.Minimize(objective), constraints).solve(
        solver=cp.CLARABEL, tol_gap_abs=1e-12, tol_gap_rel=1e-12, tol_feas=1e-12)
    if y.value is None:
        raise ConvergenceError("the QP fallback on Gamma_C returned no solution", [])
    z = scale_t * np.asarray(y.value) / d
    nu = np.asarray(upper.dual_value - lower.dual_value) if Q.shape[0] else np.zeros(0)
    z[:n_c] = np.maximum(z[:n_c], 0.0)
    return z, np.clip(nu, -1, 1)
