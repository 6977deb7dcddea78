"""Hybridisation of the PEERS system: the same discrete solution from a symmetric positive
definite matrix, with the contact tractions as its last unknowns.

The saddle-point matrix [[A, B], [B^T, 0]] of (3.97) is indefinite, which rules out a
Cholesky factorisation. Breaking the normal continuity of the Raviart-Thomas rows
(Arnold-Brezzi hybridisation) and enforcing it again by a multiplier mu per edge and row,

    a~(sigma, tau) + b(u, tau) + s(eta, tau) + sum_T int_{dT} mu . tau n_T ds = ...,

makes sigma, the bubbles and u element-local. They are eliminated triangle by triangle
from the element matrices the problem assembled (:class:`ngdual.forms.BrokenPeers`); what
remains couples only the edge multipliers mu and the rotation eta,
and its negative is symmetric positive definite (the negated Schur complement of an
invertible saddle point whose multipliers satisfy the inf-sup condition).

mu is minus the displacement trace. On the boundary it is what the formulation already
prescribes: mu = -mean_e(u_D) on Gamma_D (the right-hand side of (3.62)), the edge means of
the coarse P1 phi on Gamma_N (d_N of (3.24)), and on every fine Gamma_C edge e

    mu_e = n_e zeta_n,e + t_e zeta_t,e,   zeta_n = M lambda_n - mean_e(g),  zeta_t = M lambda_t,

(plus the known end values of lambda where Gamma_C meets Gamma_D, :class:`ContactEdges`)

with M the edge means of the coarse h~ hats (the RT_0 normal trace is constant on e, so
int_e lambda tau.n ds = |e| mean_e(lambda) (tau.n)_e: d_{C,n}, d_{C,t} and g(tau) of (3.24)
are reproduced exactly). The fine contact values zeta are left free in the matrix H and
ordered last; a Cholesky factorisation with them last yields the Schur complement
S = H_zz - H_zJ H_JJ^{-1} H_Jz (the Steklov-Poincare operator of Gamma_C) at no extra
cost: the edge moments of the traction, t_e = (int_e sigma_n, int_e sigma_t), are the
affine function t(zeta) = t_hat - S zeta of zeta (:class:`ContactSchur`).
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from .. import peers
from ..forms import DiscreteProblem, boundary_regex
from ..geometry import tangent
from ..sparse import to_scipy
from .settings import Model


@dataclass
class ContactEdges:
    """The fine edges of Gamma_C, chain by chain (the order of :mod:`ngdual.friction`).

    ``edges`` are their facet dofs; ``hat_means`` (n_edges x N_C) is M: the mean of
    every coarse h~ hat on every fine edge; ``normals`` the outward unit normals,
    ``lengths`` |e|. ``gap`` and ``offset_t`` are the known parts of the fine contact
    values, zeta_n = M lambda_n - gap and zeta_t = M lambda_t - offset_t: ``gap`` is
    mean_e(g) minus the edge mean of the prescribed end values of lambda_n (where
    Gamma_C meets Gamma_D), ``offset_t`` minus that of lambda_t.
    """

    edges: np.ndarray
    lengths: np.ndarray
    normals: np.ndarray
    hat_means: sp.csr_matrix
    gap: np.ndarray
    offset_t: np.ndarray

    @property
    def tangents(self) -> np.ndarray:
        """t = (n_2, -n_1), the tangent of (3.24)."""
        return tangent(self.normals)

    def __len__(self) -> int:
        return len(self.edges)


def _boundary_edges(mesh: ngs.Mesh, facet: ngs.FESpace, hdiv: ngs.FESpace
                    ) -> dict[str, np.ndarray]:
    """Rows (facet dof, RT_0 dof, vertex a, vertex b) of every boundary segment, by label.

    Read from two forms on every labelled part of the boundary, int_e mu (psi . n) ds and
    int_e mu v ds (mu the edge multipliers, psi the RT_0 functions, v the P1 hats): on a
    segment e only its own mu and psi and the hats of its two vertices do not vanish. Dof
    numbers, not edge numbers: netgen keeps the edges of coarser levels after
    ``mesh.Refine()``, and the facet space numbers only the edges in use.
    """
    hats = ngs.H1(mesh, order=1)
    n = ngs.specialcf.normal(2)
    out = {}
    for label in dict.fromkeys(mesh.GetBoundaries()):
        ds = ngs.ds(definedon=mesh.Boundaries(re.escape(label)))
        flux = ngs.BilinearForm(trialspace=facet, testspace=hdiv)
        flux += facet.TrialFunction() * (hdiv.TestFunction().Trace() * n) * ds
        ends = ngs.BilinearForm(trialspace=facet, testspace=hats)
        ends += facet.TrialFunction() * hats.TestFunction() * ds
        rt, edges = _nonzeros(flux.Assemble().mat)
        vertices, edges_v = _nonzeros(ends.Assemble().mat)
        if not len(edges):
            continue
        order = np.argsort(edges_v, kind="stable")
        pairs = vertices[order].reshape(-1, 2)
        if not (np.array_equal(edges_v[order][::2], edges)
                and np.array_equal(edges_v[order][1::2], edges)):
            raise RuntimeError(f"the boundary segments of {label!r} are not edges with "
                               "one RT_0 function and two vertices")
        out[label] = np.column_stack([edges, rt, pairs])
    return out


def _nonzeros(matrix) -> tuple[np.ndarray, np.ndarray]:
    """(row, column) of the entries of an assembled NGSolve matrix that do not vanish (up
    to rounding), sorted by column."""
    A = to_scipy(matrix, copy=False).tocsc()
    rows = A.indices
    cols = np.repeat(np.arange(A.shape[1]), np.diff(A.indptr))
    keep = np.abs(A.data) > 1e-12 * np.abs(A.data).max(initial=0.0)
    return rows[keep].astype(int), cols[keep]


def _normal_fluxes(hdiv: ngs.FESpace, mesh: ngs.Mesh, labels: list[str]) -> np.ndarray:
    """int_e psi_e.n ds and int_e n_i psi_e.n ds (i = 1, 2) per RT_0 dof of the edges ``labels``.

    The normal trace of an RT_0 basis function is constant on its edge, so the data moments
    of :mod:`ngdual.forms` are (flux) x (edge mean of the data), and the edge means follow
    from the assembled right-hand side exactly, whatever quadrature produced it.
    """
    v = hdiv.TestFunction()
    n = ngs.specialcf.normal(2)
    ds = ngs.ds(definedon=mesh.Boundaries(boundary_regex(labels)))
    out = []
    for f in (ngs.CF(1.0), n[0], n[1]):
        form = ngs.LinearForm(hdiv)
        form += f * (v.Trace() * n) * ds
        form.Assemble()
        out.append(form.vec.FV().NumPy().copy())
    return np.array(out)


class HybridSystem:
    """The hybridised, statically condensed system of (3.62), reduced to H w = r.

    Unknowns w: mu on the interior edges (two rows), eta, the coarse phi, and last the
    fine contact values zeta = (zeta_n, zeta_t) (``contact_index``). H is symmetric
    positive definite; with zeta prescribed, the other rows of H w = r are exactly
    the rows of (3.62) for sigma, u, eta, phi, and t(zeta) = r_z - (H w)_z are the
    traction moments (int_e sigma_n, int_e sigma_t) on the fine Gamma_C edges.

    The element matrices of a~ + b + s are those the problem assembled once
    (:class:`ngdual.forms.BrokenPeers`); only the coupling sum_T int_{dT} mu . tau n_T ds is
    assembled here. The element-local unknowns (the broken sigma rows, the bubbles, u) are
    eliminated triangle by triangle: with B_T their block, C_T their coupling to the
    interface unknowns (eta, mu) of T and f_T their load,

        S = K_II - sum_T C_T^T B_T^{-1} C_T,    g = - sum_T C_T^T B_T^{-1} f_T,

    and they are recovered from the interface values x_I as B_T^{-1} (f_T - C_T x_I).

    Parameters
    ----------
    problem : DiscreteProblem
        The assembled problem (its mesh, spaces, prolongations, phi right-hand side and
        element matrices).
    model : Model
        Lamé's constants and the labels of Gamma_D, Gamma_N, Gamma_C.
    """

    @staticmethod
    def takes(spaces) -> bool:
        """Whether this hybridisation solves a problem on ``spaces``: PEERS_0 with boundary
        multipliers that pair with the chords' normals (the thesis' P1 hats on h~, whose
        edge means reproduce d_C exactly against the constant RT_0 traces). Every other
        space is hybridised by :class:`~ngdual.solvers.hybrid_order.OrderHybridSystem`."""
        meshes = [m for m in (spaces.neumann, spaces.contact) if m is not None]
        return spaces.order == 0 and not any(m.curve_normal for m in meshes)

    def __init__(self, problem: DiscreteProblem, model: Model):
        start = time.perf_counter()
        self.problem = problem
        mesh = problem.fes.mesh
        self.mesh = mesh
        broken = problem.broken
        facet = ngs.FacetFESpace(mesh, order=0)
        eta = broken.fes.Range(peers.PEERS.index("eta"))
        self.n_eta = eta.stop - eta.start
        self.n_interface = self.n_eta + 2 * facet.ndof
        broken_rt = broken.fes.components[peers.PEERS.index("r1")]
        blocks = self._elements(broken, _edge_coupling(broken_rt, facet), facet.ndof)
        self.assemble_seconds = time.perf_counter() - start

        start = time.perf_counter()
        S, g = self._condense(*blocks, broken.matrix[eta.start:eta.stop][:, eta.start:eta.stop])
        self._reduction(model, facet, S, g)
        self.reduce_seconds = time.perf_counter() - start

    def _elements(self, broken, coupling: sp.csr_matrix, n_facets: int
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """B_T, C_T and f_T of every triangle (stacked); its local unknowns (``local``) and
        its interface unknowns (``interface``: eta, then mu_1, mu_2 after them).

        Read from NGSolve's sparsity pattern: a row of an element-local unknown holds
        exactly the unknowns of its triangle, sorted, the local ones (the broken sigma rows,
        the bubbles, u) before eta.
        """
        pb, fes = self.problem, broken.fes
        K = broken.matrix
        ranges = [fes.Range(i) for i in range(len(peers.PEERS))]
        eta = ranges[peers.PEERS.index("eta")]
        u1 = ranges[peers.PEERS.index("u1")]
        width = int(K.indptr[u1.start + 1] - K.indptr[u1.start])
        # one row of u1 (P0) per triangle: its columns are the triangle's unknowns
        dofs = K.indices[K.indptr[u1.start:u1.stop, None] + np.arange(width)]
        n_local = int(np.count_nonzero(dofs[0] < eta.start))
        local = dofs[:, :n_local]
        if not (np.all(np.diff(K.indptr)[:eta.start] == width)
                and np.all(dofs[:, n_local:] >= eta.start) and np.all(local < eta.start)):
            raise RuntimeError("the PEERS matrix does not have one block per triangle")
        at = K.indptr[local][..., None] + np.arange(width)
        if not np.array_equal(K.indices[at], np.broadcast_to(dofs[:, None, :], at.shape)):
            raise RuntimeError("the PEERS matrix does not have one block per triangle")
        values = K.data[at]
        del at
        rt_rows = []
        for name in ("r1", "r2"):
            rg = ranges[peers.PEERS.index(name)]
            inside = (dofs[0, :n_local] >= rg.start) & (dofs[0, :n_local] < rg.stop)
            rt_rows.append((np.flatnonzero(inside), local[:, inside] - rg.start))
        positions, rt = rt_rows[0]
        n_edges = len(positions)
        at = coupling.indptr[rt][..., None] + np.arange(n_edges)
        if not np.all(np.diff(coupling.indptr) == n_edges):
            raise RuntimeError("the edge coupling does not have one block per triangle")
        facets = coupling.indices[at[:, 0, :]]
        flux = coupling.data[at]
        n_vertices = width - n_local
        self.interface = np.concatenate([dofs[:, n_local:] - eta.start,
                                         self.n_eta + facets,
                                         self.n_eta + n_facets + facets], axis=1)
        C = np.zeros((len(local), n_local, n_vertices + 2 * n_edges))
        C[:, :, :n_vertices] = values[:, :, n_local:]
        for k, (pos, _) in enumerate(rt_rows):
            C[:, pos[:, None], n_vertices + k * n_edges + np.arange(n_edges)] = flux
        load = np.zeros(fes.ndof)
        for name in ("u1", "u2"):
            rg = ranges[peers.PEERS.index(name)]
            load[rg.start:rg.stop] = pb.rhs[pb.blocks[name]]
        self.local, self._ranges = local, ranges
        return values[:, :, :n_local], C, load[local]

    def _condense(self, B: np.ndarray, C: np.ndarray, f: np.ndarray, K_eta: sp.csr_matrix
                  ) -> tuple[sp.csr_matrix, np.ndarray]:
        """S and g on the interface unknowns (eta, mu_1, mu_2), K_eta their block K_II;
        keeps B_T^{-1} C_T and B_T^{-1} f_T for :meth:`unknowns`."""
        solved = np.linalg.solve(B, np.concatenate([C, f[..., None]], axis=2))
        self._extension, self._inner = solved[..., :-1], solved[..., -1]
        schur = -np.einsum("eki,ekj->eij", C, self._extension)
        iface, n = self.interface, self.n_interface
        g = -np.bincount(iface.ravel(), np.einsum("eki,ek->ei", C, self._inner).ravel(),
                         minlength=n)
        width = iface.shape[1]
        S = sp.csr_matrix((schur.ravel(), (np.repeat(iface, width, axis=1).ravel(),
                                           np.tile(iface, (1, width)).ravel())), shape=(n, n))
        K_eta = K_eta.tocoo()
        if np.any(K_eta.data):  # a~ + b + s has no eta-eta term; kept for any volume form
            S = S + sp.csr_matrix((K_eta.data, (K_eta.row, K_eta.col)), shape=(n, n))
        return S, g

    def _reduction(self, model: Model, facet: ngs.FESpace, S: sp.csr_matrix,
                   r_cond: np.ndarray) -> None:
        """Build c = T w + c0 (interface values from the reduced unknowns), H and r."""
        pb, mesh = self.problem, self.mesh
        m1, m2 = self.n_eta, self.n_eta + facet.ndof
        hdiv = pb.spaces.components["r1"]
        labelled = _boundary_edges(mesh, facet, hdiv)
        fluxes = _normal_fluxes(hdiv, mesh, model.labels("dirichlet") + model.labels("contact"))
        F1 = pb.rhs[pb.blocks["r1"]]
        F2 = pb.rhs[pb.blocks["r2"]]

        def edges_of(role):
            rows = [labelled[lab] for lab in model.labels(role) if lab in labelled]
            return np.vstack(rows) if rows else np.zeros((0, 4), dtype=int)

        dirichlet, neumann = edges_of("dirichlet"), edges_of("neumann")
        on_boundary = np.zeros(facet.ndof, dtype=bool)
        on_boundary[np.concatenate([e[:, 0] for e in labelled.values()])] = True
        interior = np.flatnonzero(~on_boundary)
        self.contact = self._contact_edges(model, labelled, fluxes, F1, F2)
        n_int, n_v = len(interior), self.n_eta
        n_phi = pb.spaces.coarse_ndof("phi1") if "phi1" in pb.blocks else 0
        n_c = len(self.contact)
        blocks = np.cumsum([0, n_int, n_int, n_v, n_phi, n_phi, n_c, n_c])
        self.n_w = int(blocks[-1])
        self.contact_index = np.arange(blocks[5], blocks[7])
        self.phi_index = np.arange(blocks[3], blocks[5])
        rows, cols, vals = [], [], []

        def put(r, c, v):
            rows.append(np.asarray(r)), cols.append(np.asarray(c))
            vals.append(np.broadcast_to(np.asarray(v, dtype=float), np.shape(r)))

        k = np.arange(n_int)
        put(m1 + interior, blocks[0] + k, 1.0)
        put(m2 + interior, blocks[1] + k, 1.0)
        put(np.arange(n_v), blocks[2] + np.arange(n_v), 1.0)
        c0 = np.zeros(self.n_interface)
        if len(dirichlet):  # F = int_e u_D . tau n ds (3.62): minus the mean of u_D
            rt = dirichlet[:, 1]
            c0[m1 + dirichlet[:, 0]] = -F1[rt] / fluxes[0][rt]
            c0[m2 + dirichlet[:, 0]] = -F2[rt] / fluxes[0][rt]
        if pb.spaces.neumann is not None:  # mu_e = the edge mean of the coarse P1 phi
            coarse = pb.spaces.neumann
            facet_of = {frozenset(int(v) for v in row[2:]): row[0] for row in neumann}
            facets = np.array([facet_of[frozenset((int(a), int(b)))]
                               for a, b in coarse.fine_edges()[0]])
            dof = coarse.fine_edge_dofs(pb.spaces.components["phi1"])
            P = pb.spaces.prolongations["phi1"].tocsr()
            mean = (0.5 * (P[dof[:, 0]] + P[dof[:, 1]])).tocoo()
            for comp, start in ((0, m1), (1, m2)):
                put(start + facets[mean.row], blocks[3 + comp] + mean.col, mean.data)
                lift_range = pb.fes.Range(pb.names.index(("phi1", "phi2")[comp]))
                lift = pb.lift[lift_range.start:lift_range.stop]
                c0[start + facets] = 0.5 * (lift[dof[:, 0]] + lift[dof[:, 1]])
        ce = self.contact
        j = np.arange(n_c)
        for comp, start in ((0, m1), (1, m2)):
            put(start + ce.edges, blocks[5] + j, ce.normals[:, comp])
            put(start + ce.edges, blocks[6] + j, ce.tangents[:, comp])
        T = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(self.n_interface, self.n_w))
        self.T, self.c0 = T, c0
        self.H = (-(T.T @ (S @ T))).tocsr()
        self.H.sum_duplicates()
        r = -(T.T @ (r_cond - S @ c0))
        if n_phi:
            r[self.phi_index] -= pb.rhs[pb.index("phi1", "phi2")]
        self.r = r

    def _contact_edges(self, model: Model, labelled: dict, fluxes: np.ndarray, F1: np.ndarray,
                       F2: np.ndarray) -> ContactEdges:
        """Fine Gamma_C edges; mean_e(g) from F = int_e g n.tau n ds, the right-hand side of g."""
        pb = self.problem
        contact = pb.spaces.contact
        if contact is None:
            return ContactEdges(np.zeros(0, dtype=int), np.zeros(0), np.zeros((0, 2)),
                                sp.csr_matrix((0, 0)), np.zeros(0), np.zeros(0))
        edge_of = {}
        for lab in model.labels("contact"):
            for row in labelled.get(lab, []):
                edge_of[frozenset(int(v) for v in row[2:])] = row[:2]
        gamma_c = pb.spaces.gamma_c
        edges = np.array([edge_of[frozenset((int(a), int(b)))] for a, b in gamma_c.vertices]
                         ).reshape(-1, 2)
        rt = edges[:, 1]
        flux = fluxes[0][rt]
        # NGSolve's normal of the assembled forms, read from the RT_0 fluxes, rather than
        # gamma_c.normals from the vertex coordinates: the two agree to round-off, and these
        # are the normals with which F's moments below were integrated
        normals = np.column_stack([fluxes[1][rt], fluxes[2][rt]]) / flux[:, None]
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        # the sigma rows of F hold int_e (g - lift_n) tau_n - int_e lift_t tau_t on e
        gap = (normals[:, 0] * F1[rt] + normals[:, 1] * F2[rt]) / flux
        offset_t = (normals[:, 1] * F1[rt] - normals[:, 0] * F2[rt]) / flux
        return ContactEdges(edges[:, 0], gamma_c.lengths, normals,
                            gamma_c.hat_means(pb.spaces.prolongations["lam_n"]), gap, offset_t)

    def unknowns(self, w: np.ndarray, lam_t: np.ndarray | None = None,
                 lam_n: np.ndarray | None = None) -> np.ndarray:
        """The unknown vector of ``problem.K`` from w (and the contact multipliers).

        Recovers the element-local sigma, bubbles and u triangle by triangle and maps the
        broken Raviart-Thomas rows to the continuous ones.
        """
        pb = self.problem
        interface = self.T @ w + self.c0
        values = np.zeros(pb.broken.fes.ndof)
        values[self.local] = self._inner - np.einsum("eij,ej->ei", self._extension,
                                                     interface[self.interface])
        eta = self._ranges[peers.PEERS.index("eta")]
        values[eta.start:eta.stop] = interface[:self.n_eta]
        x = np.zeros(pb.n)
        peers_part = pb.broken.to_conforming(values)
        x[:len(peers_part)] = peers_part
        if "phi1" in pb.blocks:
            x[pb.index("phi1", "phi2")] = w[self.phi_index]
        if lam_t is not None:
            x[pb.index("lam_t")] = lam_t
            x[pb.index("lam_n")] = lam_n
        return x


def _edge_coupling(broken_rt: ngs.FESpace, facet: ngs.FESpace) -> sp.csr_matrix:
    """D[i, j] = int_{dT} mu_j (psi_i . n_T) ds for the broken RT_0 functions psi_i and the
    edge multipliers mu_j (constant on every element edge: P0 times the RT_0 normal trace)."""
    n = ngs.specialcf.normal(2)
    dT = ngs.dx(element_boundary=True, intrules={ngs.SEGM: ngs.IntegrationRule(ngs.SEGM, 2)})
    form = ngs.BilinearForm(trialspace=facet, testspace=broken_rt)
    form += facet.TrialFunction() * (broken_rt.TestFunction() * n) * dT
    form.Assemble()
    return to_scipy(form.mat)

