"""Gamma_C in one place: its fine edges, coarse meshes, normals, gap and end values.

:class:`ContactBoundary` is built once per discrete problem (:class:`ngdual.forms.Spaces`)
from the scene and the mesh. Friction terms, the solvers, post-processing and the
estimator read Gamma_C from it instead of deriving it again:

* the fine edges of T_h on Gamma_C chain by chain in arc-length order (vertex pairs,
  lengths, midpoints, outward normals n and tangents t = (n_2, -n_1) of (3.24));
* the h~ mesh of lambda_n, lambda_t and the h^ mesh of nu (:mod:`ngdual.boundary`), the
  h~ and h^ edge of every fine edge and the mean of every h~ hat on every fine edge;
* the gap g (a formula, or from a foundation line, :class:`ngdual.scene.Contact`) as an
  NGSolve coefficient, at points, and its P1 interpolant g_h on the h~ mesh (the gap of
  ``contact.discrete_gap = "nodal"``), or with the facet multipliers its P_k interpolant on
  every fine edge, taken on the boundary curve the edge is a chord of, along the curve's
  normal (:meth:`on_curve`, :func:`curve_normal`), and with the coarse multipliers of order
  k its P_{k+1} interpolant on every h~ edge, taken on the curve in the same way;
* the prescribed end values of lambda_n = g - u_n and lambda_t = -u_t where Gamma_C meets
  Gamma_D (``contact.ends = "consistent"``): g - u_D.n and -u_D.t; zero for ``"thesis"``.
"""

from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from .boundary import CoarseMesh, FacetMesh, edge_normals, host_space
from .boundary.coarse_order import CoarseOrderMesh
from .expr import Expression
from .geometry import Side, tangent
from .scene import Scene, gap_at
from .scene.contact import foundation_gap


def trace_space(mesh: ngs.Mesh, labels: list[str]) -> ngs.FESpace:
    """The fine trace space of lambda_n, lambda_t: P1 on every fine edge of Gamma_C,
    discontinuous between edges (see :class:`ContactBoundary`), the host of the facet
    multipliers of order 1 (:func:`ngdual.boundary.host_space`)."""
    return host_space(mesh, labels, 1)


def _vertex_normals(chain) -> np.ndarray:
    """Outward unit normals at the vertices of ``chain`` (``path_points`` order): the mean
    of the two edge normals inside the chain, the end edge's at an end of an open chain."""
    n = edge_normals(chain)
    mean = np.vstack([n[:1], n[:-1] + n[1:], n[-1:]])
    if chain.closed:
        mean[0] = mean[-1] = n[0] + n[-1]
    return mean / np.linalg.norm(mean, axis=1)[:, None]


def _means(space: ngs.FESpace, labels: list[str], bubble_dofs: np.ndarray,
           lengths: np.ndarray) -> np.ndarray:
    """The means over their fine edges of the functions ``bubble_dofs`` of ``space``."""
    if not bubble_dofs.size:
        return np.zeros(bubble_dofs.shape)
    integrals = ngs.LinearForm(space)
    integrals += space.TestFunction() * ngs.ds(definedon=space.mesh.Boundaries("|".join(labels)))
    integrals.Assemble()
    return integrals.vec.FV().NumPy()[bubble_dofs] / lengths[:, None]


def _contact_arcs(scene: Scene) -> list[tuple[Side, float]]:
    """The arcs of Gamma_C with the sign that turns the radial direction from the centre
    into the outward normal (+1: the body lies inside the circle)."""
    arcs = []
    for side in scene.geometry.curves():
        if side.is_arc and side.label in scene.labels("contact"):
            points, normals = side.sample(2)
            arcs.append((side, float(np.sign(np.sum((points[0] - side.center) * normals[0])))))
    return arcs


def curve_normal(scene: Scene, mesh: ngs.Mesh) -> ngs.CoefficientFunction:
    """The outward unit normal of the boundary curve of Gamma_C on its fine edges, as an
    NGSolve coefficient: on an arc the radial direction at every point of a chord (the
    arc's normal on the same ray, :meth:`ContactBoundary.on_curve`), on a straight side the
    edge normal. The facet multipliers pair with sigma in it
    (:func:`ngdual.forms.couplings.coupling_forms`), so that lambda_n = g - u.n and the
    frictionless t.sigma n = 0 hold for the arc's normal and tangent, not for a chord's,
    which differ from them by up to |e| / (2 R)."""
    n = ngs.specialcf.normal(2)
    arcs = _contact_arcs(scene)
    if not arcs:
        return n
    values = {}
    for side, sign in arcs:
        radial = ngs.CF((ngs.x - float(side.center[0]), ngs.y - float(side.center[1])))
        values[side.label] = sign * radial / ngs.sqrt(radial * radial)
    return mesh.BoundaryCF(values, default=n)


def gap_coefficient(scene: Scene) -> ngs.CoefficientFunction:
    """g on Gamma_C as an NGSolve coefficient (boundary integrals only: it may use n)."""
    contact = scene.contact
    if contact.foundation is None:
        return Expression(contact.gap_formula).coefficient()
    n = ngs.specialcf.normal(2)
    return foundation_gap(contact, ngs.x, ngs.y, n[0], n[1])


@dataclass(frozen=True)
class ContactBoundary:
    """Gamma_C of one mesh (see the module docstring).

    Attributes
    ----------
    coarse, friction : CoarseMesh
        The h~ mesh of the contact multipliers and the h^ mesh of nu (None without friction).
    vertices : numpy.ndarray
        (n, 2) fine vertex numbers of every fine edge, chain by chain along the chains.
    lengths, midpoints, normals : numpy.ndarray
        |e|, midpoints and outward unit normals of the fine edges.
    htilde_edge, hhat_edge : numpy.ndarray
        The h~ (and h^) edge holding every fine edge.
    edge_dofs : numpy.ndarray
        (n, 2) dofs of the fine trace space of lambda at the start and end of every
        fine edge. That space is P1 on every fine edge and discontinuous from edge to
        edge (``Discontinuous(H1, BND=True)``): the coarse multipliers are continuous
        along a chain but not across a kink, where two chains share a vertex. With the
        facet multipliers of order k (``coarse`` a :class:`~ngdual.boundary.facet.FacetMesh`)
        the space is P_max(k,1) on every fine edge and these are its vertex dofs.
    bubble_dofs, bubble_means : numpy.ndarray
        (n, k - 1) dofs of the edge bubbles of that space on every fine edge and the means
        of their functions over it (none for the P1 trace space).
    """

    scene: Scene
    coarse: CoarseMesh
    friction: CoarseMesh | None
    vertices: np.ndarray
    lengths: np.ndarray
    midpoints: np.ndarray
    normals: np.ndarray
    htilde_edge: np.ndarray
    hhat_edge: np.ndarray | None
    edge_dofs: np.ndarray
    bubble_dofs: np.ndarray
    bubble_means: np.ndarray

    @classmethod
    def build(cls, scene: Scene, coarse: CoarseMesh, friction: CoarseMesh | None,
              space: ngs.FESpace) -> ContactBoundary:
        """Gamma_C from its coarse meshes and the fine trace space (:func:`trace_space`)."""
        vertices, htilde_edge = coarse.fine_edges()
        if isinstance(coarse, (FacetMesh, CoarseOrderMesh)):
            host = coarse.host_dofs(space)
            edge_dofs, bubble_dofs = host[:, :2], host[:, 2:]
        else:
            edge_dofs = coarse.fine_edge_dofs(space)
            bubble_dofs = np.zeros((len(edge_dofs), 0), dtype=int)
        pts = [ch.path_points for ch in coarse.chains]
        starts = np.vstack([p[:-1] for p in pts])
        ends = np.vstack([p[1:] for p in pts])
        lengths = np.linalg.norm(ends - starts, axis=1)
        normals = np.vstack([edge_normals(ch) for ch in coarse.chains])
        hhat_edge = friction.fine_edges()[1] if friction is not None else None
        return cls(scene, coarse, friction, vertices, lengths, 0.5 * (starts + ends), normals,
                   htilde_edge, hhat_edge, edge_dofs, bubble_dofs,
                   _means(space, scene.labels("contact"), bubble_dofs, lengths))

    def __len__(self) -> int:
        return len(self.lengths)

    @property
    def tangents(self) -> np.ndarray:
        """t = (n_2, -n_1), the tangent of (3.24)."""
        return tangent(self.normals)

    def prolongation(self, n_fine: int, ends: bool = False) -> sp.csr_matrix:
        """Coarse h~ P1 dofs (or the fixed-end hats, ``ends=True``) -> fine trace dofs."""
        return self.coarse.p1_prolongation(self.edge_dofs, n_fine, ends)

    def hat_means(self, prolongation: sp.csr_matrix) -> sp.csr_matrix:
        """M (n_edges x N_C): the mean of every coarse function on every fine edge.

        The vertex functions of the trace space have the mean 1/2 on their edge, its bubbles
        ``bubble_means`` (facet multipliers of order k >= 2)."""
        P = prolongation.tocsr()
        if P.shape[1] == 0:  # no function (the facet multipliers fix no end)
            return sp.csr_matrix((len(self.edge_dofs), 0))
        means = 0.5 * (P[self.edge_dofs[:, 0]] + P[self.edge_dofs[:, 1]])
        for j in range(self.bubble_dofs.shape[1]):
            means = means + sp.diags(self.bubble_means[:, j]) @ P[self.bubble_dofs[:, j]]
        return means.tocsr()

    def vertex_values(self, fine: np.ndarray) -> np.ndarray:
        """Fine trace values at the vertices of every chain (``path_points`` order)."""
        out, edge = [], 0
        for chain in self.coarse.chains:
            d = self.edge_dofs[edge:edge + chain.n_edges]
            out.append(np.concatenate([fine[d[:, 0]], fine[d[-1:, 1]]]))
            edge += chain.n_edges
        return np.concatenate(out)

    def gap_at_edges(self) -> np.ndarray:
        """g at the fine edge midpoints."""
        return gap_at(self.scene.contact, self.midpoints, self.normals)

    def vertex_normals(self) -> np.ndarray:
        """Outward normals at the fine vertices of every chain (``path_points`` order): the
        mean of the two edge normals inside a chain, the end edge's at a chain end."""
        return np.vstack([_vertex_normals(chain) for chain in self.coarse.chains])

    def gap_at_vertices(self) -> np.ndarray:
        """g at the fine vertices of every chain (``path_points`` order)."""
        pts = np.vstack([ch.path_points for ch in self.coarse.chains])
        return gap_at(self.scene.contact, pts, self.vertex_normals())

    def gap_at_nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """g at the h~ nodes: (at the dofs, in dof order; at the fixed ends, in the order
        of ``coarse.end_points()``), with the vertex normals of :meth:`vertex_normals`.

        These are the nodal values of g_h = I_h~ g, the gap of ``contact.discrete_gap =
        "nodal"`` (:meth:`gap_interpolant`).
        """
        dofs, ends = [], []
        for c, chain in enumerate(self.coarse.chains):
            points, normals = chain.path_points, _vertex_normals(chain)
            for out, positions in ((dofs, self.coarse.dof_positions(c)),
                                   (ends, self.coarse.end_positions(c))):
                out.append(gap_at(self.scene.contact, points[positions], normals[positions]))
        return np.concatenate(dofs), np.concatenate(ends)

    def discrete_gap_at_vertices(self, prolongation: sp.csr_matrix, end_hats: sp.csr_matrix
                                 ) -> np.ndarray:
        """The gap the discrete problem sees, at the fine vertices (``path_points`` order):
        g_h = I_h~ g for ``contact.discrete_gap = "nodal"``, g itself for ``"thesis"``; so
        g_h - lambda_n^h is the discrete normal displacement u_n^h. Arguments as in
        :meth:`gap_interpolant`."""
        if self.scene.contact.discrete_gap == "thesis":
            return self.gap_at_vertices()
        return self.vertex_values(self.gap_interpolant(prolongation, end_hats))

    def gap_interpolant(self, prolongation: sp.csr_matrix, end_hats: sp.csr_matrix
                        ) -> np.ndarray:
        """Fine trace coefficients of g_h, the interpolant of g in the multiplier space:
        I_h~ g, P1 on the h~ mesh for the thesis' hats; for the Bernstein bases of degree
        p >= 2 the interpolant with its negative coefficients raised to zero.

        ``prolongation`` and ``end_hats`` are :meth:`prolongation` without and with
        ``ends=True``. With g_h for g in g(tau) of (3.32), lambda_n - g_h = -u_n lies in the
        multiplier space: the discrete problem sees u_n only through its h~ nodal values,
        the contact condition lambda_n >= 0 is u_n <= g at the h~ nodes, and without load
        lambda_n = g_h, sigma = 0 solves (3.62) for any g >= 0 (g itself would prescribe
        u_n = g - lambda_n on the fine edges wherever g is not P1 on h~).

        At degree p >= 2 the contact condition acts on the Bernstein coefficients of
        lambda_n, and a nonnegative polynomial may have a negative one: x^2 on [-h, h] has
        the middle coefficient -h^2. The interpolant of a gap that touches zero inside an
        edge (a curved body at its first point of contact) would then be no admissible
        lambda_n, and without load the discrete problem would push the body off by about
        h^2 / R (a stress of 1e-5 of the loaded Hertz run at k = 1). Raised to zero, those
        coefficients give a g_h >= 0 with lambda_n = g_h admissible, so no load gives no
        stress at every order; g_h moves by at most the negative coefficients, O(h^2 g'')
        on the few edges where g vanishes (docs/theory/order.md).
        """
        if isinstance(self.coarse, FacetMesh):
            # the facet multipliers: g of the boundary curve interpolated on every fine edge
            return prolongation @ np.maximum(self.coarse.interpolant(
                lambda points, edges: gap_at(self.scene.contact, *self.on_curve(points, edges))),
                0.0)
        if isinstance(self.coarse, CoarseOrderMesh):
            # degree k + 1 on every h~ edge, g of the boundary curve at its control points
            at_dofs, at_ends = self.coarse.interpolant(
                lambda points, edges: gap_at(self.scene.contact, *self.on_curve(points, edges)))
            at_dofs = np.maximum(at_dofs, 0.0)
        else:
            at_dofs, at_ends = self.gap_at_nodes()
        return prolongation @ at_dofs + end_hats @ at_ends

    def on_curve(self, points: np.ndarray, edges: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
        """``points`` of the fine ``edges`` moved onto the boundary curve of Gamma_C that the
        edges approximate, and its outward unit normals there (:func:`curve_normal`).

        The fine edges are chords: where Gamma_C is an arc of radius R, a chord lies inside
        the body by its sagitta, up to |e|^2 / (8 R), and its normal is the arc's only at
        its midpoint. A point x of a chord moves along the radius to the arc, where the gap
        is measured along the arc's normal: the body is the arc, not the polygon of its
        chords. On straight sides (and at the vertices, which lie on the arc) nothing moves,
        so the P1 interpolant of the gap is that of the polygon; at k >= 2 the chords' gap
        would put the kinks of the polygon at every vertex, an O(h / R) jump of the slope of
        u_n, into the contact zone, where the traces of RT_k resolve them as pressure peaks
        (docs/theory/order.md).
        """
        points = np.asarray(points, dtype=float)
        normals = self.normals[edges].copy()
        moved = points.copy()
        starts = np.vstack([chain.path_points[:-1] for chain in self.coarse.chains])
        stops = np.vstack([chain.path_points[1:] for chain in self.coarse.chains])
        for side, sign in _contact_arcs(self.scene):
            r = np.linalg.norm(side.start - side.center)
            # the edges of this arc: both end points on it
            on_arc = np.maximum(np.abs(np.linalg.norm(starts - side.center, axis=1) - r),
                                np.abs(np.linalg.norm(stops - side.center, axis=1) - r))
            mine = on_arc[edges] <= 1e-9 * r
            radial = points[mine] - side.center
            radial /= np.linalg.norm(radial, axis=1)[:, None]
            moved[mine] = side.center + r * radial
            normals[mine] = sign * radial
        return moved, normals

    def end_values(self, u_d: tuple[str, str]) -> tuple[np.ndarray, np.ndarray]:
        """(lambda_n, lambda_t) at the fixed ends (``coarse.end_points()``).

        ``"consistent"``: g - u_D.n and -u_D.t with the normal of the end edge;
        ``"thesis"``: zero (C_h~ of (3.61)).
        """
        points = self.coarse.end_points()
        if self.scene.contact.ends == "thesis" or not len(points):
            return np.zeros(len(points)), np.zeros(len(points))
        normals = self.coarse.end_normals()
        u = np.column_stack([Expression(e).numpy(points[:, 0], points[:, 1]) for e in u_d])
        g = gap_at(self.scene.contact, points, normals)
        return g - np.sum(u * normals, axis=1), -np.sum(u * tangent(normals), axis=1)
