"""Coarse boundary meshes and the multiplier spaces on Gamma_N, Gamma_C and A_C.

The multipliers live on meshes coarser than the trace of T_h (Section 3.2):
phi, lambda_t, lambda_n on h~ = 2h (P1, zero at the end points of their
boundary part) and nu on h^ = h~ or 2h~ (P0). A coarse mesh is built from the
fine boundary edges of a boundary part: the edges are ordered into chains and
grouped ``factor`` at a time, so every fine edge lies entirely on one coarse
edge (the nesting assumed in Section 3.2) and h~ ~ factor * h locally, on
uniform and on locally refined meshes alike.

After a local refinement of T_h the coarse meshes follow the fine one
(:meth:`CoarseMesh.follow`, :class:`BoundaryMeshes`) instead of being grouped
afresh, which keeps them nested from one adaptive step to the next.

A coarse P1 function is represented by its values at the fine boundary
vertices: :meth:`CoarseMesh.p1_prolongation` is the matrix mapping coarse
nodal values to the nodal values of the fine trace space, through which all
forms assembled by NGSolve on the fine trace are restricted to the coarse space.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp


@dataclass(frozen=True)
class Chain:
    """A connected piece of a boundary part: fine vertices in order along it."""

    vertices: np.ndarray
    points: np.ndarray
    closed: bool

    @property
    def path_vertices(self) -> np.ndarray:
        """Vertices along the chain, the first repeated at the end of a closed chain."""
        return np.append(self.vertices, self.vertices[0]) if self.closed else self.vertices

    @property
    def path_points(self) -> np.ndarray:
        """Coordinates of :attr:`path_vertices`."""
        return np.vstack([self.points, self.points[:1]]) if self.closed else self.points

    @property
    def arclength(self) -> np.ndarray:
        """Arc length at every vertex of :attr:`path_points`."""
        steps = np.linalg.norm(np.diff(self.path_points, axis=0), axis=1)
        return np.concatenate([[0.0], np.cumsum(steps)])

    @property
    def n_edges(self) -> int:
        return len(self.vertices) if self.closed else len(self.vertices) - 1


def boundary_chains(mesh: ngs.Mesh, labels: list[str]) -> list[Chain]:
    """Order the fine boundary edges carrying one of ``labels`` into chains."""
    wanted = set(labels)
    segments = [tuple(v.nr for v in el.vertices) for el in mesh.Elements(ngs.BND)
                if el.mat in wanted]
    neighbours: dict[int, list[int]] = {}
    for a, b in segments:
        neighbours.setdefault(a, []).append(b)
        neighbours.setdefault(b, []).append(a)
    coords = {v.nr: v.point for v in mesh.vertices}
    unvisited, chains = set(neighbours), []
    while unvisited:
        ends = sorted(v for v in unvisited if len(neighbours[v]) == 1)
        start = ends[0] if ends else min(unvisited)
        order, prev = [start], None
        unvisited.discard(start)
        while True:
            nxt = [w for w in neighbours[order[-1]] if w != prev and w in unvisited]
            if not nxt:
                break
            prev = order[-1]
            order.append(nxt[0])
            unvisited.discard(nxt[0])
        closed = not ends
        verts = np.array(order)
        chains.append(Chain(verts, np.array([coords[v] for v in verts]), closed))
    return chains


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
    """

    chains: tuple[Chain, ...]
    nodes: tuple[np.ndarray, ...]

    @classmethod
    def from_fine(cls, mesh: ngs.Mesh, labels: list[str], factor: int) -> CoarseMesh:
        """Group the fine boundary edges of ``labels`` ``factor`` at a time."""
        chains = tuple(boundary_chains(mesh, labels))
        return cls(chains, tuple(_group(c.n_edges, factor) for c in chains))

    def coarsened(self, factor: int) -> CoarseMesh:
        """Group this mesh's edges ``factor`` at a time (h^ = factor * h~, nested)."""
        return CoarseMesh(self.chains,
                          tuple(n[_group(len(n) - 1, factor)] for n in self.nodes))

    def follow(self, mesh: ngs.Mesh, labels: list[str], factor: int) -> CoarseMesh:
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
        chains = tuple(boundary_chains(mesh, labels))
        return self._follow(chains, [np.arange(c.n_edges + 1) for c in chains], factor)

    def follow_within(self, fine: CoarseMesh, factor: int) -> CoarseMesh:
        """This h^ mesh carried over to the refined h~ mesh ``fine`` (see :meth:`follow`).

        The units are now the edges of ``fine``: h^ edges stay unions of
        ``factor`` to ``2 * factor - 1`` h~ edges and nested across steps.
        """
        return self._follow(fine.chains, list(fine.nodes), factor)

    def _follow(self, chains: tuple[Chain, ...], units: list[np.ndarray],
                factor: int) -> CoarseMesh:
        """Split the old coarse edges at the positions ``units`` of each new chain."""
        if len(chains) != len(self.chains):
            raise ValueError("the refined boundary has a different number of chains")
        nodes = []
        for new, unit in zip(chains, units):
            position = {int(v): p for p, v in enumerate(new.vertices)}
            old = next(c for c, ch in enumerate(self.chains) if int(ch.vertices[0]) in position)
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
        """Coarse node positions carrying a dof: all but the ends of an open chain."""
        n = self.nodes[c]
        return n[:-1] if self.chains[c].closed else n[1:-1]

    def _ends(self, c: int) -> np.ndarray:
        """Positions of the end nodes of chain c (none for a closed chain)."""
        n = self.nodes[c]
        return n[:0] if self.chains[c].closed else n[[0, -1]]

    def end_points(self) -> np.ndarray:
        """Coordinates of the end nodes of all open chains, in the order of ``ends=True``."""
        pts = [self.chains[c].points[self._ends(c)] for c in range(len(self.chains))]
        return np.vstack(pts) if pts else np.zeros((0, 2))

    @property
    def n_p1_dofs(self) -> int:
        """dim of the coarse P1 space vanishing at the ends of every open chain."""
        return sum(len(self.dof_positions(c)) for c in range(len(self.chains)))

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

    def p1_prolongation(self, fine_dof_of_vertex, n_fine: int, ends: bool = False
                        ) -> sp.csr_matrix:
        """Matrix of the coarse P1 hats evaluated at the fine vertices.

        With ``ends=True`` only the hats of the chain end nodes (excluded from the
        space, but needed to lift non-zero end values) are returned.

        Parameters
        ----------
        fine_dof_of_vertex : callable
            Maps a fine vertex number to its dof in the fine trace space.
        n_fine : int
            Number of dofs of the fine trace space.

        Returns
        -------
        scipy.sparse.csr_matrix of shape (n_fine, n_p1_dofs).
        """
        rows, cols, vals = [], [], []
        offset = 0
        for c, chain in enumerate(self.chains):
            s, nodes = chain.arclength, self.nodes[c]
            carriers = self._ends(c) if ends else self.dof_positions(c)
            dof_of_pos = {int(p): offset + k for k, p in enumerate(carriers)}
            offset += len(carriers)
            for e in range(len(nodes) - 1):
                a, b = nodes[e], nodes[e + 1]
                for p in range(a, b + 1):
                    if p == b and (b != nodes[-1] or chain.closed):
                        continue  # a shared node belongs to the next edge
                    t = (s[p] - s[a]) / (s[b] - s[a])
                    fine = fine_dof_of_vertex(int(chain.vertices[p % len(chain.vertices)]))
                    for pos, w in ((a, 1 - t), (b, t)):
                        key = int(pos) % chain.n_edges if chain.closed else int(pos)
                        if key in dof_of_pos and w > 0:
                            rows.append(fine)
                            cols.append(dof_of_pos[key])
                            vals.append(w)
        return sp.csr_matrix((vals, (rows, cols)), shape=(n_fine, offset))

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
            neumann = CoarseMesh.from_fine(mesh, scene.labels("neumann"), factor)
        if scene.has_contact:
            contact = CoarseMesh.from_fine(mesh, scene.labels("contact"), factor)
            if scene.has_friction:
                friction = contact.coarsened(scene.contact.hhat_factor)
        return cls(neumann, contact, friction)

    def follow(self, scene, mesh: ngs.Mesh) -> BoundaryMeshes:
        """These coarse meshes carried over to ``mesh``, a refinement of their fine mesh."""
        factor = scene.contact.htilde_factor
        neumann = contact = friction = None
        if self.neumann is not None:
            neumann = self.neumann.follow(mesh, scene.labels("neumann"), factor)
        if self.contact is not None:
            contact = self.contact.follow(mesh, scene.labels("contact"), factor)
            if self.friction is not None:
                friction = self.friction.follow_within(contact, scene.contact.hhat_factor)
        return BoundaryMeshes(neumann, contact, friction)
