"""One sparse LU factorisation of the fixed saddle-point matrix, reused for every solve, and
the linear solve of a problem without contact.

The matrix [[A, B], [B^T, 0]] of Algorithms 3.38/3.41 never changes during the
iteration, so it is factorised once (NGSolve's UMFPACK by default, SciPy's
SuperLU as an alternative) and every Uzawa step costs one forward/back solve.

UMFPACK runs with one BLAS thread: its BLAS calls go to NGSolve's threaded OpenBLAS,
with which the factorisation of Example 3.46, level 6 (247k unknowns) took 64 s of CPU
on 2 cores against 4.4 s with one thread (small dense updates dominated by thread
synchronisation).
"""

from __future__ import annotations

import time

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from threadpoolctl import threadpool_limits

from ..forms import DiscreteProblem
from .result import Solution

BACKENDS = ("umfpack", "superlu")
BLAS_THREADS = 1


class Factorization:
    """LU factors of a square sparse matrix.

    >>> import scipy.sparse as sp
    >>> Factorization(sp.identity(3, format="csr")).solve(np.ones(3))
    array([1., 1., 1.])
    """

    def __init__(self, matrix: sp.spmatrix, backend: str = "umfpack"):
        if backend not in BACKENDS:
            raise ValueError(f"unknown backend {backend!r}; use one of {BACKENDS}")
        start = time.perf_counter()
        self.backend, self.shape = backend, matrix.shape
        if backend == "umfpack":
            coo = matrix.tocoo()
            self._mat = ngs.la.SparseMatrixd.CreateFromCOO(
                coo.row.astype(np.int64).tolist(), coo.col.astype(np.int64).tolist(),
                coo.data.tolist(), matrix.shape[0], matrix.shape[1])
            with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
                self._inv = self._mat.Inverse(inverse="umfpack")
            self._rhs, self._sol = self._mat.CreateColVector(), self._mat.CreateColVector()
        else:
            self._lu = spla.splu(matrix.tocsc())
        self.seconds = time.perf_counter() - start

    def solve_many(self, rhs: np.ndarray) -> np.ndarray:
        """Solve for every column of ``rhs`` (n x k) with the stored factors."""
        rhs = np.asarray(rhs, dtype=float)
        if rhs.shape[1] == 0:
            return np.zeros(rhs.shape)
        if self.backend == "superlu":
            return self._lu.solve(rhs)
        with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
            return np.column_stack([self._umfpack_solve(col) for col in rhs.T])

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solve with the stored factors."""
        if self.backend == "superlu":
            return self._lu.solve(np.asarray(rhs, dtype=float))
        with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
            return self._umfpack_solve(rhs)

    def _umfpack_solve(self, rhs: np.ndarray) -> np.ndarray:
        self._rhs.FV().NumPy()[:] = rhs
        self._sol.data = self._inv * self._rhs
        return self._sol.FV().NumPy().copy()


def solve_linear(problem: DiscreteProblem, backend: str = "umfpack") -> Solution:
    """One saddle-point solve: the whole problem when there is no contact boundary."""
    saddle = problem.saddle
    fact = Factorization(problem.block(saddle, saddle), backend)
    start = time.perf_counter()
    x = np.zeros(problem.K.shape[0])
    x[saddle] = fact.solve(problem.rhs[saddle])
    solve_s = time.perf_counter() - start
    return Solution(problem, x, True, "linear",
                    timings={"assemble": problem.assemble_seconds, "factorize": fact.seconds,
                             "solve": solve_s})
