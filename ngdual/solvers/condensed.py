"""The saddle-point system condensed onto Gamma_C: one factorisation, many right-hand sides.

Every Uzawa step of Algorithms 3.38 and 3.41 solves K y = r(z) with the fixed
matrix K = [[A, B], [B^T, 0]] and a right-hand side that depends affinely on
the few unknowns living on Gamma_C, z = (lambda_n, tau): lambda_n enters the
sigma rows as -C_n lambda_n, and the friction load tau = Q_F^T nu enters the
lambda_t rows. The iteration only ever looks at a few linear functionals of y
(C_n^T sigma, lambda_t, sigma_n on the fine Gamma_C edges), so with

    Z = K^{-1} R      (R: the columns through which z enters, m = N_C + N_C of them)
    y = y_0 + Z z,    O y = O y_0 + (O Z) z     (O: the observed functionals)

every step costs a small dense matrix-vector product instead of a sparse
forward/back solve. Z is computed in blocks of columns (and kept only for the Gram data) and
reduced at once to G = O Z and (optionally) to the Gram data Z^T Z and y_0^T Z
that give the norm of y and of its increments exactly (Z^T Z from Z itself when
it fits in ``KEEP_Z_BYTES``, else as R^T K^{-1} Z with m more solves, K being
symmetric), so the Uzawa loops keep the thesis' stopping
rule (relative increment of all unknowns, step 5 of Algorithm 3.38) and their
iterates are those of the uncondensed loops up to rounding.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .linear import Factorization

BLOCK = 64
KEEP_Z_BYTES = 2 * 2**30


class CondensedResponse:
    """The affine map z -> O y(z) of the saddle-point system, y(z) = K^{-1}(r_0 + R z).

    Parameters
    ----------
    fact : Factorization
        Factors of K.
    r0 : numpy.ndarray
        Right-hand side for z = 0.
    inputs : scipy.sparse matrix (n x m)
        R: how z enters the right-hand side.
    outputs : scipy.sparse matrix (k x n)
        O: the functionals of y the iteration needs.

    >>> import scipy.sparse as sp
    >>> K = sp.csr_matrix(np.array([[2.0, 1.0], [1.0, 3.0]]))
    >>> resp = CondensedResponse(Factorization(K), np.array([1.0, 0.0]),
    ...                          sp.csr_matrix(np.array([[0.0], [1.0]])), sp.identity(2))
    >>> np.allclose(resp.observe(np.array([2.0])), np.linalg.solve(K.toarray(), [1.0, 2.0]))
    True
    """

    def __init__(self, fact: Factorization, r0: np.ndarray, inputs: sp.spmatrix,
                 outputs: sp.spmatrix, gram: bool = True):
        self.fact, self.r0 = fact, r0
        self.inputs, self.outputs = sp.csc_matrix(inputs), sp.csr_matrix(outputs)
        m = self.inputs.shape[1]
        self.y0 = fact.solve(r0)
        self.o0 = self.outputs @ self.y0
        self.G = np.zeros((self.outputs.shape[0], m))
        self.gram = np.zeros((m, m)) if gram else None
        self.y0_Z = np.zeros(m)
        self.n_solves = 1
        # Z itself, if it fits, gives the Gram data Z^T Z without the m further solves of
        # R^T K^{-1} Z (the same matrix, K being symmetric)
        keep = gram and len(r0) * m * 8 <= KEEP_Z_BYTES
        Z_all = np.empty((len(r0), m)) if keep else None
        for start in range(0, m, BLOCK):
            blk = slice(start, min(start + BLOCK, m))
            Z = fact.solve_many(self.inputs[:, blk].toarray())
            self.G[:, blk] = self.outputs @ Z
            self.y0_Z[blk] = self.y0 @ Z
            self.n_solves += Z.shape[1]
            if keep:
                Z_all[:, blk] = Z
            elif gram:  # Z^T Z = R^T K^{-1} Z (K symmetric): no need to keep Z
                self.gram[:, blk] = self.inputs.T @ fact.solve_many(Z)
                self.n_solves += Z.shape[1]
        if keep:
            self.gram = Z_all.T @ Z_all
        if gram:
            self.gram = 0.5 * (self.gram + self.gram.T)
        self.y0_y0 = float(self.y0 @ self.y0)

    def observe(self, z: np.ndarray) -> np.ndarray:
        """O y(z)."""
        return self.o0 + self.G @ z

    def norm(self, z: np.ndarray) -> float:
        """||y(z)||_2 without forming y."""
        return float(np.sqrt(max(self.y0_y0 + 2 * self.y0_Z @ z + z @ self.gram @ z, 0.0)))

    def distance(self, z: np.ndarray, w: np.ndarray) -> float:
        """||y(z) - y(w)||_2 = ||Z (z - w)||_2."""
        d = z - w
        return float(np.sqrt(max(d @ self.gram @ d, 0.0)))

    def solution(self, z: np.ndarray) -> np.ndarray:
        """y(z) itself: one forward/back solve."""
        return self.fact.solve(self.r0 + self.inputs @ z)
