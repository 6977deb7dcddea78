"""The projection P^+ onto C_h^+ (3.98) in a selectable H^{1/2}-equivalent metric.

Remark 3.40: step 4 of Algorithm 3.38 is the convex QP

    lambda_n = argmin_{chi >= 0} 1/2 chi^T W chi - chi^T c,
    c = W lambda_n^{i-1} + rho C_n^T sigma^i,

with W the matrix of the metric on the unknowns of lambda_n. Every multiplier space has its
unknowns in a positive basis -- the thesis' P1 hats, the Bernstein polynomials of the
coarse family of degree k + 1 and of the facet family of degree k -- so that C_h^+ is
chi >= 0 coefficient by coefficient at every order, and W is made of the space's own mass
matrix M and arc-length stiffness L (``mass_stiffness()`` of the classes of
:mod:`ngdual.boundary`; broken, with its jumps penalised, for the discontinuous facet
family). Two metrics are offered:

``h12``
    W = (E*/2) M (M^{-1} L)^{1/2}: the discrete H^{1/2}_{00}(Gamma_C)
    interpolation norm of the multiplier space, scaled like the Steklov-Poincare operator
    of a plane-strain half-plane (normal stress (E*/2)|k| per unit normal displacement of
    wave number k). Spectrally equivalent to the hypersingular operator the thesis
    uses, so the iteration count does not grow with the level. The QP is posed
    by SciPy's NNLS (or as a cvxpy QP, Clarabel, polished on its active set).
``euclidean``
    W = (E*/2) I: a diagonal metric with the closed-form projection
    max(0, c / w), the clip of every coefficient. Cheap per step, but the number of steps
    grows with 1/h.

The factor E* = E/(1 - nu^2) makes rho dimensionless: the same rho works for
E = 2e5 and E = 2e11.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.optimize as spo

from ..boundary import CoarseMesh
from ..tolerances import CLARABEL_TOLERANCES


def metric_matrix(contact: CoarseMesh, modulus: float, kind: str) -> np.ndarray:
    """The metric W on the unknowns of the multiplier space ``contact`` of Gamma_C (dense, or
    a 1-D diagonal)."""
    if kind == "euclidean":
        return np.full(contact.n_coefficients, modulus / 2)
    if kind == "h12":
        mass, stiff = contact.mass_stiffness()
        vals, vecs = sla.eigh(stiff, mass)
        mv = mass @ vecs
        # with a free end the constants (or, between two free ends, also the linears
        # at low frequency) make L singular: the spectrum is floored at (pi / 2 l)^2,
        # the lowest eigenvalue of a chain of length l fixed at one end only, which
        # leaves the metric unchanged where every end is fixed (the thesis' C_h~)
        floor = (np.pi / (2 * contact.edge_lengths().sum())) ** 2
        return modulus / 2 * (mv * np.sqrt(np.maximum(vals, floor))) @ mv.T
    raise ValueError(f"unknown metric {kind!r}")


class NonnegativeProjection:
    """chi = argmin_{chi >= 0} 1/2 chi^T W chi - c^T chi (the W-projection of W^{-1} c).

    Parameters
    ----------
    W : numpy.ndarray
        Symmetric positive definite metric; a 1-D array means a diagonal one,
        solved in closed form.
    solver : {"nnls", "cvxpy"}
        For a dense W: with W = R^T R the QP is the non-negative least-squares
        problem min ||R chi - R^{-T} c|| (SciPy's active-set NNLS, exact), or
        the QP posed in cvxpy and solved by Clarabel, then polished on its
        active set. Both give the same chi (tested).
    """

    def __init__(self, W: np.ndarray, solver: str = "nnls"):
        self.W = np.asarray(W, dtype=float)
        self.diagonal = self.W.ndim == 1
        self.solver = solver
        if self.diagonal:
            return
        self._scale = float(np.max(np.abs(np.diag(self.W))))
        self._root = sla.cholesky(self.W / self._scale, lower=False)
        if solver == "cvxpy":
            import cvxpy as cp  # 0.9 s to import: only when a QP is solved

            n = self.W.shape[0]
            self._chi = cp.Variable(n)
            self._c = cp.Parameter(n)
            objective = 0.5 * cp.sum_squares(self._root @ self._chi) - self._c @ self._chi
            self._problem = cp.Problem(cp.Minimize(objective), [self._chi >= 0])
        elif solver != "nnls":
            raise ValueError(f"unknown projection solver {solver!r}")

    def matvec(self, x: np.ndarray) -> np.ndarray:
        return self.W * x if self.diagonal else self.W @ x

    def __call__(self, c: np.ndarray) -> np.ndarray:
        if self.diagonal:
            return np.maximum(c / self.W, 0.0)
        if self.solver == "nnls":
            rhs = sla.solve_triangular(self._root, c / self._scale, trans="T")
            return spo.nnls(self._root, rhs, maxiter=50 * len(c))[0]
        import cvxpy as cp

        self._c.value = c / self._scale
        self._problem.solve(solver=cp.CLARABEL, **CLARABEL_TOLERANCES)
        chi = np.maximum(np.asarray(self._chi.value, dtype=float), 0.0)
        return self._polish(chi, c)

    def _polish(self, chi: np.ndarray, c: np.ndarray) -> np.ndarray:
        """Re-solve exactly on the active set found by the interior-point solver."""
        tol = 1e-7 * max(float(np.max(chi)), np.finfo(float).tiny)
        free = chi > tol
        exact = np.zeros_like(chi)
        if free.any():
            exact[free] = np.linalg.solve(self.W[np.ix_(free, free)], c[free])
        multiplier = self.W @ exact - c
        scale = np.max(np.abs(c)) + np.finfo(float).tiny
        if exact.min() >= 0 and multiplier[~free].min(initial=0.0) >= -1e-10 * scale:
            return exact
        return chi

    def residual(self, lam: np.ndarray, gradient: np.ndarray) -> float:
        """Natural residual ||lam - P(W lam + gradient)||_W / ||lam||_W of the VI (3.103)."""
        step = lam - self(self.matvec(lam) + gradient)
        norm = np.sqrt(max(lam @ self.matvec(lam), 0.0))
        return float(np.sqrt(max(step @ self.matvec(step), 0.0)) / (norm or 1.0))
