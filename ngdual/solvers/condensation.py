"""The two eliminations of the element-local unknowns that
:class:`~ngdual.solvers.hybrid.HybridSystem` combines, triangle by triangle: NGSolve's static
condensation of the broken PEERS_k form with its edge multipliers mu (:func:`condensed_form`,
:func:`interface_block`), and the batched element blocks read from the broken matrix
(:class:`ElementBlocks`, :func:`element_schur`) for the triangles the boundary multipliers
couple. Each gives C_T^T B_T^{-1} C_T on the global unknowns; they agree to round-off
(tests/test_hybrid_order.py)."""

from __future__ import annotations

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from .. import peers
from ..forms.integrators import differentiated_integrands, parallel_tasks
from ..forms.peers_block import BrokenPeers, peers_form
from ..sparse import to_scipy

SCHUR_CHUNK = 2048  # triangles per batch of element_schur (PEERS_2: 48 MB of blocks)


def local_dofs(fes: ngs.FESpace, elements: np.ndarray, n_local: int) -> np.ndarray:
    """(triangles, local unknowns): the element-local unknowns of ``fes`` (those below
    ``n_local``) of every triangle of ``elements``, in increasing order (no rows, as many
    columns as the mesh's first triangle has, without ``elements``: a scene without
    Gamma_N and Gamma_C)."""
    def own(nr: int) -> list[int]:
        return sorted(d for d in fes.GetDofNrs(ngs.ElementId(ngs.VOL, nr)) if 0 <= d < n_local)

    rows = [own(nr) for nr in elements.tolist()]
    size = len(rows[0]) if rows else len(own(0))
    if any(len(r) != size for r in rows):
        raise RuntimeError("the triangles do not have the same number of local unknowns")
    return np.array(rows, dtype=np.int64).reshape(len(rows), size)


def check_no_global_block(matrix: sp.csr_matrix, n_local: int) -> None:
    """The PEERS form has no term between two global unknowns (a~ + b + s: eta meets tau
    alone), so the condensations need no K_II; refuse a broken matrix that has one."""
    tail = slice(matrix.indptr[n_local], None)
    if np.any(matrix.data[tail][matrix.indices[tail] >= n_local]):
        raise RuntimeError("the broken PEERS matrix couples eta with eta")


class ElementBlocks:
    """The element blocks of chosen triangles, read from the broken matrix's rows (each
    holds its triangle's local unknowns first, in increasing order, then its eta): the
    inverses B_T^{-1} and the couplings C_T to the global unknowns (eta, mu, the
    multipliers)."""

    def __init__(self, matrix: sp.csr_matrix, n_local: int, rt_ranges: tuple,
                 mu: sp.csr_matrix, coupled: sp.csr_matrix):
        self.matrix, self.n_local, self.rt_ranges = matrix, n_local, rt_ranges
        self.mu, self.coupled = mu, coupled

    def of(self, local: np.ndarray) -> tuple[sp.bsr_matrix, sp.csr_matrix]:
        """(B^{-1}, C) of the triangles whose local unknowns are the rows of ``local``."""
        matrix, n_local = self.matrix, self.n_local
        L = local.ravel()
        size = local.shape[1]
        M_L = matrix[L]
        lengths = np.diff(M_L.indptr)
        place = np.arange(M_L.nnz) - np.repeat(M_L.indptr[:-1], lengths)
        inside = place < size
        if not (np.array_equal(M_L.indices[inside], np.repeat(local, size, axis=0).ravel())
                and np.all(M_L.indices[~inside] >= n_local)):
            raise RuntimeError("the element-local unknowns couple across triangles")
        B_inv = block_inverse(M_L.data[inside].reshape(-1, size, size))
        K_LI = sp.csr_matrix((M_L.data[~inside], M_L.indices[~inside] - n_local,
                              np.concatenate([[0], np.cumsum(lengths - size)])),
                             shape=(len(L), matrix.shape[0] - n_local))
        rows = []
        for r in self.rt_ranges:   # the broken RT_k rows' coupling to their mu
            own = np.flatnonzero((L >= r.start) & (L < r.stop))
            rows.append(sp.csr_matrix((np.ones(len(own)), (own, L[own] - r.start)),
                                      shape=(len(L), r.stop - r.start)) @ self.mu)
        return B_inv, sp.hstack([K_LI, *rows, self.coupled[L]], format="csr")


def edge_term(mu, tau, order: int, elements: ngs.BitArray | None = None
               ) -> ngs.comp.SumOfIntegrals:
    """sum_T int_{dT} mu (tau . n_T) ds, exact for the P_k multipliers mu and the broken
    RT_k functions tau (a degree 2k integrand on every edge), over the triangles of
    ``elements`` (default all)."""
    n = ngs.specialcf.normal(2)
    rule = {ngs.SEGM: ngs.IntegrationRule(ngs.SEGM, 2 * order)}
    dx = ngs.dx(element_boundary=True, intrules=rule) if elements is None else ngs.dx(
        element_boundary=True, intrules=rule, definedonelements=elements)
    return mu * (tau * n) * dx


def multiplier_space(mesh: ngs.Mesh, order: int) -> ngs.FESpace:
    """The P_k multipliers mu of the interior edges: ``FacetFESpace(order=k)`` without the
    boundary edges' functions (a boundary edge has one triangle, nothing to glue)."""
    facet = ngs.FacetFESpace(mesh, order=order, dirichlet=".*")
    return ngs.Compress(facet, active_dofs=facet.FreeDofs())


def condensed_form(broken: BrokenPeers, order: int, elements: ngs.BitArray
                    ) -> ngs.BilinearForm:
    """The hybridised PEERS_k form a~ + b + s + sum_T int_{dT} mu . tau n_T ds on the broken
    space and two rows of multipliers mu (:func:`multiplier_space`), assembled by NGSolve
    with static condensation (``condense=True``): every triangle's block of element-local
    unknowns (the broken RT_k rows, the bubbles, u) is inverted and eliminated in C++,
    ``form.mat`` is the Schur complement on eta and mu, and ``inner_solve``,
    ``harmonic_extension`` and its transpose give the element solves. Only the triangles
    of ``elements`` are integrated: the others' local unknowns stay out of every block.

    The interior dofs of eta (its H1 order k + 1 has them from k = 2 on) are NGSolve's
    LOCAL_DOF; they are made INTERFACE_DOF here, global as they are in the broken matrix,
    whose element-local unknowns are those numbered below eta.
    """
    mesh = broken.fes.mesh
    facet = multiplier_space(mesh, order)
    fes = ngs.FESpace(list(broken.fes.components) + [facet, facet])
    eta = fes.Range(peers.PEERS.index("eta"))
    inner = np.flatnonzero(~np.array(fes.components[peers.PEERS.index("eta")]
                                     .FreeDofs(coupling=True), dtype=bool))
    for dof in (eta.start + inner).tolist():
        fes.SetCouplingType(dof, ngs.COUPLING_TYPE.INTERFACE_DOF)
    names = list(peers.PEERS) + ["mu1", "mu2"]
    trial, test = (dict(zip(names, f)) for f in (fes.TrialFunction(), fes.TestFunction()))
    form = ngs.BilinearForm(fes, condense=True)
    with differentiated_integrands():
        form += peers_form({n: trial[n] for n in peers.PEERS},
                           {n: test[n] for n in peers.PEERS}, broken.lame, order,
                           elements=elements)
        for mu, r in (("mu1", "r1"), ("mu2", "r2")):
            form += (edge_term(trial[mu], test[r], order, elements)
                     + edge_term(test[mu], trial[r], order, elements))
        with parallel_tasks(mesh):
            form.Assemble()
    return form


def interface_block(matrix, n_local: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(data, columns, row starts) of the block of NGSolve's condensed ``matrix`` on the
    unknowns from ``n_local`` on (eta, mu), read from its CSR arrays without a copy of the
    whole: the condensation leaves the rows of the element-local unknowns empty and the
    other rows without their columns."""
    values, columns, starts = (np.asarray(a) for a in matrix.CSR())
    first = int(starts[n_local])
    indices = columns[first:].astype(np.int64) - n_local
    if first or (len(indices) and indices.min() < 0):
        raise RuntimeError("NGSolve's condensed matrix couples the element-local unknowns")
    return values[first:].copy(), indices, starts[n_local:].astype(np.int64) - first


def edge_coupling(broken_rt: ngs.FESpace, facet: ngs.FESpace, order: int,
                  elements: ngs.BitArray | None = None) -> sp.csr_matrix:
    """D[i, j] = sum_T int_{dT} mu_j (psi_i . n_T) ds for the broken RT_k functions psi_i and
    the multipliers mu_j of the interior edges (``facet``, :func:`multiplier_space`); only
    the rows of the triangles of ``elements`` (default all) are filled."""
    form = ngs.BilinearForm(trialspace=facet, testspace=broken_rt)
    form += edge_term(facet.TrialFunction(), broken_rt.TestFunction(), order, elements)
    form.Assemble()
    return to_scipy(form.mat)


def block_inverse(blocks: np.ndarray) -> sp.bsr_matrix:
    """The block-diagonal matrix of the inverses of ``blocks`` (triangles, size, size),
    inverted in one batched LAPACK call."""
    n, size, _ = blocks.shape
    return sp.bsr_matrix((np.linalg.inv(blocks), np.arange(n), np.arange(n + 1)),
                         shape=(n * size, n * size))


def element_schur(B_inv: sp.bsr_matrix, A_LI: sp.csr_matrix,
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
    if n_tri == 0:
        return sp.csr_matrix((n_glob, n_glob))
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
