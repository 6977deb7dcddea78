"""Exact integrals of functions that are polynomial on every triangle piece between lines x = b.

An exact manufactured field that is piecewise polynomial in strips of x (see
:mod:`ngdual.verification.piecewise`) minus a finite element field is a polynomial on each
triangle that no breakpoint line x = b crosses; there a Gauss rule of the right order
integrates it exactly (NGSolve, element by element). A crossed triangle is clipped into
its strips, each piece fanned into triangles and integrated with the same rule, the
integrand evaluated at the mapped points. This keeps the errors exact when the end points
of the contact or stick sets do not lie on mesh lines (where a plain Gauss rule on the
crossed triangles misses a jump of div sigma by several percent).
"""

from __future__ import annotations

import ngsolve as ngs
import numpy as np

from ..mesh import mesh_arrays


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _clip(polygon: list[np.ndarray], x0: float, keep_right: bool) -> list[np.ndarray]:
    """Sutherland-Hodgman: the part of a convex polygon with x >= x0 (or x <= x0)."""
    def inside(p):
        return p[0] >= x0 if keep_right else p[0] <= x0

    out = []
    for k, p in enumerate(polygon):
        q = polygon[(k + 1) % len(polygon)]
        if inside(p):
            out.append(p)
        if inside(p) != inside(q):
            t = (x0 - p[0]) / (q[0] - p[0])
            out.append(p + t * (q - p))
    return out


def strip_pieces(triangle: np.ndarray, breaks) -> list[np.ndarray]:
    """Sub-triangles (k, 3, 2) covering ``triangle`` with none crossing a line x = b."""
    cuts = [-np.inf, *sorted(breaks), np.inf]
    pieces = []
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        poly = [np.asarray(p, float) for p in triangle]
        if np.isfinite(lo):
            poly = _clip(poly, lo, keep_right=True)
        if poly and np.isfinite(hi):
            poly = _clip(poly, hi, keep_right=False)
        if len(poly) < 3:
            continue
        for k in range(1, len(poly) - 1):
            tri = np.array([poly[0], poly[k], poly[k + 1]])
            area = 0.5 * abs(_cross(tri[1] - tri[0], tri[2] - tri[0]))
            if area > 1e-14 * (1.0 + np.ptp(triangle[:, 0]) * np.ptp(triangle[:, 1])):
                pieces.append(tri)
    return pieces


class PiecewiseQuadrature:
    """Exact quadrature on ``mesh`` for integrands polynomial of degree <= ``order`` on every
    piece of every triangle between the lines x = b, b in ``breaks``.

    The crossed triangles and their clipped quadrature points are found once; every
    :meth:`integrate` then costs one NGSolve integration and one point evaluation.
    """

    def __init__(self, mesh: ngs.Mesh, breaks, order: int):
        self.mesh, self.order = mesh, order
        points, triangles = mesh_arrays(mesh)
        breaks = np.asarray(sorted(set(breaks)), dtype=float)
        rule = ngs.IntegrationRule(ngs.TRIG, order)
        ref = np.array([p[:2] for p in rule.points])
        weights = np.array(rule.weights)
        xs = points[triangles][:, :, 0]
        lo, hi = xs.min(axis=1), xs.max(axis=1)
        crossed = np.any((breaks[None, :] > lo[:, None]) & (breaks[None, :] < hi[:, None]),
                         axis=1)
        self.crossed = np.flatnonzero(crossed)
        qx, qy, qw = [], [], []
        for e in self.crossed:
            inside = breaks[(breaks > lo[e]) & (breaks < hi[e])]
            for a, b, c in strip_pieces(points[triangles[e]], inside):
                mapped = (np.outer(ref[:, 0], a) + np.outer(ref[:, 1], b)
                          + np.outer(1.0 - ref.sum(axis=1), c))
                qx.append(mapped[:, 0])
                qy.append(mapped[:, 1])
                qw.append(abs(_cross(b - a, c - a)) * weights)   # 2 |piece| w
        self.weights = np.concatenate(qw) if qw else np.zeros(0)
        self.points = mesh(np.concatenate(qx), np.concatenate(qy)) if qx else None

    def integrate(self, cf: ngs.CoefficientFunction) -> float:
        """int_Omega cf dx (scalar ``cf``)."""
        per_element = ngs.Integrate(cf, self.mesh, order=self.order, element_wise=True).NumPy()
        total = float(per_element.sum() - per_element[self.crossed].sum())
        if self.points is not None:
            total += float(np.dot(self.weights, np.asarray(cf(self.points)).ravel()))
        return total
