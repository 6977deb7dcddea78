"""The convergence test of a discrete solution of (3.62): its residuals against the scales
of the problem.

A residual is small only relative to something. Measured against its own quantity it
counts round-off as a violation of size one wherever that quantity vanishes: with nothing
in contact the traction moments t_n on Gamma_C are round-off, and max(t_n) / max|t_n| is
then 1. Measured absolutely it grows with the units: with E in pascals a stress is 1e6
times larger than with E in megapascals, and so is the round-off of every force equation.
So every residual of (3.62) is measured here against scales of the problem that never
vanish while the problem has data, and that scale with the units as the residual does:

* the displacement scale D: the largest displacement-like unknown (u, phi, lambda_n = g -
  u_n, lambda_t = -u_t) and the prescribed end values of phi (-u_D at the ends of Gamma_N).
  A body lifted off its foundation has lambda_n = g > 0; a body pressed on it has u. The
  rotation's scale is D / L.
* the stress scale S = max(E* D / L, max |sigma|): the stress a displacement D causes over
  the body's length L (E* = E / (1 - nu^2)), or the stress that is there.
* the size of each equation of (3.62): the terms of its row at the problem's scale,
  |K| x_ref with x_ref = S on the stress unknowns and D on the others, plus the terms at
  the solution, |K| |x|, plus its right-hand side. A stress equation has the units of a
  displacement, a multiplier equation (equilibrium, symmetry, the moments t_i on Gamma_C)
  those of a force; each is compared with its own row size.

A change of units (E, the tractions and a Tresca bound by a factor e, the lengths by c)
scales D, S and every row size as it scales the residual, so the relative residuals and the
verdict do not change (tests/test_scaling.py); a friction bound enters the size of the
friction conditions it bounds, so bounds far from the pressure (1e-6 to 1e6 of it) are
judged like any other.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..forms import DiscreteProblem
from ..friction import FrictionForms, MomentFriction
from ..peers import STRESS
from .coulomb import coulomb_bound

TOLERANCE = 1e-9   # relative residuals of (3.62) accepted as round-off
DISPLACEMENTS = ("u1", "u2", "phi1", "phi2", "lam_n", "lam_t")


def exceeding(found: dict, floors: dict | None = None) -> dict:
    """The residuals of ``found`` above what is accepted as round-off: ``TOLERANCE``, or a
    residual's own floor in ``floors`` where that is larger. A Coulomb bound made of a normal
    stress cannot agree with its map better than that stress's round-off: the thesis' sigma_n
    recovered on the fine edges of a strongly graded, nearly incompressible body
    (Cattaneo-Mindlin at order 0 to tol 1e-3, 946 955 unknowns, 1 364 contact multipliers)
    carries 1.6e-10 of relative noise, its Coulomb fixed point settles at changes of 3e-9
    and the bound's residual at 2.3e-9; the solver's floor for it is the fixed point's own
    (SAFETY times that noise).

    >>> exceeding({"stationarity": 2e-9, "coulomb_bound": 2e-9}, {"coulomb_bound": 1e-8})
    {'stationarity': 2e-09}
    """
    return {k: v for k, v in found.items() if not v <= accepted(k, floors)}


def accepted(name: str, floors: dict | None = None) -> float:
    """The largest value of the residual ``name`` accepted as round-off: ``TOLERANCE``, or its
    floor in ``floors`` where that is larger (:func:`exceeding`)."""
    return max(TOLERANCE, (floors or {}).get(name, 0.0))


def displacement_scale(problem: DiscreteProblem, x: np.ndarray) -> float:
    """D: the largest displacement-like unknown of ``x`` (u, phi, lambda_n, lambda_t) or
    prescribed end value of phi (module docstring)."""
    moved = np.abs(x[problem.index(*DISPLACEMENTS)])
    return max(float(np.max(moved, initial=0.0)),
               float(np.max(np.abs(problem.lift), initial=0.0)))


@dataclass(frozen=True)
class Scales:
    """The scales of one discrete problem at one solution (module docstring).

    Attributes
    ----------
    displacement : float
        D, the largest displacement-like unknown or datum.
    stress : float
        S = max(E* D / L, max |sigma|).
    rows : numpy.ndarray
        The size of every equation of (3.62): |K| x_ref + |K| |x| + |rhs| row by row.
    """

    displacement: float
    stress: float
    rows: np.ndarray

    @staticmethod
    def sizes(problem: DiscreteProblem, x: np.ndarray) -> tuple[float, float]:
        """(D, S) of ``problem`` at ``x``, without the row sizes."""
        D = displacement_scale(problem, x)
        modulus, L = problem.units
        S = max(modulus * D / L, float(np.max(np.abs(x[problem.index(*STRESS)]), initial=0.0)))
        return D, S

    @classmethod
    def of(cls, problem: DiscreteProblem, x: np.ndarray) -> Scales:
        """The scales of ``problem`` at its solution ``x``."""
        D, S = cls.sizes(problem, x)
        modulus, L = problem.units
        sigma = problem.index(*STRESS)
        reference = np.full(problem.n, D)
        reference[sigma] = S
        reference[problem.index("eta")] = D / L   # a rotation: a strain
        # |K| x_ref + |K| |x| in one product: the terms are linear in the magnitudes
        rows = problem.terms(reference + np.abs(x)) + np.abs(problem.rhs)
        return cls(D, S, rows)

    def relative(self, residual: np.ndarray, rows: np.ndarray) -> float:
        """||residual|| / ||size of its rows||: the backward error of a block of equations
        (0 for an empty block or for a problem without data, where x = 0 exactly)."""
        size = float(np.linalg.norm(self.rows[rows]))
        return float(np.linalg.norm(residual)) / size if size > 0 else 0.0

    def per_row(self, values: np.ndarray, rows: np.ndarray, extra: np.ndarray | float = 0.0
                ) -> float:
        """max_i |values_i| / (size of row i + ``extra``_i): the worst violation of a condition
        imposed row by row (the contact and friction conditions on the moments of Gamma_C;
        ``extra`` a friction bound that the condition compares with)."""
        size = self.rows[rows] + extra
        if not len(size):
            return 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(size > 0, np.abs(values) / size, 0.0)
        return float(np.max(ratio, initial=0.0))


def moments(problem: DiscreteProblem, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """t_n, t_t = C^T sigma - r on every coefficient (the lambda rows of K x - rhs)."""
    residual = problem.apply(x) - problem.rhs
    return residual[problem.lam_n], residual[problem.index("lam_t")]


def residuals(problem: DiscreteProblem, x: np.ndarray, law: str, mu_f: float,
              F: np.ndarray | None, edges: EdgeFriction | None = None) -> dict:
    """Relative residuals of (3.103) on ``problem.K`` and, with the bound F on the
    coefficients, of the friction law, each against the scales of the problem
    (:class:`~ngdual.solvers.convergence.Scales`: the displacement scale D and the size of each
    equation, never the residual's own quantity):

    * ``stationarity``, ``equality``: the backward errors of the stress rows and of the
      multiplier rows (equilibrium, symmetry, phi, and lambda_t: their rows carry Q_F^T nu
      = t_t with friction);
    * ``lambda_n_negative`` = max(-lambda_n) / D; ``sigma_n_positive`` = max t_n,i / T_i
      and ``complementarity`` = max |lambda_n,i t_n,i| / (D T_i), T_i the size of the
      moment row i;
    * with F: ``friction_bound`` = max (|t_t,i| - F_i)^+ / (T_i + F_i); ``slip`` = max
      |F_i |lambda_t,i| - lambda_t,i t_t,i| / (D (T_i + F_i)) (stick where |t_t,i| < F_i,
      slip along t_t,i); for Coulomb ``coulomb_bound`` = max |F_i - mu_f (-t_n,i)| /
      (mu_f T_i), zero where that vanishes (a moment at 1e-6 of the largest, as the
      fixed point sets it: :func:`ngdual.tolerances.friction_vanishes`).

    With the thesis' nu on the h^ mesh (``edges``: its friction forms and nu; F given per
    fine edge, Q = Q_F of (3.95)) the friction law reads t_t = Q^T nu, |nu_j| <= 1,
    nu_j q_j = |q_j| (q = Q lambda_t): the lambda_t rows belong to ``equality`` with Q^T nu
    on their right, ``friction_bound`` = max (|nu_j| - 1)^+, ``slip`` the sign residual
    sum_j (|q_j| - nu_j q_j) over the friction work at D
    (:func:`ngdual.solvers.nested.sign_residual`), and ``coulomb_bound`` = max |F_e -
    F(sigma_h)_e| / (mu_f S) over the fine edges, F(sigma_h) the thesis' (3.123).
    """
    if edges is not None:
        return _edge_residuals(problem, x, law, mu_f, F, edges)
    scales = Scales.of(problem, x)
    i_lam, i_lam_t = problem.lam_n, problem.index("lam_t")
    residual = problem.apply(x) - problem.rhs
    t_n, t_t = residual[i_lam], residual[i_lam_t]
    rows = problem.mult
    if F is not None:  # the lambda_t rows carry Q_F^T nu = t_t: no equation of their own
        rows = np.setdiff1d(rows, i_lam_t)
    D = scales.displacement
    lam_n, lam_t = x[i_lam], x[i_lam_t]
    found = {
        "stationarity": scales.relative(residual[problem.sigma], problem.sigma),
        "equality": scales.relative(residual[rows], rows),
        "lambda_n_negative": float(max(0.0, -lam_n.min(initial=0.0))) / (D or 1.0),
        "sigma_n_positive": scales.per_row(np.maximum(t_n, 0.0), i_lam),
        "complementarity": scales.per_row(lam_n * t_n, i_lam) / (D or 1.0),
    }
    if F is not None:
        found["friction_bound"] = scales.per_row(np.maximum(np.abs(t_t) - F, 0.0), i_lam_t, F)
        found["slip"] = scales.per_row(F * np.abs(lam_t) - lam_t * t_t, i_lam_t, F) / (D or 1.0)
    if law == "coulomb":
        # F of the moments on K as the solver defines it: zero where it vanishes (at most
        # 1e-6 of its largest value, tolerances.friction_vanishes), as the F it returns
        mapped = coulomb_bound(MomentFriction(), t_n, mu_f, 0.0)
        found["coulomb_bound"] = scales.per_row(mapped - F, i_lam) / mu_f
    return found


class EdgeFriction(NamedTuple):
    """The thesis' friction law on the h^ mesh: its forms and the multiplier nu."""

    forms: FrictionForms
    nu: np.ndarray


def _edge_residuals(problem: DiscreteProblem, x: np.ndarray, law: str, mu_f: float,
                    F: np.ndarray, edges: EdgeFriction) -> dict:
    """:func:`residuals` with the thesis' friction law on the h^ mesh (its docstring)."""
    from .nested import sign_residual  # nested imports this module's displacement scale

    scales = Scales.of(problem, x)
    D, i_lam = scales.displacement, problem.lam_n
    i_lam_t = problem.index("lam_t")
    Q = edges.forms.q_matrix(F)
    residual = problem.apply(x) - problem.rhs
    t_n = residual[i_lam]
    residual[i_lam_t] -= Q.T @ edges.nu
    lam_n = x[i_lam]
    found = {
        "stationarity": scales.relative(residual[problem.sigma], problem.sigma),
        "equality": scales.relative(residual[problem.mult], problem.mult),
        "lambda_n_negative": float(max(0.0, -lam_n.min(initial=0.0))) / (D or 1.0),
        "sigma_n_positive": scales.per_row(np.maximum(t_n, 0.0), i_lam),
        "complementarity": scales.per_row(lam_n * t_n, i_lam) / (D or 1.0),
        "friction_bound": float(max(0.0, np.max(np.abs(edges.nu), initial=0.0) - 1.0)),
        "slip": sign_residual(Q, edges.nu, x[i_lam_t], D),
    }
    if law == "coulomb":
        mapped = coulomb_bound(edges.forms, edges.forms.T_n @ x, mu_f, 0.0)
        found["coulomb_bound"] = float(np.max(np.abs(mapped - F), initial=0.0)
                                       / (mu_f * scales.stress or 1.0))
    return found
