"""The coarse multipliers of order k: continuous P_{k+1} on the h~ mesh, in the Bernstein basis.

The first multiplier family of docs/theory/order.md at order k >= 1: phi on Gamma_N and
lambda_n, lambda_t on Gamma_C are continuous piecewise polynomials of degree p = k + 1 on the
coarse h~ mesh of Section 3.2 (:class:`~ngdual.boundary.coarse.CoarseMesh`), fixed at the
fixed chain ends as the thesis' P1 hats are (zero, or the end values the data prescribe,
``contact.ends``). On every coarse edge E = [A, B], with t in [0, 1] its arc-length
parameter,

    mu|_E = sum_{j=0}^p c_{E,j} B_j(t),    B_j = binom(p, j) (1 - t)^(p-j) t^j,

and neighbouring edges share the coefficient of their common node (c_{E,p} = c_{E',0} = the
value there), so mu is continuous along a chain. The Bernstein basis is positive: c >= 0
implies mu >= 0, and the sign condition lambda_n >= 0 of (3.62) sits on the unknowns as for
the hats (the vertex coefficients are the hats' nodal values at p = 1).

NGSolve assembles the forms on the host of the facet family of degree p,
:func:`~ngdual.boundary.facet.host_space` (P_p on every fine edge, discontinuous), and
:meth:`CoarseOrderMesh.prolongation` maps the coarse coefficients to it in two exact steps:
the restriction of every B_j(t) to a fine edge inside E is a polynomial of degree p, whose
Bernstein coefficients on that edge are found by interpolation at p + 1 points, and the
fine Bernstein functions go to the host by :meth:`~ngdual.boundary.facet.FacetMesh.prolongation`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from .coarse import CoarseMesh, WithoutP1
from .facet import FacetMesh, bernstein_matrices, bernstein_values


@dataclass(frozen=True)
class CoarseOrderMesh(WithoutP1, CoarseMesh):
    """A coarse h~ mesh carrying continuous Bernstein polynomials of degree ``degree`` = k + 1.

    The unknowns run chain by chain along the chain: the coefficient of a coarse node that
    carries a dof (:meth:`CoarseMesh.dof_positions`), then the p - 1 inner coefficients of the
    coarse edge that starts there, and so on; the coefficients of the fixed end nodes are
    numbered apart (``ends=True`` of :meth:`prolongation`), as the thesis' end hats are.
    """

    curve_normal: ClassVar[bool] = True   # degree k + 1 resolves the curve's normal

    degree: int = 1

    @classmethod
    def of(cls, coarse: CoarseMesh, degree: int) -> CoarseOrderMesh:
        """The coarse mesh ``coarse`` (fresh or followed) with Bernstein polynomials of
        degree ``degree``."""
        return cls(coarse.chains, coarse.nodes, coarse.free, coarse.breaks, degree)

    def numbering(self) -> tuple[list[np.ndarray], int, int]:
        """Per chain the (n_coarse_edges, p + 1) unknown of every Bernstein coefficient of
        every coarse edge, and the numbers of unknowns and of fixed-end coefficients.

        A fixed end's coefficient j is numbered ``n_unknowns + e``, e its place among the
        fixed ends (the order of :meth:`CoarseMesh.end_points`).
        """
        p = self.degree
        tables, count, n_ends = [], 0, 0
        for c, chain in enumerate(self.chains):
            nodes = [int(q) for q in self.nodes[c]]
            if chain.closed:
                nodes[-1] = nodes[0]
            fixed = {int(q) for q in self.end_positions(c)}
            number = {}  # node position -> unknown (>= 0) or -1 - its place among the ends
            table = np.empty((len(nodes) - 1, p + 1), dtype=int)
            for e, position in enumerate(nodes):
                if position not in number:
                    if position in fixed:
                        number[position], n_ends = -1 - n_ends, n_ends + 1
                    else:
                        number[position], count = count, count + 1
                if e < len(nodes) - 1:
                    table[e, 1:p] = np.arange(count, count + p - 1)
                    count += p - 1
            table[:, 0] = [number[q] for q in nodes[:-1]]
            table[:, p] = [number[q] for q in nodes[1:]]
            tables.append(table)
        return [np.where(t < 0, count - 1 - t, t) for t in tables], count, n_ends

    @property
    def n_coefficients(self) -> int:
        """The unknowns: the coefficients of the nodes with a dof and the inner ones."""
        return self.numbering()[1]

    def mass_stiffness(self) -> tuple[np.ndarray, np.ndarray]:
        """The mass matrix M and the arc-length stiffness L of the continuous Bernstein
        polynomials on the unknowns (the fixed end coefficients left out, as the thesis'
        C_h~ leaves out its end hats), dense: they define the H^{1/2} metric of the
        projection step of the Uzawa algorithms
        (:func:`ngdual.solvers.projections.metric_matrix`)."""
        mass_ref, stiff_ref = bernstein_matrices(self.degree)
        tables, n, _ = self.numbering()
        mass, stiff = np.zeros((n, n)), np.zeros((n, n))
        for chain, nodes, table in zip(self.chains, self.nodes, tables):
            for ell, row in zip(np.diff(chain.arclength[nodes]), table):
                keep = row < n
                cells = np.ix_(row[keep], row[keep])
                np.add.at(mass, cells, ell * mass_ref[np.ix_(keep, keep)])
                np.add.at(stiff, cells, stiff_ref[np.ix_(keep, keep)] / ell)
        return mass, stiff

    def dof_positions(self, c: int) -> np.ndarray:
        """For every unknown of chain c (unknown order) the chain vertex nearest its control
        point in arc length: the node views of Gamma_C (post-processing, the checks) read
        the coefficients there, as for the facet family."""
        p, s, nodes = self.degree, self.chains[c].arclength, self.nodes[c]
        tables, n, _ = self.numbering()
        targets = (s[nodes[:-1], None]
                   + np.arange(p + 1)[None, :] / p * np.diff(s[nodes])[:, None]).ravel()
        columns = tables[c].ravel()
        nearest = np.abs(s[None, :] - targets[:, None]).argmin(axis=1)
        own = columns < n
        _, first = np.unique(columns[own], return_index=True)
        return nearest[own][first]

    def fine_facets(self) -> FacetMesh:
        """The fine edges of this mesh's chains as the facet mesh of degree p (the host)."""
        return FacetMesh(self.chains, tuple(np.arange(c.n_edges + 1) for c in self.chains),
                         tuple((True, True) for _ in self.chains), self.breaks, self.degree)

    def host_dofs(self, space: ngs.FESpace) -> np.ndarray:
        """The host dofs of every fine edge (:meth:`FacetMesh.host_dofs`)."""
        return self.fine_facets().host_dofs(space)

    def _parameters(self, c: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For every fine edge of chain c its coarse edge and the parameters t of that
        coarse edge at the edge's start and end (arc length, as the P1 hats)."""
        s, nodes = self.chains[c].arclength, self.nodes[c]
        fine = np.arange(self.chains[c].n_edges)
        owner = np.searchsorted(nodes, fine, side="right") - 1
        a, b = s[nodes[owner]], s[nodes[owner + 1]]
        return owner, (s[fine] - a) / (b - a), (s[fine + 1] - a) / (b - a)

    def restriction(self) -> sp.csr_matrix:
        """((p + 1) n_fine_edges, n_unknowns + n_ends): coarse coefficients -> the Bernstein
        coefficients of degree p on every fine edge (the fixed ends' in the last columns)."""
        p = self.degree
        tables, n, n_ends = self.numbering()
        tau = np.arange(p + 1) / p
        inverse = np.linalg.inv(bernstein_values(p, tau))
        rows, cols, vals, edge = [], [], [], 0
        for c in range(len(self.chains)):
            owner, t0, t1 = self._parameters(c)
            for k in range(len(owner)):
                # B_j(t) at the fine edge's points tau, then its fine Bernstein coefficients
                values = bernstein_values(p, t0[k] + tau * (t1[k] - t0[k]))
                local = inverse @ values          # (fine coefficient i, coarse j)
                local[np.abs(local) < 1e-14] = 0.0
                i, j = np.nonzero(local)
                rows.append((p + 1) * (edge + k) + i)
                cols.append(tables[c][owner[k], j])
                vals.append(local[i, j])
            edge += len(owner)
        shape = ((p + 1) * edge, n + n_ends)
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))), shape=shape)

    def prolongation(self, space: ngs.FESpace, labels: list[str], ends: bool = False
                     ) -> sp.csr_matrix:
        """(space.ndof, n_unknowns): coarse Bernstein coefficients -> host coefficients of
        ``space`` (:func:`~ngdual.boundary.facet.host_space` of degree p); with ``ends=True``
        (space.ndof, n_ends), the functions of the fixed end coefficients, which lift the end
        values (:func:`ngdual.forms.couplings.end_lift`)."""
        n = self.n_coefficients
        R = self.restriction()
        R = R[:, n:] if ends else R[:, :n]
        return (self.fine_facets().prolongation(space, labels) @ R).tocsr()

    def control_points(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The points at t = j / p of every coarse edge on the fine polygon, the fine edge
        (numbered along the chains) each lies on, and its column in ``numbering``
        (unknowns, then fixed ends), one row per coefficient of every coarse edge."""
        p = self.degree
        tables = self.numbering()[0]
        points, edges, columns, offset = [], [], [], 0
        for c, chain in enumerate(self.chains):
            s, nodes, path = chain.arclength, self.nodes[c], chain.path_points
            for e in range(len(nodes) - 1):
                target = s[nodes[e]] + np.arange(p + 1) / p * (s[nodes[e + 1]] - s[nodes[e]])
                k = np.clip(np.searchsorted(s, target, side="right") - 1,
                            nodes[e], nodes[e + 1] - 1)
                r = (target - s[k]) / (s[k + 1] - s[k])
                points.append(path[k] + r[:, None] * (path[k + 1] - path[k]))
                edges.append(offset + k)
                columns.append(tables[c][e])
            offset += chain.n_edges
        return np.vstack(points), np.concatenate(edges), np.concatenate(columns)

    def node_points(self) -> np.ndarray:
        """The control point of every unknown (on the fine polygon), in unknown order."""
        points, _, columns = self.control_points()
        out = np.zeros((self.n_coefficients, 2))
        keep = columns < len(out)
        out[columns[keep]] = points[keep]
        return out

    def interpolant(self, values_at) -> tuple[np.ndarray, np.ndarray]:
        """(unknowns, fixed ends): the Bernstein coefficients of the interpolant of degree p
        on every coarse edge of a function at the points t = j / p (equispaced in arc length;
        the Gauss-Lobatto points at p <= 2): ``values_at(points, edges)`` gives its values at
        points of the fine edges ``edges``. A node shared by two coarse edges gets the same
        coefficient from both, the function's value there."""
        p = self.degree
        points, edges, columns = self.control_points()
        values = np.asarray(values_at(points, edges), dtype=float).reshape(-1, p + 1)
        coefficients = np.linalg.solve(bernstein_values(p, np.arange(p + 1) / p),
                                       values.T).T
        coefficients[:, [0, p]] = values[:, [0, p]]   # the node values, exactly
        out = np.zeros(self.n_coefficients + len(self.end_points()))
        out[columns] = coefficients.ravel()
        return out[:self.n_coefficients], out[self.n_coefficients:]
