"""The discrete inf-sup constant of the PEERS triple (Lemma 3.28), computed.

On a domain clamped all round (no boundary multipliers) the inf-sup condition (3.69) of
Lemma 3.28 is the one of the PEERS triple (Arnold, Brezzi, Douglas, Lemma 4.4): there is
beta > 0, independent of h, with

    sup_{tau in X_h} (b(v, tau) + s(xi, tau)) / ||tau||_X >= beta ||(v, xi)||_{L^2}

for all (v, xi) in M_h x S_h (b + s the part of B of (3.46) on M_h x S_h, s of (3.32)).
With the Gram matrices X of the norm on X_h and Y of L^2 on M_h x S_h (:func:`gram_matrix`)
and the matrix B of b + s, the supremum is attained at tau = X^{-1} B y, so the best
constant is

    beta_h^2 = min_y (y^T B^T X^{-1} B y) / (y^T Y y),

the smallest eigenvalue of the pencil (B^T X^{-1} B, Y): beta_h is the smallest singular value
of B from the X-norm to the Y-norm (:func:`smallest_singular_values`; Boffi, Brezzi, Fortin,
*Mixed finite element methods and applications*, Ch. 3). Its largest singular value is the
continuity constant of b + s in the same norms (:func:`largest_singular_value`).

The inf-sup constants of the boundary multipliers are a study of their own
(:mod:`ngdual.studies.bench.infsup`, ``ngdual bench infsup``).
"""

from __future__ import annotations

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .. import peers
from ..sparse import to_scipy


def gram_matrix(problem, with_div: bool = True) -> sp.csr_matrix:
    """The block-diagonal Gram matrix of the PEERS unknowns of ``problem``.

        int sigma : tau + div sigma . div tau + u . v + eta xi dx

    on X_h x M_h x S_h: the H(div) inner product on the stress rows (the L^2 one with
    ``with_div=False``), L^2 on u and eta; zero on the boundary multipliers.

    Parameters
    ----------
    problem : ngdual.forms.Problem
        The assembled system (:func:`ngdual.forms.assemble`), for its product space and its
        order of the unknowns.
    with_div : bool
        Whether the norm on X_h holds ||div tau||^2 (the norm ||.||_X of Lemma 3.28).

    Returns
    -------
    scipy.sparse.csr_matrix
        The matrix in the order of ``problem``'s unknowns: ``G[problem.sigma][:, problem.sigma]``
        is X, ``G[problem.mult][:, problem.mult]`` is Y.
    """
    trial = dict(zip(problem.names, problem.fes.TrialFunction()))
    test = dict(zip(problem.names, problem.fes.TestFunction()))
    sigma, div_sigma, u, eta = peers.triple(trial)
    tau, div_tau, v, xi = peers.triple(test)
    integrand = ngs.InnerProduct(sigma, tau)
    if with_div:
        integrand = integrand + div_sigma * div_tau
    form = ngs.BilinearForm(problem.fes)
    form += (integrand + u * v + eta * xi) * ngs.dx
    form.Assemble()
    return to_scipy(form.mat)


def _schur(X: sp.spmatrix, B: sp.spmatrix) -> spla.LinearOperator:
    """B^T X^{-1} B as an operator: X is factorised once and never inverted densely."""
    x_lu = spla.splu(X.tocsc())
    m = B.shape[1]
    return spla.LinearOperator((m, m), matvec=lambda y: B.T @ x_lu.solve(B @ y))


def smallest_singular_values(X: sp.spmatrix, B: sp.spmatrix, Y: sp.spmatrix, k: int = 3,
                             shift: float = -1e-6) -> np.ndarray:
    """The ``k`` smallest singular values of ``B`` from the X-norm to the Y-norm.

    They are the square roots of the smallest eigenvalues of the pencil (B^T X^{-1} B, Y),
    found by shift-invert Lanczos about ``shift``; (B^T X^{-1} B - shift Y)^{-1} r is the
    second block of the solution of the saddle-point system [[X, B], [B^T, shift Y]] with
    right-hand side (0, -r), so that X^{-1} never becomes dense.

    Parameters
    ----------
    X, B, Y : scipy.sparse matrix
        The Gram matrix of X_h, the matrix of b + s (rows X_h, columns M_h x S_h) and the
        Gram matrix of M_h x S_h (:func:`gram_matrix`).
    k : int
        How many singular values.
    shift : float
        The shift of the Lanczos iteration, below zero so that the shifted pencil is
        regular even where B has a kernel.

    Returns
    -------
    numpy.ndarray
        The ``k`` smallest singular values, ascending; the first is beta_h of Lemma 3.28.
    """
    n, m = B.shape
    saddle = spla.splu(sp.bmat([[X, B], [B.T, shift * Y]], format="csc"))
    inverse = spla.LinearOperator((m, m),
                                  matvec=lambda r: saddle.solve(np.r_[np.zeros(n), -r])[n:])
    values = spla.eigsh(_schur(X, B), k=k, M=Y, sigma=shift, OPinv=inverse,
                        return_eigenvectors=False)
    return np.sqrt(np.maximum(np.sort(values), 0.0))


def largest_singular_value(X: sp.spmatrix, B: sp.spmatrix, Y: sp.spmatrix) -> float:
    """The largest singular value of ``B`` from the X-norm to the Y-norm: the continuity
    constant of b + s in these norms, the square root of the largest eigenvalue of the pencil
    (B^T X^{-1} B, Y) (Lanczos)."""
    largest = spla.eigsh(_schur(X, B), k=1, M=Y.tocsc(), which="LA",
                         return_eigenvectors=False).max()
    return float(np.sqrt(largest))


def half_norm(mass: np.ndarray, stiff: np.ndarray) -> np.ndarray:
    """The discrete H^{1/2} norm matrix M V diag((1 + k^2)^{1/2}) V^T M of a boundary space.

    The interpolation norm between L^2 (the mass matrix ``mass``) and H^1 (``mass`` plus the
    arc-length stiffness ``stiff``), from the eigenpairs (k^2, V) of ``stiff`` against
    ``mass``, V normalised in ``mass``.
    """
    vals, vecs = sla.eigh(stiff, mass)
    mv = mass @ vecs
    return (mv * np.sqrt(1.0 + np.maximum(vals, 0.0))) @ mv.T


def dense_singular_values(X: sp.spmatrix, B: np.ndarray, Y: np.ndarray,
                          indices=(0,)) -> list[float]:
    """Singular values of the dense ``B`` from the X-norm to the Y-norm, by position.

    The square roots of the eigenvalues of the pencil (B^T X^{-1} B, Y) at the positions
    ``indices`` (ascending; -1 the largest), with B^T X^{-1} B formed densely column by
    column from one factorisation of X: for the few hundred columns of boundary multipliers,
    where Y (:func:`half_norm`) is dense anyway. Position 0 is the inf-sup constant beta_h,
    position -1 the continuity constant.
    """
    solve = spla.factorized(X.tocsc())
    XinvB = np.column_stack([solve(B[:, j]) for j in range(B.shape[1])])
    S = B.T @ XinvB
    out = []
    for index in indices:
        i = index % B.shape[1]
        value = sla.eigh(0.5 * (S + S.T), Y, eigvals_only=True, subset_by_index=[i, i])[0]
        out.append(float(np.sqrt(max(value, 0.0))))
    return out
