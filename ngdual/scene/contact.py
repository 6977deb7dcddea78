"""Gamma_C of a scene: where the contact sides meet the rest of the boundary (junctions), the
foundation line and the gap g it gives, points and normals on Gamma_C, the scene's round-off;
and the checks that Gamma_C can be posed (foundation or gap, ends, kinks, g >= 0, the Tresca
bound)."""

from __future__ import annotations

import numpy as np

from .. import geometry
from ..expr import Expression
from .domain import role_of
from .errors import Problems, SceneError
from .tables import CONTACT_ENDS, Contact, Scene
from .values import finite, show

KINK_ANGLE = 1e-6  # radians: two contact sides meeting at a larger angle form a kink


CUSP_ANGLE = np.pi * (1 - 1e-3)  # radians: a kink turning farther is a cusp (no normal cone)


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
