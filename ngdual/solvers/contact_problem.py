"""The contact problem condensed onto Gamma_C, t(z) = b - G z, and its solution.

Both active-set solvers condense (3.62) onto the contact multipliers z = (lambda_n,
lambda_t): the hybridised one (:mod:`ngdual.solvers.active_set`) through the Schur
complement of its Cholesky factor, the conforming one (:mod:`ngdual.solvers.conforming`)
through columns of K^{-1}. What remains is the same small dense problem

    t(z) = b - G z,    G symmetric positive definite,

with the contact conditions on lambda_n and t_n and a friction law on lambda_t and t_t:
the semismooth Newton method of :mod:`ngdual.solvers.semismooth` solves it for no friction
or a given (Tresca) bound, and the fixed point of Remark 3.45
(:func:`ngdual.solvers.coulomb.coulomb_fixed_point`) runs around it for Coulomb friction.

The friction law is what the multiplier spaces give (:func:`ngdual.friction.friction_law`):
the thesis' nu on the h^ mesh, Q_F of (3.95) with a bound per fine edge, whose Coulomb
bound needs sigma_n on every fine edge (:class:`EdgeStress`); or a bound on every
coefficient, Q_F = diag(F_i), whose Coulomb bound is made of the normal moments t_n
themselves (:class:`Condensed`), where the Coulomb problem on fixed sets is one linear
solve (:func:`coulomb_on_sets`).
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .coulomb import coulomb_fixed_point
from .semismooth import EPS, SAFETY, BoundarySolution, condition_number, semismooth_newton


@dataclass
class Condensed:
    """The contact problem on the coefficients ``J``: t(z) = b - G z, z = (lambda_n,
    lambda_t) on J, each of length ``n_c`` = |J|. The normal stress of its Coulomb bound
    is the normal moments t_n (``moments``)."""

    G: np.ndarray
    b: np.ndarray
    J: np.ndarray

    moments = True   # the Coulomb bound is made of the moments t_n (on_sets applies)

    @property
    def n_c(self) -> int:
        return len(self.J)

    @functools.cached_property
    def roundoff(self) -> float:
        """eps max(kappa_1(G), dim G): the relative accuracy of the small problem (G is
        fixed once built: its Cholesky-based estimate is computed once, not at each of the
        contact solve's, the fixed point's and the convergence test's reads)."""
        return EPS * max(condition_number(self.G), float(len(self.b)), 1.0)

    @property
    def stress_scale(self) -> float:
        """The size of the normal stress the Coulomb bound is made of, with z = 0."""
        return float(np.max(np.abs(self.b), initial=0.0))

    def traction(self, state: BoundarySolution) -> np.ndarray:
        """t = b - G z for the state's multipliers."""
        return self.b - self.G @ np.concatenate([state.lam_n, state.lam_t])

    def normal_stress(self, state: BoundarySolution) -> np.ndarray:
        """The normal moments t_n on J (what the Coulomb bound is made of)."""
        return self.traction(state)[:self.n_c]

    @property
    def stress_roundoff(self) -> float:
        """The relative round-off of ``normal_stress``: that of t = b - G z."""
        return self.roundoff


class EdgeStress(Condensed):
    """A contact problem whose Coulomb bound is made of sigma_n on the fine Gamma_C edges
    (the thesis' (3.123)): ``stress(z)`` gives it for the multipliers z, ``scale`` its size
    at z = 0 and ``noise`` its relative round-off."""

    moments = False

    def __init__(self, G: np.ndarray, b: np.ndarray, stress, scale: float, noise: float):
        super().__init__(G, b, np.arange(len(b) // 2))
        self._stress, self._scale, self._noise = stress, scale, noise

    @property
    def stress_scale(self) -> float:
        return self._scale

    @property
    def stress_roundoff(self) -> float:
        """The relative round-off of ``normal_stress``: the recovery's ``noise`` or G's."""
        return max(self.roundoff, self._noise)

    def normal_stress(self, state: BoundarySolution) -> np.ndarray:
        return self._stress(np.concatenate([state.lam_n, state.lam_t]))


def start_state(first, J: np.ndarray, friction: bool, n_rows: int) -> BoundarySolution | None:
    """The Newton start on J from a coarser solution's (lambda_n, lambda_t) (None: z = 0);
    ``n_rows`` friction rows (nu) start at zero."""
    if first is None:
        return None
    lam_t = first[1][J] if friction else np.zeros(len(J))
    return BoundarySolution(np.maximum(first[0][J], 0.0), lam_t, np.zeros(n_rows),
                            np.zeros(len(J), dtype=bool), np.zeros(n_rows, dtype=bool), 0,
                            False, {})


def coulomb_on_sets(cond: Condensed, mu_f: float, state: BoundarySolution
                    ) -> np.ndarray | None:
    """The normal moments t_n of the Coulomb problem on the sets of the Tresca solution
    ``state`` (None if that linear system is singular): with t = b - G z and F_i = mu_f
    (-t_n,i) (:class:`~ngdual.friction.MomentFriction`), the conditions on fixed sets are
    linear in z alone,

        lambda_n,i = 0 (contact),           t_n,i = 0 (separation),
        lambda_t,i = 0 (stick),             t_t,i + mu_f s_i t_n,i = 0 (slip with sign s_i,
                                             t_t,i = 0 where F_i = 0),

    the Newton step of the Coulomb law itself (Hueber, Stadler and Wohlmuth) on the sets the
    fixed point of Remark 3.45 has found; :func:`ngdual.solvers.coulomb.coulomb_fixed_point`
    checks it as it checks its own steps."""
    n = cond.n_c
    G, b = cond.G, cond.b
    stick = state.stick
    sign = np.where(stick, 0.0, np.sign(state.nu))
    rows = np.vstack([-G[:n], -G[n:] - mu_f * sign[:, None] * G[:n]])
    rhs = np.concatenate([-b[:n], -b[n:] - mu_f * sign * b[:n]])
    fixed = np.concatenate([state.contact, stick])   # lambda_n = 0, lambda_t = 0 there
    rows[fixed] = np.eye(2 * n)[fixed]
    rhs[fixed] = 0.0
    try:
        with warnings.catch_warnings():   # an ill-conditioned system is no step, not noise
            warnings.simplefilter("error", sla.LinAlgWarning)
            z = sla.solve(rows, rhs, check_finite=False)
    except (sla.LinAlgError, sla.LinAlgWarning, ValueError):
        return None
    return (b - G @ z)[:n] if np.all(np.isfinite(z)) else None


def solve_contact(cond: Condensed, law: str, mu_f: float, bound: np.ndarray | None,
                  friction, first, max_iter: int, tol: float, progress=None):
    """The contact (and friction) problem t(z) = b - G z by the semismooth Newton method,
    the Coulomb fixed point of Remark 3.45 around it: (state, F or None, history,
    iterations).

    ``friction`` is the law's ``q_matrix(F)`` and ``coulomb_bound_of(sigma_n, mu_f)``
    (:mod:`ngdual.friction`); ``bound`` a Tresca bound as that law takes it; ``first`` a
    start's (lambda_n, lambda_t) on every coefficient (None: z = 0); ``tol`` the relative
    change at which the Coulomb fixed point stops.
    """
    floor = SAFETY * cond.roundoff
    if law == "coulomb":
        # a normal stress below the round-off of the stress scale bounds nothing
        noise = SAFETY * cond.stress_roundoff * mu_f * cond.stress_scale
        on_sets = functools.partial(coulomb_on_sets, cond, mu_f) if cond.moments else None
        return coulomb_fixed_point(cond, friction, mu_f, tol, max_iter, progress, noise,
                                   start_state(first, cond.J, True, 0), on_sets)
    Q = friction.q_matrix(bound).toarray() if law == "tresca" else None
    state = semismooth_newton(cond.G, cond.b, cond.n_c, Q,
                              start_state(first, cond.J, Q is not None,
                                          0 if Q is None else Q.shape[0]), tol=floor)
    return state, bound, [], {"outer": 1, "inner": int(state.iterations)}
