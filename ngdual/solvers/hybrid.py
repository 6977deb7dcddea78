"""The hybridised system of (3.62): PEERS_k with its boundary multipliers as a symmetric
positive definite matrix whose last unknowns are the contact multipliers.

One construction for every order k and multiplier family. The saddle-point matrix of
(3.97) is indefinite, which rules out a Cholesky factorisation; breaking the normal
continuity of the Raviart-Thomas rows (Arnold-Brezzi hybridisation, ``problem.broken``,
:func:`ngdual.forms.broken_peers`: every triangle has its own RT_k functions) and enforcing
it again across every interior edge e by a multiplier mu of degree k per edge and row,

    a~(sigma, tau) + b(u, tau) + s(eta, tau) + sum_T int_{dT} mu . tau n_T ds
        + d(lambda, tau) = F(tau),

makes sigma, the bubbles and u element-local. d are the couplings of (3.24) to phi on
Gamma_N and lambda_n, lambda_t on Gamma_C, F the data (u_D on Gamma_D, the gap g on
Gamma_C). A boundary edge has one triangle, so its broken functions are the conforming
ones and d and F are taken from ``problem.K`` and ``problem.rhs`` as they are, whatever the
multipliers' space: the thesis' P1 hats on the h~ mesh (k = 0), the continuous P_{k+1} on
h~ (:mod:`ngdual.boundary.coarse_order`) or the facet P_k on the fine edges
(:mod:`ngdual.boundary.facet`); on Gamma_D nothing is added (the normal trace is free).
With B_T the block of the element-local unknowns (the saddle point of a~ and b on T,
invertible because div maps RT_k onto P_k), C their coupling to the global unknowns
x_I = (eta, mu, phi, lambda) and f their load, the global unknowns solve

    H x_I = r,    H = C^T B^{-1} C - K_II,    r = C^T B^{-1} f - F_I,

H = -(K_II - C^T B^{-1} C) symmetric positive definite: eta, mu, phi and lambda are all
multipliers of sigma, and the sigma block of B_T^{-1} is positive semidefinite with a
kernel on which the inf-sup condition of the multipliers acts. The contact multipliers
(the coefficients of lambda_n, and of lambda_t with friction) are ordered last; the
Cholesky factorisation of H with them last (:class:`~ngdual.solvers.cholesky.SchurCholesky`)
gives the Schur complement G on them for free, and the lambda rows of (3.62) read

    t(z) = b - G z,    t = C_lambda^T sigma - r_lambda,

the contact problem of :mod:`ngdual.solvers.contact_problem`, on the exact discrete problem
(3.62) (:mod:`ngdual.solvers.active_set` solves it). One back substitution, the element
solves and one step of iterative refinement against the residual of ``problem.K``
(:meth:`HybridSystem.solve`) give every unknown.

The thesis hybridises differently (Section 3.5: the fine Gamma_C traces zeta last, their
Schur complement S, G = M^T S M with M the hats' edge means); H here has the multipliers'
coefficients last instead, and is the same discrete problem: on the thesis' configuration
the two give the same solution to round-off (5e-15 to 4e-12 of the unknowns, levels 2-4 of
Example 3.46, Hertz and the punch; docs/theory/order.md).
"""

from __future__ import annotations

import time

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from .. import peers
from ..forms import DiscreteProblem
from ..sparse import to_scipy
from .cholesky import SchurCholesky

SCHUR_CHUNK = 2048  # triangles per batch of _element_schur (PEERS_2: 48 MB of blocks)


class HybridSystem:
    """The hybridised system of (3.62) at order k, H x_I = r.

    Parameters
    ----------
    problem : DiscreteProblem
        Any assembled problem (every order k, either multiplier family).
    friction : bool
        Whether lambda_t is a contact unknown (ordered last with lambda_n) or eliminated
        with the other multipliers (no friction: t_t = 0).

    Attributes
    ----------
    H : scipy.sparse.csr_matrix
        The symmetric positive definite matrix on the global unknowns x_I (eta, mu_1,
        mu_2, the other multipliers, the contact ones); :meth:`rhs` is its right-hand side
        for a right-hand side of ``problem.K``.
    contact_index : numpy.ndarray
        The positions of the contact unknowns in x_I (the last ones): lambda_n, then
        lambda_t with friction, in the order of ``problem.lam_n`` and ``problem.index("lam_t")``.
    seconds : dict
        ``broken`` (the edge coupling and the couplings of the multipliers to the broken
        rows) and ``condense`` (the elimination of the element-local unknowns).
    """

    def __init__(self, problem: DiscreteProblem, friction: bool):
        start = time.perf_counter()
        self.problem = problem
        # the multipliers' rows of K are those of its boundary part (the PEERS block has none)
        spaces, boundary = problem.spaces, problem.boundary
        self.broken = broken = problem.broken
        fes = broken.fes
        ranges = {name: fes.Range(i) for i, name in enumerate(peers.PEERS)}
        n_b, n_p = fes.ndof, len(np.bincount(broken.conforming))
        # the broken matrix with sorted rows, which _element_dofs and the element blocks read
        matrix = broken.matrix if broken.matrix.has_sorted_indices else \
            broken.matrix.sorted_indices()
        self.local = _element_dofs(matrix, ranges["eta"].start)
        mu = _edge_coupling(fes.components[peers.PEERS.index("r1")], spaces.order)
        n_mu = mu.shape[1]
        contact = problem.lam_n if not friction else np.concatenate(
            [problem.lam_n, problem.index("lam_t")])
        others = np.setdiff1d(np.arange(n_p, problem.n), contact)
        multipliers = np.concatenate([others, contact])
        # a boundary edge has one triangle: d acts on its broken functions unchanged
        Q = sp.csr_matrix((np.ones(n_p), (_first_copies(broken.conforming, n_p),
                                          np.arange(n_p))), shape=(n_b, n_p))
        # K is symmetric: its multiplier rows are few, its PEERS rows many
        coupled = (Q @ boundary[multipliers][:, :n_p].T).tocsr()
        self._Q = Q
        self.seconds = {"broken": time.perf_counter() - start}

        start = time.perf_counter()
        eta = np.arange(ranges["eta"].start, n_b)
        L = self.local.ravel()
        n_l, n_m = len(L), len(multipliers)
        # the global unknowns: eta, mu_1, mu_2, the other multipliers, the contact ones
        self.interface = np.concatenate([eta, n_b + np.arange(2 * n_mu + n_m)])
        where = np.empty(n_b, dtype=np.int64)  # the row of every broken unknown of L
        where[L] = np.arange(n_l)
        rows = [sp.csr_matrix((np.ones(r.stop - r.start),
                               (where[r.start:r.stop], np.arange(r.stop - r.start))),
                              shape=(n_l, r.stop - r.start)) @ mu
                for r in (ranges["r1"], ranges["r2"])]
        # the local rows of the broken matrix, triangle by triangle: each row holds its
        # triangle's local unknowns first (in the order of self.local), then its eta
        M_L = matrix[L]
        size = self.local.shape[1]
        lengths = np.diff(M_L.indptr)
        place = np.arange(M_L.nnz) - np.repeat(M_L.indptr[:-1], lengths)
        local = place < size
        if not (np.array_equal(M_L.indices[local], np.repeat(self.local, size, axis=0).ravel())
                and np.all(M_L.indices[~local] >= n_l)):
            raise RuntimeError("the element-local unknowns couple across triangles")
        self.B_inv = _block_inverse(M_L.data[local].reshape(-1, size, size))
        K_LI = sp.csr_matrix((M_L.data[~local], M_L.indices[~local] - n_l,
                              np.concatenate([[0], np.cumsum(lengths - size)])),
                             shape=(n_l, len(eta)))
        K_II = matrix[n_l:][:, n_l:]
        self.A_LI = sp.hstack([K_LI, *rows, coupled[L]], format="csr")
        A_II = sp.bmat([[K_II, None, coupled[eta]],
                        [None, sp.csr_matrix((2 * n_mu, 2 * n_mu)), None],
                        [coupled[eta].T, None, boundary[multipliers][:, multipliers]]],
                       format="csr")
        self.H = (_element_schur(self.B_inv, self.A_LI) - A_II).tocsr()
        self.H = 0.5 * (self.H + self.H.T)
        n_i = len(self.interface)
        self.contact_index = np.arange(n_i - len(contact), n_i)
        self._sizes = (n_b, n_p, n_mu, multipliers)
        self._contact = contact
        self.seconds["condense"] = time.perf_counter() - start

    @property
    def contact_unknowns(self) -> np.ndarray:
        """The positions of the contact multipliers (``contact_index`` of x_I) in the
        unknown vector of ``problem.K``."""
        return self._contact

    def _load(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The loads (f_L, f_I) of the element-local and the global unknowns for a
        right-hand side F of ``problem.K``. A load on a conforming function goes to one of
        its broken copies: where the normal traces are continuous, the copies' rows sum to
        the conforming row."""
        n_b, n_p, n_mu, multipliers = self._sizes
        f = np.concatenate([self._Q @ F[:n_p], np.zeros(2 * n_mu), F[multipliers]])
        return f[self.local.ravel()], f[self.interface]

    def rhs(self, F: np.ndarray) -> np.ndarray:
        """r = C^T B^{-1} f_L - f_I of H x_I = r for the right-hand side F of ``problem.K``."""
        f_L, f_I = self._load(F)
        return self.A_LI.T @ (self.B_inv @ f_L) - f_I

    def unknowns(self, w: np.ndarray, F: np.ndarray) -> np.ndarray:
        """The unknown vector of ``problem.K`` from the global unknowns x_I = ``w`` of the
        right-hand side F: the element-local sigma, bubbles and u recovered triangle by
        triangle, the broken Raviart-Thomas rows mapped to the conforming ones."""
        n_b, n_p, n_mu, multipliers = self._sizes
        f_L, _ = self._load(F)
        z = np.zeros(len(self.interface) + self.local.size)
        z[self.interface] = w
        z[self.local.ravel()] = self.B_inv @ (f_L - self.A_LI @ w)
        x = np.zeros(self.problem.n)
        x[:n_p] = self.broken.to_conforming(z[:n_b])
        x[multipliers] = z[n_b + 2 * n_mu:]
        return x

    def functional(self, T: sp.spmatrix, F: np.ndarray) -> tuple[np.ndarray, object]:
        """(positions, value): the positions in x_I that ``T @ unknowns(w, F)`` reads, and
        the affine function of ``w[positions]`` that gives it, for an operator T on the
        PEERS unknowns of ``problem.K`` (e.g. sigma_n on the fine Gamma_C edges): only the
        triangles holding T's unknowns are recovered."""
        n_b, n_p, n_mu, multipliers = self._sizes
        T = sp.csc_matrix(T)
        if T[:, n_p:].nnz:
            raise ValueError("T must act on the PEERS unknowns only")
        read = np.diff(T.indptr[:n_p + 1]) > 0
        conforming = self.broken.conforming
        copies = read[conforming]          # the broken unknowns that restrict T's unknowns
        triangles = np.flatnonzero(copies[self.local].any(axis=1))
        local = self.local[triangles].ravel()
        if np.count_nonzero(copies) != np.count_nonzero(copies[local]):
            raise ValueError("T reads unknowns that are not element-local")
        size = self.local.shape[1]
        rows = (triangles[:, None] * size + np.arange(size)).ravel()
        coupling = self.A_LI[rows]
        positions = np.unique(coupling.indices)
        inverse = sp.bsr_matrix((self.B_inv.data[triangles], np.arange(len(triangles)),
                                 np.arange(len(triangles) + 1)), shape=(len(rows), len(rows)))
        count = np.bincount(conforming, minlength=n_p)
        mean = sp.csr_matrix((1.0 / count[conforming[local]], (conforming[local],
                                                               np.arange(len(rows)))),
                             shape=(n_p, len(rows)))
        recover = (T[:, :n_p] @ mean @ inverse).tocsr()
        f_L, _ = self._load(F)
        offset = recover @ f_L[rows]
        slope = (recover @ coupling[:, positions]).tocsr()
        return positions, lambda values: offset - slope @ values

    def solve(self, chol: SchurCholesky, y: np.ndarray, F: np.ndarray, z: np.ndarray
              ) -> np.ndarray:
        """The unknowns of ``problem.K`` for the right-hand side F and the contact
        multipliers z (H factorised by ``chol``, y = ``chol.forward(self.rhs(F))``),
        refined once against the residual of ``problem.K``: the broken copies of a
        conforming function agree only to the round-off of the element solves, which the
        rows of (3.62) amplify on graded meshes (Hertz at k = 1, level 2: the relative
        residual of the equality rows 1.2e-9 without the step, 3.8e-13 after)."""
        x = self.unknowns(chol.solve_with_last(y, z), F)
        R = F - self.problem.apply(x)
        R[self._contact] = 0.0  # the contact rows carry the tractions t(z)
        dw = chol.solve_with_last(chol.forward(self.rhs(R)), np.zeros(len(z)))
        return x + self.unknowns(dw, R)


def _element_dofs(matrix: sp.csr_matrix, n_local: int) -> np.ndarray:
    """(triangles, local unknowns): the element-local unknowns (those numbered below
    ``n_local``: the broken sigma rows, the bubbles, u) of every triangle, in increasing
    order, the triangles by their first unknown.

    Read from NGSolve's sparsity pattern of the broken PEERS matrix, which holds every pair
    of unknowns of a triangle (explicit zeros included) and couples the local unknowns of
    different triangles nowhere: the first column of a local unknown's row is the first
    unknown of its triangle (:class:`HybridSystem` checks that no entry couples two).
    """
    if not matrix.has_sorted_indices:
        matrix = matrix.sorted_indices()
    first = matrix.indices[matrix.indptr[:n_local]]
    triangles, label, counts = np.unique(first, return_inverse=True, return_counts=True)
    if np.any(counts != counts[0]) or np.any(triangles >= n_local):
        raise RuntimeError("the triangles do not have the same number of local unknowns")
    return np.argsort(label, kind="stable").reshape(len(triangles), -1)


def _first_copies(conforming: np.ndarray, n_p: int) -> np.ndarray:
    """For every conforming PEERS unknown the first broken unknown that restricts it."""
    first = np.empty(n_p, dtype=np.int64)
    first[conforming[::-1]] = np.arange(len(conforming))[::-1]
    return first


def _edge_coupling(broken_rt: ngs.FESpace, order: int) -> sp.csr_matrix:
    """D[i, j] = sum_T int_{dT} mu_j (psi_i . n_T) ds for the broken RT_k functions psi_i and
    the P_k multipliers mu_j of the interior edges (``FacetFESpace(order=k)``)."""
    mesh = broken_rt.mesh
    facet = ngs.Compress(ngs.FacetFESpace(mesh, order=order))
    n = ngs.specialcf.normal(2)
    form = ngs.BilinearForm(trialspace=facet, testspace=broken_rt)
    form += facet.TrialFunction() * (broken_rt.TestFunction() * n) * ngs.dx(
        element_boundary=True, intrules={ngs.SEGM: ngs.IntegrationRule(ngs.SEGM, 2 * order)})
    form.Assemble()
    boundary = np.array(facet.GetDofs(mesh.Boundaries(".*")), dtype=bool)
    return to_scipy(form.mat).tocsc()[:, np.flatnonzero(~boundary)].tocsr()


def _block_inverse(blocks: np.ndarray) -> sp.bsr_matrix:
    """The block-diagonal matrix of the inverses of ``blocks`` (triangles, size, size),
    inverted in one batched LAPACK call."""
    n, size, _ = blocks.shape
    return sp.bsr_matrix((np.linalg.inv(blocks), np.arange(n), np.arange(n + 1)),
                         shape=(n * size, n * size))


def _element_schur(B_inv: sp.bsr_matrix, A_LI: sp.csr_matrix,
                   chunk: int = SCHUR_CHUNK) -> sp.csr_matrix:
    """C^T B^{-1} C for the block-diagonal B^{-1} (one block per triangle) and the coupling
    C = ``A_LI`` of the element-local unknowns (rows, triangle by triangle) to the global
    ones: the sum over the triangles of C_T^T B_T^{-1} C_T, each C_T the dense block of the
    few global unknowns its triangle couples to. Computed ``chunk`` triangles at a time by
    batched dense products (one matrix per triangle), which costs about half the two
    sparse products B^{-1} C and C^T (B^{-1} C) (PEERS_2, 512 triangles, 25 065 unknowns:
    0.023 s against 0.045 s); the sum of the element contributions is the same matrix up to
    round-off."""
    size = B_inv.blocksize[0]
    n_tri, n_glob = B_inv.shape[0] // size, A_LI.shape[1]
    A_LI = A_LI.tocsr()
    A_LI.sum_duplicates()
    # the global unknowns of every triangle: the union of its rows' columns, sorted
    owner = sp.csr_matrix((np.ones(A_LI.shape[0]), (np.arange(A_LI.shape[0]) // size,
                                                    np.arange(A_LI.shape[0]))),
                          shape=(n_tri, A_LI.shape[0]))
    # (ones, not |A_LI|: a product drops the sums that vanish, and NGSolve's pattern holds
    # explicit zeros)
    ones = sp.csr_matrix((np.ones(A_LI.nnz), A_LI.indices, A_LI.indptr), shape=A_LI.shape)
    pattern = (owner @ ones).tocsr()
    pattern.sort_indices()
    counts = np.diff(pattern.indptr)
    width = int(counts.max(initial=0))
    slot = np.arange(pattern.nnz) - np.repeat(pattern.indptr[:-1], counts)
    columns = np.full((n_tri, width), -1, dtype=np.int64)
    columns[np.repeat(np.arange(n_tri), counts), slot] = pattern.indices
    # the slot of every entry of A_LI in its triangle's list (the lists are sorted, and so
    # are their keys triangle * n_glob + column over all triangles)
    rows = np.repeat(np.arange(A_LI.shape[0]), np.diff(A_LI.indptr))
    keys = np.repeat(np.arange(n_tri), counts) * n_glob + pattern.indices
    where = np.searchsorted(keys, rows // size * n_glob + A_LI.indices)
    entry_slot = slot[where]
    inverse = B_inv.data
    parts = []
    for first in range(0, n_tri, chunk):
        last = min(first + chunk, n_tri)
        lo, hi = A_LI.indptr[first * size], A_LI.indptr[last * size]
        C = np.zeros((last - first, size, width))
        C[rows[lo:hi] // size - first, rows[lo:hi] % size, entry_slot[lo:hi]] = A_LI.data[lo:hi]
        S = np.matmul(C.transpose(0, 2, 1), np.matmul(inverse[first:last], C))
        cols = columns[first:last]
        valid = (cols[:, :, None] >= 0) & (cols[:, None, :] >= 0)
        parts.append((S[valid], np.broadcast_to(cols[:, :, None], S.shape)[valid],
                      np.broadcast_to(cols[:, None, :], S.shape)[valid]))
    data, i, j = (np.concatenate(p) for p in zip(*parts))
    return sp.csr_matrix((data, (i, j)), shape=(n_glob, n_glob))
