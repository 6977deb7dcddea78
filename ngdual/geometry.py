"""The boundary of a scene's domain as curves: straight sides and circular arcs.

A polygon side ``i`` runs from ``points[i]`` to ``points[i+1]`` (counter-clockwise, the
body on its left). A side whose label is listed in ``geometry.arcs`` with a centre c is
the minor circular arc around c between its end points instead of the segment. The
outward unit normal n and the tangent t = (n_2, -n_1) of (3.24) are those of the curve.

This module holds the geometric facts that validation, meshing and the contact boundary
need from the scene (sampled curves, normals, the turning angle where two sides meet,
simplicity of the boundary), so none of them derives them on its own.

>>> s = Side("arc", np.array([-1.0, 0.0]), np.array([1.0, 0.0]), np.array([0.0, 1.0]))
>>> bool(np.allclose(s.sample(3)[0][1], [0.0, 1 - np.sqrt(2)]))
True
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MAX_ARC_PIECE = np.pi / 4  # netgen gets an arc as rational quadratic splines of <= 45 degrees

# Every geometric and sign check (coincident points, the foundation line, the gap >= 0, the
# values at the ends of Gamma_C, an arc's round-off) treats lengths below ROUND_OFF times
# the scene's length scale as zero (:func:`round_off`). Points, distances and gaps computed
# in double precision are off by a few eps = 2.2e-16 times the coordinates involved (the
# hertz-cylinder rotated by 30 degrees: gaps of -1.9e-15 on a domain of size 8); 1e-10 is
# five decades above that and far below any length a scene means.
ROUND_OFF = 1e-10


def tangent(normal):
    """t = (n_2, -n_1), the tangent of (3.24) to the outward unit normal n.

    ``normal`` is one normal or an array of them (..., 2), or NGSolve's normal coefficient
    function (``ngsolve.specialcf.normal(2)``), whose tangent is a coefficient function.
    Along a counter-clockwise boundary t runs against the direction of travel.

    >>> tangent(np.array([0.6, -0.8]))
    array([-0.8, -0.6])
    """
    if isinstance(normal, np.ndarray):
        return np.stack([normal[..., 1], -normal[..., 0]], axis=-1)
    import ngsolve as ngs  # here only: scenes are read and checked without NGSolve

    return ngs.CF((normal[1], -normal[0]))


def right_normal(direction: np.ndarray) -> np.ndarray:
    """The unit normal (d_2, -d_1) / |d| to the right of the direction d (..., 2): the
    outward normal of an edge traversed counter-clockwise around the domain.

    >>> right_normal(np.array([[2.0, 0.0]]))
    array([[ 0., -1.]])
    """
    return tangent(direction) / np.linalg.norm(direction, axis=-1)[..., None]


@dataclass(frozen=True)
class Side:
    """One side of the boundary: a segment, or a circular arc around ``center``."""

    label: str
    start: np.ndarray
    end: np.ndarray
    center: np.ndarray | None = None

    @property
    def is_arc(self) -> bool:
        return self.center is not None

    def _angles(self) -> tuple[float, float, float]:
        """Radius, start angle and signed sweep of the minor arc from start to end."""
        a, b = self.start - self.center, self.end - self.center
        sweep = float(np.arctan2(a[0] * b[1] - a[1] * b[0], a @ b))
        return float(np.linalg.norm(a)), float(np.arctan2(a[1], a[0])), sweep

    def sample(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """``n`` >= 2 points from start to end (equal parameter steps) and the outward normals."""
        return self.at(np.linspace(0.0, 1.0, n), normals=True)

    def at(self, s: np.ndarray, normals: bool = False):
        """The points at parameters ``s`` in [0, 1] (proportional to arc length), and with
        ``normals`` the outward unit normals there."""
        s = np.asarray(s, dtype=float)
        if not self.is_arc:
            d = self.end - self.start
            points = self.start + s[:, None] * d
            if not normals:
                return points
            normal = np.array([d[1], -d[0]]) / np.linalg.norm(d)
            return points, np.tile(normal, (len(s), 1))
        r, phi0, sweep = self._angles()
        phi = phi0 + s * sweep
        radial = np.column_stack([np.cos(phi), np.sin(phi)])
        if not normals:
            return self.center + r * radial
        # counter-clockwise sweep: the body lies to the left, i.e. inside the circle
        return self.center + r * radial, (radial if sweep > 0 else -radial)

    def tangent(self, at_end: bool) -> np.ndarray:
        """Unit tangent in the direction of travel at the start or the end of the side."""
        _, normals = self.sample(2)
        return -tangent(normals[-1 if at_end else 0])

    def spline_pieces(self) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """(start, control point, end) of rational quadratic splines that are the arc exactly."""
        r, phi0, sweep = self._angles()
        m = max(1, int(np.ceil(abs(sweep) / MAX_ARC_PIECE - 1e-9)))
        phi = phi0 + np.linspace(0.0, sweep, m + 1)
        pts = self.center + r * np.column_stack([np.cos(phi), np.sin(phi)])
        pieces = []
        for k in range(m):
            mid = 0.5 * (phi[k] + phi[k + 1])
            half = 0.5 * (phi[k + 1] - phi[k])
            # the tangents at both ends meet on the bisector at distance r / cos(half)
            control = self.center + r / np.cos(half) * np.array([np.cos(mid), np.sin(mid)])
            pieces.append((pts[k], control, pts[k + 1]))
        return pieces

    def arc_error(self, tolerance: float) -> str | None:
        """Why this arc is not a valid minor arc (None when it is).

        ``tolerance`` is the scene's :func:`round_off`. The points of an arc, c + r (cos phi,
        sin phi), carry a round-off of about eps (|c| + r); an arc whose points are not known
        to the scene's round-off (a radius above about 2e5 times the scene's length scale)
        is straight to double precision, and netgen fails on the largest ones.
        """
        if not self.is_arc:
            return None
        ra, rb = np.linalg.norm(self.start - self.center), np.linalg.norm(self.end - self.center)
        if min(ra, rb) <= 0 or abs(ra - rb) > 1e-6 * max(ra, rb):
            return (f"the end points of side {self.label!r} are at distances {ra:.6g} and "
                    f"{rb:.6g} from the centre; an arc needs equal distances")
        blur = np.finfo(float).eps * (float(np.abs(self.center).max()) + max(ra, rb))
        if blur > tolerance:
            return (f"side {self.label!r} has radius {max(ra, rb):.3g}: its points are known "
                    f"only to {blur:.2g} in double precision, more than the scene's round-off "
                    f"{tolerance:.2g}; make it a straight side (remove it from geometry.arcs) "
                    "or give a centre closer to it")
        _, _, sweep = self._angles()
        if abs(sweep) >= np.pi * (1 - 1e-9):
            return (f"side {self.label!r} spans 180 degrees or more; split it into two sides "
                    "(an arc is the shorter arc between its end points)")
        return None


def sides(points, labels, arcs: dict | None = None) -> list[Side]:
    """The sides of the boundary, counter-clockwise."""
    arr = np.asarray(points, dtype=float)
    arcs = arcs or {}
    out = []
    for i, label in enumerate(labels):
        center = arcs.get(label)
        out.append(Side(label, arr[i], arr[(i + 1) % len(arr)],
                        None if center is None else np.asarray(center, dtype=float)))
    return out


def outline(boundary: list[Side], per_arc: int = 64) -> np.ndarray:
    """The closed boundary as a polygon (arcs sampled), without repeating the first point."""
    pts = []
    for side in boundary:
        xy = side.sample(per_arc)[0] if side.is_arc else side.start[None, :]
        pts.append(xy[:-1] if side.is_arc else xy)
    return np.vstack(pts)


def length_scale(boundary: list[Side]) -> float:
    """The scene's length scale: the larger of the domain's size (the longest side of its
    bounding box) and the distance of its farthest point from the origin.

    Coordinates far from the origin carry a round-off in proportion to their size, so a
    translated copy of a domain has the length scale of where it lies.
    """
    poly = outline(boundary)
    return max(float(np.ptp(poly, axis=0).max()), float(np.abs(poly).max()))


def round_off(boundary: list[Side]) -> float:
    """The length below which two positions of the scene are the same: :data:`ROUND_OFF`
    times its :func:`length_scale`; every geometric and sign check compares with it."""
    return ROUND_OFF * length_scale(boundary)


def signed_area(poly: np.ndarray) -> float:
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def self_intersection(poly: np.ndarray) -> np.ndarray | None:
    """A point where two non-adjacent edges of the closed polygon meet (None if it is simple).

    Every pair of edges is screened at once (a pair that may meet: crossing within the
    tolerances of :func:`_segments_meet`, or parallel and collinear); the screened pairs are
    decided by :func:`_segments_meet` in the order (i, j), so the first meeting is returned."""
    a = np.asarray(poly, dtype=float)
    b = np.roll(a, -1, axis=0)
    n = len(a)
    i, j = np.triu_indices(n, 2)
    keep = ~((i == 0) & (j == n - 1))
    i, j = i[keep], j[keep]
    d1, d2, rp = b[i] - a[i], b[j] - a[j], a[j] - a[i]

    def cross(x, y):
        return x[:, 0] * y[:, 1] - x[:, 1] * y[:, 0]

    denom = cross(d1, d2)
    scale = np.maximum(np.einsum("ij,ij->i", d1, d1), np.einsum("ij,ij->i", d2, d2))
    parallel = np.abs(denom) <= 1e-14 * scale
    with np.errstate(divide="ignore", invalid="ignore"):
        t, u = cross(rp, d2) / denom, cross(rp, d1) / denom
    lo, hi = -1e-12, 1 + 1e-12
    crossing = ~parallel & (t >= lo) & (t <= hi) & (u >= lo) & (u <= hi)
    collinear = parallel & (np.abs(cross(rp, d1)) <= 1e-12 * scale)
    for k in np.flatnonzero(crossing | collinear):
        hit = _segments_meet(a[i[k]], b[i[k]], a[j[k]], b[j[k]])
        if hit is not None:
            return hit
    return None


def _segments_meet(p, q, r, s) -> np.ndarray | None:
    d1, d2 = q - p, s - r
    denom = d1[0] * d2[1] - d1[1] * d2[0]
    scale = max(np.linalg.norm(d1), np.linalg.norm(d2)) ** 2
    if abs(denom) <= 1e-14 * scale:
        # parallel: they meet only if collinear and overlapping
        if abs((r - p)[0] * d1[1] - (r - p)[1] * d1[0]) > 1e-12 * scale:
            return None
        t = [(x - p) @ d1 / (d1 @ d1) for x in (r, s)]
        return p + max(0.0, min(t)) * d1 if max(t) >= 0 and min(t) <= 1 else None
    t = ((r - p)[0] * d2[1] - (r - p)[1] * d2[0]) / denom
    u = ((r - p)[0] * d1[1] - (r - p)[1] * d1[0]) / denom
    if -1e-12 <= t <= 1 + 1e-12 and -1e-12 <= u <= 1 + 1e-12:
        return p + t * d1
    return None


def turning_angle(before: Side, after: Side) -> float:
    """Signed angle (radians) by which the boundary turns where ``before`` ends and ``after``
    starts: > 0 at a convex corner, < 0 at a re-entrant one, 0 where they join smoothly."""
    t0, t1 = before.tangent(at_end=True), after.tangent(at_end=False)
    return float(np.arctan2(t0[0] * t1[1] - t0[1] * t1[0], t0 @ t1))
