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

from .scene import contact_junctions


@dataclass(frozen=True)
class Chain:
    """A connected piece of a boundary part: fine vertices in order along it.

    ``ccw`` is true when the order runs with the boundary's orientation (the body on
    the left), which fixes the sign of the outward normals (:func:`edge_normals`).
    """

    vertices: np.ndarray
    points: np.ndarray
    closed: bool
    ccw: bool = True

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


def boundary_chains(mesh: ngs.Mesh, labels: list[str], breaks: frozenset = frozenset()
                    ) -> list[Chain]:
    """Order the fine boundary edges carrying one of ``labels`` into chains.

    A chain ends where the boundary part ends and at the vertices ``breaks`` (the kinks
    of Gamma_C, where the normal and tangential multipliers are discontinuous).
    """
    return [piece for chain in _chains(mesh, labels) for piece in _split_at(chain, breaks)]


def _split_at(chain: Chain, breaks: frozenset) -> list[Chain]:
    """``chain`` cut at the vertices in ``breaks`` (a closed chain opens at the first)."""
    cuts = [k for k, v in enumerate(chain.vertices) if int(v) in breaks]
    if not cuts:
        return [chain]
    verts, pts = chain.vertices, chain.points
    if chain.closed:
        k = cuts[0]
        verts = np.append(np.roll(verts, -k), verts[k])
        pts = np.vstack([np.roll(pts, -k, axis=0), pts[k:k + 1]])
        cuts = [c - k if c >= k else c - k + len(chain.vertices) for c in cuts]
        cuts = sorted(cuts) + [len(verts) - 1]
    else:
        cuts = [c for c in cuts if 0 < c < len(verts) - 1] + [len(verts) - 1]
    pieces, start = [], 0
    for c in cuts:
        if c > start:
            pieces.append(Chain(verts[start:c + 1], pts[start:c + 1], False, chain.ccw))
        start = c
    return pieces


def _chains(mesh: ngs.Mesh, labels: list[str]) -> list[Chain]:
    """Connected chains of the fine boundary edges carrying one of ``labels``."""
    wanted = set(labels)
    segments = [tuple(v.nr for v in el.vertices) for el in mesh.Elements(ngs.BND)
                if el.mat in wanted]
    directed = set(segments)
    neighbours: dict[int, list[int]] = {}
    for a, b in segments:
        neighbours.setdefault(a, []).append(b)
        neighbours.setdefault(b, []).append(a)
    coords = mesh.ngmesh.Coordinates()  # (nv, 2), in the vertex numbers of NGSolve
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
        ccw = (order[0], order[1]) in directed
        chains.append(Chain(verts, coords[verts], closed, ccw))
    return chains


def edge_normals(chain: Chain) -> np.ndarray:
    """Outward unit normals of the fine edges of ``chain``, in chain order."""
    d = np.diff(chain.path_points, axis=0)
    n = np.column_stack([d[:, 1], -d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]
    return n if chain.ccw else -n


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
class EndRule:
    """Where the chains of a boundary part break and which of their ends are free.

    ``breaks``: fine vertex numbers where a chain is cut; ``free_points``: coordinates
    of the chain ends that carry a dof (all other ends of open chains are fixed).
    """

    breaks: frozenset = frozenset()
    free_points: tuple = ()

    def is_free(self, point: np.ndarray) -> bool:
        return any(np.linalg.norm(point - q) <= 1e-9 * (1 + np.linalg.norm(q))
                   for q in self.free_points)

    def free_ends(self, chains) -> tuple[tuple[bool, bool], ...]:
        return tuple((False, False) if ch.closed
                     else (self.is_free(ch.points[0]), self.is_free(ch.points[-1]))
                     for ch in chains)


def end_rule(scene, mesh: ngs.Mesh, role: str) -> EndRule:
    """The :class:`EndRule` of Gamma_C (``role = "contact"``) or Gamma_N (``"neumann"``).

    Gamma_C breaks at its kinks, and its multipliers are free there; with
    ``contact.ends = "consistent"`` they are also free where Gamma_C meets Gamma_N, and
    phi on Gamma_N is free where Gamma_N meets Gamma_C. Every other end (where a part
    meets Gamma_D, and all ends for ``"thesis"``) is fixed (see :class:`ngdual.scene.Contact`).
    """
    junctions = contact_junctions(scene) if scene.has_contact else []
    kinks = [p for p, kind, _ in junctions if kind == "kink"]
    touching = [p for p, kind, _ in junctions if kind == "neumann"]
    consistent = scene.contact.ends == "consistent"
    if role == "contact":
        labels = set(scene.labels("contact"))
        # only the vertices of Gamma_C can be kinks (a full vertex scan costs seconds at L8)
        candidates = {v.nr: np.array(mesh[v].point) for el in mesh.Elements(ngs.BND)
                      if el.mat in labels for v in el.vertices} if kinks else {}
        breaks = frozenset(nr for nr, xy in candidates.items()
                           if any(np.linalg.norm(xy - k) <= 1e-9 * (1 + np.linalg.norm(k))
                                  for k in kinks))
        return EndRule(breaks, tuple(kinks) + (tuple(touching) if consistent else ()))
    return EndRule(frozenset(), tuple(touching) if consistent else ())


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
    """

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
            carriers = self.end_positions(c) if ends else self.dof_positions(c)
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

    def p1_edge_prolongation(self, edge_dofs: np.ndarray, n_fine: int, ends: bool = False
                             ) -> sp.csr_matrix:
        """The coarse P1 hats at both ends of every fine edge, for a fine space that is
        discontinuous from edge to edge (needed at the kinks of Gamma_C).

        ``edge_dofs`` (n_fine_edges, 2): the fine dofs at the start and the end of every
        fine edge, in the chain order of :meth:`fine_edges`. ``ends`` as in
        :meth:`p1_prolongation`. Returns a csr_matrix of shape (n_fine, n_dofs).
        """
        rows, cols, vals = [], [], []
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
                            rows.append(edge_dofs[edge + k, end])
                            cols.append(dof_of_pos[key])
                            vals.append(w)
            edge += chain.n_edges
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
