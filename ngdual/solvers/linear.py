"""One sparse LU factorisation of the fixed saddle-point matrix, reused for every solve, and
the linear solve of a problem without contact.

The matrix [[A, B], [B^T, 0]] of Algorithms 3.38/3.41 never changes during the
iteration, so it is factorised once (NGSolve's UMFPACK) and every Uzawa step costs one
forward/back solve. UMFPACK runs with ``BLAS_THREADS`` (:mod:`ngdual.tolerances`).
"""

from __future__ import annotations

import functools
import time

import numpy as np
import scipy.sparse as sp
from threadpoolctl import ThreadpoolController

from ..forms import DiscreteProblem
from ..solution import Solution
from ..sparse import to_ngsolve
from ..tolerances import BLAS_THREADS


@functools.cache
def _blas_controller() -> ThreadpoolController:
    """threadpoolctl's view of the process's BLAS libraries, scanned once: a scan costs about
    1.4 ms, and every solve limits the threads twice. cvxopt and scipy.linalg are imported
    first, so that every BLAS a solver can call is loaded when the scan looks."""
    import cvxopt  # noqa: F401  (CHOLMOD's BLAS)
    import scipy.linalg  # noqa: F401
    return ThreadpoolController()


def blas_threads():
    """A context in which every loaded BLAS runs ``BLAS_THREADS`` threads (restored on exit)."""
    return _blas_controller().limit(limits=BLAS_THREADS, user_api="blas")


class Factorization:
    """LU factors of a square sparse matrix (UMFPACK).

    >>> import scipy.sparse as sp
    >>> Factorization(sp.identity(3, format="csr")).solve(np.ones(3))
    array([1., 1., 1.])
    """

    def __init__(self, matrix: sp.spmatrix):
        start = time.perf_counter()
        self.shape = matrix.shape
        self._mat = to_ngsolve(matrix)
        with blas_threads():
            self._inv = self._mat.Inverse(inverse="umfpack")
        self._rhs, self._sol = self._mat.CreateColVector(), self._mat.CreateColVector()
        self.seconds = time.perf_counter() - start

    def solve_many(self, rhs: np.ndarray) -> np.ndarray:
        """Solve for every column of ``rhs`` (n x k) with the stored factors."""
        rhs = np.asarray(rhs, dtype=float)
        if rhs.shape[1] == 0:
            return np.zeros(rhs.shape)
        with blas_threads():
            return np.column_stack([self._umfpack_solve(col) for col in rhs.T])

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solve with the stored factors."""
        with blas_threads():
            return self._umfpack_solve(rhs)

    def _umfpack_solve(self, rhs: np.ndarray) -> np.ndarray:
        self._rhs.FV().NumPy()[:] = rhs
        self._sol.data = self._inv * self._rhs
        return self._sol.FV().NumPy().copy()


def solve_linear(problem: DiscreteProblem) -> Solution:
    """One saddle-point solve: the whole problem when there is no contact boundary."""
    saddle = problem.saddle
    fact = Factorization(problem.block(saddle, saddle))
    start = time.perf_counter()
    x = np.zeros(problem.n)
    x[saddle] = fact.solve(problem.rhs[saddle])
    solve_s = time.perf_counter() - start
    return Solution(problem, x, True, "linear",
                    timings={"assemble": problem.assemble_seconds, "factorize": fact.seconds,
                             "solve": solve_s})
