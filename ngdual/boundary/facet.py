"""The facet multipliers of order k: discontinuous P_k on the fine edges, in the Bernstein basis.

The second multiplier family of docs/theory/order.md: phi on Gamma_N and lambda_n, lambda_t
on Gamma_C are polynomials of degree k on every fine edge of T_h, discontinuous from edge to
edge -- the space of the normal traces of RT_k, so that d(mu, tau) of (3.24) pairs them with
the stresses as the hybridisation does (inf-sup stable by construction).

The unknowns are the Bernstein coefficients of every fine edge e = [a, b],

    mu|_e = sum_{i=0}^k c_{e,i} B_i,    B_i = binom(k, i) lambda_a^(k-i) lambda_b^i,

lambda_a, lambda_b the barycentric coordinates of e. The Bernstein basis is positive and a
partition of unity, so c_{e,i} >= 0 for all i implies mu >= 0 on e (and is equivalent to it
at k <= 1): the sign condition lambda_n >= 0 of (3.62) becomes a sign condition on the
unknowns, as for the hats of the thesis, and every contact solver that imposes lambda_n >= 0
on the unknowns imposes it here.

NGSolve assembles the forms on a host space, ``Discontinuous(H1(order=max(k, 1)), BND=True)``
on the fine edges (vertex functions lambda_a, lambda_b and edge bubbles), and
:meth:`FacetMesh.prolongation` maps Bernstein coefficients to host coefficients, exactly as
the coarse hats are mapped (:meth:`ngdual.boundary.CoarseMesh.p1_prolongation`).
The Bernstein functions are projected onto the host by NGSolve (``Set``), which reproduces a
polynomial of the host exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb
from typing import ClassVar

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from ..mesh import edge_dofs
from .chains import EndRule, boundary_chains
from .coarse import CoarseMesh, WithoutP1


def host_space(mesh: ngs.Mesh, labels: list[str], order: int) -> ngs.FESpace:
    """The host of the facet P_k multipliers: P_max(k,1) on every fine edge of ``labels``,
    discontinuous from edge to edge (compressed)."""
    h1 = ngs.H1(mesh, order=max(order, 1), definedon=mesh.Boundaries("|".join(labels)))
    # BND=True (discontinuous across boundary elements) works but is missing from the flag
    # list NGSolve checks keywords against, which would print a warning
    level, ngs.ngsglobals.msg_level = ngs.ngsglobals.msg_level, 0
    try:
        return ngs.Compress(ngs.Discontinuous(h1, BND=True))
    finally:
        ngs.ngsglobals.msg_level = level


def control_parameters(order: int) -> np.ndarray:
    """The parameters t in [0, 1] of the Bernstein control points of degree k along an edge
    (i / k; the midpoint at k = 0). The interpolation points of :meth:`FacetMesh.interpolant`."""
    return np.array([0.5]) if order == 0 else np.arange(order + 1) / order


def bernstein_values(order: int, t: np.ndarray) -> np.ndarray:
    """B_i(t), i = 0..k, at the parameters ``t`` (points x k + 1)."""
    t = np.asarray(t, dtype=float)[:, None]
    i = np.arange(order + 1)[None, :]
    return np.array([comb(order, j) for j in range(order + 1)]) * (1 - t) ** (order - i) * t ** i


def bernstein_derivatives(order: int, t: np.ndarray) -> np.ndarray:
    """dB_i / dt, i = 0..k, at the parameters ``t``: k (B_{i-1}^{k-1} - B_i^{k-1})."""
    t = np.asarray(t, dtype=float)
    if order == 0:
        return np.zeros((len(t), 1))
    lower = np.zeros((len(t), order + 2))
    lower[:, 1:-1] = bernstein_values(order - 1, t)
    return order * (lower[:, :-1] - lower[:, 1:])


def bernstein_matrices(order: int) -> tuple[np.ndarray, np.ndarray]:
    """The mass int_0^1 B_i B_j dt and the stiffness int_0^1 B_i' B_j' dt of the Bernstein
    polynomials of degree k on [0, 1] (Gauss-Legendre, exact): on an edge of length l they
    are l times and 1 / l times these."""
    points, weights = np.polynomial.legendre.leggauss(order + 1)
    t, w = (points + 1) / 2, weights / 2
    values, slopes = bernstein_values(order, t), bernstein_derivatives(order, t)
    return values.T @ (w[:, None] * values), slopes.T @ (w[:, None] * slopes)


@dataclass(frozen=True)
class FacetMesh(WithoutP1, CoarseMesh):
    """The fine edges of a boundary part as the mesh of the facet P_k multipliers.

    A :class:`CoarseMesh` whose edges are the fine edges themselves (every chain vertex is a
    node) and whose chain ends are all free (the multipliers are discontinuous: no end
    value is prescribed, so nothing is lifted), with the order k of the multipliers. Its
    "dofs" are the k + 1 Bernstein coefficients of every fine edge, chain by chain and
    edge by edge along the chain; :meth:`node_points` are their control points.
    ``clamped`` says for the first and the last end of every chain whether the end rule
    fixes it (where the part meets Gamma_D): the multipliers stay free there, but the body
    is held, which the metric of :meth:`mass_stiffness` takes into account.
    """

    traces: ClassVar[bool] = True   # P_k per fine edge: the normal traces of RT_k
    curve_normal: ClassVar[bool] = True

    order: int = 0
    clamped: tuple[tuple[bool, bool], ...] = ()

    @classmethod
    def on_fine(cls, mesh: ngs.Mesh, labels: list[str], order: int,
                ends: EndRule | None = None) -> FacetMesh:
        """The fine edges of ``labels`` in chains, broken where ``ends`` breaks them."""
        ends = ends or EndRule()
        chains = tuple(boundary_chains(mesh, labels, ends.breaks))
        clamped = tuple((False, False) if c.closed else (not first, not last)
                        for c, (first, last) in zip(chains, ends.free_ends(chains)))
        return cls(chains, tuple(np.arange(c.n_edges + 1) for c in chains),
                   tuple((True, True) for _ in chains), ends.breaks, order, clamped)

    @property
    def n_coefficients(self) -> int:
        """k + 1 Bernstein coefficients on every fine edge."""
        return (self.order + 1) * self.n_edges

    def mass_stiffness(self) -> tuple[np.ndarray, np.ndarray]:
        """The mass matrix M and the broken arc-length stiffness L on the Bernstein
        coefficients, dense.

        The multipliers are discontinuous, so L is the broken H^1 seminorm with the jumps
        penalised, |mu|_{1,h}^2 = sum_e |mu|_{1,e}^2 + sum_a [mu]_a^2 / h_a (h_a the mean
        length of the two edges at the inner chain vertex a; the coefficients at the ends
        of an edge are its end values): the seminorm of a continuous mu, and for the modes
        that jump from edge to edge of the size 1 / h^2 that their wave number gives them.
        At a ``clamped`` chain end the value there counts as a jump to zero, mu(a)^2 / h_a
        (h_a the length of the end edge): the norm of H^{1/2}_00, in which the coarse
        family leaves the end coefficient out. A value at a clamped corner moves against
        the held body; without the term the metric underestimates its stiffness by a
        factor that grows like log(1 / h) (6 to 13 on Example 3.46, levels 1-3).
        (M, L) define the H^{1/2} metric of the projection step of the Uzawa algorithms
        (:func:`ngdual.solvers.projections.metric_matrix`).
        """
        k = self.order
        mass_ref, stiff_ref = bernstein_matrices(k)
        lengths = self.edge_lengths()
        mass = np.kron(np.diag(lengths), mass_ref)
        stiff = np.kron(np.diag(1.0 / lengths), stiff_ref)
        clamped = self.clamped or tuple((False, False) for _ in self.chains)
        offset = 0
        for chain, held in zip(self.chains, clamped):
            m = chain.n_edges
            h = lengths[offset:offset + m]
            for e in range(m - 1 if not chain.closed else m):
                after = (e + 1) % m
                a, b = (offset + e) * (k + 1) + k, (offset + after) * (k + 1)
                weight = 2.0 / (h[e] + h[after])
                stiff[[a, b, a, b], [a, b, b, a]] += [weight, weight, -weight, -weight]
            for end, edge, coefficient in zip(held, (0, m - 1), (0, k)):
                if end:
                    at = (offset + edge) * (k + 1) + coefficient
                    stiff[at, at] += 1.0 / h[edge]
            offset += m
        return mass, stiff

    def node_points(self) -> np.ndarray:
        """The Bernstein control points a + (i / k)(b - a) of every fine edge, in unknown order."""
        t = control_parameters(self.order)
        out = []
        for chain in self.chains:
            p = chain.path_points
            out.append((p[:-1, None, :] + t[None, :, None] * (p[1:] - p[:-1])[:, None, :])
                       .reshape(-1, 2))
        return np.vstack(out) if out else np.zeros((0, 2))

    def dof_positions(self, c: int) -> np.ndarray:
        """For every Bernstein coefficient of chain c (unknown order) the chain vertex its
        control point lies at or after, the end vertex past the middle of the edge: the node
        views of Gamma_C (post-processing, the checks) read the coefficients there."""
        t = control_parameters(self.order)
        edges = np.arange(self.chains[c].n_edges)
        return (edges[:, None] + (t > 0.5)[None, :]).ravel()

    def host_dofs(self, space: ngs.FESpace) -> np.ndarray:
        """(n_edges, max(k, 1) + 1) dofs of the host ``space`` on every fine edge, in the order
        of :meth:`fine_edges`: the start vertex's, the end vertex's, then the bubbles
        (:func:`ngdual.mesh.edge_dofs`)."""
        vertices, _ = self.fine_edges()
        return np.array(edge_dofs(space, vertices), dtype=int)

    def prolongation(self, space: ngs.FESpace, labels: list[str]) -> sp.csr_matrix:
        """(space.ndof, n_coefficients): Bernstein coefficients -> host coefficients.

        B_i = binom(k, i) lambda_a^(k-i) lambda_b^i is set on the host with lambda_a, lambda_b
        its vertex functions; its coefficients are exact to round-off (the vertex ones are
        B_i(a), B_i(b) in {0, 1} exactly).
        """
        dofs = self.host_dofs(space)
        k, n_edges = self.order, len(dofs)
        start, end = ngs.GridFunction(space), ngs.GridFunction(space)
        start.vec.FV().NumPy()[dofs[:, 0]] = 1.0
        end.vec.FV().NumPy()[dofs[:, 1]] = 1.0
        region = space.mesh.Boundaries("|".join(labels))
        rows, cols, vals = [], [], []
        for i in range(k + 1):
            basis = ngs.GridFunction(space)
            basis.Set(comb(k, i) * start ** (k - i) * end ** i, ngs.BND, definedon=region)
            coefficients = basis.vec.FV().NumPy()[dofs]
            coefficients[:, :2] = bernstein_values(k, [0.0, 1.0])[:, i]  # exact at the ends
            keep = coefficients != 0
            rows.append(dofs[keep])
            cols.append(np.broadcast_to((k + 1) * np.arange(n_edges)[:, None] + i,
                                        dofs.shape)[keep])
            vals.append(coefficients[keep])
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(space.ndof, self.n_coefficients))

    def interpolant(self, values_at) -> np.ndarray:
        """Bernstein coefficients of the edge-wise interpolant of a function at the control
        parameters of :func:`control_parameters` (equispaced, which at k <= 2 are the
        Gauss-Lobatto points): ``values_at(points, edge)`` gives its values at points of the
        fine edges ``edge``."""
        t = control_parameters(self.order)
        V = bernstein_values(self.order, t)
        vertices = [chain.path_points for chain in self.chains]
        starts = np.vstack([p[:-1] for p in vertices])
        steps = np.vstack([np.diff(p, axis=0) for p in vertices])
        edges = np.repeat(np.arange(len(starts)), len(t))
        points = (starts[:, None, :] + t[None, :, None] * steps[:, None, :]).reshape(-1, 2)
        values = np.asarray(values_at(points, edges)).reshape(len(starts), len(t))
        return np.linalg.solve(V, values.T).T.ravel()
