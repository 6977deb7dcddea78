"""The discrete problem as convex QPs: a solver independent of Algorithms 3.38/3.41.

The algebraic problem (3.103), i.e. the discrete variational inequality (3.68)
without friction, is the KKT system of

    min_sigma 1/2 sigma^T A sigma - g^T sigma   s.t.  B^T sigma = b,  C_n^T sigma <= 0,

with the multipliers (u, eta, phi, lambda_t) of the equalities and lambda_n >= 0
of the inequalities. Here the QP is solved directly by Clarabel's interior-point
method through cvxpy and then polished once on the active set it found, so
nothing is shared with the Uzawa iteration or its saddle-point factorisation.

With friction and a given bound F, (3.62) is the KKT system of the QP in (sigma, nu)

    min 1/2 sigma^T A sigma - g^T sigma
    s.t. B^T sigma - (0, 0, 0, Q_F^T nu) = b,  C_n^T sigma <= 0,  |nu_j| <= 1,

(stationarity in nu is nu_j = sign (Q_F lambda_t)_j, i.e. (3.62)_7); Coulomb
friction iterates this QP on F = mu_f |sigma_n| of (3.123) to a fixed point
(:func:`solve_qp_friction`).

Condensed onto Gamma_C, the same problem is a small dense QP in the contact multipliers
(:func:`contact_qp`), the fallback of the semismooth Newton method when its active sets cycle.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..forms import DiscreteProblem
from ..friction import MomentFriction, build_friction_forms, tresca_bound, tresca_moments
from ..solution import ConvergenceError, Solution
from ..tolerances import CLARABEL_TOLERANCES, CLARABEL_WHOLE_PROBLEM
from .settings import Model

FEASIBILITY_TOL = 1e-10  # the polished active set is accepted up to this relative violation


def solve_qp(problem: DiscreteProblem, model: Model) -> Solution:
    """Solve the frictionless problem (3.103); see :func:`_solve_qp`.

    ``model`` gives E*, the scale of the QP's variables.
    """
    return _solve_qp(problem, model.plane_strain_modulus)


def _solve_qp(problem: DiscreteProblem, modulus: float,
              Q: sp.spmatrix | None = None) -> Solution:
    """Solve (3.103), the algebraic form of (3.68), as one convex QP in sigma (Clarabel via cvxpy).

    The QP is posed in scaled variables so that its numbers are O(1): the
    compliance block is multiplied by the plane-strain modulus E* and sigma is
    measured in the stress unit ``s = max(max|b|, E* max|g|)``. Then
    ``sigma = s z``, and the multipliers of the scaled QP give
    ``(u, eta, phi, lambda_t, lambda_n) = (s / E*) * (duals)``.

    With ``Q`` (= Q_F, N_A x N_C) the friction variable nu (|nu| <= 1) enters
    the lambda_t rows of the equality; ``Solution.nu`` is then set and the
    active-set polish is skipped (it would need the stick/slip sets too).

    Returns
    -------
    Solution
        ``x`` ordered like ``problem.K``; ``residuals`` holds the relative
        stationarity residual ||A sigma + B y + C_n lambda_n - g|| / (||g|| + ||A sigma||),
        the equality residual, the three contact residuals of (3.103) and
        ``polished`` (1.0 if the active-set polish was accepted).
    """
    import cvxpy as cp  # 0.9 s to import: only when a QP is solved

    i_sigma, i_mult, i_lam = problem.sigma, problem.mult, problem.lam_n
    A = problem.block(i_sigma, i_sigma)
    B = problem.block(i_sigma, i_mult)
    C_n = problem.block(i_sigma, i_lam)
    g, b = problem.rhs[i_sigma], problem.rhs[i_mult]
    stress = max(np.max(np.abs(b), initial=0.0), modulus * np.max(np.abs(g), initial=0.0)) or 1.0
    A_s, g_s, b_s = modulus * A, modulus / stress * g, b / stress

    start = time.perf_counter()
    z = cp.Variable(len(i_sigma))
    lhs, constraints, nu = B.T @ z, [], None
    if Q is not None:
        nu = cp.Variable(Q.shape[0])
        rows = problem.index("lam_t") - len(i_sigma)  # lambda_t rows within mult
        inject = sp.csr_matrix((np.ones(len(rows)), (rows, np.arange(len(rows)))),
                               shape=(len(i_mult), Q.shape[1]))
        lhs = lhs - (inject @ Q.T / stress) @ nu
        constraints.append(cp.abs(nu) <= 1)
    equality, contact = lhs == b_s, C_n.T @ z <= 0
    qp = cp.Problem(cp.Minimize(0.5 * cp.quad_form(z, A_s, assume_PSD=True) - g_s @ z),
                    [equality, contact, *constraints])
    qp.solve(solver=cp.CLARABEL, **CLARABEL_WHOLE_PROBLEM)
    if z.value is None:
        raise RuntimeError(f"Clarabel returned no solution (status {qp.status!r})")
    # cvxpy's Lagrangian is f + y^T (B^T z - b) + lambda^T C_n^T z, the sign of (3.103)
    scaled = (z.value, equality.dual_value, np.maximum(contact.dual_value, 0.0))
    qp_s = time.perf_counter() - start

    start = time.perf_counter()
    polished = _polish(A_s, B, C_n, g_s, b_s, *scaled) if Q is None else None
    polish_s = time.perf_counter() - start
    z_v, y_v, lam_v = polished if polished is not None else scaled

    x = np.zeros(problem.n)
    x[i_sigma] = stress * z_v
    x[i_mult] = stress / modulus * y_v
    x[i_lam] = stress / modulus * lam_v
    nu_v = None if nu is None else np.clip(nu.value, -1.0, 1.0)
    b_nu = b if nu is None else b + inject @ (Q.T @ nu_v)  # the lambda_t rows carry Q_F^T nu
    residuals = {**contact_problem_residuals(A, B, C_n, g, b_nu, x[i_sigma], x[i_mult],
                                             x[i_lam]),
                 "polished": float(polished is not None)}
    converged = polished is not None or qp.status == cp.OPTIMAL
    return Solution(problem, x, converged, "qp", iterations={"outer": 0, "inner": 0},
                    residuals=residuals,
                    timings={"assemble": problem.assemble_seconds, "qp": qp_s,
                             "polish": polish_s, "solve": qp_s + polish_s},
                    nu=nu_v)


def solve_qp_friction(problem: DiscreteProblem, model: Model, tol: float = 1e-10,
                      max_iter: int = 200) -> Solution:
    """Tresca or Coulomb friction by the QP in (sigma, nu), iterated on F for Coulomb.

    ``model`` gives the law, mu_f and E*.
    Tresca: one QP with the given bound. Coulomb: F^0 = mu_f |sigma_n| of the
    frictionless QP, then F^{k+1} = mu_f |sigma_n(sigma^k)| (3.123) until the
    relative change of F is <= ``tol`` (successive substitution: no Uzawa step,
    no metric, no factorisation shared with :mod:`ngdual.solvers.nested`). With the facet
    multipliers of order k the law acts on the Bernstein moments
    (:class:`ngdual.friction.MomentFriction`: Q_F = diag(F_i), F_i = int F B_i ds or
    mu_f (-t_n,i)); ``friction_bound`` and ``nu`` are then reported per fine edge
    (:class:`ngdual.friction.FacetFrictionForms`).

    Raises
    ------
    ConvergenceError
        If the fixed point on F does not converge in ``max_iter`` QPs.
    """
    law, mu_f, modulus = model.law, model.mu_f, model.plane_strain_modulus
    if law not in ("tresca", "coulomb"):
        raise ValueError(f"the friction QP solves Tresca or Coulomb friction, not law {law!r}")
    forms = build_friction_forms(problem)
    facet = problem.spaces.contact.traces
    # the facet multipliers bound every Bernstein moment (ngdual.friction.MomentFriction)
    friction_law = MomentFriction() if facet else forms

    def coulomb(x):
        if facet:
            return friction_law.coulomb_bound_of((problem.K @ x - problem.rhs)[problem.lam_n],
                                                 mu_f)
        return forms.coulomb_bound(x, mu_f)

    start = time.perf_counter()
    if law == "tresca":
        bound = tresca_moments(problem) if facet else tresca_bound(forms, problem)
        history = [0.0]
        sol = _solve_qp(problem, modulus, friction_law.q_matrix(bound))
    else:
        sol = _solve_qp(problem, modulus)
        history = []
        while len(history) < max_iter:
            bound = coulomb(sol.x)
            sol = _solve_qp(problem, modulus, friction_law.q_matrix(bound))
            mapped = coulomb(sol.x)
            history.append(float(np.linalg.norm(mapped - bound)
                                 / (np.linalg.norm(mapped) or 1.0)))
            if history[-1] <= tol:
                break
        else:
            raise ConvergenceError(f"the fixed point on F did not converge in {max_iter} QPs",
                                   history)
    if facet:  # per fine edge, as the active-set method reports them
        sol.nu = forms.edge_nu((problem.K @ sol.x - problem.rhs)[problem.index("lam_t")], bound)
    sol.friction_bound = forms.edge_bound(bound) if facet else bound
    sol.friction_forms = forms
    sol.method, sol.history = f"qp-{law}", history
    sol.iterations = {"outer": len(history), "inner": 0}
    sol.timings["solve"] = time.perf_counter() - start
    return sol


def _polish(A, B, C_n, g, b, z, y, lam):
    """Solve the KKT system with C_n^T sigma = 0 imposed where lambda_n > 0, else None.

    A constraint counts as active where its multiplier is relatively larger
    than its slack (the usual interior-point identification). The result is
    accepted only if it satisfies lambda_n >= 0 and C_n^T sigma <= 0: then it
    meets every KKT condition of the strictly convex QP, so it is the solution
    whichever active set was guessed.
    """
    slack = -(C_n.T @ z)
    active = lam / (np.max(lam, initial=0.0) or 1.0) > slack / (np.max(slack, initial=0.0) or 1.0)
    C_a = C_n[:, active]
    n_s, n_m, n_a = len(z), B.shape[1], int(active.sum())
    kkt = sp.bmat([[A, B, C_a], [B.T, None, None], [C_a.T, None, None]], format="csc")
    sol = spla.spsolve(kkt, np.concatenate([g, b, np.zeros(n_a)]))
    z_p, y_p = sol[:n_s], sol[n_s:n_s + n_m]
    lam_p = np.zeros_like(lam)
    lam_p[active] = sol[n_s + n_m:]
    traction = C_n.T @ z_p
    if not np.all(np.isfinite(sol)):
        return None
    if lam_p.min(initial=0.0) < -FEASIBILITY_TOL * (np.max(np.abs(lam_p), initial=0.0) or 1.0):
        return None
    if traction.max(initial=0.0) > FEASIBILITY_TOL * (np.max(np.abs(traction), initial=0.0) or 1.0):
        return None
    return z_p, y_p, np.maximum(lam_p, 0.0)


def contact_problem_residuals(A, B, C_n, g, b, sigma, y, lam) -> dict:
    """Relative residuals of (3.103) for the blocks A, B, C_n of K (:func:`product_residuals`)."""
    return product_residuals(A @ sigma, B @ y + C_n @ lam, B.T @ sigma, C_n.T @ sigma, g, b, lam)


def product_residuals(a_sigma, coupling, b_sigma, traction, g, b, lam) -> dict:
    """Relative residuals of (3.103): stationarity, equalities, sign conditions, complementarity,
    from the products of K with the solution: A sigma, B y + C_n lambda_n, B^T sigma and the
    traction moments C_n^T sigma (taken from K's blocks, or from K x without forming K)."""
    lam_scale = np.max(np.abs(lam), initial=0.0) or 1.0
    tr_scale = np.max(np.abs(traction), initial=0.0) or 1.0
    return {
        "stationarity": float(np.linalg.norm(a_sigma + coupling - g)
                              / ((np.linalg.norm(g) + np.linalg.norm(a_sigma)) or 1.0)),
        "equality": float(np.linalg.norm(b_sigma - b) / (np.linalg.norm(b) or 1.0)),
        "lambda_n_negative": float(max(0.0, -lam.min(initial=0.0)) / lam_scale),
        "sigma_n_positive": float(max(0.0, traction.max(initial=0.0)) / tr_scale),
        "complementarity": float(abs(lam @ traction)
                                 / ((np.linalg.norm(lam) * np.linalg.norm(traction)) or 1.0)),
    }


def contact_qp(G: np.ndarray, b: np.ndarray, Q: np.ndarray, n_c: int
               ) -> tuple[np.ndarray, np.ndarray] | None:
    """The contact problem condensed onto Gamma_C as the convex QP it is, by Clarabel:

        min 1/2 z^T G z - b^T z + ||Q lambda_t||_1   s.t.  lambda_n >= 0,

    z = (lambda_n, lambda_t) of length 2 ``n_c``, t(z) = b - G z the traction moments, Q = Q_F
    (:mod:`ngdual.solvers.semismooth`, whose fallback it is). Returns (z, nu), nu the
    multipliers of |Q lambda_t| <= s clipped to [-1, 1], or None if Clarabel returns no
    solution. It starts the Newton polish, so it is solved to CLARABEL_TOLERANCES only.
    """
    import cvxpy as cp  # 0.9 s to import: only when a QP is solved

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
    with warnings.catch_warnings():
        # "solution may be inaccurate": it is only the start of the Newton polish
        warnings.simplefilter("ignore", UserWarning)
        try:
            cp.Problem(cp.Minimize(objective), constraints).solve(
                solver=cp.CLARABEL, **CLARABEL_TOLERANCES)
        except cp.error.SolverError:
            return None
    if y.value is None:
        return None
    z = scale_t * np.asarray(y.value) / d
    nu = np.asarray(upper.dual_value - lower.dual_value) if Q.shape[0] else np.zeros(0)
    z[:n_c] = np.maximum(z[:n_c], 0.0)
    return z, np.clip(nu, -1, 1)
