"""The hybridised system at order k: PEERS_k with its boundary multipliers as a symmetric
positive definite matrix whose last unknowns are the contact multipliers.

:mod:`ngdual.solvers.hybrid` hybridises the thesis' method (k = 0, multipliers on the coarse
h~ mesh). At every order k with the facet multipliers (:mod:`ngdual.boundary.facet`) the
same construction holds and is simpler, because the boundary multipliers already live where
the hybridisation puts its own: on the fine edges, P_k per edge, the space of the normal
traces of RT_k. It takes the boundary couplings from K as they are, so the coarse
multipliers of order k >= 1 (:mod:`ngdual.boundary.coarse_order`) are solved by it too.

The Raviart-Thomas rows of sigma are broken (``problem.broken``,
:func:`ngdual.forms.broken_peers`: every triangle has its own RT_k functions), and the
continuity of their normal traces across every interior edge e is enforced again by a
multiplier mu of degree k per edge and row,

    a~(sigma, tau) + b(u, tau) + s(eta, tau) + sum_T int_{dT} mu . tau n_T ds
        + d(lambda, tau) = F(tau),

d the couplings of (3.24) to phi on Gamma_N and lambda_n, lambda_t on Gamma_C, F the data
(u_D on Gamma_D, the gap g on Gamma_C). A boundary edge has one triangle, so its broken
functions are the conforming ones and d and F are taken from ``problem.K`` and
``problem.rhs`` as they are; on Gamma_D nothing is added (the normal trace is free).
sigma (the broken RT_k rows), the bubbles and u (discontinuous P_k) are element-local. With
B_T their block (the saddle point of a~ and b on T, invertible because div maps RT_k onto
P_k), C their coupling to the global unknowns x_I = (eta, mu, phi, lambda) and f their load,
the global unknowns solve

    H x_I = r,    H = C^T B^{-1} C - K_II,    r = C^T B^{-1} f - F_I,

H = -(K_II - C^T B^{-1} C) symmetric positive definite: eta, mu, phi and lambda are all
multipliers of sigma, and the sigma block of B_T^{-1} is positive semidefinite with a
kernel on which the inf-sup condition of the multipliers acts. The contact multipliers
(the Bernstein coefficients of lambda_n, and of lambda_t with friction) are ordered last;
the Cholesky factorisation of H with them last (:class:`~ngdual.solvers.cholesky.SchurCholesky`)
gives the Schur complement G on them for free, and the lambda rows of (3.62) read

    t(z) = b - G z,    t = C_lambda^T sigma - r_lambda,

the moments of :mod:`ngdual.solvers.conforming` on every coefficient: the contact and
friction problem of the semismooth Newton method, on the exact discrete problem (3.62).
One back substitution, the element solves and one step of iterative refinement against
the residual of ``problem.K`` (:meth:`OrderHybridSystem.solve`) give every unknown. G and b
carry the round-off of the Cholesky factors, which a nearly incompressible body amplifies
(Cattaneo-Mindlin, nu = 0.4999, k = 1, level 2: the slip residual of the friction law on K
2.0e-9, its tolerance 1e-9): where the residuals on K are not round-off, b takes the
difference between the moments on K and t(z), and the contact problem is solved again
(at most ``CONTACT_REFINEMENTS`` times; once there). The solution is checked on K by
:func:`~ngdual.solvers.conforming.checked_solution`, as the conforming solver's is.

Where K is singular (a body held by Gamma_C alone floats when nothing touches) H is too,
and :func:`~ngdual.solvers.conforming.conforming_active_set` solves the problem instead.
Measured against it (docs/theory/order.md): the same solution to 2e-11, 3-43 times faster.
"""

from __future__ import annotations

import time

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .. import peers
from ..forms import DiscreteProblem
from ..friction import MomentFriction, tresca_moments
from ..solution import Solution
from ..sparse import to_scipy
from ..tolerances import COULOMB_FIXED_POINT_TOL
from .cholesky import SchurCholesky
from .conforming import Condensed, checked_solution, conforming_active_set, solve_condensed
from .convergence import TOLERANCE, moments, residuals
from .linear import blas_threads
from .settings import ActiveSetSettings
from .start import ContactStart

CONTACT_REFINEMENTS = 2  # corrections of b by the moments on K (hybrid_active_set)
SCHUR_CHUNK = 2048  # triangles per batch of _element_schur (PEERS_2: 48 MB of blocks)


class OrderHybridSystem:
    """The hybridised system of (3.62) at order k, H x_I = r.

    Parameters
    ----------
    problem : DiscreteProblem
        An assembled problem of order k >= 1, or of order 0 with the facet multipliers.
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
    unknown of its triangle (:class:`OrderHybridSystem` checks that no entry couples two).
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


def hybrid_active_set(problem: DiscreteProblem, settings: ActiveSetSettings,
                      start: ContactStart | None = None, tol: float = COULOMB_FIXED_POINT_TOL,
                      ordering: str = "amd") -> Solution:
    """Solve (3.62) at order k on the hybridised system: one
    Cholesky factorisation, semismooth Newton on the Schur complement of the contact
    multipliers, one back substitution (module docstring).

    The same discrete solution as :func:`~ngdual.solvers.conforming.conforming_active_set`,
    checked the same way: the residuals of (3.62) and of the friction law on ``problem.K``.

    Parameters
    ----------
    problem, settings, start, tol
        As for :func:`~ngdual.solvers.conforming.conforming_active_set`: the problem with
        the facet multipliers, the model and the bound on the Coulomb fixed-point steps, a
        coarser solution to start the Newton method from, the fixed point's tolerance.
    ordering : {"amd", "metis"}
        Fill-reducing ordering of H.

    Raises
    ------
    ConvergenceError
        If the contact problem is not solved, the Coulomb fixed point does not converge, or
        the residuals of (3.62) exceed :data:`ngdual.solvers.convergence.TOLERANCE`.
    """
    model = settings.model
    law = model.law
    begin = time.perf_counter()
    first = start.at(problem.spaces.contact.node_points()) if start is not None else None
    hybrid = OrderHybridSystem(problem, friction=law != "none")
    try:
        chol = SchurCholesky(hybrid.H, hybrid.contact_index, ordering)
    except ArithmeticError:
        # H is singular where K is (a body held by Gamma_C alone has rigid motions when
        # nothing touches): the conforming solver eliminates every multiplier instead
        return conforming_active_set(problem, settings, start, tol)
    after_factor = time.perf_counter()
    y = chol.forward(hybrid.rhs(problem.rhs))
    substitute = time.perf_counter() - after_factor
    n_c = len(problem.lam_n)
    G, b = chol.schur, chol.reduced_rhs(y)
    if law == "none":  # lambda_t eliminated, t_t = 0: the identity block of semismooth_newton
        G, b = sla.block_diag(G, np.eye(n_c)), np.concatenate([b, np.zeros(n_c)])
    contact_start = time.perf_counter()
    bound = tresca_moments(problem) if law == "tresca" else None
    friction = MomentFriction()
    cond = Condensed(0.5 * (G + G.T), b, np.arange(n_c))
    first_contact = first
    with blas_threads():
        for refinement in range(CONTACT_REFINEMENTS + 1):
            state, F, history, iterations = solve_condensed(
                cond, law, model.mu_f, bound, friction, first_contact, settings.max_iter, tol)
            back = time.perf_counter()
            z = state.lam_n if law == "none" else np.concatenate([state.lam_n, state.lam_t])
            x = hybrid.solve(chol, y, problem.rhs, z)
            found = residuals(problem, x, law, model.mu_f, F)
            if refinement == CONTACT_REFINEMENTS or max(found.values()) <= TOLERANCE:
                break
            # the moments on K are exact for these multipliers, those of the Schur
            # complement carry the round-off of the Cholesky factors: b takes the difference
            on_K = np.concatenate(moments(problem, x))[:len(z)]
            cond.b[:len(z)] += on_K - cond.traction(state)[:len(z)]
            first_contact = (state.lam_n, state.lam_t)
    end = time.perf_counter()
    # the keys of ngdual.solvers.active_set: "factorize" prepares, "solve" follows it
    seconds = {"assemble": problem.assemble_seconds, "hybrid_assemble": hybrid.seconds["broken"],
               "hybridize": hybrid.seconds["broken"] + hybrid.seconds["condense"],
               "cholesky": sum(chol.seconds.values()), "contact": back - contact_start,
               "substitute": substitute + end - back, "solve": end - after_factor,
               "total_solver": end - begin}
    seconds["factorize"] = seconds["hybridize"] + seconds["cholesky"]
    return checked_solution(problem, x, law, model.mu_f, F, "active-set-hybrid",
                            {**iterations, "condensed": n_c, "contact_refinements": refinement},
                            history, seconds, found)
