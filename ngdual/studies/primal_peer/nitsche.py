"""A primal peer for contact: displacement finite elements with Nitsche contact (NGSolve).

This is "the method a user would pick instead" of ngdual's dual-dual mixed method: conforming
P1 or P2 Lagrange elements for the displacement of a 2D plane-strain elastic body, unilateral
contact with a rigid foundation (``u_n <= g`` on Gamma_C, n the body's outward normal) imposed
by Nitsche's method, frictionless or with Tresca / Coulomb friction, solved by a semismooth
(generalised) Newton method with a sparse direct solver (UMFPACK).

Nitsche's method (Chouly & Hild 2013; Chouly, Hild & Renard 2015). With beta = gamma / h,
gamma = gamma0 * E and h the length of the boundary edge (NGSolve's ``specialcf.mesh_size``
on a boundary integral),

    P_n(u)   = sigma_n(u) - beta (u_n - g),      P_n^theta(v) = theta sigma_n(v) - beta v_n,
    P_t(u)   = sigma_t(u) - beta u_t,            P_t^theta(v) = theta sigma_t(v) - beta v_t,

and the discrete problem is: find u (u = u_D on Gamma_D) such that for all v (v = 0 on Gamma_D)

    a(u, v) - int_C theta/beta sigma(u)n . sigma(v)n
            + int_C 1/beta [P_n(u)]_- P_n^theta(v) + int_C 1/beta [P_t(u)]_s P_t^theta(v) = L(v),

where [x]_- = min(x, 0), [x]_s the projection onto [-s, s], and s = 0 (frictionless, then the
tangential theta term is absent too), s = the Tresca bound (Chouly 2014), or
s = -mu_f [P_n(u)]_- (Coulomb, Chouly-Hild-Renard 2015). The contact pressure and the
tangential traction of the discrete solution are the Nitsche-consistent
p = -[P_n(u)]_- >= 0 and lambda_t = [P_t(u)]_s; their integrals are the contact forces, and
they balance the support force on Gamma_D (the residual there) up to quadrature.

theta and gamma0: the defaults are theta = -1 (skew-symmetric) and gamma0 = 1.
* theta = -1 is stable for every gamma0 > 0 (the Jacobian's linear part is
  a(v, v) + int beta v_n^2 or a(v, v) + int sigma_n(v)^2 / beta: coercive without a
  trace-inverse condition), so gamma0 can be chosen for accuracy alone, independently of the
  order and of lambda; theta = 0 and theta = 1 need gamma0 above a threshold proportional to
  (lambda + 2 mu) / E times the trace-inverse constant (which grows like order^2; Chouly,
  Hild & Renard 2015). With gamma = gamma0 E fixed by E, that threshold is about 17 times
  higher for nu = 0.49 (the Cattaneo-Mindlin case) than for nu = 0.3.
* gamma0 small, because with a curved gap the penalty term is inconsistent at the discrete level by
  beta (I_h g - g) ~ gamma0 E h / (8R) for P1 (u_n can only follow the parabola piecewise
  linearly), an O(gamma0 h / a) relative pressure error. Measured on Hertz
  (``--gamma-study --levels 1 3``): gamma0 = 100 gives P1 pressure errors of 60-110 % (the
  pressure becomes spikes between the quadrature points, whose integral is then 70 % off the
  Galerkin reaction on level 1), gamma0 = 10 about twice the errors of gamma0 = 1, and
  0.1 <= gamma0 <= 1 about the same errors with theta = -1; theta = 0 degrades at
  gamma0 = 0.1 (P2: 4.8 % instead of 1.3 %, its stability limit), and theta = 1 does not
  converge for gamma0 <= 1 (unstable). For Coulomb friction Newton failed for some
  gamma0 <= 0.1.
* The pressure reported is p = -[P_n(u_h)]_- (consistent for every theta). Newton takes
  about one or two more steps with theta = -1 than with theta = 0.

Error behaviour: the Hertz pressure has square-root edges at x = +-a, so the L2 pressure
error is O(h / a) for P1 and P2 alike; its constant depends on where +-a falls inside an
element and varies by a factor of up to about 4 between meshes (P2: 0.1 to 0.4, P1: 0.6 to
1.2 in units of h / a), so errors need not decrease between two consecutive levels; they do
over two levels (a factor 4 in h).

    python -m benchmarks.primal_peer                 # Hertz, P1 and P2, levels 1..5
    python -m benchmarks.primal_peer --cattaneo --orders 2 --hc 0.025 --levels 1 2 3 4
                                                     # Cattaneo-Mindlin (Coulomb), P2
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass, field

import ngsolve as ngs
import numpy as np
from netgen.geom2d import SplineGeometry
from threadpoolctl import threadpool_limits

from ngdual.expr import Expression
from ngdual.verification import cattaneo_mindlin, hertz, mcewen_approach

__all__ = ["NewtonError", "PrimalResult", "solve_primal", "solve_scene_primal",
           "primal_samples", "hertz_mesh", "hertz_case", "cattaneo_mindlin_case",
           "hertz_pressure"]


class NewtonError(RuntimeError):
    """The semismooth Newton iteration did not reach the tolerance."""


def _scalar(value) -> ngs.CoefficientFunction:
    if isinstance(value, ngs.CoefficientFunction):
        return value
    if isinstance(value, str):
        return Expression(value).coefficient()
    return ngs.CF(float(value))


def _vector(value) -> ngs.CoefficientFunction:
    if isinstance(value, ngs.CoefficientFunction):
        if value.dim != 2:
            raise ValueError(f"a vector load needs 2 components, got dim {value.dim}")
        return value
    if isinstance(value, str):
        raise ValueError("give a vector load as a pair, e.g. ('0', '-1')")
    first, second = value
    return ngs.CF((_scalar(first), _scalar(second)))


def _labels(value) -> list[str]:
    if value is None:
        return []
    if isinstance(value, str):
        return [value]
    return list(value)


def _strain(u):
    g = ngs.Grad(u)
    return 0.5 * (g + g.trans)


def _lame(E: float, nu: float) -> tuple[float, float]:
    return E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))


def _stress(u, mu: float, lam: float):
    eps = _strain(u)
    return 2 * mu * eps + lam * ngs.Trace(eps) * ngs.Id(2)


def _facet_integral(cfs, mesh: ngs.Mesh, labels: list[str], bonus_intorder: int = 8) -> list:
    """int over the boundary ``labels`` of each CF, evaluated from the volume side.

    ``ngs.Integrate`` on a boundary sees only the trace of a GridFunction (its Grad is 0
    there); a skeleton ``ds`` in a LinearForm evaluates volume gradients, so the integrals
    are the sums of such linear forms tested with the facet-wise constant 1.
    """
    space = ngs.FacetFESpace(mesh, order=0)
    q = space.TestFunction()
    dsk = ngs.ds(skeleton=True, definedon=mesh.Boundaries("|".join(labels)),
                 bonus_intorder=bonus_intorder)
    values = []
    for cf in cfs:
        lf = ngs.LinearForm(space)
        lf += cf * q * dsk
        lf.Assemble()
        values.append(float(sum(lf.vec)))
    return values


def _minus(x):
    """[x]_- = min(x, 0)."""
    return ngs.IfPos(x, 0, x)


def _project(x, s):
    """The projection of x onto [-s, s] (s >= 0)."""
    return ngs.IfPos(x - s, s, ngs.IfPos(-s - x, -s, x))


@dataclass
class _ContactEdges:
    """The boundary edges of Gamma_C: end points, lengths, outward normals, tangents."""

    p0: np.ndarray
    p1: np.ndarray
    length: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray

    @classmethod
    def of(cls, mesh: ngs.Mesh, labels: list[str]) -> _ContactEdges:
        mask = mesh.Boundaries("|".join(labels)).Mask()
        pts = np.array([v.point for v in mesh.vertices])
        p0, p1, cen = [], [], []
        for el in mesh.Elements(ngs.BND):
            if not mask[el.index]:
                continue
            a, b = (v.nr for v in el.vertices)
            p0.append(pts[a])
            p1.append(pts[b])
            # the volume element next to the edge, for the outward orientation
            vol = mesh[mesh[el.edges[0]].elements[0]]
            cen.append(pts[[v.nr for v in vol.vertices]].mean(axis=0))
        if not p0:
            raise ValueError(f"no boundary edges with labels {labels}")
        p0, p1, cen = np.array(p0), np.array(p1), np.array(cen)
        d = p1 - p0
        length = np.linalg.norm(d, axis=1)
        n = np.column_stack([d[:, 1], -d[:, 0]]) / length[:, None]
        flip = np.einsum("ij,ij->i", n, 0.5 * (p0 + p1) - cen) < 0
        n[flip] *= -1
        t = np.column_stack([n[:, 1], -n[:, 0]])
        return cls(p0, p1, length, n, t)

    def locate(self, points: np.ndarray) -> np.ndarray:
        """The index of the nearest edge for each point (shape (N, 2))."""
        d = self.p1 - self.p0
        rel = points[:, None, :] - self.p0[None, :, :]
        s = np.clip(np.einsum("kij,ij->ki", rel, d) / (self.length**2)[None, :], 0, 1)
        foot = self.p0[None, :, :] + s[..., None] * d[None, :, :]
        return np.argmin(np.linalg.norm(points[:, None, :] - foot, axis=2), axis=1)


@dataclass
class PrimalResult:
    """The converged discrete solution of :func:`solve_primal` and what it cost.

    ``contact_force`` = int p, ``tangential_force`` = int lambda_t over Gamma_C;
    ``contact_length`` / ``stick_length`` the lengths of {p > 0} and of
    {p > 0, |P_t(u_h)| < s}; ``support_force`` the force of the supports on Gamma_D on the
    body (the residual on the Dirichlet DOFs); ``times`` in seconds: "assemble" (residuals
    and Jacobians), "solve" (factorisations and solves), "total" (all of solve_primal).
    ``x_mid`` are the midpoints of the Gamma_C edges sorted by x; ``pressure_mid`` and
    ``traction_mid`` the Nitsche-consistent p = -[P_n(u_h)]_- and lambda_t = [P_t(u_h)]_s
    there (tangent t = (n_y, -n_x), i.e. +x on a side with outward normal +y).
    """

    u: ngs.GridFunction
    ndof: int
    newton_iterations: int
    residuals: list[float]
    times: dict
    converged: bool
    x_mid: np.ndarray
    pressure_mid: np.ndarray
    traction_mid: np.ndarray
    h_mid: np.ndarray
    contact_force: float
    tangential_force: float
    contact_length: float
    stick_length: float
    support_force: np.ndarray
    pressure_cf: ngs.CoefficientFunction = field(repr=False)
    traction_cf: ngs.CoefficientFunction = field(repr=False)
    _edges: _ContactEdges = field(repr=False)
    _pointwise: object = field(repr=False)

    def pressure(self, points) -> np.ndarray:
        """p = -[P_n(u_h)]_- at points of Gamma_C (array (N, 2)), h of the edge they lie on."""
        return self._pointwise(np.atleast_2d(np.asarray(points, float)))[0]

    def traction(self, points) -> np.ndarray:
        """lambda_t = [P_t(u_h)]_s at points of Gamma_C (array (N, 2))."""
        return self._pointwise(np.atleast_2d(np.asarray(points, float)))[1]


def solve_primal(mesh: ngs.Mesh, *, E: float, nu: float, dirichlet, neumann=(), contact,
                 body_force=(0, 0), traction=(0, 0), displacement=(0, 0), gap,
                 order: int = 1, law: str = "none", mu_f: float = 0.0, tresca_bound=None,
                 gamma0: float = 1.0, theta: float = -1.0, tol: float = 1e-10,
                 max_newton: int = 50) -> PrimalResult:
    """Solve the contact problem by P``order`` Lagrange elements, Nitsche contact, Newton.

    ``dirichlet``, ``neumann``, ``contact``: lists of boundary labels of ``mesh``
    (``displacement`` prescribed on the first, ``traction`` on the second; sides in none of
    them are traction free). Loads are pairs of numbers / formulas in x, y / CFs or a
    2-vector CF; ``gap`` and ``tresca_bound`` scalars of the same kinds. ``law``: "none",
    "tresca" (bound ``tresca_bound``) or "coulomb" (coefficient ``mu_f``).

    Newton stops when the residual (on the free DOFs) is below ``tol`` times the initial one;
    otherwise :class:`NewtonError` is raised.
    """
    t_total = time.perf_counter()
    if order not in (1, 2, 3, 4):
        raise ValueError(f"order must be 1..4, got {order}")
    if law not in ("none", "tresca", "coulomb"):
        raise ValueError(f"law must be 'none', 'tresca' or 'coulomb', got {law!r}")
    if law == "tresca" and tresca_bound is None:
        raise ValueError("law='tresca' needs tresca_bound")
    if law == "coulomb" and mu_f < 0:
        raise ValueError("mu_f must be >= 0")
    if gamma0 <= 0:
        raise ValueError("gamma0 must be > 0")
    dirichlet, neumann, contact = _labels(dirichlet), _labels(neumann), _labels(contact)
    known = set(mesh.GetBoundaries())
    for label in dirichlet + neumann + contact:
        if label not in known:
            raise ValueError(f"unknown boundary label {label!r} (mesh has {sorted(known)})")
    if not contact:
        raise ValueError("contact needs at least one boundary label")

    mu, lam = _lame(E, nu)
    fes = ngs.VectorH1(mesh, order=order, dirichlet="|".join(dirichlet))
    u, v = fes.TnT()
    n = ngs.specialcf.normal(2)
    t = ngs.CF((n[1], -n[0]))
    h = ngs.specialcf.mesh_size
    beta = gamma0 * E / h
    g = _scalar(gap)
    dsc = ngs.ds(skeleton=True, definedon=mesh.Boundaries("|".join(contact)))

    def parts(w):
        sn = _stress(w, mu, lam) * n
        return sn * n, sn * t, w * n, w * t

    sn_u, st_u, un_u, ut_u = parts(u)
    sn_v, st_v, un_v, ut_v = parts(v)
    pn = sn_u - beta * (un_u - g)
    pt = st_u - beta * ut_u
    if law == "none":
        s = None
    elif law == "tresca":
        s = _scalar(tresca_bound)
    else:
        s = -mu_f * _minus(pn)

    a = ngs.BilinearForm(fes)
    a += ngs.InnerProduct(_stress(u, mu, lam), _strain(v)) * ngs.dx
    form = 1 / beta * _minus(pn) * (theta * sn_v - beta * un_v)
    if theta != 0:
        form += -theta / beta * sn_u * sn_v
    if s is not None:
        form += 1 / beta * _project(pt, s) * (theta * st_v - beta * ut_v)
        if theta != 0:
            form += -theta / beta * st_u * st_v
    a += form * dsc

    f = ngs.LinearForm(fes)
    f += _vector(body_force) * v * ngs.dx
    if neumann:
        f += _vector(traction) * v * ngs.ds(definedon=mesh.Boundaries("|".join(neumann)))
    f.Assemble()

    gfu = ngs.GridFunction(fes)
    if dirichlet:
        gfu.Set(_vector(displacement), ngs.BND,
                definedon=mesh.Boundaries("|".join(dirichlet)))
    free = fes.FreeDofs()
    res = gfu.vec.CreateVector()
    times = {"assemble": 0.0, "solve": 0.0}

    def residual() -> float:
        t0 = time.perf_counter()
        a.Apply(gfu.vec, res)
        res.data -= f.vec
        times["assemble"] += time.perf_counter() - t0
        r = res.FV().NumPy()
        return float(np.linalg.norm(r[np.asarray(free, dtype=bool)]))

    r0 = residual()
    residuals = [r0]
    converged = r0 == 0.0
    iterations = 0
    while not converged and iterations < max_newton:
        t0 = time.perf_counter()
        a.AssembleLinearization(gfu.vec)
        if not np.all(np.isfinite(a.mat.AsVector().FV().NumPy())):
            # NGSolve linearises by automatic differentiation through the data as well, and
            # e.g. sqrt(max(0, w)) has the derivative 0 * inf = nan where w = 0
            raise ValueError("the Jacobian has non-finite entries: the gap or the Tresca "
                             "bound is not differentiable somewhere on Gamma_C; write "
                             "sqrt(max(0, w)) as ifpos(w, sqrt(ifpos(w, w, 1)), 0)")
        t1 = time.perf_counter()
        # one BLAS thread: NGSolve's threaded OpenBLAS spin-waits on shared cores (the same
        # UMFPACK factorisation took 0.57 s with one thread and 1.6-3 s without the limit)
        with threadpool_limits(limits=1):
            inv = a.mat.Inverse(free, inverse="umfpack")
            du = (inv * res).Evaluate()
        gfu.vec.data -= du
        times["assemble"] += t1 - t0
        times["solve"] += time.perf_counter() - t1
        iterations += 1
        residuals.append(residual())
        converged = residuals[-1] <= tol * r0
        if not np.isfinite(residuals[-1]):
            break
    if not converged:
        raise NewtonError(f"semismooth Newton did not converge in {iterations} steps "
                          f"(relative residuals {[f'{r / r0:.2e}' for r in residuals]})")

    # the force of the supports on the body: the residual tested with (1, 0) and (0, 1) on
    # Gamma_D (the Galerkin reaction; it balances the contact and applied forces exactly)
    support_force = np.zeros(2)
    if dirichlet:
        w = ngs.GridFunction(fes)
        for i, unit in enumerate(((1, 0), (0, 1))):
            w.vec[:] = 0
            w.Set(ngs.CF(unit), ngs.BND, definedon=mesh.Boundaries("|".join(dirichlet)))
            support_force[i] = ngs.InnerProduct(res, w.vec)

    # Nitsche-consistent contact tractions of the discrete solution
    sn_h, st_h, un_h, ut_h = parts(gfu)
    pn_h = sn_h - beta * (un_h - g)
    p_cf = -_minus(pn_h)
    if law == "none":
        s_h = ngs.CF(0.0)
    elif law == "tresca":
        s_h = _scalar(tresca_bound)
    else:
        s_h = mu_f * p_cf
    lt_cf = _project(st_h - beta * ut_h, s_h)
    in_contact = ngs.IfPos(p_cf, 1.0, 0.0)
    pt_h = st_h - beta * ut_h
    stick = ngs.IfPos(s_h - ngs.IfPos(pt_h, pt_h, -pt_h), 1.0, 0.0)
    contact_force, tangential_force, contact_length, stick_length = _facet_integral(
        [p_cf, lt_cf, in_contact, in_contact * stick], mesh, contact, bonus_intorder=12)
    if law == "none":
        stick_length = 0.0

    edges = _ContactEdges.of(mesh, contact)
    sigma = _stress(gfu, mu, lam)

    def pointwise(points: np.ndarray):
        k = edges.locate(points)
        nn, tt, hh = edges.normal[k], edges.tangent[k], edges.length[k]
        q = points - 1e-9 * hh[:, None] * nn  # nudge inside, so the point search succeeds
        mp = mesh(q[:, 0], q[:, 1])
        sig = np.asarray(sigma(mp)).reshape(-1, 2, 2)
        disp = np.asarray(gfu(mp)).reshape(-1, 2)
        gap_val = np.asarray(g(mp)).reshape(-1)
        sn_vec = np.einsum("kij,kj->ki", sig, nn)
        b = gamma0 * E / hh
        p_n = np.einsum("ki,ki->k", sn_vec, nn) - b * (np.einsum("ki,ki->k", disp, nn) - gap_val)
        p = np.maximum(-p_n, 0.0)
        p_t = np.einsum("ki,ki->k", sn_vec, tt) - b * np.einsum("ki,ki->k", disp, tt)
        if law == "none":
            bound = np.zeros_like(p)
        elif law == "tresca":
            bound = np.asarray(_scalar(tresca_bound)(mp)).reshape(-1)
        else:
            bound = mu_f * p
        return p, np.clip(p_t, -bound, bound)

    mid = 0.5 * (edges.p0 + edges.p1)
    order_x = np.argsort(mid[:, 0], kind="stable")
    mid = mid[order_x]
    p_mid, t_mid = pointwise(mid)
    times["total"] = time.perf_counter() - t_total
    return PrimalResult(u=gfu, ndof=fes.ndof, newton_iterations=iterations,
                        residuals=residuals, times=times, converged=converged,
                        x_mid=mid[:, 0], pressure_mid=p_mid, traction_mid=t_mid,
                        h_mid=edges.length[order_x], contact_force=contact_force,
                        tangential_force=tangential_force, contact_length=contact_length,
                        stick_length=stick_length, support_force=support_force,
                        pressure_cf=p_cf, traction_cf=lt_cf,
                        _edges=edges, _pointwise=pointwise)


# --------------------------------------------------------------------------------------------
# An ngdual scene solved by the peer, as the sample arrays of ngdual.verification.reference
# --------------------------------------------------------------------------------------------

def _scene_gap(contact, mesh: ngs.Mesh, labels: list[str]) -> ngs.CoefficientFunction:
    """The scene's gap as a CF (a formula, or the distance to the foundation line along the
    outward normal of Gamma_C, as :func:`ngdual.scene.gap_at`). The CF is also evaluated
    inside the body (the pressure at points), where no normal exists: a foundation line
    needs a straight Gamma_C, whose normal is then a constant."""
    from ngdual.scene import foundation_line

    if contact.foundation is None:
        return _scalar(contact.gap_formula)
    point, n_f = foundation_line(contact)
    normals = _ContactEdges.of(mesh, labels).normal
    if np.ptp(normals, axis=0).max() > 1e-12:
        raise ValueError("a foundation line needs a straight Gamma_C for the peer")
    return (((ngs.x - point[0]) * n_f[0] + (ngs.y - point[1]) * n_f[1])
            / float(-(normals[0] @ n_f)))


def solve_scene_primal(scene, level: int, order: int, **kw) -> tuple[PrimalResult, float]:
    """Solve an ngdual scene (its mesh on ``level``, material, loads, gap, friction law) by
    the peer with P``order`` elements; returns the result and the wall time, meshing
    included. Tresca bounds and free ends are the scene's; "thesis" end values of Gamma_C
    (lambda = 0 at a clamped end) have no primal counterpart and are refused."""
    from ngdual.mesh import build_mesh

    if scene.contact.ends == "thesis":
        raise ValueError("the peer solves the consistent problem: set contact.ends = "
                         "\"consistent\" (the thesis' end values contradict u = u_D)")
    start = time.perf_counter()
    mesh = build_mesh(scene.geometry, level)
    law = scene.friction.law
    result = solve_primal(
        mesh, E=scene.material.E, nu=scene.material.nu, dirichlet=scene.labels("dirichlet"),
        neumann=scene.labels("neumann"), contact=scene.labels("contact"),
        body_force=scene.loads.body_force, traction=scene.loads.traction,
        displacement=scene.loads.displacement,
        gap=_scene_gap(scene.contact, mesh, scene.labels("contact")), order=order,
        law=law, mu_f=scene.friction.mu if law == "coulomb" else 0.0,
        tresca_bound=scene.friction.bound if law == "tresca" else None, **kw)
    return result, time.perf_counter() - start


def primal_samples(scene, result: PrimalResult, subdivisions: int = 1) -> dict:
    """The peer's solution as sample arrays (:mod:`ngdual.verification.reference`): sigma
    and u at the P2 nodes of every triangle (exact for P1 and P2), and the pressure at
    3-point Gauss points of every Gamma_C edge split into ``subdivisions`` parts (``p_x``,
    ``p_w``, ``p``), so that each part lies in one edge of a reference ``log2(subdivisions)``
    levels finer."""
    from ngdual.verification.reference import element_samples, gauss_samples

    lam, mu = scene.material.lame
    mesh = result.u.space.mesh
    out = element_samples(mesh, {"sigma": _stress(result.u, mu, lam), "u": result.u})
    edges = result._edges
    if np.ptp(edges.p0[:, 1]) > 1e-12 or np.ptp(edges.p1[:, 1]) > 1e-12:
        raise ValueError("pressure samples need a horizontal Gamma_C")
    x0 = np.minimum(edges.p0[:, 0], edges.p1[:, 0])
    x1 = np.maximum(edges.p0[:, 0], edges.p1[:, 0])
    x, w = gauss_samples(x0, x1, subdivisions)
    y = np.full_like(x, edges.p0[0, 1])
    out.update(p_x=x, p_w=w, p=result.pressure(np.column_stack([x, y])))
    return out


# --------------------------------------------------------------------------------------------
# Hertz and Cattaneo-Mindlin on a block [-L, L] x [-H, 0] pushed into a rigid cylinder
# --------------------------------------------------------------------------------------------

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
    err2, norm2 = _facet_integral([(res.pressure_cf - p_h) ** 2, p_h**2], mesh, ["contact"],
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
    err2, norm2 = _facet_integral([(res.traction_cf - q) ** 2, q**2], mesh, ["contact"],
                                  bonus_intorder=12)
    return CattaneoRow(level=level, order=order, ndof=res.ndof,
                       newton_iterations=res.newton_iterations, time_total=res.times["total"],
                       P=P, Q=Q, a_hertz=a, c_formula=c, c_measured=res.stick_length / 2,
                       traction_l2_error=math.sqrt(err2 / norm2),
                       hc=kw.get("hc", 0.025) / 2 ** (level - 1), result=res)


def _hertz_table(orders, levels, hc: float = 0.025, **kw) -> None:
    print(f"Hertz (frictionless), theta = {kw.get('theta', -1.0)}, "
          f"gamma0 = {kw.get('gamma0', 1.0)}, level-1 contact edges hc = {hc}")
    print(f"{'P':>2} {'lvl':>3} {'h_C':>8} {'ndof':>7} {'it':>3} {'time/s':>7} {'asm/s':>6} "
          f"{'sol/s':>6} {'L2 rel':>9} {'max rel':>9} {'a_Hertz':>8} {'a_h':>8} {'P':>9} "
          f"{'reaction':>9} {'uy/McEwen':>9}")
    for order in orders:
        for level in levels:
            r = hertz_case(order, level, mesh_kw={"hc": hc}, **kw)
            print(f"{order:>2} {level:>3} {r.hc:>8.5f} {r.ndof:>7} {r.newton_iterations:>3} "
                  f"{r.time_total:>7.2f} {r.time_assemble:>6.2f} {r.time_solve:>6.2f} "
                  f"{r.l2_error:>9.2e} {r.max_error:>9.2e} {r.a_hertz:>8.5f} "
                  f"{r.a_measured:>8.5f} {r.force:>9.6f} {r.reaction:>9.6f} "
                  f"{r.approach_ratio:>9.4f}", flush=True)


def _cattaneo_table(orders, levels, hc: float = 0.025, **kw) -> None:
    print(f"Cattaneo-Mindlin ({kw.get('law', 'coulomb')}), nu = {kw.get('nu', 0.49)}, "
          f"theta = {kw.get('theta', -1.0)}, gamma0 = {kw.get('gamma0', 1.0)}")
    print(f"{'P':>2} {'lvl':>3} {'h_C':>8} {'ndof':>7} {'it':>3} {'time/s':>7} {'P':>9} "
          f"{'Q':>10} {'a':>8} {'c formula':>9} {'c_h':>8} {'|dc|/h_C':>8} {'q L2 rel':>9}")
    for order in orders:
        for level in levels:
            r = cattaneo_mindlin_case(order, level, mesh_kw={"hc": hc}, **kw)
            print(f"{order:>2} {level:>3} {r.hc:>8.5f} {r.ndof:>7} {r.newton_iterations:>3} "
                  f"{r.time_total:>7.2f} {r.P:>9.5f} {r.Q:>10.6f} {r.a_hertz:>8.5f} "
                  f"{r.c_formula:>9.5f} {r.c_measured:>8.5f} "
                  f"{abs(r.c_measured - r.c_formula) / r.hc:>8.2f} "
                  f"{r.traction_l2_error:>9.2e}", flush=True)


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    p.add_argument("--orders", type=int, nargs="+", default=[1, 2])
    p.add_argument("--theta", type=float, default=-1.0)
    p.add_argument("--gamma0", type=float, default=1.0)
    p.add_argument("--cattaneo", action="store_true", help="the Cattaneo-Mindlin study")
    p.add_argument("--law", default="coulomb", choices=["coulomb", "tresca"])
    p.add_argument("--nu", type=float, default=None)
    p.add_argument("--hc", type=float, default=0.05, help="contact edge length on level 1")
    p.add_argument("--gamma-study", action="store_true",
                   help="Hertz errors for every --thetas x --gammas")
    p.add_argument("--thetas", type=float, nargs="+", default=[-1.0, 0.0, 1.0])
    p.add_argument("--gammas", type=float, nargs="+", default=[0.3, 1.0, 3.0, 10.0, 100.0])
    args = p.parse_args(argv)
    if args.gamma_study:
        for theta in args.thetas:
            for gamma0 in args.gammas:
                try:
                    _hertz_table(args.orders, args.levels, hc=args.hc, theta=theta,
                                 gamma0=gamma0)
                except NewtonError as err:
                    print("  ", err)
        return
    if args.cattaneo:
        kw = {"theta": args.theta, "gamma0": args.gamma0, "law": args.law}
        if args.nu is not None:
            kw["nu"] = args.nu
        _cattaneo_table(args.orders, args.levels, hc=args.hc, **kw)
        return
    kw = {"theta": args.theta, "gamma0": args.gamma0}
    if args.nu is not None:
        kw["nu"] = args.nu
    _hertz_table(args.orders, args.levels, hc=args.hc, **kw)


if __name__ == "__main__":
    main()
