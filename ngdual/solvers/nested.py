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
same projection as a cvxpy QP is :func:`box_projection_qp`. The friction forms say what
nu is (:class:`~ngdual.friction.FrictionForms`: ``nu_mass``, ``nu_matrix``, ``given_bound``,
``bound_of_normal``): with the facet multipliers of order k the law holds on every
Bernstein coefficient (:class:`~ngdual.friction.MomentFriction`), nu_i and F_i per
coefficient, Q_F = diag(F_i), the metric the lumped mass int B_i ds, and the box
projection clips every coefficient; nu and F are reported per fine edge, as the active-set
method reports them.

Stopping (honest): the iteration stops only when the increments of nu (and,
for Coulomb, of F) and the residual of nu lambda_t = |lambda_t| are below eps2
*and* the inner loop converged; every residual of the discrete variational
inequality (3.62) is reported.

rho_2 is dimensionless: the step applied is rho_2 / lambda_max(H), H the
operator of the nu iteration (:class:`FrictionStep`), computed from the
tangential block of the Gamma_C response, so 0 < rho_2 < 2 converges for any E,
load scale and level. The number of outer steps still grows like 1/h^: the
mass-matrix metric of Remark 3.44 is not H^{-1/2}-equivalent, so the condition
number of H grows like |Gamma_C| / h^. With ``solver.condensed`` (the default for
nested Uzawa) the loops run on the condensed Gamma_C response
(:mod:`ngdual.solvers.condensed`), so that an outer step costs small dense products
instead of sparse solves.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..forms import DiscreteProblem
from ..friction import FrictionForms, build_friction_forms
from ..solution import ConvergenceError, Solution
from ..tolerances import CLARABEL_TOLERANCES, DIVERGENCE_FACTOR, friction_vanishes
from .condensed import CondensedResponse
from .convergence import displacement_scale
from .settings import Model, NestedUzawaSettings
from .uzawa import ContactLoop


def box_projection_qp(c: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """argmin_{|psi_j| <= 1} 1/2 psi^T M psi - c^T psi as a cvxpy QP (Remark 3.44)."""
    import cvxpy as cp  # 0.9 s to import: only when a QP is solved

    psi = cp.Variable(len(c))
    scale = float(mass.max())
    objective = 0.5 * cp.sum(cp.multiply(mass / scale, cp.square(psi))) - (c / scale) @ psi
    cp.Problem(cp.Minimize(objective), [cp.abs(psi) <= 1]).solve(solver=cp.CLARABEL,
                                                               **CLARABEL_TOLERANCES)
    return np.clip(np.asarray(psi.value, dtype=float), -1.0, 1.0)


def box_projection(c: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """The same projection in closed form for the diagonal mass matrix."""
    return np.clip(c / mass, -1.0, 1.0)


def _relative(new: np.ndarray, old: np.ndarray) -> float:
    return float(np.linalg.norm(new - old) / (np.linalg.norm(new) or 1.0))


def sign_residual(Q: sp.spmatrix, nu: np.ndarray, lam_t: np.ndarray,
                  displacement: float = 0.0) -> float:
    """Residual of (3.62)_7, sum_j (|q_j| - nu_j q_j) / j with q = Q_F lambda_t.

    Zero iff nu_j = sign q_j wherever q_j != 0; relative to the friction work j =
    max(int F |lambda_t| ds, int F ds times the problem's ``displacement`` scale D
    (:func:`~ngdual.solvers.convergence.displacement_scale`)), so that stick (q = 0) counts
    as exact and the round-off of a vanishing lambda_t (no load) is not measured against
    itself.
    """
    q = Q @ lam_t
    work = max(float(np.sum(Q @ np.abs(lam_t))), float(np.sum(Q)) * displacement)
    return float(np.sum(np.abs(q) - nu * q) / work) if work > 0 else 0.0


def friction_residuals(forms: FrictionForms, problem: DiscreteProblem, x: np.ndarray,
                       nu: np.ndarray, bound: np.ndarray, traction_scale: float = 0.0) -> dict:
    """Residuals of (3.62)_5,7 and of |sigma_t| <= F on Gamma_C (relative, 0 = exact).

    ``nu_sign``: q(kappa - nu, lambda_t) <= 0 for all kappa in Lambda_h^
    (:func:`sign_residual`).
    ``nu_bound``: |nu_j| <= 1.
    ``tangential``: the equation C_t^T sigma = Q_F^T nu of (3.62)_5.
    ``sigma_t_bound``: |int sigma_t mu_i| <= int F mu_i for every h~ hat mu_i (the
    discrete form of |sigma_t| <= F, Proposition 3.25).
    The tangential residuals are relative to the tractions on Gamma_C,
    max(|C_n^T sigma|, |C_t^T sigma|, int F mu_i, ``traction_scale``), not to the bound
    alone, which may vanish (no contact: F = mu_f |sigma_n| = 0) while the tractions do
    not. (Pointwise on the fine edges |sigma_t| <= F is not part of the discrete problem:
    only the hat moments of sigma_t are constrained, and sigma_t oscillates at the fine
    scale, also where F = 0.)
    """
    Q = forms.nu_matrix(bound)
    sigma, lam_t = x[problem.sigma], x[problem.index("lam_t")]
    tangential = problem.block(problem.sigma, problem.index("lam_t")).T @ sigma
    normal = problem.block(problem.sigma, problem.lam_n).T @ sigma
    hat_bound = Q.T @ np.ones(Q.shape[0])
    scale = max(np.max(np.abs(tangential), initial=0.0), np.max(np.abs(normal), initial=0.0),
                np.max(hat_bound, initial=0.0), traction_scale) or 1.0
    return {
        "nu_sign": sign_residual(Q, nu, lam_t, displacement_scale(problem, x)),
        "nu_bound": float(max(0.0, np.abs(nu).max(initial=0.0) - 1.0)),
        "tangential": float(np.max(np.abs(tangential - Q.T @ nu), initial=0.0) / scale),
        "sigma_t_bound": float(max(0.0, np.max(np.abs(tangential) - hat_bound, initial=0.0))
                               / scale),
    }


STAGNATION_WINDOW = 400  # outer steps without halving the best residual


class FrictionStep:
    """Step 8 / 10': nu <- P^Lambda(nu + s M^{-1} Q_F lambda_t) with a scale-free step s.

    The map nu -> M^{-1} Q_F lambda_t(Q_F^T nu) is linear with the symmetric
    negative semidefinite operator -H, H = M^{-1/2} Q_F S_t Q_F^T M^{-1/2}, where
    S_t = -d lambda_t / d tau is the tangential block of the Gamma_C response
    (the inverse of the (2,2) Schur complement, hence SPD). The step
    s = rho_2 / lambda_max(H) makes rho_2 dimensionless: the gradient-projection
    iteration contracts for 0 < rho_2 < 2 (Theorem 3.42's bound, computed
    instead of estimated), independently of E, the load scale and the level.
    For Coulomb friction H changes with the bound F, so s is recomputed with it.
    """

    def __init__(self, forms: FrictionForms, S_t: np.ndarray, rho2: float, metric: str):
        self.forms, self.S_t, self.rho2, self.metric = forms, S_t, rho2, metric
        self.mass = forms.nu_mass
        self.bound = None

    def set_bound(self, bound: np.ndarray) -> None:
        """Take the friction bound F (:meth:`FrictionForms.nu_matrix`): Q_F, the metric and
        the step."""
        self.bound, self.Q = bound, self.forms.nu_matrix(bound)
        if self.metric == "jacobi":
            diag = np.einsum("ij,jk,ik->i", self.Q.toarray(), self.S_t, self.Q.toarray())
            # the diagonal is quadratic in F: the edges without friction (tolerances
            # module) get the largest weight, so that their nu stays where it is
            no_friction = friction_vanishes(np.sqrt(np.maximum(diag, 0.0)))
            self.mass = np.where(no_friction, max(diag.max(initial=0.0), 1e-300), diag)
        QM = (self.Q.T / np.sqrt(self.mass)).T
        lam_max = (float(np.linalg.eigvalsh(QM @ self.S_t @ QM.T)[-1]) if bound.max() > 0
                   else 0.0)
        self.step = self.rho2 / lam_max if lam_max > 0 else 0.0

    def __call__(self, nu: np.ndarray, lam_t: np.ndarray) -> np.ndarray:
        return box_projection(self.mass * nu + self.step * (self.Q @ lam_t), self.mass)

    def load(self, nu: np.ndarray) -> np.ndarray:
        """tau = Q_F^T nu, the lambda_t-row load of step 3 / 5."""
        return self.Q.T @ nu


def _stagnation_message(model: Model, outer: int, what: str) -> str:
    remedies = ["a smaller solver.rho2"]
    if model.hhat_factor == 1:
        remedies.insert(0, "contact.hhat_factor = 2 (with h^ = h~ the inf-sup condition "
                           "(3.74) for nu fails where the contact zone reaches the end of "
                           "Gamma_C, and nu is not unique)")
    if model.law == "coulomb":
        remedies.append("a smaller friction.mu (the Coulomb fixed point F = mu_f |sigma_n| "
                        "need not contract for large mu)")
    return f"nested Uzawa {what} (outer step {outer}); try " + ", or ".join(remedies)


def nested_uzawa(problem: DiscreteProblem, settings: NestedUzawaSettings,
                 progress: Callable[[int, float], None] | None = None) -> Solution:
    """Solve (3.62) with Tresca (Algorithm 3.41) or Coulomb (Remark 3.45) friction.

    Parameters
    ----------
    settings : NestedUzawaSettings
        The friction law ("tresca": the given bound of the assembled problem;
        "coulomb": mu_f) in ``settings.model``, and: ``rho1``, the dimensionless step of
        the lambda_n update (the metric W carries E*); ``rho2`` in (0, 2), the step of
        the nu update relative to its stability bound (:class:`FrictionStep`); ``eps1``,
        ``eps2``, the tolerances of the inner loop and of the outer increments (nu, F,
        lambda_n); ``max_iter``, the bound on the outer iterations (and on the inner
        ones per outer step); ``loop_order``, "friction-outer" (Algorithm 3.41: nu
        outside, lambda_n inside) or "contact-outer" (Remark 3.43); ``friction_metric``,
        "jacobi" or "mass", the diagonal metric of P^Lambda (:class:`FrictionStep`);
        ``condensed``, iterate on the Gamma_C response from one factorisation
        (:mod:`ngdual.solvers.condensed`) instead of one sparse solve per step (the same
        iterates to round-off).

    Stopping is honest: the iteration ends only when the inner loop converged
    (complementarity of lambda_n to eps1), the relative increments of nu, F
    (Coulomb) and, for ``contact-outer``, lambda_n are <= eps2, and so is the
    residual of nu lambda_t = |lambda_t| (:func:`sign_residual`); the thesis'
    increment-only test (step 9 / 9') can stop while nu is still far from its
    limit. Every residual of (3.62) is reported.

    Raises
    ------
    ConvergenceError
        When the residual becomes NaN, grows by ``DIVERGENCE_FACTOR``, does not halve within
        ``STAGNATION_WINDOW`` outer steps, or is not below eps2 after
        ``max_iter`` outer steps (the message names the remedies).
    """
    s, model = settings, settings.model
    law, mu_f, rho1, eps1, max_iter = model.law, model.mu_f, s.rho1, s.eps1, s.max_iter
    if law not in ("tresca", "coulomb"):
        raise ValueError(f"nested Uzawa solves Tresca or Coulomb friction, not law {law!r}")
    if s.loop_order not in ("friction-outer", "contact-outer"):
        raise ValueError(f"unknown loop_order {s.loop_order!r}")
    start_all = time.perf_counter()
    forms = build_friction_forms(problem)
    normal, normal_rhs = forms.normal_functionals(problem)
    loop = ContactLoop(problem, s.metric, model.plane_strain_modulus, s.condensed,
                       extra_outputs=normal[:, problem.saddle])
    n_c = loop.n_c
    if loop.response is not None:
        S_t = -loop.response.G[n_c:2 * n_c, n_c:]
    else:
        S_t = -CondensedResponse(loop.fact, loop.r0, loop.E_t, loop.E_t.T, gram=False).G
    friction = FrictionStep(forms, 0.5 * (S_t + S_t.T), s.rho2, s.friction_metric)
    start = time.perf_counter()

    lam = np.zeros(n_c)
    nu = np.zeros(len(forms.nu_mass))
    inner_total = 0
    if law == "tresca":
        friction.set_bound(forms.given_bound(problem))
    else:  # F^0 from the frictionless solution (Remark 3.45: F^0(sigma^0))
        state, inner_total, _, _ = loop.run(lam, rho1, eps1, max_iter)
        lam = state.lam
        friction.set_bound(forms.bound_of_normal(state.extra - normal_rhs, mu_f))

    def coulomb_update(state) -> float:                                       # step 8'
        if law != "coulomb":
            return 0.0
        bound = forms.bound_of_normal(state.extra - normal_rhs, mu_f)
        change = _relative(bound, friction.bound)
        friction.set_bound(bound)
        return change

    if s.loop_order == "contact-outer":   # one plain step of Algorithm 3.38 per outer step
        contact_step = loop.plain_step(rho1, "solver.loop_order = \"friction-outer\", whose "
                                             "inner loop takes the step relative to that bound")
    history, converged, best, best_at = [], False, np.inf, 0
    for outer in range(1, max_iter + 1):
        if s.loop_order == "friction-outer":
            state, inner, _, inner_ok = loop.run(lam, rho1, eps1, max_iter,   # steps 3-7
                                                 tau=friction.load(nu))
            lam = state.lam
            change_F = coulomb_update(state)
            sign = sign_residual(friction.Q, nu, state.lam_t)
            nu_new = friction(nu, state.lam_t)                                # step 8 / 10'
            change = max(_relative(nu_new, nu), change_F, sign)
        else:  # Remark 3.43: nu (and F) converge inside for fixed lambda_n
            inner, inner_ok = 0, False
            while inner < max_iter and not inner_ok:
                inner += 1
                state = loop.respond(lam, friction.load(nu))
                change_F = coulomb_update(state)
                sign = sign_residual(friction.Q, nu, state.lam_t)
                nu_new = friction(nu, state.lam_t)
                inner_ok = max(_relative(nu_new, nu), change_F) <= eps1
                nu = nu_new
            lam_new = loop.projection(loop.projection.matvec(lam)
                                      + contact_step * state.traction)
            change = max(_relative(lam_new, lam), change_F, sign)
            lam = lam_new
        inner_total += inner
        nu = nu_new
        history.append(change)
        if progress:
            progress(outer, change)
        if not np.isfinite(change) or change > DIVERGENCE_FACTOR * max(history[0], 1e-300):
            raise ConvergenceError(f"nested Uzawa diverged at outer step {outer} "
                                   f"(rho1 = {rho1}, rho2 = {s.rho2})", history)
        if inner_ok and change <= s.eps2:                                      # step 9 / 9'
            converged = True
            break
        if change < 0.5 * best:
            best, best_at = change, outer
        elif outer - best_at > STAGNATION_WINDOW:
            raise ConvergenceError(_stagnation_message(model, outer, "stagnated: the "
                                   f"residual did not halve in {STAGNATION_WINDOW} outer steps"),
                                   history)
    else:
        raise ConvergenceError(_stagnation_message(
            model, outer, f"did not converge in solver.max_iter = {max_iter} steps"),
            history)
    # one last inner solve so that (sigma, lambda) match the final nu and F exactly
    state, inner, _, inner_ok = loop.run(lam, rho1, eps1, max_iter, tau=friction.load(nu))
    inner_total += inner
    converged = converged and inner_ok
    x = np.zeros(problem.n)
    x[problem.saddle], x[problem.lam_n] = loop.solution(state), state.lam
    bound = friction.bound
    t_t = (problem.apply(x) - problem.rhs)[problem.index("lam_t")]
    nu_reported, bound_reported = forms.reported(nu, bound, t_t)
    return Solution(problem, x, converged, f"nested-uzawa-{law}-{s.metric}-{s.loop_order}",
                    iterations={"outer": outer, "inner": inner_total},
                    residuals={"outer_increment": history[-1], **loop.residuals(state),
                               **friction_residuals(forms, problem, x, nu, bound)},
                    history=history,
                    timings={"assemble": problem.assemble_seconds,
                             "factorize": loop.fact.seconds,
                             "condense": loop.condense_seconds,
                             "solve": time.perf_counter() - start,
                             "total_solver": time.perf_counter() - start_all},
                    nu=nu_reported, friction_bound=bound_reported, friction_forms=forms,
                    nu_l2=forms.l2_norm_nu(nu_reported,
                                           forms.per_hat_edge(bound_reported) > 0))
