"""Checks of the domain: the polygon (points, labels, arcs, mesh sizes), its boundary parts
(one condition per side, a Dirichlet side) and the formulas on them (finite and integrable
where they act). Gamma_C's own data and checks are in :mod:`.contact`."""

from __future__ import annotations

import re

import numpy as np

from .. import geometry
from ..expr import Expression, quote
from .errors import Problems, SceneError, SceneTypeError
from .tables import GEOMETRY_KINDS, ROLES, Geometry, Scene
from .values import field_type_problems, finite, positive, show

LABEL = re.compile(r"[A-Za-z0-9_-]+")


SHORT_SIDE = 1e-9  # relative to the diameter: shorter sides are degenerate (netgen crashes)


def _side_table(geo: Geometry, key: str, value: str) -> list[tuple[str, object]]:
    """The entries of ``geometry.<key>``, a table side label -> ``value``, labels checked."""
    table = getattr(geo, key)
    if not isinstance(table, dict):
        raise SceneError(f"geometry.{key}", f"must be a table label = {value}")
    for label in table:
        if label not in geo.labels:
            raise SceneError(f"geometry.{key}.{label}", f"unknown side label {show(label)}; the "
                                                        f"sides are {', '.join(geo.labels)}")
    return list(table.items())


def _validate_points(geo: Geometry) -> np.ndarray:
    """The polygon's vertices as an array; refuses non-numbers and degenerate polygons."""
    if not isinstance(geo.points, (list, tuple)) or len(geo.points) < 3:
        raise SceneError("geometry.points", f"need at least three [x, y] points, got "
                                            f"{show(geo.points)}")
    problems = Problems()
    for i, p in enumerate(geo.points):
        if not (isinstance(p, (list, tuple)) and len(p) == 2 and all(finite(c) for c in p)):
            problems.add(f"geometry.points[{i}]", f"must be a pair of finite numbers [x, y], "
                                                  f"got {show(p)}")
    if not isinstance(geo.labels, (list, tuple)) or not all(
            isinstance(lab, str) and LABEL.fullmatch(lab) for lab in geo.labels):
        # labels become netgen boundary names, selected by regular expressions
        problems.add("geometry.labels", f"must be a list of names made of letters, digits, "
                                        f"'_' and '-', got {show(geo.labels)}")
    elif len(geo.labels) != len(geo.points):
        problems.add("geometry.labels", f"need one label per side ({len(geo.points)}), "
                                        f"got {len(geo.labels)}")
    problems.raise_any()
    pts = np.asarray(geo.points, dtype=float)
    size = float(np.ptp(pts, axis=0).max())
    if size > 1e100 or size < 1e-100:
        raise SceneError("geometry.points", f"the polygon's size {size:.3g} is outside "
                                            "[1e-100, 1e100]; rescale the units")
    # coincident vertices give zero-length sides or touching boundaries, which netgen
    # cannot mesh (a zero-length side crashes it), so they are refused before meshing
    for i in range(len(pts)):
        for j in range(i + 1, len(pts)):
            if np.linalg.norm(pts[i] - pts[j]) <= SHORT_SIDE * size:
                where = f"({pts[i, 0]:.4g}, {pts[i, 1]:.4g})"
                if j == i + 1 or (i == 0 and j == len(pts) - 1):
                    side = i if j == i + 1 else j
                    raise SceneError("geometry.points", f"points[{i}] and points[{j}] "
                                     f"coincide at {where}: side {side} "
                                     f"({show(geo.labels[side])}) has zero length; remove the "
                                     "repeated point")
                raise SceneError("geometry.points", f"points[{i}] and points[{j}] coincide "
                                                    f"at {where}: the boundary touches itself")
    return pts


def validate_geometry(geo: Geometry) -> None:
    """Raise a :class:`SceneError` for a geometry that cannot be meshed (checked before
    netgen sees it: a zero-length side crashes netgen, a self-intersecting one hangs it)."""
    if not isinstance(geo, Geometry):
        raise SceneTypeError("geometry", f"must be an ngdual.scene.Geometry, got "
                                         f"{type(geo).__name__}")
    wrong = [(f, m) for f, m in field_type_problems("geometry", geo)]
    if wrong:
        raise SceneError("", "", wrong)
    if geo.kind not in GEOMETRY_KINDS:
        raise SceneError("geometry.kind", f"unknown kind {show(geo.kind)}; use one of "
                                          + ", ".join(GEOMETRY_KINDS))
    positive(geo.level, "geometry.level", integer=True)
    if geo.kind != "polygon":
        for key in ("arcs", "side_maxh", "points", "labels"):
            if getattr(geo, key):
                raise SceneError(f"geometry.{key}", f"{key} needs kind = \"polygon\" (the "
                                                    f"{show(geo.kind)} geometry is fixed)")
        return
    _validate_points(geo)
    for label, centre in _side_table(geo, "arcs", "[x, y] (the arc's centre)"):
        ok = isinstance(centre, (list, tuple)) and len(centre) == 2 and all(
            finite(c) for c in centre)
        if not ok:
            raise SceneError(f"geometry.arcs.{label}", f"the centre must be [x, y], got "
                                                       f"{show(centre)}")
    for label, h in _side_table(geo, "side_maxh", "mesh size"):
        positive(h, f"geometry.side_maxh.{label}")
    curves = geo.curves()
    tolerance = geometry.round_off(curves)
    for curve in curves:
        problem = curve.arc_error(tolerance)
        if problem:
            raise SceneError(f"geometry.arcs.{curve.label}", problem)
    poly = geometry.outline(curves)
    hit = geometry.self_intersection(poly)
    if hit is not None:
        field_name = "geometry.arcs" if geo.arcs else "geometry.points"
        raise SceneError(field_name, f"the boundary intersects itself at ({hit[0]:.4g}, "
                                     f"{hit[1]:.4g})")
    if geometry.signed_area(poly) <= 0:
        raise SceneError("geometry.points", "the polygon must be listed counter-clockwise "
                                            "and have positive area")
    positive(geo.maxh, "geometry.maxh")


def validate_boundary(scene: Scene) -> None:
    """Raise a :class:`SceneError` unless every side has exactly one condition (dirichlet,
    neumann or contact) and at least one side is clamped."""
    sides = scene.geometry.sides()
    known = {label for label, _, _ in sides}
    seen: dict[str, str] = {}
    for role, labels in scene.boundary.items():
        for label in labels:
            if label not in known:
                raise SceneError(f"boundary.{role}", f"unknown boundary label {show(label)}; the "
                                                     f"geometry has {', '.join(sorted(known))}")
            if label in seen:
                raise SceneError(f"boundary.{role}", f"label {show(label)} is already "
                                                     f"{seen[label]}")
            seen[label] = role
    missing = sorted(known - set(seen))
    if missing:
        raise SceneError("boundary", f"boundary label {show(missing[0])} has no condition; "
                                     "list it under dirichlet, neumann or contact")
    if not scene.labels("dirichlet"):
        raise SceneError("boundary.dirichlet", "at least one Dirichlet side is needed "
                                               "(rigid body motions are not excluded otherwise)")


def role_of(scene: Scene, label: str) -> str:
    """dirichlet, neumann or contact: the condition on the sides labelled ``label``."""
    return next(role for role in ROLES if label in scene.labels(role))


def validate_formulas_on_sides(scene: Scene, loads: dict[str, list[Expression]]) -> None:
    """Traction, boundary displacement, gap and Tresca bound where they act.

    Each formula must be finite on its closed sides (their end points are mesh vertices)
    and integrable there (:func:`_pole`). The body force and the quadrature points of the
    actual mesh are checked before assembly (:mod:`ngdual.quadrature_check`).
    """
    problems = Problems()
    curves = scene.geometry.curves()
    if isinstance(scene.loads.traction, dict):  # each pair on its own side
        fields = [(f"loads.traction.{label}[{i}]", e, [label], "Gamma_N")
                  for label, both in loads["traction"].items() for i, e in enumerate(both)]
    else:  # the one pair of every side, checked on all of them together
        both = next(iter(loads["traction"].values()), [])
        fields = [(f"loads.traction[{i}]", e, scene.labels("neumann"), "Gamma_N")
                  for i, e in enumerate(both)]
    fields += [(f"loads.displacement[{i}]", e, scene.labels("dirichlet"), "Gamma_D")
               for i, e in enumerate(loads["displacement"])]
    con, fr = scene.contact, scene.friction
    if scene.has_contact and con.foundation is None:
        fields.append(("contact.gap", Expression(con.gap_formula), scene.labels("contact"),
                       "Gamma_C"))
    if fr.law == "tresca":
        fields.append(("friction.bound", Expression(fr.bound), scene.labels("contact"),
                       "Gamma_C"))
    for name, expr, labels, where in fields:
        with problems.check():
            _formula_on_sides(expr, name, [c for c in curves if c.label in labels], where)
    problems.raise_any()


PROBE_POINTS = 8192   # samples per side in which the largest values of a formula are sought


POLE_ORDER = 0.99     # |f| ~ |s - a|^-p near a with p >= 1 is not integrable


def _formula_on_sides(expr: Expression, field_name: str, curves: list, where: str) -> None:
    """Refuse a formula that is not finite, or not integrable, on the closed ``curves``."""
    if expr.constant is not None:  # folded and checked finite at parse time
        return
    for curve in curves:
        s = np.concatenate([[0.0, 1.0], (np.arange(PROBE_POINTS) + 0.5) / PROBE_POINTS])
        xy = curve.at(s)
        values = expr.numpy(xy[:, 0], xy[:, 1])
        bad = ~np.isfinite(values)
        if bad.any():
            i = int(np.argmax(bad))
            raise SceneError(field_name, f"{quote(expr.text)} is not finite on {where} at "
                                         f"({xy[i, 0]:.4g}, {xy[i, 1]:.4g}) "
                                         f"(value {values[i]})")
        pole = _pole(expr, curve, s, np.abs(values))
        if pole is not None:
            point, order, value = pole
            raise SceneError(field_name, f"{quote(expr.text)} is not integrable on {where}: "
                             f"|f| grows like 1/distance^{order:.2g} towards ({point[0]:.6g}, "
                             f"{point[1]:.6g})" + (f" (value {value})" if not
                                                   np.isfinite(value) else ""))


def _pole(expr: Expression, curve, s: np.ndarray, values: np.ndarray):
    """``(point, order, value)`` of a non-integrable singularity of ``expr`` on ``curve``.

    The (up to) three largest sampled values of |f| are zoomed in on together (the
    largest value in a window shrinking 20x per step locates a maximum to round-off),
    and the growth of |f| towards each measured between the distances 1e-7 and 1e-10
    (in the side's parameter): a pole |s - a|^-p gives the order p, a bounded or merely
    steep function about 0, a logarithm about 0.1. None when every order is below 1.
    """
    def f(t):
        q = curve.at(np.clip(t, 0.0, 1.0).ravel())
        return np.abs(expr.numpy(q[:, 0], q[:, 1])).reshape(np.shape(t))

    width = 1.0 / PROBE_POINTS
    starts: list[float] = []
    for i in np.argsort(values)[::-1][:64]:
        if len(starts) < 3 and all(abs(s[i] - t) >= 4 * width for t in starts):
            starts.append(float(s[i]))
    a, w = np.array(starts), width
    offsets = np.linspace(-1.0, 1.0, 41)
    for _ in range(8):
        t = a[:, None] + w * offsets[None, :]
        v = f(t)
        # a non-finite value is the singular point itself
        v = np.where(np.isfinite(v), v, np.inf)
        a, w = t[np.arange(len(a)), np.argmax(v, axis=1)], w / 20
    probes = a[:, None] + np.array([-1e-10, -1e-7, 1e-10, 1e-7])[None, :]
    v = f(probes)
    peaks = f(a)
    inside = (probes >= 0) & (probes <= 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        orders = np.log10(v[:, [0, 2]] / v[:, [1, 3]]) / 3
    orders = np.where(inside[:, [0, 2]] & inside[:, [1, 3]] & (v[:, [1, 3]] > 0),
                      np.nan_to_num(orders, nan=0.0, posinf=np.inf), 0.0).max(axis=1)
    for k in range(len(a)):
        if orders[k] >= POLE_ORDER:
            return curve.at(a[k:k + 1])[0], float(orders[k]), float(peaks[k])
    return None
