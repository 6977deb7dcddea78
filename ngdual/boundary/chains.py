"""The fine boundary edges of a boundary part as chains, and where the chains break.

A chain is a connected piece of a boundary part: its fine vertices in order along it, with
the orientation that fixes the outward normals. Chains end where the part ends and at the
kinks of Gamma_C (:class:`EndRule`), where the normal and tangential multipliers are
discontinuous; which chain ends carry a multiplier dof is the end rule of the scene's
``contact.ends``.
"""

from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np

from ..geometry import right_normal, round_off
from ..scene import contact_junctions


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
    n = right_normal(d)
    return n if chain.ccw else -n


@dataclass(frozen=True)
class EndRule:
    """Where the chains of a boundary part break and which of their ends are free.

    ``breaks``: fine vertex numbers where a chain is cut; ``free_points``: coordinates
    of the chain ends that carry a dof (all other ends of open chains are fixed);
    ``tolerance``: the distance below which two points are the same (the scene's
    :func:`ngdual.geometry.round_off`).
    """

    breaks: frozenset = frozenset()
    free_points: tuple = ()
    tolerance: float = 0.0

    def is_free(self, point: np.ndarray) -> bool:
        return any(np.linalg.norm(point - q) <= self.tolerance for q in self.free_points)

    def free_ends(self, chains) -> tuple[tuple[bool, bool], ...]:
        return tuple((False, False) if ch.closed
                     else (self.is_free(ch.points[0]), self.is_free(ch.points[-1]))
                     for ch in chains)


def nearest_vertex(vertices: dict, point, tolerance: float = np.inf) -> int | None:
    """The number of the vertex of ``vertices`` (number -> position) nearest to ``point``,
    None when none lies within ``tolerance`` of it.

    >>> nearest_vertex({3: np.array([0.0, 0.0]), 7: np.array([1e-12, 0.0])}, (1e-12, 0.0))
    7
    """
    if not vertices:
        return None
    numbers = list(vertices)
    distances = np.linalg.norm(np.array([vertices[nr] for nr in numbers]) - point, axis=1)
    best = int(np.argmin(distances))
    return numbers[best] if distances[best] <= tolerance else None


def end_rule(scene, mesh: ngs.Mesh, role: str) -> EndRule:
    """The :class:`EndRule` of Gamma_C (``role = "contact"``) or Gamma_N (``"neumann"``).

    Gamma_C breaks at its kinks, and its multipliers are free there; with
    ``contact.ends = "consistent"`` they are also free where Gamma_C meets Gamma_N, and
    phi on Gamma_N is free where Gamma_N meets Gamma_C. Every other end (where a part
    meets Gamma_D, and all ends for ``"thesis"``) is fixed (see :class:`ngdual.scene.Contact`).
    """
    junctions = contact_junctions(scene) if scene.has_contact else []
    tolerance = round_off(scene.geometry.curves())
    kinks = [p for p, kind, _ in junctions if kind == "kink"]
    touching = [p for p, kind, _ in junctions if kind == "neumann"]
    consistent = scene.contact.ends == "consistent"
    if role == "contact":
        labels = set(scene.labels("contact"))
        # only the vertices of Gamma_C can be kinks (a full vertex scan costs seconds at L8)
        candidates = {v.nr: np.array(mesh[v].point) for el in mesh.Elements(ngs.BND)
                      if el.mat in labels for v in el.vertices} if kinks else {}
        # one vertex per kink, the nearest: a mesh graded to edges below the round-off near
        # a kink has several vertices within it, and each would cut Gamma_C into another chain
        breaks = frozenset(nr for nr in (nearest_vertex(candidates, k, tolerance)
                                         for k in kinks) if nr is not None)
        return EndRule(breaks, tuple(kinks) + (tuple(touching) if consistent else ()),
                       tolerance)
    return EndRule(frozenset(), tuple(touching) if consistent else (), tolerance)

