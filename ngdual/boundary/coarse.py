"""The coarse meshes h~ and h^ of the multipliers and their P1 spaces.

The multipliers live on meshes coarser than the trace of T_h (Section 3.2):
phi, lambda_t, lambda_n on h~ = 2h (P1, zero at the end points of their
boundary part) and nu on h^ = h~ or 2h~ (P0). A coarse mesh is built from the
fine boundary edges of a boundary part: the edges are ordered into chains
(:mod:`ngdual.boundary.chains`) and grouped ``factor`` at a time, so every fine edge lies
entirely on one coarse edge (the nesting assumed in Section 3.2) and h~ ~ factor * h
locally, on uniform and on locally refined meshes alike.

After a local refinement of T_h the coarse meshes follow the fine one
(:meth:`CoarseMesh.follow`, :class:`BoundaryMeshes`) instead of being grouped
afresh, which keeps them nested from one adaptive step to the next.

A coarse P1 function is represented by its values at both ends of every fine boundary
edge: :meth:`CoarseMesh.p1_prolongation` is the matrix mapping coarse nodal values to the
coefficients of a fine P1 trace space, through which all forms assembled by NGSolve on the
fine trace are restricted to the coarse space. At order k >= 1 the same coarse meshes carry
continuous polynomials of degree k + 1 (:mod:`ngdual.boundary.coarse_order`).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations
from typing import ClassVar

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from ..mesh import edge_dofs
from .chains import Chain, EndRule, boundary_chains, edge_normals, end_rule


def _group(n_edges: int, factor: int) -> np.ndarray:
    """Positions 0..n_edges of the coarse nodes when grouping ``factor`` edges at a time."""
    q, r = divmod(n_edges, factor)
    if q == 0:
        return np.array([0, n_edges])
    nodes = list(range(0, q * factor + 1, factor))
    if r:
        # a short remainder joins the last group, a long one becomes its own edge
        if 2 * r >= factor:
            nodes.append(n_edges)
        else:
            nodes[-1] = n_edges
    return np.array(nodes)


def _split(points: np.ndarray, arclength: np.ndarray, factor: int) -> list[int]:
    """Nodes after ``points[0]`` when splitting the m = len(points) - 1 units between them.

    m < 2 * factor: no split (only the end). Otherwise m // factor parts of
    ``factor`` units, the remainder spread one unit each over the parts, placed
    so that the longest part is shortest (first such placement on ties).
    """
    m = len(points) - 1
    if m < 2 * factor:
        return [int(points[-1])]
    q, r = divmod(m, factor)
    best, best_length = None, np.inf
    for extra in combinations(range(q), r):
        sizes = [factor + (k in extra) for k in range(q)]
        cut = np.concatenate([[0], np.cumsum(sizes)])
        length = np.max(np.diff(arclength[points[cut]]))
        if length < best_length * (1 - 1e-12):
            best, best_length = cut, length
    return [int(p) for p in points[best[1:]]]


@dataclass(frozen=True)
class CoarseMesh:
    """A coarse 1D mesh on a boundary part, nested in the fine boundary edges.

    ``nodes[c]`` holds the positions (indices into ``chains[c].vertices``,
    position ``n_edges`` meaning the chain's end) of the coarse nodes of chain c.
    ``free[c]`` says for the first and the last node of an open chain whether the P1
    space has a dof there (a free end, where the part meets Gamma_N or a kink) or not
    (a fixed end: its value is prescribed, zero or lifted from the data; the thesis'
    C_h~ of (3.61) has only fixed ends). ``breaks`` are the fine vertices where chains
    are cut (kinks).

    As the space of the boundary multipliers it says what the rest of the code needs to know
    of it (the thesis' P1 hats here; :class:`~ngdual.boundary.coarse_order.CoarseOrderMesh`
    and :class:`~ngdual.boundary.facet.FacetMesh` say it of theirs): ``traces``, whether the
    multipliers are P_k on every fine edge, the normal traces of RT_k themselves, so that
    their moments are the traces and the friction law bounds every moment; ``curve_normal``,
    whether d_C of (3.24) pairs them with the normal of the boundary curve rather than with
    that of its chords (the thesis' hats at order 0 take the chords').
    """

    traces: ClassVar[bool] = False
    curve_normal: ClassVar[bool] = False

    chains: tuple[Chain, ...]
    nodes: tuple[np.ndarray, ...]
    free: tuple[tuple[bool, bool], ...] = ()
    breaks: frozenset = frozenset()

    def __post_init__(self):
        if not self.free:
            object.__setattr__(self, "free", tuple((False, False) for _ in self.chains))

    @classmethod
    def from_fine(cls, mesh: ngs.Mesh, labels: list[str], factor: int,
                  ends: EndRule | None = None) -> CoarseMesh:
        """Group the fine boundary edges of ``labels`` ``factor`` at a time.

        ``ends`` says where chains break and which chain ends are free (default: no
        breaks, all ends fixed).
        """
        ends = ends or EndRule()
        chains = tuple(boundary_chains(mesh, labels, ends.breaks))
        return cls(chains, tuple(_group(c.n_edges, factor) for c in chains),
                   ends.free_ends(chains), ends.breaks)

    def coarsened(self, factor: int) -> CoarseMesh:
        """Group this mesh's edges ``factor`` at a time (h^ = factor * h~, nested)."""
        return CoarseMesh(self.chains,
                          tuple(n[_group(len(n) - 1, factor)] for n in self.nodes),
                          self.free, self.breaks)

    def follow(self, mesh: ngs.Mesh, labels: list[str], factor: int,
               ends: EndRule | None = None) -> CoarseMesh:
        """This coarse mesh carried over to the (locally) refined fine ``mesh``.

        Netgen keeps the numbers of the old vertices when it refines, so every
        old coarse node is still a fine vertex. Each old coarse edge E now
        holds m fine edges: if m >= 2 * factor, E is split at fine vertices
        into m // factor edges of ``factor`` or ``factor + 1`` fine edges
        (where the extra ones go is chosen to make the longest part shortest);
        otherwise E is kept. Guarantees, by induction over the steps:

        * every coarse edge is a union of fine edges (nesting of Section 3.2);
        * the coarse meshes are nested: the old coarse nodes are kept;
        * a coarse edge made by :meth:`from_fine` or by a split holds between
          ``factor`` and ``2 * factor - 1`` fine edges, and keeps doing so
          (a kept edge has m < 2 * factor), so h~/h stays within
          [1, 2 * factor - 1] times the ratio of neighbouring fine edge lengths:
          h~ ~ factor * h locally, however strongly the mesh is graded.

        Under uniform refinement this reproduces :meth:`from_fine` of the finer level.
        """
        ends = ends or EndRule(self.breaks)
        chains = tuple(boundary_chains(mesh, labels, ends.breaks))
        followed = self._follow(chains, [np.arange(c.n_edges + 1) for c in chains], factor)
        return CoarseMesh(followed.chains, followed.nodes, ends.free_ends(chains), ends.breaks)

    def follow_within(self, fine: CoarseMesh, factor: int) -> CoarseMesh:
        """This h^ mesh carried over to the refined h~ mesh ``fine`` (see :meth:`follow`).

        The units are now the edges of ``fine``: h^ edges stay unions of
        ``factor`` to ``2 * factor - 1`` h~ edges and nested across steps.
        """
        followed = self._follow(fine.chains, list(fine.nodes), factor)
        return CoarseMesh(followed.chains, followed.nodes, fine.free, fine.breaks)

    def _follow(self, chains: tuple[Chain, ...], units: list[np.ndarray],
                factor: int) -> CoarseMesh:
        """Split the old coarse edges at the positions ``units`` of each new chain."""
        if len(chains) != len(self.chains):
            raise ValueError("the refined boundary has a different number of chains")
        nodes = []
        for new, unit in zip(chains, units):
            position = {int(v): p for p, v in enumerate(new.vertices)}
            # the old chain whose vertices all lie on the new one (chains cut at a kink
            # share the kink vertex, so one vertex does not identify a chain)
            old = next(c for c, ch in enumerate(self.chains)
                       if all(int(v) in position for v in ch.vertices))
            old_vertices = self.chains[old].path_vertices[self.nodes[old]]
            if new.closed:
                corners = sorted(position[int(v)] for v in old_vertices[:-1]) + [new.n_edges]
            else:
                corners = sorted(position[int(v)] for v in old_vertices)
            if corners[0] != 0 or corners[-1] != new.n_edges:
                raise ValueError("the old coarse nodes do not span the refined chain")
            s = new.arclength
            out = [0]
            for a, b in zip(corners[:-1], corners[1:]):
                inner = unit[(unit > a) & (unit < b)]
                out.extend(_split(np.concatenate([[a], inner, [b]]), s, factor))
            nodes.append(np.array(out))
        return CoarseMesh(chains, tuple(nodes))

    @property
    def n_edges(self) -> int:
        return sum(len(n) - 1 for n in self.nodes)

    def dof_positions(self, c: int) -> np.ndarray:
        """Coarse node positions carrying a dof: all but the fixed ends of an open chain."""
        n = self.nodes[c]
        if self.chains[c].closed:
            return n[:-1]
        first, last = self.free[c]
        return n[(0 if first else 1):(len(n) if last else len(n) - 1)]

    def end_positions(self, c: int) -> np.ndarray:
        """Positions of the fixed end nodes of chain c (none for a closed chain)."""
        n = self.nodes[c]
        if self.chains[c].closed:
            return n[:0]
        return n[[k for k, free in zip((0, len(n) - 1), self.free[c]) if not free]]

    def end_points(self) -> np.ndarray:
        """Coordinates of the fixed end nodes, in the order of ``ends=True``."""
        pts = [self.chains[c].points[self.end_positions(c)] for c in range(len(self.chains))]
        return np.vstack(pts) if pts else np.zeros((0, 2))

    def end_normals(self) -> np.ndarray:
        """Outward unit normals of the fine edges at the fixed end nodes (``end_points``).

        At a fixed end the P1 hat lives on the end edge, whose normal is the one used.
        """
        out = []
        for c, chain in enumerate(self.chains):
            normals = edge_normals(chain)
            for pos in self.end_positions(c):
                out.append(normals[min(int(pos), chain.n_edges - 1)])
        return np.array(out).reshape(-1, 2)

    @property
    def n_p1_dofs(self) -> int:
        """dim of the coarse P1 space vanishing at the fixed ends of every open chain."""
        return sum(len(self.dof_positions(c)) for c in range(len(self.chains)))

    @property
    def n_coefficients(self) -> int:
        """The unknowns of the multiplier space: the nodal values of the P1 hats."""
        return self.n_p1_dofs

    def mass_stiffness(self) -> tuple[np.ndarray, np.ndarray]:
        """The mass matrix and the arc-length stiffness of the multiplier space on its
        unknowns (:meth:`p1_mass_stiffness`): what the H^{1/2} metric of the Uzawa
        algorithms is made of (:func:`ngdual.solvers.projections.metric_matrix`)."""
        return self.p1_mass_stiffness()

    def node_points(self) -> np.ndarray:
        """Coordinates of the coarse P1 dofs, in dof order."""
        out = []
        for c, chain in enumerate(self.chains):
            pos = self.dof_positions(c) % len(chain.vertices)
            out.append(chain.points[pos])
        return np.vstack(out) if out else np.zeros((0, 2))

    def edge_lengths(self) -> np.ndarray:
        """Lengths of all coarse edges, chain by chain."""
        return np.concatenate([np.diff(ch.arclength[n]) for ch, n in zip(self.chains, self.nodes)])

    def fine_edges(self) -> tuple[np.ndarray, np.ndarray]:
        """The fine edges chain by chain: their vertex pairs (n, 2) and the coarse edge of each.

        Coarse edges are numbered chain by chain as in :meth:`edge_lengths`.
        """
        pairs, owner, offset = [], [], 0
        for chain, nodes in zip(self.chains, self.nodes):
            verts = chain.path_vertices
            pairs.append(np.column_stack([verts[:-1], verts[1:]]))
            owner.append(offset + np.searchsorted(nodes, np.arange(chain.n_edges), "right") - 1)
            offset += len(nodes) - 1
        if not pairs:
            return np.zeros((0, 2), dtype=int), np.zeros(0, dtype=int)
        return np.vstack(pairs).astype(int), np.concatenate(owner)

    def fine_edge_dofs(self, space: ngs.FESpace) -> np.ndarray:
        """(n, 2) dofs of the fine P1 trace ``space`` at the start and the end of every fine
        edge, in the order of :meth:`fine_edges` (:func:`ngdual.mesh.edge_dofs`)."""
        vertices, _ = self.fine_edges()
        dofs = edge_dofs(space, vertices)
        if any(len(d) != 2 for d in dofs):
            raise RuntimeError("a fine edge has more than two dofs of the trace space")
        return np.array(dofs, dtype=int).reshape(-1, 2)

    def p1_prolongation(self, edge_dofs: np.ndarray, n_fine: int, ends: bool = False
                        ) -> sp.csr_matrix:
        """Matrix of the coarse P1 hats at both ends of every fine edge.

        With ``ends=True`` only the hats of the fixed chain end nodes (excluded from the
        space, but needed to lift non-zero end values) are returned.

        Parameters
        ----------
        edge_dofs : numpy.ndarray
            (n_fine_edges, 2) dofs of the fine trace space at the start and the end of every
            fine edge (:meth:`fine_edge_dofs`). The space may be continuous (phi on Gamma_N:
            neighbouring edges share the dof of their common vertex, where both give the
            hats the same value) or discontinuous from edge to edge (lambda on Gamma_C,
            needed at its kinks).
        n_fine : int
            Number of dofs of the fine trace space.

        Returns
        -------
        scipy.sparse.csr_matrix of shape (n_fine, n_p1_dofs).
        """
        entries = {}
        offset, edge = 0, 0
        for c, chain in enumerate(self.chains):
            s, nodes = chain.arclength, self.nodes[c]
            carriers = self.end_positions(c) if ends else self.dof_positions(c)
            dof_of_pos = {int(p): offset + k for k, p in enumerate(carriers)}
            offset += len(carriers)
            for k in range(chain.n_edges):
                e = np.searchsorted(nodes, k, side="right") - 1
                a, b = int(nodes[e]), int(nodes[e + 1])
                for end, p in enumerate((k, k + 1)):
                    t = (s[p] - s[a]) / (s[b] - s[a])
                    for pos, w in ((a, 1 - t), (b, t)):
                        key = pos % chain.n_edges if chain.closed else pos
                        if key in dof_of_pos and w > 0:
                            entries[int(edge_dofs[edge + k, end]), dof_of_pos[key]] = w
            edge += chain.n_edges
        rows, cols = (np.array([rc[i] for rc in entries], dtype=int) for i in (0, 1))
        return sp.csr_matrix((list(entries.values()), (rows, cols)), shape=(n_fine, offset))

    def p1_mass_stiffness(self) -> tuple[np.ndarray, np.ndarray]:
        """Dense P1 mass M and arc-length stiffness L on the coarse dofs."""
        n = self.n_p1_dofs
        mass, stiff = np.zeros((n, n)), np.zeros((n, n))
        offset = 0
        for c, chain in enumerate(self.chains):
            interior = [int(p) for p in self.dof_positions(c)]
            local = {p: offset + k for k, p in enumerate(interior)}
            if chain.closed:
                local[chain.n_edges] = local[0]
            offset += len(interior)
            s, nodes = chain.arclength, self.nodes[c]
            for e in range(len(nodes) - 1):
                ell = s[nodes[e + 1]] - s[nodes[e]]
                ends = [local.get(int(nodes[e])), local.get(int(nodes[e + 1]))]
                me = ell / 6 * np.array([[2, 1], [1, 2]])
                ke = np.array([[1, -1], [-1, 1]]) / ell
                for i, gi in enumerate(ends):
                    for j, gj in enumerate(ends):
                        if gi is not None and gj is not None:
                            mass[gi, gj] += me[i, j]
                            stiff[gi, gj] += ke[i, j]
        return mass, stiff


class WithoutP1:
    """A :class:`CoarseMesh` whose multipliers are not the P1 hats on its nodes (the facet
    multipliers, the coarse ones of degree k + 1): the P1 space of the base class is refused,
    its own ``prolongation`` maps the unknowns. Listed before :class:`CoarseMesh`."""

    @property
    def n_p1_dofs(self) -> int:
        raise TypeError(f"{type(self).__name__} has no coarse P1 space")

    def p1_prolongation(self, edge_dofs, n_fine, ends=False):
        raise TypeError(f"{type(self).__name__} has no coarse P1 hats; use "
                        f"{type(self).__name__}.prolongation")

    def p1_mass_stiffness(self):
        raise TypeError(f"{type(self).__name__} has no coarse P1 space")


@dataclass(frozen=True)
class BoundaryMeshes:
    """The coarse meshes of a scene: h~ on Gamma_N and Gamma_C, h^ on Gamma_C (or None).

    :meth:`for_scene` groups the fine edges of a fresh mesh; :meth:`follow`
    carries the meshes over to a (locally) refined mesh, nested and with
    h~ ~ factor * h locally (see :meth:`CoarseMesh.follow`).
    """

    neumann: CoarseMesh | None
    contact: CoarseMesh | None
    friction: CoarseMesh | None

    @classmethod
    def for_scene(cls, scene, mesh: ngs.Mesh) -> BoundaryMeshes:
        """h~ = ``htilde_factor`` * h and h^ = ``hhat_factor`` * h~ on a fresh mesh."""
        factor = scene.contact.htilde_factor
        neumann = contact = friction = None
        if scene.labels("neumann"):
            neumann = CoarseMesh.from_fine(mesh, scene.labels("neumann"), factor,
                                           end_rule(scene, mesh, "neumann"))
        if scene.has_contact:
            contact = CoarseMesh.from_fine(mesh, scene.labels("contact"), factor,
                                           end_rule(scene, mesh, "contact"))
            if scene.has_friction:
                friction = contact.coarsened(scene.contact.hhat_factor)
        return cls(neumann, contact, friction)

    def follow(self, scene, mesh: ngs.Mesh) -> BoundaryMeshes:
        """These coarse meshes carried over to ``mesh``, a refinement of their fine mesh."""
        factor = scene.contact.htilde_factor
        neumann = contact = friction = None
        if self.neumann is not None:
            neumann = self.neumann.follow(mesh, scene.labels("neumann"), factor,
                                          end_rule(scene, mesh, "neumann"))
        if self.contact is not None:
            contact = self.contact.follow(mesh, scene.labels("contact"), factor,
                                          end_rule(scene, mesh, "contact"))
            if self.friction is not None:
                friction = self.friction.follow_within(contact, scene.contact.hhat_factor)
        return BoundaryMeshes(neumann, contact, friction)
