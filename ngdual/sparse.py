"""Sparse matrices between NGSolve and SciPy: the one conversion each way that ngdual uses."""

from __future__ import annotations

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp


def to_scipy(matrix, copy: bool = True) -> sp.csr_matrix:
    """An assembled NGSolve sparse matrix as a SciPy CSR matrix.

    Made from NGSolve's own CSR arrays (``matrix.CSR()``, rows already sorted by column):
    no COO triplets to sort. The copy outlives the bilinear form that owns ``matrix``;
    ``copy=False`` shares its values and columns instead, valid only while the form lives
    (for a matrix that is about to be combined into a new one).

    >>> import ngsolve as ngs
    >>> from ngdual.mesh import thesis_mesh
    >>> fes = ngs.L2(thesis_mesh(1), order=0)
    >>> u, v = fes.TnT()
    >>> float(to_scipy(ngs.BilinearForm(u * v * ngs.dx).Assemble().mat).diagonal().sum())
    16.0
    """
    values, columns, row_starts = matrix.CSR()
    return sp.csr_matrix((np.array(values, copy=copy), np.array(columns, copy=copy),
                          np.array(row_starts, dtype=np.int64)),
                         shape=(matrix.height, matrix.width))


def to_ngsolve(matrix: sp.spmatrix) -> ngs.la.SparseMatrixd:
    """A SciPy sparse matrix as an NGSolve one (for NGSolve's direct solvers)."""
    coo = matrix.tocoo()
    return ngs.la.SparseMatrixd.CreateFromCOO(
        coo.row.astype(np.int64).tolist(), coo.col.astype(np.int64).tolist(),
        coo.data.tolist(), matrix.shape[0], matrix.shape[1])
