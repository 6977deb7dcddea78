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
:func:`ngdual.solvers.condensation.condensed_form`) on every triangle but those with an
edge on Gamma_N or Gamma_C: it inverts the element blocks and forms C_T^T B_T^{-1} C_T on
eta and mu in C++, in its task manager where a core idles
(:func:`ngdual.forms.parallel_tasks`), and its ``inner_solve`` and ``harmonic_extension``
are the element solves. The triangles at Gamma_N and Gamma_C, whose unknowns the boundary
multipliers also couple, are eliminated here from their blocks of the broken matrix
(:class:`ngdual.solvers.condensation.ElementBlocks`: a batched LAPACK inverse and dense
products). A triangle is eliminated one way only, so H, r and the element solves share its
arithmetic: the equations of K hold to their round-off (mixing two inverses of one
ill-conditioned block, Cattaneo-Mindlin's nu = 0.4999, left residuals of 1e-8 in the
multipliers' rows). The two ways give the same H to round-off (tests/test_hybrid_order.py);
on hertz-cylinder's last tolerance step (PEERS_1, 1 685 triangles) the condensation took
0.15 s with numpy on every triangle, NGSolve's takes 0.07 s on one thread and 0.04 s on
two.

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
from .cholesky import SchurCholesky
from .condensation import (
    ElementBlocks,
    check_no_global_block,
    condensed_form,
    edge_coupling,
    element_schur,
    interface_block,
    local_dofs,
)


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
        check_no_global_block(matrix, n_local)
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
        self.local = local_dofs(fes, elements, n_local)
        coupled_rows = np.flatnonzero(np.diff(coupled.indptr[:n_local + 1]))
        if not np.isin(coupled_rows, self.local).all():
            raise RuntimeError("a multiplier couples a triangle away from Gamma_N, Gamma_C")
        self.seconds = {"broken": time.perf_counter() - start}

        start = time.perf_counter()
        at_boundary = ngs.BitArray(mesh.ne)
        at_boundary.Clear()
        for nr in elements.tolist():
            at_boundary.Set(nr)
        # the other triangles: NGSolve's static condensation onto eta and mu
        self._form = form = condensed_form(broken, spaces.order, ~at_boundary)
        facet = form.space.components[-1]
        n_mu, n_m = facet.ndof, len(multipliers)
        eta = np.arange(n_local, n_b)
        # eta, mu_1, mu_2: what NGSolve's condensation keeps
        self._n_g = n_g = len(eta) + 2 * n_mu
        n_i = n_g + n_m
        # the global unknowns: eta, mu_1, mu_2, the other multipliers, the contact ones
        self.interface = np.concatenate([eta, n_b + np.arange(2 * n_mu + n_m)])
        self._sizes = (n_b, n_p, n_mu, multipliers)
        condensed = interface_block(form.mat, n_local)
        # the triangles at Gamma_N and Gamma_C: C_T^T B_T^{-1} C_T from their blocks here,
        # so that their element solves are the same arithmetic in H, rhs and unknowns
        # (their rows of the edge coupling are the only ones read: functional reads no other)
        self._blocks = ElementBlocks(matrix, n_local, (ranges["r1"], ranges["r2"]),
                                     edge_coupling(fes.components[peers.PEERS.index("r1")],
                                                   facet, spaces.order, at_boundary), coupled)
        self.B_inv, self.A_LI = self._blocks.of(self.local)
        own = element_schur(self.B_inv, self.A_LI)
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

    def _local_load(self, f: np.ndarray) -> np.ndarray:
        """The element-local part of the load ``f`` on the condensed form's unknowns
        (broken, mu_1, mu_2), zero elsewhere."""
        given = np.zeros(self._n_local + self._n_g)
        given[:self._n_local] = f[:self._n_local]
        return given

    def rhs(self, F: np.ndarray) -> np.ndarray:
        """r = C^T B^{-1} f_L - f_I of H x_I = r for the right-hand side F of ``problem.K``:
        NGSolve's condensation for the triangles away from Gamma_N, Gamma_C, their own
        blocks for the others."""
        f = self._load(F)
        r = self.A_LI.T @ (self.B_inv @ f[self.local.ravel()]) - f[self.interface]
        r[:self._n_g] -= self._condensation(self._form.harmonic_extension_trans,
                                            self._local_load(f))[self._n_local:]
        return r

    def unknowns(self, w: np.ndarray, F: np.ndarray) -> np.ndarray:
        """The unknown vector of ``problem.K`` from the global unknowns x_I = ``w`` of the
        right-hand side F: the element-local sigma, bubbles and u recovered triangle by
        triangle (B^{-1} (f_L - C w): NGSolve's element solves, their own blocks at Gamma_N
        and Gamma_C), the broken Raviart-Thomas rows mapped to the conforming ones."""
        n_b, n_p, n_mu, multipliers = self._sizes
        f = self._load(F)
        n_local = self._n_local
        local = self._condensation(self._form.inner_solve, self._local_load(f))
        local += self._condensation(self._form.harmonic_extension,
                                    np.concatenate([np.zeros(n_local), w[:self._n_g]]))
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


def _first_copies(conforming: np.ndarray, n_p: int) -> np.ndarray:
    """For every conforming PEERS unknown the first broken unknown that restricts it."""
    first = np.empty(n_p, dtype=np.int64)
    first[conforming[::-1]] = np.arange(len(conforming))[::-1]
    return first
