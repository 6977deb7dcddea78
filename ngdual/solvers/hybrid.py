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

The elimination is NGSolve's static condensation (``BilinearForm(condense=True)``,
:func:`_condensed_form`) on every triangle but those with an edge on Gamma_N or Gamma_C:
it inverts the element blocks and forms C_T^T B_T^{-1} C_T on eta and mu in C++, in its
task manager where a core idles (:func:`ngdual.forms.parallel_tasks`), and its
``inner_solve`` and ``harmonic_extension`` are the element solves. The triangles at Gamma_N
and Gamma_C, whose unknowns the boundary multipliers also couple, are eliminated here from
their blocks of the broken matrix (:class:`_Blocks`: a batched LAPACK inverse and dense
products, :func:`_element_schur`). A triangle is eliminated one way only, so H, r and the
element solves share its arithmetic: the equations of K hold to their round-off (mixing
two inverses of one ill-conditioned block, Cattaneo-Mindlin's nu = 0.4999, left residuals
of 1e-8 in the multipliers' rows). The two ways give the same H to round-off
(tests/test_hybrid_order.py); on hertz-cylinder's last tolerance step (PEERS_1, 1 685
triangles) the condensation took 0.15 s with numpy on every triangle, NGSolve's takes
0.07 s on one thread and 0.04 s on two.

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
from ..forms.integrators import differentiated_integrands, parallel_tasks
from ..forms.peers_block import BrokenPeers, peers_form
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
    local, B_inv, A_LI : numpy.ndarray, scipy.sparse.bsr_matrix, scipy.sparse.csr_matrix
        The triangles at Gamma_N and Gamma_C, eliminated from their blocks: their
        element-local unknowns (one row per triangle), the inverses of their blocks and the
        couplings of those unknowns to x_I (the other triangles are NGSolve's).
    seconds : dict
        ``broken`` (the couplings of the multipliers to the broken rows, the triangles at
        Gamma_N and Gamma_C) and ``condense`` (the elimination of the element-local
        unknowns: NGSolve's condensation, the edge coupling, the blocks, H).
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
        # the element-local unknowns (broken RT_k rows, bubbles, u) are those below eta
        self._n_local = n_local = ranges["eta"].start
        matrix = broken.matrix if broken.matrix.has_sorted_indices else \
            broken.matrix.sorted_indices()
        _check_no_global_block(matrix, n_local)
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
        # the triangles at Gamma_N and Gamma_C, whose unknowns the multipliers couple
        mesh, elements = fes.mesh, broken.coupled
        self.local = _local_dofs(fes, elements, n_local)
        coupled_rows = np.flatnonzero(np.diff(coupled.indptr[:n_local + 1]))
        if not np.isin(coupled_rows, self.local).all():
            raise RuntimeError("a multiplier couples a triangle away from Gamma_N, Gamma_C")
        self.seconds = {"broken": time.perf_counter() - start}

        start = time.perf_counter()
        # the other triangles: NGSolve's static condensation onto eta and mu
        others_only = ngs.BitArray(mesh.ne)
        others_only.Set()
        for nr in elements.tolist():
            others_only.Clear(nr)
        self._form = form = _condensed_form(broken, spaces.order, others_only)
        facet = form.space.components[-1]
        n_mu, n_m = facet.ndof, len(multipliers)
        eta = np.arange(n_local, n_b)
        n_g = len(eta) + 2 * n_mu     # eta, mu_1, mu_2: what NGSolve's condensation keeps
        n_i = n_g + n_m
        # the global unknowns: eta, mu_1, mu_2, the other multipliers, the contact ones
        self.interface = np.concatenate([eta, n_b + np.arange(2 * n_mu + n_m)])
        self._sizes = (n_b, n_p, n_mu, multipliers)
        condensed = _interface_block(form.mat, n_local)
        # the triangles at Gamma_N and Gamma_C: C_T^T B_T^{-1} C_T from their blocks here,
        # so that their element solves are the same arithmetic in H, rhs and unknowns
        self._blocks = _Blocks(matrix, n_local, (ranges["r1"], ranges["r2"]),
                               _edge_coupling(fes.components[peers.PEERS.index("r1")], facet,
                                              spaces.order), coupled)
        self.B_inv, self.A_LI = self._blocks.of(self.local)
        own = _element_schur(self.B_inv, self.A_LI) if len(self.local) else \
            sp.csr_matrix((n_i, n_i))
        A_II = sp.bmat([[sp.csr_matrix((n_g - 2 * n_mu, n_g - 2 * n_mu)), None, coupled[eta]],
                        [None, sp.csr_matrix((2 * n_mu, 2 * n_mu)), None],
                        [coupled[eta].T, None, boundary[multipliers][:, multipliers]]],
                       format="csr")
        # -(the condensed matrix) on eta and mu, with the multipliers' empty rows
        data, indices, indptr = condensed
        others_part = sp.csr_matrix(
            (-data, indices, np.concatenate([indptr, np.full(n_m, indptr[-1])])),
            shape=(n_i, n_i))
        H = others_part + own - A_II
        self.H = (0.5 * (H + H.T)).tocsr()
        self.contact_index = np.arange(n_i - len(contact), n_i)
        self._contact = contact
        self._vectors = (form.mat.CreateColVector(), form.mat.CreateColVector())
        self.seconds["condense"] = time.perf_counter() - start

    @property
    def contact_unknowns(self) -> np.ndarray:
        """The positions of the contact multipliers (``contact_index`` of x_I) in the
        unknown vector of ``problem.K``."""
        return self._contact

    def _load(self, F: np.ndarray) -> np.ndarray:
        """The load f of the broken unknowns, mu and the multipliers (the layout of
        ``interface``) for a right-hand side F of ``problem.K``. A load on a conforming
        function goes to one of its broken copies: where the normal traces are continuous,
        the copies' rows sum to the conforming row."""
        n_b, n_p, n_mu, multipliers = self._sizes
        return np.concatenate([self._Q @ F[:n_p], np.zeros(2 * n_mu), F[multipliers]])

    def _condensation(self, operator, values: np.ndarray) -> np.ndarray:
        """``operator`` of NGSolve's condensed form (inner_solve, harmonic_extension or its
        transpose) applied to ``values`` on the form's unknowns (broken, mu_1, mu_2)."""
        given, result = self._vectors
        given.FV().NumPy()[:] = values
        result.data = operator * given
        return result.FV().NumPy().copy()

    def rhs(self, F: np.ndarray) -> np.ndarray:
        """r = C^T B^{-1} f_L - f_I of H x_I = r for the right-hand side F of ``problem.K``:
        NGSolve's condensation for the triangles away from Gamma_N, Gamma_C, their own
        blocks for the others."""
        n_b, n_p, n_mu, multipliers = self._sizes
        f = self._load(F)
        n_local = self._n_local
        given = np.zeros(n_b + 2 * n_mu)
        given[:n_local] = f[:n_local]
        r = self.A_LI.T @ (self.B_inv @ f[self.local.ravel()]) - f[self.interface]
        r[:n_b - n_local + 2 * n_mu] -= self._condensation(self._form.harmonic_extension_trans,
                                                           given)[n_local:]
        return r

    def unknowns(self, w: np.ndarray, F: np.ndarray) -> np.ndarray:
        """The unknown vector of ``problem.K`` from the global unknowns x_I = ``w`` of the
        right-hand side F: the element-local sigma, bubbles and u recovered triangle by
        triangle (B^{-1} (f_L - C w): NGSolve's element solves, their own blocks at Gamma_N
        and Gamma_C), the broken Raviart-Thomas rows mapped to the conforming ones."""
        n_b, n_p, n_mu, multipliers = self._sizes
        f = self._load(F)
        n_local, n_g = self._n_local, n_b - self._n_local + 2 * n_mu
        given = np.zeros(n_b + 2 * n_mu)
        given[:n_local] = f[:n_local]
        local = self._condensation(self._form.inner_solve, given)
        given[:n_local], given[n_local:] = 0.0, w[:n_g]
        local += self._condensation(self._form.harmonic_extension, given)
        L = self.local.ravel()
        local[L] = self.B_inv @ (f[L] - self.A_LI @ w)
        z = np.zeros(len(self.interface) + n_local)
        z[:n_local] = local[:n_local]
        z[self.interface] = w
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
            raise ValueError("T reads unknowns outside the triangles at Gamma_N, Gamma_C")
        inverse, coupling = self._blocks.of(self.local[triangles])
        positions = np.unique(coupling.indices)
        count = np.bincount(conforming, minlength=n_p)
        mean = sp.csr_matrix((1.0 / count[conforming[local]], (conforming[local],
                                                               np.arange(len(local)))),
                             shape=(n_p, len(local)))
        recover = (T[:, :n_p] @ mean @ inverse).tocsr()
        offset = recover @ self._load(F)[local]
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


def _local_dofs(fes: ngs.FESpace, elements: np.ndarray, n_local: int) -> np.ndarray:
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


def _check_no_global_block(matrix: sp.csr_matrix, n_local: int) -> None:
    """The PEERS form has no term between two global unknowns (a~ + b + s: eta meets tau
    alone), so the condensations need no K_II; refuse a broken matrix that has one."""
    tail = slice(matrix.indptr[n_local], None)
    if np.any(matrix.data[tail][matrix.indices[tail] >= n_local]):
        raise RuntimeError("the broken PEERS matrix couples eta with eta")


class _Blocks:
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
        B_inv = _block_inverse(M_L.data[inside].reshape(-1, size, size))
        K_LI = sp.csr_matrix((M_L.data[~inside], M_L.indices[~inside] - n_local,
                              np.concatenate([[0], np.cumsum(lengths - size)])),
                             shape=(len(L), matrix.shape[0] - n_local))
        rows = []
        for r in self.rt_ranges:   # the broken RT_k rows' coupling to their mu
            own = np.flatnonzero((L >= r.start) & (L < r.stop))
            rows.append(sp.csr_matrix((np.ones(len(own)), (own, L[own] - r.start)),
                                      shape=(len(L), r.stop - r.start)) @ self.mu)
        return B_inv, sp.hstack([K_LI, *rows, self.coupled[L]], format="csr")


def _first_copies(conforming: np.ndarray, n_p: int) -> np.ndarray:
    """For every conforming PEERS unknown the first broken unknown that restricts it."""
    first = np.empty(n_p, dtype=np.int64)
    first[conforming[::-1]] = np.arange(len(conforming))[::-1]
    return first


def _edge_term(mu, tau, order: int, elements: ngs.BitArray | None = None
               ) -> ngs.comp.SumOfIntegrals:
    """sum_T int_{dT} mu (tau . n_T) ds, exact for the P_k multipliers mu and the broken
    RT_k functions tau (a degree 2k integrand on every edge), over the triangles of
    ``elements`` (default all)."""
    n = ngs.specialcf.normal(2)
    rule = {ngs.SEGM: ngs.IntegrationRule(ngs.SEGM, 2 * order)}
    dx = ngs.dx(element_boundary=True, intrules=rule) if elements is None else ngs.dx(
        element_boundary=True, intrules=rule, definedonelements=elements)
    return mu * (tau * n) * dx


def _multiplier_space(mesh: ngs.Mesh, order: int) -> ngs.FESpace:
    """The P_k multipliers mu of the interior edges: ``FacetFESpace(order=k)`` without the
    boundary edges' functions (a boundary edge has one triangle, nothing to glue)."""
    facet = ngs.FacetFESpace(mesh, order=order, dirichlet=".*")
    return ngs.Compress(facet, active_dofs=facet.FreeDofs())


def _condensed_form(broken: BrokenPeers, order: int, elements: ngs.BitArray
                    ) -> ngs.BilinearForm:
    """The hybridised PEERS_k form a~ + b + s + sum_T int_{dT} mu . tau n_T ds on the broken
    space and two rows of multipliers mu (:func:`_multiplier_space`), assembled by NGSolve
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
    facet = _multiplier_space(mesh, order)
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
            form += (_edge_term(trial[mu], test[r], order, elements)
                     + _edge_term(test[mu], trial[r], order, elements))
        with parallel_tasks(mesh):
            form.Assemble()
    return form


def _interface_block(matrix, n_local: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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


def _edge_coupling(broken_rt: ngs.FESpace, facet: ngs.FESpace, order: int) -> sp.csr_matrix:
    """D[i, j] = sum_T int_{dT} mu_j (psi_i . n_T) ds for the broken RT_k functions psi_i and
    the multipliers mu_j of the interior edges (``facet``, :func:`_multiplier_space`)."""
    form = ngs.BilinearForm(trialspace=facet, testspace=broken_rt)
    form += _edge_term(facet.TrialFunction(), broken_rt.TestFunction(), order)
    form.Assemble()
    return to_scipy(form.mat)


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
