"""The scales against which a discrete solution of (3.62) is judged converged.

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

Scaling E, the lengths, the loads or the friction bound by a power of ten scales D, S and
every row size as it scales the residual, so the relative residuals and the verdict do not
change (tests/test_scaling.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..forms import DiscreteProblem
from ..peers import STRESS

TOLERANCE = 1e-9   # relative residuals of (3.62) accepted as round-off
DISPLACEMENTS = ("u1", "u2", "phi1", "phi2", "lam_n", "lam_t")


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

    @classmethod
    def of(cls, problem: DiscreteProblem, x: np.ndarray) -> Scales:
        """The scales of ``problem`` at its solution ``x``."""
        moved = np.abs(x[problem.index(*DISPLACEMENTS)])
        D = max(float(np.max(moved, initial=0.0)), float(np.max(np.abs(problem.lift),
                                                                initial=0.0)))
        modulus, L = problem.units
        sigma = problem.index(*STRESS)
        S = max(modulus * D / L, float(np.max(np.abs(x[sigma]), initial=0.0)))
        reference = np.full(problem.n, D)
        reference[sigma] = S
        reference[problem.index("eta")] = D / L   # a rotation: a strain
        rows = problem.terms(reference) + problem.terms(x) + np.abs(problem.rhs)
        return cls(D, S, rows)

    def relative(self, residual: np.ndarray, rows: np.ndarray) -> float:
        """||residual|| / ||size of its rows||: the backward error of a block of equations
        (0 for an empty block or for a problem without data, where x = 0 exactly)."""
        size = float(np.linalg.norm(self.rows[rows]))
        return float(np.linalg.norm(residual)) / size if size > 0 else 0.0

    def per_row(self, values: np.ndarray, rows: np.ndarray) -> float:
        """max_i |values_i| / size of row i: the worst violation of a condition imposed row by
        row (the contact and friction conditions on the moments of Gamma_C)."""
        size = self.rows[rows]
        if not len(size):
            return 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(size > 0, np.abs(values) / size, 0.0)
        return float(np.max(ratio, initial=0.0))
