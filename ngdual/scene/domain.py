"""Checks of the domain: the polygon, its boundary parts, the foundation, the contact sides and
the formulas on them; and the contact data derived from a scene (junctions, samples, gap)."""

from __future__ import annotations

import re

import numpy as np

from .. import geometry
from ..expr import Expression, quote
from .tables import (
    CONTACT_ENDS,
    GEOMETRY_KINDS,
    ROLES,
    Contact,
    Geometry,
    Problems,
    Scene,
    SceneError,
    SceneTypeError,
)
from .values import field_type_problems, finite, positive, show

KINK_ANGLE = 1e-6  # radians: two contact sides meeting at a larger angle form a kink


CUSP_ANGLE = np.pi * (1 - 1e-3)


LABEL = re.compile(r"[A-Za-z0-9_-]+")


SHORT_SIDE = 1e-9  # relative to the diameter: shorter sides are degenerate (netgen crashes)


def round_off(scene: Scene) -> float:
    """The length below which distances, gaps and displacements of ``scene`` are zero in
    every check of the domain: :func:`ngdual.geometry.round_off` of its boundary, or of
    the point of its foundation line where that lies farther from the origin (the gap is
    computed from it)."""
    tolerance = geometry.round_off(scene.geometry.curves())
    if scene.contact.foundation is not None:
        point, _ = foundation_line(scene.contact)
        tolerance = max(tolerance, geometry.ROUND_OFF * float(np.abs(point).max()))
    return tolerance


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


def contact_junctions(scene: Scene) -> list[tuple[np.ndarray, str, float]]:
    """The end points of the contact sides and what meets Gamma_C there.

    Returns ``(point, kind, angle)`` for every corner of the boundary with a contact side
    on at least one side of it: kind ``"dirichlet"`` or ``"neumann"`` where Gamma_C meets
    that part, ``"kink"`` where two contact sides meet at an angle (the multipliers, which
    are normal and tangential components, are discontinuous there), ``"smooth"`` where
    they meet tangentially (one multiplier runs through); ``angle`` is the boundary's
    turning angle there (:func:`ngdual.geometry.turning_angle`).
    """
    curves = scene.geometry.curves()
    out = []
    for i, before in enumerate(curves):
        after = curves[(i + 1) % len(curves)]
        roles = (role_of(scene, before.label), role_of(scene, after.label))
        if "contact" not in roles:
            continue
        angle = geometry.turning_angle(before, after)
        if roles == ("contact", "contact"):
            kind = "kink" if abs(angle) > KINK_ANGLE else "smooth"
        else:
            kind = roles[1] if roles[0] == "contact" else roles[0]
        out.append((before.end, kind, angle))
    return out


def contact_samples(scene: Scene, per_side: int = 401) -> tuple[np.ndarray, np.ndarray]:
    """Points on Gamma_C and the outward normals there (``per_side`` per contact side)."""
    pts, normals = [], []
    for curve in scene.geometry.curves():
        if curve.label in scene.labels("contact"):
            xy, n = curve.sample(per_side)
            pts.append(xy)
            normals.append(n)
    return np.vstack(pts), np.vstack(normals)


def foundation_line(contact: Contact) -> tuple[np.ndarray, np.ndarray]:
    """Point and unit normal (towards the body) of the foundation line."""
    f = contact.foundation
    normal = np.asarray(f["normal"], dtype=float)
    return np.asarray(f["point"], dtype=float), normal / np.linalg.norm(normal)


def foundation_gap(contact: Contact, x, y, n_x, n_y):
    """The gap g from the foundation line at (x, y) with outward normal n = (n_x, n_y): the
    distance along n to the line through p with unit normal n_f (towards the body),

        g = (x - p) . n_f / (-n . n_f),

    for numpy arrays (:func:`gap_at`) and NGSolve coefficient functions alike
    (:func:`ngdual.contact.gap_coefficient`, where n is NGSolve's normal).
    """
    point, n_f = foundation_line(contact)
    return ((x - point[0]) * n_f[0] + (y - point[1]) * n_f[1]) / (-(n_x * n_f[0] + n_y * n_f[1]))


def gap_at(contact: Contact, xy: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """The gap g at points of Gamma_C with outward normals ``normals`` (see :class:`Contact`)."""
    if contact.foundation is None:
        return Expression(contact.gap_formula).numpy(xy[:, 0], xy[:, 1])
    return foundation_gap(contact, xy[:, 0], xy[:, 1], normals[:, 0], normals[:, 1])


def _validate_foundation(scene: Scene) -> None:
    f = scene.contact.foundation
    if not isinstance(f, dict) or set(f) != {"point", "normal"}:
        raise SceneError("contact.foundation", "must be a table {point = [x, y], normal = "
                                               f"[nx, ny]}}, got {show(f)}")
    for key in ("point", "normal"):
        v = f[key]
        ok = isinstance(v, (list, tuple)) and len(v) == 2 and all(
            finite(c) for c in v)
        if not ok:
            raise SceneError(f"contact.foundation.{key}", f"must be a pair of numbers, got "
                                                          f"{show(v)}")
    if np.linalg.norm(np.asarray(f["normal"], dtype=float)) == 0:
        raise SceneError("contact.foundation.normal", "must not be zero")
    if scene.contact.gap is not None:
        raise SceneError("contact.gap", "give either a gap formula or a foundation line, "
                                        "not both (the foundation determines the gap)")
    point, n_f = foundation_line(scene.contact)
    body = geometry.outline(scene.geometry.curves(), per_arc=401)
    depth = (body - point) @ n_f
    if depth.min() < -round_off(scene):
        i = int(np.argmin(depth))
        raise SceneError("contact.foundation", f"the foundation cuts the body: the point "
                                               f"({body[i, 0]:.4g}, {body[i, 1]:.4g}) lies "
                                               f"{-depth[i]:.3g} behind the line")
    xy, normals = contact_samples(scene)
    facing = -(normals @ n_f)
    if facing.min() <= np.cos(np.radians(89)):
        i = int(np.argmin(facing))
        raise SceneError("contact.foundation", f"Gamma_C does not face the foundation at "
                                               f"({xy[i, 0]:.4g}, {xy[i, 1]:.4g}) (its normal "
                                               "is at 89 degrees or more from the line's); "
                                               "make that part a Neumann side")


def validate_contact(scene: Scene, u_d: list[Expression]) -> None:
    """Foundation or gap, ends, kinks: what Gamma_C needs to be posed (see :class:`Contact`)."""
    con = scene.contact
    if con.ends not in CONTACT_ENDS:
        raise SceneError("contact.ends", f"unknown choice {show(con.ends)}; use one of "
                                         + ", ".join(CONTACT_ENDS))
    if not scene.has_contact:
        if con.foundation is not None:
            raise SceneError("contact.foundation", "a foundation needs a contact boundary "
                                                   "(boundary.contact is empty)")
        return
    if con.foundation is not None:
        _validate_foundation(scene)
    junctions = contact_junctions(scene)
    for point, kind, angle in junctions:
        where = f"({point[0]:.4g}, {point[1]:.4g})"
        if con.ends == "thesis" and kind == "neumann":
            raise SceneError("contact.ends", f"Gamma_N touches Gamma_C at {where}: the "
                                             "thesis' zero ends assume they do not touch; "
                                             "use contact.ends = \"consistent\"")
        if kind == "kink":
            if angle < 0 or angle > CUSP_ANGLE:
                raise SceneError("boundary.contact", f"Gamma_C has a "
                                 f"{'re-entrant' if angle < 0 else 'cusp'} kink at {where} "
                                 "where no normal cone is defined; make one of the two "
                                 "sides a Neumann or Dirichlet side")
    ends = np.array([p for p, kind, _ in junctions if kind == "dirichlet"])
    if not len(ends):
        return
    values = np.column_stack([e.numpy(ends[:, 0], ends[:, 1]) for e in u_d])
    tolerance = round_off(scene)
    if con.ends == "thesis":
        if np.abs(values).max() > tolerance:
            raise SceneError("loads.displacement", "the prescribed displacement must vanish "
                                                   "where Gamma_D meets Gamma_C (the thesis' "
                                                   "contact multipliers are zero there)")
        return
    xy, normals = contact_samples(scene)
    for p, u in zip(ends, values):
        k = int(np.argmin(np.linalg.norm(xy - p, axis=1)))
        g = float(gap_at(con, xy[k:k + 1], normals[k:k + 1])[0])
        slide = abs(u @ geometry.tangent(normals[k]))
        if scene.friction.law != "none" and slide > tolerance:
            # the friction functional q(nu, lambda_t) is posed on the lambda_t dofs only
            raise SceneError("loads.displacement", f"with friction the prescribed "
                                                   f"displacement must not slide along "
                                                   f"Gamma_C where Gamma_D meets it (u_D.t = "
                                                   f"{slide:.3g} at ({p[0]:.4g}, {p[1]:.4g}))")
        if g < u @ normals[k] - tolerance:
            raise SceneError("contact.gap", f"where Gamma_D meets Gamma_C at ({p[0]:.4g}, "
                                            f"{p[1]:.4g}) the clamp pushes the body "
                                            f"{u @ normals[k]:.3g} into the foundation but "
                                            f"the gap is {g:.3g}: need g >= u_D.n there")


def validate_formulas_on_sides(scene: Scene, loads: dict[str, list[Expression]]) -> None:
    """Traction, boundary displacement, gap and Tresca bound where they act.

    Each formula must be finite on its closed sides (their end points are mesh vertices)
    and integrable there (:func:`_pole`). The body force and the quadrature points of the
    actual mesh are checked before assembly (:mod:`ngdual.quadrature_check`).
    """
    problems = Problems()
    curves = scene.geometry.curves()
    where = {"neumann": "Gamma_N", "dirichlet": "Gamma_D", "contact": "Gamma_C"}
    fields = [(f"loads.traction[{i}]", e, "neumann") for i, e in enumerate(loads["traction"])]
    fields += [(f"loads.displacement[{i}]", e, "dirichlet")
               for i, e in enumerate(loads["displacement"])]
    con, fr = scene.contact, scene.friction
    if scene.has_contact and con.foundation is None:
        fields.append(("contact.gap", Expression(con.gap_formula), "contact"))
    if fr.law == "tresca":
        fields.append(("friction.bound", Expression(fr.bound), "contact"))
    for name, expr, role in fields:
        with problems.check():
            _formula_on_sides(expr, name, [c for c in curves if c.label in scene.labels(role)],
                              where[role])
    problems.raise_any()


def validate_gap_and_bound(scene: Scene) -> None:
    """The gap must be >= 0 on Gamma_C, a Tresca bound >= 0 and not zero everywhere."""
    if not scene.has_contact:
        return
    problems = Problems()
    con, fr = scene.contact, scene.friction
    xy, normals = contact_samples(scene)
    x, y = xy[:, 0], xy[:, 1]
    g = gap_at(con, xy, normals)
    if not np.all(np.isfinite(g)):
        i = int(np.argmin(np.isfinite(g)))
        problems.add("contact.gap", f"not finite on Gamma_C at ({x[i]:.4g}, {y[i]:.4g})")
    elif g.min() < -round_off(scene):
        i = int(np.argmin(g))
        problems.add("contact.gap", f"negative gap {g[i]:.3g} at ({x[i]:.3g}, {y[i]:.3g}); "
                                    f"the gap must be >= 0 (to the scene's round-off "
                                    f"{round_off(scene):.2g})")
    if fr.law == "tresca":
        b = Expression(fr.bound).numpy(x, y)
        if b.min() < 0:
            i = int(np.argmin(b))
            problems.add("friction.bound", f"the Tresca bound F must be >= 0 on Gamma_C, got "
                                           f"{b[i]:.3g} at ({x[i]:.4g}, {y[i]:.4g})")
        elif b.max() == 0:
            problems.add("friction.bound", "Tresca friction needs a bound F > 0 on part of "
                                           "Gamma_C (F = 0 everywhere is frictionless: use "
                                           "friction.law = \"none\")")
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
