"""A primal peer for contact: displacement finite elements with Nitsche contact (NGSolve).

This is "the method a user would pick instead" of ngdual's dual-dual mixed method: conforming
P1 or P2 Lagrange elements for the displacement of a 2D plane-strain elastic body, unilateral
contact with a rigid foundation (``u_n <= g`` on Gamma_C, n the body's outward normal) imposed
by Nitsche's method, frictionless or with Tresca / Coulomb friction, solved by a semismooth
(generalised) Newton method with a sparse direct solver (UMFPACK). n and t = (n_2, -n_1)
are the normal and tangent of each boundary edge (NGSolve's ``specialcf.normal`` in the
contact integrals), so on a curved Gamma_C (an arc meshed by straight edges) or a kinked
one the contact conditions hold in the local normal and tangential directions.

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
  linearly), an O(gamma0 h / a) relative pressure error. Measured on Hertz (``ngdual bench
  primal-peer --thetas -1 0 1 --gammas 0.1 0.3 1 3 10 100 --levels 1 3``): gamma0 = 100 gives P1
  pressure errors of 60-110 % (the pressure becomes spikes between the quadrature points,
  whose integral is then 70 % off the Galerkin reaction on level 1), gamma0 = 10 about
  twice the errors of gamma0 = 1, and 0.1 <= gamma0 <= 1 about the same errors with
  theta = -1; theta = 0 degrades at gamma0 = 0.1 (P2: 4.8 % instead of 1.3 %, its stability
  limit), and theta = 1 does not converge for gamma0 <= 1 (unstable). For Coulomb
  friction Newton failed for some gamma0 <= 0.1.
* The pressure reported is p = -[P_n(u_h)]_- (consistent for every theta). Newton takes
  about one or two more steps with theta = -1 than with theta = 0.

Error behaviour: the Hertz pressure has square-root edges at x = +-a, so the L2 pressure
error is O(h / a) for P1 and P2 alike; its constant depends on where +-a falls inside an
element and varies by a factor of up to about 4 between meshes (P2: 0.1 to 0.4, P1: 0.6 to
1.2 in units of h / a), so errors need not decrease between two consecutive levels; they do
over two levels (a factor 4 in h).
"""

from __future__ import annotations

import time

import ngsolve as ngs
import numpy as np
from threadpoolctl import threadpool_limits

from ...expr import Expression
from ...geometry import tangent
from ...tolerances import BLAS_THREADS
from .result import ContactEdges, PrimalResult


class NewtonError(RuntimeError):
    """The semismooth Newton iteration did not reach the tolerance."""


def scalar_cf(value) -> ngs.CoefficientFunction:
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
    return ngs.CF((scalar_cf(first), scalar_cf(second)))


def _labels(value) -> list[str]:
    if value is None:
        return []
    if isinstance(value, str):
        return [value]
    return list(value)


def _strain(u):
    g = ngs.Grad(u)
    return 0.5 * (g + g.trans)


def lame(E: float, nu: float) -> tuple[float, float]:
    return E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))


def stress(u, mu: float, lam: float):
    eps = _strain(u)
    return 2 * mu * eps + lam * ngs.Trace(eps) * ngs.Id(2)


def mixed_stress(u, p, mu: float):
    """sigma = 2 mu eps(u) - p I with the pressure p = -lam div u as an unknown of its own."""
    return 2 * mu * _strain(u) - p * ngs.Id(2)


def facet_integral(cfs, mesh: ngs.Mesh, labels: list[str], bonus_intorder: int = 8) -> list:
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


def solve_primal(mesh: ngs.Mesh, *, E: float, nu: float, dirichlet, neumann=(), contact,
                 body_force=(0, 0), traction=(0, 0), displacement=(0, 0), gap,
                 order: int = 1, law: str = "none", mu_f: float = 0.0, tresca_bound=None,
                 gamma0: float = 1.0, theta: float = -1.0, mixed: bool = False,
                 tol: float = 1e-10, max_newton: int = 50) -> PrimalResult:
    """Solve the contact problem by P``order`` Lagrange elements, Nitsche contact, Newton.

    ``dirichlet``, ``neumann``, ``contact``: lists of boundary labels of ``mesh``
    (``displacement`` prescribed on the first, ``traction`` on the second; sides in none of
    them are traction free). Without ``contact`` labels the problem is linear elasticity,
    solved in one Newton step, and the contact quantities of the result are zero or empty.
    Loads are pairs of numbers / formulas in x, y / CFs or a 2-vector CF; ``gap`` and
    ``tresca_bound`` scalars of the same kinds. ``gap`` may also be
    a function ``gap(x, y, n_x, n_y)`` of the point and the outward unit normal n of
    Gamma_C that takes numpy arrays and NGSolve coefficient functions alike (the distance
    to a foundation line along n, :func:`ngdual.scene.contact.foundation_gap`): on a curved
    or kinked Gamma_C the gap then follows the local normal, NGSolve's normal in the
    contact integrals and the normal of the edge a point lies on in :meth:`PrimalResult.
    pressure`. ``law``: "none", "tresca" (bound ``tresca_bound``) or "coulomb" (coefficient
    ``mu_f``).

    ``mixed=True`` solves the displacement-pressure form with Taylor-Hood elements (P``order``
    displacements, continuous P``order-1`` pressures, order >= 2): find (u, p) with
    2 mu (eps(u), eps(v)) - (p, div v) - (q, div u) - (p, q) / lam plus the Nitsche terms of
    sigma = 2 mu eps(u) - p I. For a nearly incompressible material the displacement form
    locks in shear: lam div u_h, a large number times a small inexact one, pollutes sigma_n
    and the contact pressure (cattaneo-mindlin, nu = 0.4999: P2 pressure errors of 30-48 %
    on levels 1-5 that do not decrease), which the inf-sup stable pair avoids.

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
    if mixed and order < 2:
        raise ValueError("the Taylor-Hood form (mixed=True) needs order >= 2")
    dirichlet, neumann, contact = _labels(dirichlet), _labels(neumann), _labels(contact)
    known = set(mesh.GetBoundaries())
    for label in dirichlet + neumann + contact:
        if label not in known:
            raise ValueError(f"unknown boundary label {label!r} (mesh has {sorted(known)})")

    mu, lam = lame(E, nu)
    fes = ngs.VectorH1(mesh, order=order, dirichlet="|".join(dirichlet))
    if mixed:
        fes = fes * ngs.H1(mesh, order=order - 1)
        (u, p_u), (v, p_v) = fes.TnT()
        sigma_u, sigma_v = mixed_stress(u, p_u, mu), mixed_stress(v, p_v, mu)
    else:
        u, v = fes.TnT()
        sigma_u, sigma_v = stress(u, mu, lam), stress(v, mu, lam)
    n = ngs.specialcf.normal(2)
    t = tangent(n)
    h = ngs.specialcf.mesh_size
    beta = gamma0 * E / h
    g = gap(ngs.x, ngs.y, n[0], n[1]) if callable(gap) else scalar_cf(gap)
    dsc = ngs.ds(skeleton=True, definedon=mesh.Boundaries("|".join(contact)))

    def parts(sigma, w):
        sn = sigma * n
        return sn * n, sn * t, w * n, w * t

    sn_u, st_u, un_u, ut_u = parts(sigma_u, u)
    sn_v, st_v, un_v, ut_v = parts(sigma_v, v)
    pn = sn_u - beta * (un_u - g)
    pt = st_u - beta * ut_u
    if law == "none":
        s = None
    elif law == "tresca":
        s = scalar_cf(tresca_bound)
    else:
        s = -mu_f * _minus(pn)

    a = ngs.BilinearForm(fes)
    if mixed:
        a += (2 * mu * ngs.InnerProduct(_strain(u), _strain(v)) - p_u * ngs.Trace(ngs.Grad(v))
              - p_v * ngs.Trace(ngs.Grad(u)) - p_u * p_v / lam) * ngs.dx
    else:
        a += ngs.InnerProduct(stress(u, mu, lam), _strain(v)) * ngs.dx
    form = 1 / beta * _minus(pn) * (theta * sn_v - beta * un_v)
    if theta != 0:
        form += -theta / beta * sn_u * sn_v
    if s is not None:
        form += 1 / beta * _project(pt, s) * (theta * st_v - beta * ut_v)
        if theta != 0:
            form += -theta / beta * st_u * st_v
    if contact:
        a += form * dsc

    f = ngs.LinearForm(fes)
    f += _vector(body_force) * v * ngs.dx
    if neumann:
        f += _vector(traction) * v * ngs.ds(definedon=mesh.Boundaries("|".join(neumann)))
    f.Assemble()

    def displacement_of(gf):
        return gf.components[0] if mixed else gf

    gfu = ngs.GridFunction(fes)
    u_h = displacement_of(gfu)
    sigma_h = mixed_stress(u_h, gfu.components[1], mu) if mixed else stress(gfu, mu, lam)
    if dirichlet:
        u_h.Set(_vector(displacement), ngs.BND, definedon=mesh.Boundaries("|".join(dirichlet)))
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
        # UMFPACK factorisation takes 0.57 s with one thread and 1.6-3 s without the limit)
        with threadpool_limits(limits=BLAS_THREADS):
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
            displacement_of(w).Set(ngs.CF(unit), ngs.BND,
                                   definedon=mesh.Boundaries("|".join(dirichlet)))
            support_force[i] = ngs.InnerProduct(res, w.vec)

    # Nitsche-consistent contact tractions of the discrete solution
    sn_h, st_h, un_h, ut_h = parts(sigma_h, u_h)
    pn_h = sn_h - beta * (un_h - g)
    p_cf = -_minus(pn_h)
    if law == "none":
        s_h = ngs.CF(0.0)
    elif law == "tresca":
        s_h = scalar_cf(tresca_bound)
    else:
        s_h = mu_f * p_cf
    lt_cf = _project(st_h - beta * ut_h, s_h)
    in_contact = ngs.IfPos(p_cf, 1.0, 0.0)
    pt_h = st_h - beta * ut_h
    stick = ngs.IfPos(s_h - ngs.IfPos(pt_h, pt_h, -pt_h), 1.0, 0.0)
    contact_force = tangential_force = contact_length = stick_length = 0.0
    if contact:
        contact_force, tangential_force, contact_length, stick_length = facet_integral(
            [p_cf, lt_cf, in_contact, in_contact * stick], mesh, contact, bonus_intorder=12)
    if law == "none":
        stick_length = 0.0

    edges = ContactEdges.of(mesh, contact) if contact else ContactEdges.none()

    def pointwise(points: np.ndarray):
        k = edges.locate(points)
        nn, tt, hh = edges.normal[k], edges.tangent[k], edges.length[k]
        q = points - 1e-9 * hh[:, None] * nn  # nudge inside, so the point search succeeds
        mp = mesh(q[:, 0], q[:, 1])
        sig = np.asarray(sigma_h(mp)).reshape(-1, 2, 2)
        disp = np.asarray(u_h(mp)).reshape(-1, 2)
        if callable(gap):
            # at the point the search found, as the formula gap g(mp) below
            xq, yq = np.asarray(ngs.CF((ngs.x, ngs.y))(mp)).reshape(-1, 2).T
            gap_val = gap(xq, yq, nn[:, 0], nn[:, 1])
        else:
            gap_val = np.asarray(g(mp)).reshape(-1)
        sn_vec = np.einsum("kij,kj->ki", sig, nn)
        b = gamma0 * E / hh
        p_n = np.einsum("ki,ki->k", sn_vec, nn) - b * (np.einsum("ki,ki->k", disp, nn) - gap_val)
        p = np.maximum(-p_n, 0.0)
        p_t = np.einsum("ki,ki->k", sn_vec, tt) - b * np.einsum("ki,ki->k", disp, tt)
        if law == "none":
            bound = np.zeros_like(p)
        elif law == "tresca":
            bound = np.asarray(scalar_cf(tresca_bound)(mp)).reshape(-1)
        else:
            bound = mu_f * p
        return p, np.clip(p_t, -bound, bound)

    mid = 0.5 * (edges.p0 + edges.p1)
    order_x = np.argsort(mid[:, 0], kind="stable")
    mid = mid[order_x]
    p_mid, t_mid = pointwise(mid) if contact else (np.zeros(0), np.zeros(0))
    times["total"] = time.perf_counter() - t_total
    return PrimalResult(u=u_h, sigma=sigma_h, ndof=fes.ndof, newton_iterations=iterations,
                        residuals=residuals, times=times, converged=converged,
                        x_mid=mid[:, 0], pressure_mid=p_mid, traction_mid=t_mid,
                        h_mid=edges.length[order_x], contact_force=contact_force,
                        tangential_force=tangential_force, contact_length=contact_length,
                        stick_length=stick_length, support_force=support_force,
                        pressure_cf=p_cf, traction_cf=lt_cf,
                        _edges=edges, _pointwise=pointwise)
