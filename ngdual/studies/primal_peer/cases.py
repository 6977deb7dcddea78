"""Hertz and Cattaneo-Mindlin on a block [-L, L] x [-H, 0] pushed into a rigid cylinder,
solved by the primal peer and compared with the half-plane solutions."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import ngsolve as ngs
import numpy as np
from netgen.geom2d import SplineGeometry

from ...verification import cattaneo_mindlin, hertz, mcewen_approach
from .nitsche import facet_integral, solve_primal
from .result import PrimalResult


def hertz_mesh(level: int, *, L: float = 4.0, H: float = 4.0, b: float = 0.25,
               hc: float = 0.025, maxh: float = 1.0, grading: float = 0.3,
               box: float = 0.3) -> ngs.Mesh:
    """The block [-L, L] x [-H, 0], graded towards the top centre, refined locally.

    Level 1 is a netgen mesh whose top side (label ``contact``) has edges of length ``hc`` on
    [-b, b] (``maxh`` elsewhere, netgen ``grading``); ``bottom``, ``right``, ``left`` are
    the other sides. Level k refines k-1 times every triangle whose centroid lies in
    |x| < box, y > -box (red refinement with a conforming closure), so the contact edges in
    [-b, b] have length hc / 2^(k-1) and the meshes are nested.
    """
    geo = SplineGeometry()
    pts = [(-L, -H), (L, -H), (L, 0.0), (b, 0.0), (-b, 0.0), (-L, 0.0)]
    labels = ["bottom", "right", "contact", "contact", "contact", "left"]
    ids = [geo.AppendPoint(px, py) for px, py in pts]
    for i, label in enumerate(labels):
        extra = {"maxh": hc} if i == 3 else {}
        geo.Append(["line", ids[i], ids[(i + 1) % len(ids)]], bc=label, leftdomain=1,
                   rightdomain=0, **extra)
    mesh = ngs.Mesh(geo.GenerateMesh(maxh=maxh, grading=grading))
    for _ in range(level - 1):
        pts = np.array([v.point for v in mesh.vertices])
        for el in mesh.Elements(ngs.VOL):
            cx, cy = pts[[v.nr for v in el.vertices]].mean(axis=0)
            mesh.SetRefinementFlag(el, bool(abs(cx) < box and cy > -box))
        mesh.Refine()
    return mesh


def hertz_pressure(x, P: float, R: float, E: float, nu: float):
    """The Hertz pressure of :func:`ngdual.verification.hertz` at ``x``; returns (p, a)."""
    contact = hertz(P, R, E, nu)
    return contact.pressure(np.asarray(x, float)), contact.a


def _ellipse_cf(p0: float, a: float):
    """p0 sqrt(1 - x^2/a^2) on |x| < a, 0 outside, as a CoefficientFunction."""
    w = 1 - ngs.x**2 / a**2
    # IfPos outside the sqrt, so that the CF is differentiable (see solve_primal)
    return p0 * ngs.IfPos(w, ngs.sqrt(ngs.IfPos(w, w, 1)), 0)


@dataclass
class HertzRow:
    """One Hertz solve: errors against the Hertz pressure of the computed force P."""

    level: int
    order: int
    ndof: int
    newton_iterations: int
    time_total: float
    time_assemble: float
    time_solve: float
    l2_error: float
    max_error: float
    a_hertz: float
    a_measured: float
    force: float
    reaction: float
    approach_ratio: float
    hc: float
    result: PrimalResult = field(repr=False)


def hertz_case(order: int, level: int, *, E: float = 1.0, nu: float = 0.3, R: float = 1.0,
               delta: float = 0.05, gamma0: float = 1.0, theta: float = -1.0,
               mesh_kw: dict | None = None) -> HertzRow:
    """Frictionless Hertz: bottom pushed up by ``delta``, gap x^2/(2R); errors vs Hertz.

    The Hertz pressure uses the computed total force P. ``l2_error`` is
    ||p_h - p_H||_{L2(Gamma_C)} / ||p_H||, ``max_error`` max |p_h - p_H| / p_H(0) over the
    edge midpoints, ``a_measured`` half the length of {p_h > 0}, ``reaction`` the Galerkin
    support force on the bottom (= P by equilibrium), ``approach_ratio`` u_y(0, -a) of the
    discrete solution over :func:`mcewen_approach` at depth a with the computed P.
    """
    kw = dict(mesh_kw or {})
    mesh = hertz_mesh(level, **kw)
    res = solve_primal(mesh, E=E, nu=nu, dirichlet=["bottom"], neumann=["left", "right"],
                       contact=["contact"], displacement=(0, delta), gap=f"x*x/(2*{R!r})",
                       order=order, law="none", gamma0=gamma0, theta=theta)
    P = res.contact_force
    p_mid, a = hertz_pressure(res.x_mid, P, R, E, nu)
    p0 = 2 * P / (math.pi * a)
    p_h = _ellipse_cf(p0, a)
    err2, norm2 = facet_integral([(res.pressure_cf - p_h) ** 2, p_h**2], mesh, ["contact"],
                                  bonus_intorder=12)
    uy = res.u(mesh(0.0, -a))[1] - res.u(mesh(0.0, 0.0))[1]
    hc = kw.get("hc", 0.025) / 2 ** (level - 1)
    return HertzRow(level=level, order=order, ndof=res.ndof,
                    newton_iterations=res.newton_iterations, time_total=res.times["total"],
                    time_assemble=res.times["assemble"], time_solve=res.times["solve"],
                    l2_error=math.sqrt(err2 / norm2),
                    max_error=float(np.max(np.abs(res.pressure_mid - p_mid)) / p0),
                    a_hertz=a, a_measured=res.contact_length / 2, force=P,
                    reaction=float(res.support_force[1]),
                    approach_ratio=uy / mcewen_approach(a, P, a, E, nu), hc=hc, result=res)


@dataclass
class CattaneoRow:
    """One Cattaneo-Mindlin solve: stick half-width and shear traction against the formula."""

    level: int
    order: int
    ndof: int
    newton_iterations: int
    time_total: float
    P: float
    Q: float
    a_hertz: float
    c_formula: float
    c_measured: float
    traction_l2_error: float
    hc: float
    result: PrimalResult = field(repr=False)


def cattaneo_mindlin_case(order: int, level: int, *, E: float = 1.0, nu: float = 0.49,
                          R: float = 1.0, delta: float = 0.05, shift: float = 0.012,
                          mu_f: float = 0.3, gamma0: float = 1.0, theta: float = -1.0,
                          law: str = "coulomb", mesh_kw: dict | None = None) -> CattaneoRow:
    """Hertz plus a tangential shift of the bottom, Coulomb (or Tresca) friction.

    With nu near 1/2 the normal and tangential problems decouple (Dundurs' parameter
    (1 - 2 nu) / (2 (1 - nu)) = 0.0196 for nu = 0.49; nu = 0.4999 makes P2 lock visibly
    and Newton slower) and the stick zone is |x| < c = a sqrt(1 - |Q|/(mu_f P)) with the
    shear traction q = -sign(shift) mu_f (p_H(x) - p0 (c/a) sqrt(1 - x^2/c^2) on |x| < c).
    For law="tresca" the bound is mu_f times the Hertz pressure of a frictionless solve
    first, so the same formulas apply. P1 locks at nu = 0.49 (P 26 % too large on the
    default meshes), so this case is for P2. ``c_measured`` is half the length of the stick set
    {|P_t| < s, p_h > 0}; ``traction_l2_error`` ||lambda_t - q|| / ||q|| on Gamma_C.
    """
    kw = dict(mesh_kw or {})
    mesh = hertz_mesh(level, **kw)
    common = dict(E=E, nu=nu, dirichlet=["bottom"], neumann=["left", "right"],
                  contact=["contact"], displacement=(shift, delta), gap=f"x*x/(2*{R!r})",
                  order=order, gamma0=gamma0, theta=theta)
    if law == "tresca":
        normal = solve_primal(mesh, **{**common, "displacement": (0, delta)}, law="none")
        a0 = hertz_pressure(0.0, normal.contact_force, R, E, nu)[1]
        bound = mu_f * _ellipse_cf(2 * normal.contact_force / (math.pi * a0), a0)
        res = solve_primal(mesh, **common, law="tresca", tresca_bound=bound)
    else:
        res = solve_primal(mesh, **common, law="coulomb", mu_f=mu_f)
    P, Q = res.contact_force, res.tangential_force
    exact = cattaneo_mindlin(P, Q, R, E, nu, mu_f)
    a, c, p0 = exact.hertz.a, exact.c, exact.hertz.p0
    q = -math.copysign(mu_f, shift) * (_ellipse_cf(p0, a) - _ellipse_cf(p0 * c / a, c))
    err2, norm2 = facet_integral([(res.traction_cf - q) ** 2, q**2], mesh, ["contact"],
                                  bonus_intorder=12)
    return CattaneoRow(level=level, order=order, ndof=res.ndof,
                       newton_iterations=res.newton_iterations, time_total=res.times["total"],
                       P=P, Q=Q, a_hertz=a, c_formula=c, c_measured=res.stick_length / 2,
                       traction_l2_error=math.sqrt(err2 / norm2),
                       hc=kw.get("hc", 0.025) / 2 ** (level - 1), result=res)
