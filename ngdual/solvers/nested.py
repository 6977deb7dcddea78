"""Algorithm 3.41 (nested Uzawa, Tresca) and Remark 3.45 (Coulomb without a third loop).

Outer loop (``loop_order = "friction-outer"``, Algorithm 3.41): for the current
nu the inner loop (steps 4-7, :class:`ContactLoop`) solves the contact problem
(3.108) with prescribed tangential traction d_Ct(mu_t, sigma) = q(mu_t, nu);
then nu <- P^Lambda(nu + rho_2 Phi^Lambda lambda_t) (step 8). For Coulomb, F is
recomputed from sigma_n by (3.123) before the nu update (steps 8'-10').

``loop_order = "contact-outer"`` (Remark 3.43) exchanges the loops: the inner
loop updates nu for fixed lambda_n, the outer loop updates lambda_n.

P^Lambda uses the mass matrix of L_h^ (Remark 3.44). It is diagonal (nu is
piecewise constant), so the projection is the closed form clip(., -1, 1); the
same projection as a cvxpy QP is :func:`box_projection_qp`.

Stopping (honest): the iteration stops only when the increments of nu (and,
for Coulomb, of F) are below eps2 *and* the inner loop converged; every
residual of the discrete variational inequality (3.62) is reported.

rho_2 is dimensionless: the step applied is rho_2 E* / (2 max(F)^2 h^), h^ the
mean h^ edge length, the inverse of the scale of M^{-1} Q_F S^{-1} Q_F^T for
the stiffest tangential mode (one h^ edge), so the same rho_2 works for any E
and load scale; the number of outer steps still grows like 1/h^ (the mass
matrix metric of Remark 3.44 is not H^{-1/2}-equivalent).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import cvxpy as cp
import numpy as np

from ..forms import DiscreteProblem
from ..friction import FrictionForms, build_friction_forms, tresca_bound
from .result import ConvergenceError, Solution
from .uzawa import ContactLoop


def box_projection_qp(c: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """argmin_{|psi_j| <= 1} 1/2 psi^T M psi - c^T psi as a cvxpy QP (Remark 3.44)."""
    psi = cp.Variable(len(c))
    scale = float(mass.max())
    objective = 0.5 * cp.sum(cp.multiply(mass / scale, cp.square(psi))) - (c / scale) @ psi
    cp.Problem(cp.Minimize(objective), [cp.abs(psi) <= 1]).solve(solver=cp.CLARABEL)
    return np.clip(np.asarray(psi.value, dtype=float), -1.0, 1.0)


def box_projection(c: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """The same projection in closed form for the diagonal mass matrix."""
    return np.clip(c / mass, -1.0, 1.0)


def _relative(new: np.ndarray, old: np.ndarray) -> float:
    return float(np.linalg.norm(new - old) / (np.linalg.norm(new) or 1.0))


def friction_residuals(forms: FrictionForms, x: np.ndarray, problem: DiscreteProblem,
                       nu: np.ndarray, F: np.ndarray) -> dict:
    """Residuals of (3.62)_5,7 and |sigma_t| <= F on Gamma_C (relative, 0 = exact).

    ``nu_sign`` is the residual of q(kappa - nu, lambda_t) <= 0 for all kappa in
    Lambda_h^: sum_j (|(Q lambda_t)_j| - nu_j (Q lambda_t)_j) / sum_j |(Q lambda_t)_j|.
    ``sigma_t_excess`` is max(|sigma_t| - F)_+ / max F over the fine edges: a
    pointwise check that the discrete problem only enforces in the weak sense
    (tested against the h~ hats), so values O(1) next to the corners of Gamma_C
    are expected.
    """
    Q = forms.q_matrix(F)
    lam_t = x[problem.index("lam_t")]
    qlt = Q @ lam_t
    total = np.abs(qlt).sum() or 1.0
    sigma_t = forms.T_t @ x
    f_scale = F.max() if F.max() > 0 else 1.0
    return {
        "nu_sign": float(np.sum(np.abs(qlt) - nu * qlt) / total),
        "nu_bound": float(max(0.0, np.abs(nu).max(initial=0.0) - 1.0)),
        "sigma_t_excess": float(max(0.0, np.max(np.abs(sigma_t) - F, initial=0.0)) / f_scale),
    }


def nested_uzawa(problem: DiscreteProblem, law: str, mu_f: float = 0.0, rho1: float = 1.0,
                 rho2: float = 1.0, eps1: float = 1e-8, eps2: float = 1e-6,
                 max_iter: int = 2000, metric: str = "h12", loop_order: str = "friction-outer",
                 backend: str = "umfpack",
                 progress: Callable[[int, float], None] | None = None) -> Solution:
    """Solve (3.62) with Tresca (Algorithm 3.41) or Coulomb (Remark 3.45) friction.

    Parameters
    ----------
    law : {"tresca", "coulomb"}
    mu_f : float
        Coulomb friction coefficient (ignored for Tresca, whose F is the scene's bound).
    rho1, rho2 : float
        Dimensionless step lengths of the lambda_n and nu updates.
    eps1, eps2 : float
        Tolerances of the inner loop and of the nu / F increments.
    max_iter : int
        Bound on the outer iterations (and on the inner ones per outer step).

    Raises
    ------
    ConvergenceError
        When the outer increments become NaN (the inner loop also raises on growth).
    """
    if loop_order != "friction-outer":
        raise NotImplementedError("loop_order 'contact-outer' (Remark 3.43) is not implemented "
                                  "yet; use 'friction-outer'")
    start_all = time.perf_counter()
    loop = ContactLoop(problem, metric, backend)
    forms = build_friction_forms(problem)
    modulus = problem.scene.material.plane_strain_modulus
    h_hat = float(forms.hat_lengths.mean())
    mass = forms.hat_lengths
    i_t = problem.index("lam_t")  # the saddle unknowns are a prefix of x: also positions in y
    i_b = i_t - len(problem.sigma)  # lambda_t rows in the right-hand side b of the mult rows
    b0 = problem.F[problem.mult]

    def rhs(F: np.ndarray, nu: np.ndarray) -> np.ndarray:
        """b^i of step 3: the lambda_t rows carry q(mu_t, nu)."""
        b = b0.copy()
        b[i_b] += forms.q_matrix(F).T @ nu
        return b

    start = time.perf_counter()

    lam = np.zeros(len(problem.lam_n))
    nu = np.zeros(forms.n_nu)
    x = np.zeros(problem.K.shape[0])
    if law == "tresca":
        F = tresca_bound(forms, problem)
        inner_total = 0
    else:  # F^0 from the frictionless solution (Remark 3.45: F^0(sigma^0))
        y, lam, inner_total, _, _ = loop.run(b0, lam, rho1, eps1, max_iter)
        x[problem.saddle], x[problem.lam_n] = y, lam
        F = forms.coulomb_bound(x, mu_f)
    history, converged = [], False
    for outer in range(1, max_iter + 1):
        y, lam, inner, _, inner_ok = loop.run(rhs(F, nu), lam, rho1, eps1,   # steps 3-7
                                              max_iter)
        inner_total += inner
        x[problem.saddle], x[problem.lam_n] = y, lam
        change_F = 0.0
        if law == "coulomb":                                                 # step 8'
            F_new = forms.coulomb_bound(x, mu_f)
            change_F = _relative(F_new, F)
            F = F_new
        Q = forms.q_matrix(F)
        f_max = F.max()
        step = rho2 * modulus / (2 * f_max**2 * h_hat) if f_max > 0 else 0.0
        nu_new = box_projection(mass * nu + step * (Q @ y[i_t]), mass)      # step 8 / 10'
        change_nu = _relative(nu_new, nu)
        nu = nu_new
        history.append(max(change_nu, change_F))
        if progress:
            progress(outer, history[-1])
        if not np.isfinite(history[-1]):
            raise ConvergenceError(f"nested Uzawa diverged at outer step {outer}", history)
        if inner_ok and change_nu <= eps2 and change_F <= eps2:              # step 9 / 9'
            converged = True
            break
    # one last inner solve so that (sigma, lambda) match the final nu and F exactly
    y, lam, inner, _, inner_ok = loop.run(rhs(F, nu), lam, rho1, eps1, max_iter)
    inner_total += inner
    converged = converged and inner_ok
    x[problem.saddle], x[problem.lam_n] = y, lam
    return Solution(problem, x, converged, f"nested-uzawa-{law}-{metric}",
                    iterations={"outer": outer, "inner": inner_total},
                    residuals={"nu_increment": history[-1], **loop.residuals(y, lam),
                               **friction_residuals(forms, x, problem, nu, F)},
                    history=history,
                    timings={"assemble": problem.assemble_seconds,
                             "factorize": loop.fact.seconds,
                             "solve": time.perf_counter() - start,
                             "total_solver": time.perf_counter() - start_all},
                    nu=nu, friction_bound=F,
                    nu_l2=forms.l2_norm_nu(nu, forms.per_hat_edge(F) > 0))
