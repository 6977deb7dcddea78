"""Sparse Cholesky factorisation with chosen unknowns eliminated last, and their Schur complement.

For a symmetric positive definite H and a small index set I (the contact unknowns), a
factorisation P H P^T = L L^T whose permutation puts I last contains the Schur
complement for free: with J the other unknowns,

    S = H_II - H_IJ H_JJ^{-1} H_JI = L_II L_II^T,

so the dense operator of the contact boundary costs no extra solves (compare
:class:`~ngdual.solvers.condensed.CondensedResponse`, which needs one solve per column).
The factorisation is CHOLMOD's supernodal LL^T (through cvxopt) with a user ordering: an
AMD ordering of J (or a METIS nested dissection, pymetis) followed by I. On Example 3.46
AMD is the faster of the two up to level 7 at least: METIS saves ~15% of the fill but its
ordering costs more than that saves. The triangular solves run on the
extracted factor with SuperLU's ``gstrs`` (:func:`_superlu_gstrs`).
"""

from __future__ import annotations

import time

import cvxopt
import cvxopt.amd
import cvxopt.cholmod as cholmod
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..extras import require
from .linear import blas_threads

ORDERINGS = ("amd", "metis")


def fill_reducing_order(H: sp.spmatrix, method: str = "amd") -> np.ndarray:
    """A fill-reducing permutation of the symmetric matrix H (nested dissection or AMD)."""
    if method not in ORDERINGS:
        raise ValueError(f"unknown ordering {method!r}; use one of {ORDERINGS}")
    n = H.shape[0]
    if n == 0:
        return np.zeros(0, dtype=int)
    if method == "metis":
        pymetis = require("pymetis", "metis")
        graph = sp.csr_matrix(H, copy=True)
        graph.setdiag(0)
        graph.eliminate_zeros()
        graph.sort_indices()
        perm, _ = pymetis.nested_dissection(pymetis.CSRAdjacency(graph.indptr, graph.indices))
        return np.asarray(perm, dtype=int)
    H = sp.coo_matrix(H)
    lower = H.row >= H.col
    return _amd(H.row[lower], H.col[lower], n)


def _amd(rows: np.ndarray, cols: np.ndarray, n: int) -> np.ndarray:
    """SuiteSparse's AMD ordering (through cvxopt) of the symmetric n x n pattern whose lower
    triangle has the entries (``rows``, ``cols``)."""
    A = cvxopt.spmatrix(cvxopt.matrix(np.ones(len(rows))), cvxopt.matrix(rows.astype(int)),
                        cvxopt.matrix(cols.astype(int)), (n, n))
    return np.asarray(cvxopt.amd.order(A), dtype=int).ravel()


def _superlu_gstrs(L: sp.csc_matrix):
    """``solve(trans, b)``: L^{-1} b ("N") or L^{-T} b ("T") for the unit lower triangular L
    (CSC, its unit diagonal stored) by SuperLU's ``gstrs``, the kernel of SciPy's
    ``spsolve_triangular`` called without that function's per-call copy of L (its
    ``setdiag``, its transpose): the same arithmetic, bit for bit, in 40-50 % of the time
    (19 and 24 ms against 50 and 48 ms with 114 877 unknowns). None where SciPy's private
    module or the 32-bit indices are not available: ``spsolve_triangular`` then."""
    try:
        from scipy.sparse.linalg._dsolve import _superlu
    except ImportError:
        return None
    n = L.shape[0]
    if L.nnz >= 2**31 or not hasattr(_superlu, "gstrs"):
        return None
    data, indices = L.data, L.indices.astype(np.intc)
    indptr = L.indptr.astype(np.intc)
    empty = (np.zeros(0), np.zeros(0, dtype=np.intc), np.zeros(n + 1, dtype=np.intc))

    def solve(trans: str, b: np.ndarray) -> np.ndarray:
        x, info = _superlu.gstrs(trans, n, L.nnz, data, indices, indptr, n, 0, *empty,
                                 np.array(b, dtype=float))
        if info:
            raise np.linalg.LinAlgError("the Cholesky factor is singular")
        return x

    return solve


class SchurCholesky:
    """P H P^T = L L^T with the unknowns ``last`` eliminated last.

    Attributes
    ----------
    schur : numpy.ndarray
        S = H_II - H_IJ H_JJ^{-1} H_JI (dense, I = ``last`` in the given order).
    nnz : int
        Nonzeros of L (the fill).
    seconds : dict
        ``order``, ``factor`` (CHOLMOD) and ``extract`` (factor to SciPy, S) times.

    >>> H = sp.csr_matrix(np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 2.0]]))
    >>> chol = SchurCholesky(H, np.array([2]), ordering="amd")
    >>> bool(np.isclose(chol.schur[0, 0], 2 - np.array([0, 1]) @ np.linalg.solve(
    ...     H.toarray()[:2, :2], [0, 1])))
    True
    >>> bool(np.allclose(H @ chol.solve(np.ones(3)), 1.0))
    True
    """

    def __init__(self, H: sp.spmatrix, last: np.ndarray, ordering: str = "amd"):
        H = sp.coo_matrix(H)
        n, m = H.shape[0], len(last)
        self.n, self.m = n, m
        times = {}
        start = time.perf_counter()
        keep = np.ones(n, dtype=bool)
        keep[last] = False
        rest = np.flatnonzero(keep)
        # H[rest][:, rest] from H's triplets (two fancy indexings of a CSR matrix cost more)
        number = np.cumsum(keep) - 1
        inside = keep[H.row] & keep[H.col]
        sub = fill_reducing_order(sp.coo_matrix(
            (H.data[inside], (number[H.row[inside]], number[H.col[inside]])),
            shape=(len(rest), len(rest))), ordering)
        self.perm = np.concatenate([rest[sub], np.asarray(last, dtype=int)])
        times["order"] = time.perf_counter() - start

        start = time.perf_counter()
        # H symmetric: its entries on and below the diagonal of P H P^T, the lower triangle
        # CHOLMOD reads
        place = np.empty(n, dtype=np.int64)
        place[self.perm] = np.arange(n)
        rows, cols = place[H.row], place[H.col]
        lower = rows >= cols
        A = cvxopt.spmatrix(cvxopt.matrix(H.data[lower].astype(float)),
                            cvxopt.matrix(rows[lower].astype(int)),
                            cvxopt.matrix(cols[lower].astype(int)), (n, n))
        del rows, cols, lower
        saved = dict(cholmod.options)
        # the ordering is ours (nmethods = 1) and must not be postordered, so that the
        # unknowns I stay last and the factor's trailing block is the Schur complement
        cholmod.options.update({"nmethods": 1, "postorder": False, "supernodal": 2})
        try:
            with blas_threads():
                F = cholmod.symbolic(A, p=cvxopt.matrix(np.arange(n, dtype=np.int32)))
                cholmod.numeric(A, F)
        except ArithmeticError as err:
            raise np.linalg.LinAlgError(f"the matrix is not positive definite (column "
                                        f"{err.args[0]})") from None
        finally:
            cholmod.options.clear()
            cholmod.options.update(saved)
        del A
        times["factor"] = time.perf_counter() - start

        start = time.perf_counter()
        colptr, rowind, values = cholmod.getfactor(F).CCS
        del F
        L = sp.csc_matrix((np.asarray(values).ravel(), np.asarray(rowind).ravel().astype(np.int32),
                           np.asarray(colptr).ravel().astype(np.int64)), shape=(n, n))
        del colptr, rowind, values
        self.nnz = int(L.nnz)
        first = L.indptr[:-1]
        if not np.array_equal(L.indices[first], np.arange(n)):
            raise RuntimeError("CHOLMOD returned a factor without leading diagonal entries")
        self.diag = L.data[first].copy()
        tail = L[n - m:, n - m:].toarray() if m else np.zeros((0, 0))
        self.tail = np.tril(tail)
        self.schur = self.tail @ self.tail.T
        # unit lower triangular factor for SciPy's triangular solves: L = U D
        L.data /= np.repeat(self.diag, np.diff(L.indptr))
        L.indptr = L.indptr.astype(np.int32) if L.nnz < 2**31 else L.indptr
        self._unit = L
        self._gstrs = _superlu_gstrs(L)
        times["extract"] = time.perf_counter() - start
        self.seconds = times

    def forward(self, b: np.ndarray) -> np.ndarray:
        """y = L^{-1} P b."""
        b = np.asarray(b, dtype=float)[self.perm]
        if self._gstrs is not None:
            return self._gstrs("N", b) / self.diag
        y = spla.spsolve_triangular(self._unit, b, lower=True, unit_diagonal=True,
                                    overwrite_A=True)
        return y / self.diag

    def backward(self, y: np.ndarray) -> np.ndarray:
        """x = P^T L^{-T} y."""
        y = np.asarray(y, dtype=float) / self.diag
        if self._gstrs is not None:
            z = self._gstrs("T", y)
        else:
            z = spla.spsolve_triangular(self._unit.T, y, lower=False, unit_diagonal=True,
                                        overwrite_A=True)
        x = np.empty_like(z)
        x[self.perm] = z
        return x

    def solver_on(self, rows: np.ndarray):
        """``solve(y, x_last)``: ``solve_with_last(y, x_last)[rows]`` at the cost of the
        rows' ancestors in the elimination tree, not of the whole back substitution.

        In the back substitution z_j = y_j - sum_k L_kj z_k, L_kj != 0 only for ancestors
        k of j in the elimination tree (parent(j): the first row below the diagonal of
        column j), so the ancestors of ``rows`` form a triangular system of their own
        (Example 3.46, level 6: 9 432 of 114 877 unknowns for the stress on Gamma_C).
        """
        n, m = self.n, self.m
        position = np.empty(n, dtype=np.int64)
        position[self.perm] = np.arange(n)
        L = self._unit
        has_parent = np.diff(L.indptr) > 1
        parent = np.full(n, -1, dtype=np.int64)
        parent[has_parent] = L.indices[L.indptr[:-1][has_parent] + 1]
        seen = np.zeros(n, dtype=bool)
        for j in position[np.asarray(rows, dtype=np.int64)]:
            while j >= 0 and not seen[j]:
                seen[j] = True
                j = parent[j]
        closure = np.flatnonzero(seen)
        sub = L[closure][:, closure].tocsc()
        sub.sort_indices()
        solve_sub = _superlu_gstrs(sub)
        at = np.searchsorted(closure, position[rows])
        last = closure >= n - m
        from_last = closure[last] - (n - m)
        given = position[rows] >= n - m
        diag = self.diag[closure]

        def solve(y: np.ndarray, x_last: np.ndarray) -> np.ndarray:
            part = y[closure] / diag
            part[last] = (self.tail.T @ x_last)[from_last] / diag[last]
            z = solve_sub("T", part) if solve_sub is not None else spla.spsolve_triangular(
                sub.T, part, lower=False, unit_diagonal=True)
            out = z[at]
            out[given] = x_last[position[rows][given] - (n - m)]
            return out

        return solve

    def solve(self, b: np.ndarray) -> np.ndarray:
        """H^{-1} b."""
        return self.backward(self.forward(b))

    def reduced_rhs(self, y: np.ndarray) -> np.ndarray:
        """r_I - H_IJ H_JJ^{-1} r_J from the forward solve y = L^{-1} P r."""
        return self.tail @ y[self.n - self.m:]

    def solve_with_last(self, y: np.ndarray, x_last: np.ndarray) -> np.ndarray:
        """x with x_I = ``x_last`` and the J rows of H x = r satisfied (y = L^{-1} P r)."""
        y = y.copy()
        y[self.n - self.m:] = self.tail.T @ x_last
        x = self.backward(y)
        x[self.perm[self.n - self.m:]] = x_last  # exactly: a contact coefficient at zero stays zero
        return x
