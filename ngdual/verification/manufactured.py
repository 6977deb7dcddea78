"""Manufactured contact solutions with known contact, stick and slip sets, and their exact errors.

The body is the rectangle of Example 3.46, Omega = (-4, 4) x (-1, 1) with its structured
mesh (levels 1, 2, ...: h~ = 2h = 2^(2-k) on Gamma_C), clamped sides Gamma_D = {x = +-4}
carrying the exact displacement, Gamma_N = top with the exact traction, and
Gamma_C = bottom (y = -1, outward normal n = (0, -1), t = (n_2, -n_1) = (-1, 0)).
On Gamma_C ngdual's conventions (:mod:`ngdual.forms`, Theorem 3.10) give

    sigma_n = sigma_22,   sigma_t = t . sigma n = sigma_12,
    lambda_n = g - u_n = g + u_2,   lambda_t = -u_t = u_1,

and from (3.62)_5,7 sigma_t = F nu with nu = sign(lambda_t) where lambda_t != 0: a slipping
point moves against its tangential traction, sigma_t u_t + F |u_t| = 0 as in (3.1).

The displacement is built from its traces. Given on Gamma_C (functions of x, Y = y + 1)
the tangential multiplier lambda_t, the normal displacement u_n, the normal and tangential
stresses sigma_n, sigma_t and interior terms c_1, c_2,

    u_1 = lambda_t + Y b_1 + Y^2 c_1,    u_2 = -u_n + Y b_2 + Y^2 c_2,
    b_1 = sigma_t / mu + u_n',           b_2 = (sigma_n - lam lambda_t') / (lam + 2 mu),

so that u = (lambda_t, -u_n), sigma_12 = sigma_t and sigma_22 = sigma_n on Y = 0. The gap is
g = u_n + lambda_n with the chosen lambda_n >= 0, f = -div sigma, t0 = sigma n on the top and
u_D = u on the sides.

The traces are piecewise polynomials in x with breakpoints at the end points of the contact,
stick and slip sets. There sigma_n, lambda_n and the friction margin F - |sigma_t| start
like (.)_+^2 (C^1 functions) and lambda_t, whose derivative enters b_2, like (.)_+^3 (C^2).
So u is C^1 with piecewise polynomial second derivatives: u in H^{5/2-eps}, sigma in
H^{3/2-eps} (in H^1), lambda_t, lambda_n in H^{3/2}(Gamma_C), and div sigma = -f is piecewise
polynomial with jumps across the lines x = const through the set end points.

Why quadratic onsets and a small lift. The discrete sets are decided node by node against
the exact margins next to a set end point -- the pressure, the gap lambda_n, F - |sigma_t| at
distance ~h~ -- and these must dominate the O(h^2) nodal errors. A d^2 margin scales like
them, so only a bounded number of nodes can be misclassified; a d^3 margin (the smoothest
choice, sigma in H^2) falls below them as h -> 0. The gap opens with a small coefficient
(``LIFT``) because the P1 multiplier lambda_n^h has a kink at the last contact node, which
the discrete solution pays for with a concentrated normal force proportional to the
opening (see :func:`contact_profile`); with a 5x larger ``LIFT`` that force separates the
node before it on level 6.

Every case presses the middle of Gamma_C into contact and lifts off towards the clamped
ends: the exact lambda_n and lambda_t vanish at the ends of Gamma_C, whatever values the
discrete multipliers take there (zero in C_h~ of (3.61), or the data's values).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import cached_property

import ngsolve as ngs
import numpy as np

from ..expr import Expression
from ..friction import hat_projection
from ..mesh import mesh_size
from ..post import contact_traces, friction_diagnostics
from ..quantities import fields
from ..rates import observed_rates
from ..scene import Contact, Friction, Geometry, Loads, Material, Scene, Solver, validate
from ..solvers import solve_scene
from ..solvers.result import Solution
from .integrate import PiecewiseQuadrature
from .piecewise import Piecewise

Y0 = -1.0                       # Gamma_C is the side y = Y0
HALF_WIDTH = 4.0                # Gamma_C = (-4, 4) x {Y0}
E, NU = 1000.0, 0.3
PRESSURE = 5.0                  # peak contact pressure |sigma_n|
LIFT = 0.002                    # peak of lambda_n on the separated parts (see contact_profile)
SLIDE = 0.005                   # scale of lambda_t = u_1 on Gamma_C
APPROACH = 0.01                 # u_n = APPROACH (1 - x^2/16)^2 on Gamma_C
ONSET = 2                       # sigma_n, lambda_n, F - |sigma_t| grow like d^ONSET from a set
                                # end point, lambda_t like d^(ONSET + 1) (lambda_t' enters u_2)
QUANTITIES = ("sigma", "sigma_hdiv", "u", "eta", "lam_n", "lam_t")
SETS = ("contact_set", "stick_set")


# --- building blocks on Gamma_C ----------------------------------------------------------------

def _x() -> Piecewise:
    return Piecewise.x()


def cap(a: float, k: int = ONSET) -> Piecewise:
    """(1 - x^2/a^2)_+^k: one on x = 0, zero outside (-a, a)."""
    return Piecewise.window(-a, a, (1.0 - _x() * _x() / (a * a)) ** k)


def bump(left: float, right: float, k: int = ONSET) -> Piecewise:
    """((x - left)(right - x) / ((right - left)/2)^2)_+^k: one at the middle of (left, right)."""
    half = 0.5 * (right - left)
    inside = ((_x() - left) * (right - _x()) / (half * half)) ** k
    return Piecewise.window(left, right, inside)


def smooth_sign(b: float) -> Piecewise:
    """sign(x) for |x| >= b, the odd C^1 smoothstep p(x/b) inside.

    p(z) = z (3 - z^2) / 2: p(1) = 1, p'(1) = 0, and 1 - |p| = (1 - |z|)^2 (2 + |z|) / 2 > 0
    for |z| < 1, a quadratic margin at the end of the stick zone.
    """
    z = _x() / b
    p = z * (3.0 - z * z) / 2.0
    return Piecewise((-b, b), ({(0, 0): -1.0}, p.pieces[0], {(0, 0): 1.0}))


def stick_towards_ends(b: float, d: float, k: int = ONSET) -> Piecewise:
    """smooth_sign(b) on |x| <= d, sign(x) (1 - ((|x| - d)/(4 - d))^k) beyond: |.| < 1 there."""
    right = 1.0 - Piecewise.ramp(d, k, 1.0 / (HALF_WIDTH - d))
    left = Piecewise.ramp(-d, k, 1.0 / (HALF_WIDTH - d), right=False) - 1.0
    outer = Piecewise((-d, d), (left.pieces[0], {}, right.pieces[-1]))
    inner = Piecewise.window(-d, d, smooth_sign(b))
    return inner + outer


# --- the cases ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class ExactSolution:
    """Exact fields (functions of x, y) and traces on Gamma_C (functions of x)."""

    u: tuple[Piecewise, Piecewise]
    sigma: tuple[tuple[Piecewise, Piecewise], tuple[Piecewise, Piecewise]]
    div_sigma: tuple[Piecewise, Piecewise]
    eta: Piecewise
    gap: Piecewise
    lam_n: Piecewise
    lam_t: Piecewise
    sigma_n: Piecewise
    sigma_t: Piecewise
    friction_bound: Piecewise

    @property
    def degree(self) -> int:
        """Largest polynomial degree of u, sigma, div sigma and eta on one strip."""
        parts = [*self.u, *self.sigma[0], *self.sigma[1], *self.div_sigma, self.eta]
        return max(p.degree for p in parts)


@dataclass(frozen=True)
class ManufacturedCase:
    """A manufactured contact problem on the rectangle of Example 3.46 (see the module doc).

    The traces on Gamma_C are functions of x; ``contact_set`` and ``stick_set`` are the
    exact sets as intervals of x (the stick set: contact points with u_t = 0 and
    |sigma_t| < F; empty without friction).
    """

    name: str
    description: str
    law: str
    lam_t: Piecewise
    u_n: Piecewise
    lam_n: Piecewise
    sigma_n: Piecewise
    sigma_t: Piecewise
    contact_set: tuple[tuple[float, float], ...]
    stick_set: tuple[tuple[float, float], ...] = ()
    mu_f: float = 0.0
    tresca_bound: Piecewise = field(default_factory=lambda: Piecewise.constant(0.0))
    interior: tuple[Piecewise, Piecewise] = field(default_factory=lambda: (
        0.002 * (1.0 + _x() / 4.0), -0.001 * (1.0 + _x() * _x() / 16.0)))
    material: Material = field(default_factory=lambda: Material(E, NU))

    @cached_property
    def exact(self) -> ExactSolution:
        lam, mu = self.material.lame
        Y = Piecewise.y() - Y0
        b1 = self.sigma_t / mu + self.u_n.dx()
        b2 = (self.sigma_n - lam * self.lam_t.dx()) / (lam + 2 * mu)
        u = (self.lam_t + Y * b1 + Y * Y * self.interior[0],
             -self.u_n + Y * b2 + Y * Y * self.interior[1])
        grad = [[u[i].dx(), u[i].dy()] for i in range(2)]
        div_u = grad[0][0] + grad[1][1]
        sigma = tuple(tuple(mu * (grad[i][j] + grad[j][i]) + (lam * div_u if i == j else 0.0)
                            for j in range(2)) for i in range(2))
        div_sigma = tuple(sigma[i][0].dx() + sigma[i][1].dy() for i in range(2))
        eta = 0.5 * (grad[0][1] - grad[1][0])
        if self.law == "coulomb":
            bound = self.mu_f * (-self.sigma_n)
        elif self.law == "tresca":
            bound = self.tresca_bound
        else:
            bound = Piecewise.constant(0.0)
        return ExactSolution(u, sigma, div_sigma, eta, self.u_n + self.lam_n, self.lam_n,
                             self.lam_t, self.sigma_n, self.sigma_t, bound)

    def scene(self, method: str = "auto", level: int = 1, ends: str = "consistent") -> Scene:
        """The validated scene: f = -div sigma, t0 = sigma n on the top, u_D = u on the sides.

        ``method``: ``solver.method``; ``ends``: ``contact.ends`` (the exact multipliers
        vanish at the ends of Gamma_C, so "consistent" and "thesis" pose the same problem).
        """
        ex = self.exact
        traction = [ex.sigma[0][1].text(), ex.sigma[1][1].text()]   # n = (0, 1) on the top
        sc = Scene(name=f"manufactured-{self.name}",
                   geometry=Geometry(kind="thesis-3.46", level=level),
                   boundary={"dirichlet": ["left", "right"], "neumann": ["top"],
                             "contact": ["bottom"]},
                   material=Material(self.material.E, self.material.nu),
                   loads=Loads(body_force=[(-d).text() for d in ex.div_sigma],
                               traction=traction,
                               displacement=[c.text() for c in ex.u]),
                   # max(0, .): the expanded polynomial is zero at the clamped ends only up
                   # to round-off, and the scene's gap must be >= 0
                   contact=Contact(gap=f"max(0, {ex.gap.text()})", ends=ends),
                   friction=Friction(law=self.law, mu=self.mu_f,
                                     bound=self.tresca_bound.text()),
                   solver=Solver(method=method))
        validate(sc)
        return sc


def frictionless_case(a: float = 2.0, name: str | None = None) -> ManufacturedCase:
    """Contact on [-a, a] (sigma_n = -P (1 - x^2/a^2)^3), lift-off towards the clamped ends."""
    x = _x()
    return ManufacturedCase(
        name=name or f"frictionless-a{a:g}",
        description=f"frictionless; contact set [-{a:g}, {a:g}]",
        law="none",
        lam_t=SLIDE * (x / 4.0) * (1.0 - x * x / 16.0),
        u_n=APPROACH * (1.0 - x * x / 16.0) ** 2,
        lam_n=LIFT * (bump(-HALF_WIDTH, -a) + bump(a, HALF_WIDTH)),
        sigma_n=-PRESSURE * cap(a),
        sigma_t=Piecewise.constant(0.0),
        contact_set=((-a, a),))


def tresca_case(b: float = 1.0, a: float = 2.0, d: float = 3.0, bound: float = 1.0,
                name: str | None = None) -> ManufacturedCase:
    """Tresca, F = ``bound`` on all of Gamma_C: contact [-a, a], slip on b < |x| < d.

    Stick where |x| <= b or |x| >= d (|sigma_t| < F, u_t = 0), slip in between with
    sigma_t = F sign(x) = F sign(lambda_t); b < a < d, so the stick set in contact is [-b, b].
    """
    return _friction_case(
        a, name or f"tresca-b{b:g}-a{a:g}-d{d:g}", "tresca",
        f"Tresca F = {bound:g}; contact [-{a:g}, {a:g}], stick [-{b:g}, {b:g}] "
        f"and |x| >= {d:g}",
        lam_t=SLIDE * (bump(b, d, ONSET + 1) - bump(-d, -b, ONSET + 1)),
        sigma_t=bound * stick_towards_ends(b, d), stick_set=((-b, b),),
        tresca_bound=Piecewise.constant(bound))


def coulomb_case(b: float = 2.0 / 3.0, a: float = 7.0 / 3.0, mu_f: float = 0.5,
                 name: str | None = None) -> ManufacturedCase:
    """Coulomb, F = mu_f |sigma_n|: contact [-a, a], stick [-b, b], slip on b < |x| <= a."""
    return _friction_case(
        a, name or f"coulomb-b{b:.4g}-a{a:.4g}", "coulomb",
        f"Coulomb mu_f = {mu_f:g}; contact [-{a:.4g}, {a:.4g}], stick [-{b:.4g}, {b:.4g}]",
        lam_t=SLIDE * (bump(b, HALF_WIDTH, ONSET + 1) - bump(-HALF_WIDTH, -b, ONSET + 1)),
        sigma_t=mu_f * PRESSURE * cap(a) * smooth_sign(b), stick_set=((-b, b),), mu_f=mu_f)


def _friction_case(a: float, name: str, law: str, description: str,
                   **friction) -> ManufacturedCase:
    """The frictionless case with contact [-a, a] and the tangential fields ``friction``
    (lam_t, sigma_t, stick_set and the law's bound) of a friction law."""
    base = frictionless_case(a)
    return ManufacturedCase(name=name, description=description, law=law, u_n=base.u_n,
                            lam_n=base.lam_n, sigma_n=base.sigma_n, contact_set=((-a, a),),
                            **friction)


CASES = {
    # contact-set end points on coarse (h~) nodes on every level
    "frictionless": lambda: frictionless_case(2.0, "frictionless"),
    "tresca": lambda: tresca_case(1.0, 2.0, 3.0, 1.0, "tresca"),
    "coulomb-nodes": lambda: coulomb_case(1.0, 2.0, 0.5, "coulomb-nodes"),
    # end points at a third of an h~ edge on every level (7/3, 2/3 are not dyadic)
    "frictionless-offnode": lambda: frictionless_case(7.0 / 3.0, "frictionless-offnode"),
    "coulomb": lambda: coulomb_case(2.0 / 3.0, 7.0 / 3.0, 0.5, "coulomb"),
}


def manufactured_case(name: str) -> ManufacturedCase:
    """One of :data:`CASES` by name."""
    if name not in CASES:
        raise KeyError(f"unknown manufactured case {name!r}; known: {', '.join(CASES)}")
    return CASES[name]()


# --- errors ------------------------------------------------------------------------------------

def _coefficient(p: Piecewise) -> ngs.CoefficientFunction:
    return Expression(p.text()).coefficient()


def volume_errors(case: ManufacturedCase, solution: Solution,
                  order: int | None = None) -> dict:
    """L2 errors of sigma, div sigma, u, eta, the H(div) error of sigma and ||sigma||_L2.

    Integrated exactly (:class:`~ngdual.verification.integrate.PiecewiseQuadrature`:
    ``order``, by default twice the exact fields' degree, on every triangle piece between
    the breakpoint lines x = const of the exact solution).
    """
    ex = case.exact
    order = order or 2 * ex.degree
    mesh = solution.problem.fes.mesh
    breaks = sorted({b for p in (*ex.u, *ex.sigma[0], *ex.sigma[1], *ex.div_sigma, ex.eta)
                     for b in p.breaks})

    quadrature = PiecewiseQuadrature(mesh, breaks, order)

    def l2(cf):
        return math.sqrt(max(quadrature.integrate(ngs.InnerProduct(cf, cf)), 0.0))

    f = fields(solution)
    s = ngs.CF(tuple(_coefficient(ex.sigma[i][j]) for i in range(2) for j in range(2)),
               dims=(2, 2))
    out = {"sigma": l2(s - f.sigma),
           "div_sigma": l2(ngs.CF(tuple(_coefficient(d) for d in ex.div_sigma)) - f.div_sigma),
           "u": l2(ngs.CF(tuple(_coefficient(c) for c in ex.u)) - f.u),
           "eta": l2(_coefficient(ex.eta) - f.eta),
           "norm_sigma": l2(s)}
    out["sigma_hdiv"] = math.hypot(out["sigma"], out["div_sigma"])
    return out


def _boundary_l2(x_nodes: np.ndarray, values: np.ndarray, exact: Piecewise) -> float:
    """L2 norm on Gamma_C of (piecewise linear ``values`` at ``x_nodes``) - exact, exactly.

    Gauss-Legendre on every fine edge, split at the breakpoints of ``exact``.
    """
    points, weights = np.polynomial.legendre.leggauss(exact.degree // 2 + 2)
    trace = exact.at_y(Y0)
    total = 0.0
    for x0, x1, v0, v1 in zip(x_nodes[:-1], x_nodes[1:], values[:-1], values[1:]):
        lo, hi = min(x0, x1), max(x0, x1)
        cuts = [lo, *(b for b in trace.breaks if lo < b < hi), hi]
        for a, b in zip(cuts[:-1], cuts[1:]):
            xq = 0.5 * (a + b) + 0.5 * (b - a) * points
            vh = v0 + (v1 - v0) * (xq - x0) / (x1 - x0)
            total += 0.5 * (b - a) * np.sum(weights * (vh - trace.numpy(xq, 0.0 * xq)) ** 2)
    return math.sqrt(total)


def _coarse_nodes(solution: Solution, flags: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """(x of the h~ nodes, per-node flag) for every chain of Gamma_C, ends included.

    ``flags`` holds one flag per coarse dof (dof order); nodes without a dof (the ends of
    Gamma_C, where lambda_n^h is prescribed: zero in every manufactured case) count as true.
    """
    contact = solution.problem.spaces.contact
    out, offset = [], 0
    for c, chain in enumerate(contact.chains):
        nodes = contact.nodes[c]
        node_flags = np.ones(len(nodes), dtype=bool)
        for k, position in enumerate(contact.dof_positions(c)):
            node_flags[np.flatnonzero(nodes == position)] = flags[offset + k]
        offset += len(contact.dof_positions(c))
        out.append((chain.path_points[nodes][:, 0], node_flags))
    return out


def _edges_of(chains) -> list[tuple[float, float]]:
    """The h~ edges whose two nodes are flagged: where the P1 function is identically zero."""
    out = []
    for xs, flags in chains:
        for k in range(len(xs) - 1):
            if flags[k] and flags[k + 1]:
                out.append((min(xs[k], xs[k + 1]), max(xs[k], xs[k + 1])))
    return out


def symmetric_difference(a, b) -> float:
    """Length of (A \\ B) u (B \\ A) for unions of intervals A and B of the real line.

    >>> symmetric_difference([(0, 2)], [(1, 3)])
    2.0
    """
    cuts = sorted({p for iv in (*a, *b) for p in iv})

    def inside(ivs, x):
        return any(lo <= x <= hi for lo, hi in ivs)

    return float(sum(hi - lo for lo, hi in zip(cuts[:-1], cuts[1:])
                     if inside(a, 0.5 * (lo + hi)) != inside(b, 0.5 * (lo + hi))))


def intersection(a, b) -> list[tuple[float, float]]:
    """A n B for unions of intervals A and B of the real line (as intervals of positive length).

    >>> intersection([(0, 2), (3, 5)], [(1, 4)])
    [(1, 2), (3, 4)]
    """
    out = [(max(p, r), min(q, s)) for p, q in a for r, s in b]
    return [(p, q) for p, q in out if q > p]


def discrete_sets(solution: Solution) -> dict:
    """The discrete contact and stick sets as unions of intervals of x.

    Contact: the h~ edges on which lambda_n^h vanishes identically (both nodes in contact,
    :func:`ngdual.post.contact_traces`; the ends of Gamma_C, where lambda_n^h is fixed to
    zero, count as in contact). Stick: the h^ edges where the discrete friction variable
    sticks, |nu| < 1 with F > 0 (``edge_status == "stick"`` in
    :func:`ngdual.post.friction_diagnostics`; there (Q_F lambda_t^h) = 0), within the
    contact set. (The node status of ``friction_diagnostics`` calls a node stick only if
    every h^ edge under its hat sticks, so its stick nodes span up to one h~ edge less at
    each end of a stick zone.)
    """
    tr = contact_traces(solution)
    out = {"contact": _edges_of(_coarse_nodes(solution, tr.coarse_in_contact)), "stick": []}
    if solution.nu is not None:
        diag = friction_diagnostics(solution)
        hat = solution.problem.spaces.friction
        edges = [(min(p, q), max(p, q)) for chain, nodes in zip(hat.chains, hat.nodes)
                 for p, q in zip(chain.path_points[nodes][:-1, 0], chain.path_points[nodes][1:, 0])]
        stick = [e for e, status in zip(edges, diag.edge_status) if status == "stick"]
        out["stick"] = intersection(stick, out["contact"])
    return out


def _grid_x(coarse) -> list[np.ndarray]:
    """x of the nodes (ends included) of a coarse boundary mesh, chain by chain."""
    return [chain.path_points[nodes][:, 0] for chain, nodes in zip(coarse.chains, coarse.nodes)]


def set_resolution(grid: list[np.ndarray], exact) -> float:
    """|exact set \\ union of the grid edges inside it|: the set error of a discrete set that
    classifies every node of ``grid`` (x per chain) exactly (zero if every end point of
    ``exact`` is a node)."""
    def inside(x):
        return any(lo - 1e-12 <= x <= hi + 1e-12 for lo, hi in exact)

    nodes = [(xs, np.array([inside(x) for x in xs])) for xs in grid]
    return symmetric_difference(_edges_of(nodes), exact)


def boundary_errors(case: ManufacturedCase, solution: Solution) -> dict:
    """L2(Gamma_C) errors of lambda_n, lambda_t and the contact / stick set errors (lengths).

    ``contact_set_resolution`` / ``stick_set_resolution``: :func:`set_resolution` of the
    exact sets on the h~ / h^ mesh, the part of the set error that the grid forces.
    """
    ex = case.exact
    spaces = solution.problem.spaces
    tr = contact_traces(solution)
    x = tr.node_xy[:, 0]
    sets = discrete_sets(solution)
    out = {"lam_n": _boundary_l2(x, tr.lam_n, ex.lam_n),
           "lam_t": _boundary_l2(x, tr.lam_t, ex.lam_t),
           "contact_set": symmetric_difference(sets["contact"], case.contact_set),
           "contact_set_resolution": set_resolution(_grid_x(spaces.contact), case.contact_set),
           "stick_set": None, "stick_set_resolution": None}
    if case.law != "none":
        out["stick_set"] = symmetric_difference(sets["stick"], case.stick_set)
        out["stick_set_resolution"] = set_resolution(_grid_x(spaces.friction), case.stick_set)
    return out


def manufactured_study(case: ManufacturedCase | str, levels=(1, 2, 3, 4, 5),
                       method: str = "auto") -> list[dict]:
    """Solve ``case`` on every level and measure every error against the exact solution.

    Returns one row per level: ``level``, ``h`` (largest triangle diameter), ``htilde``
    and ``hhat`` (largest h~ and h^ edges; h^ None without friction), ``ndof``, the L2
    errors ``sigma``, ``div_sigma``, ``u``, ``eta``, the H(div) error ``sigma_hdiv``, the
    L2(Gamma_C) errors ``lam_n``, ``lam_t`` of the coarse P1 multipliers against g - u_n
    and -u_t, the lengths ``contact_set`` and ``stick_set`` (None without friction) of the
    symmetric differences between the discrete sets (:func:`discrete_sets`) and the exact
    ones with their grid resolutions (:func:`boundary_errors`), ``norm_sigma`` and the wall
    time ``seconds`` of the solve. Orders: :func:`convergence_orders`.
    """
    case = manufactured_case(case) if isinstance(case, str) else case
    scene = case.scene(method)
    rows = []
    for level in levels:
        start = time.perf_counter()
        solution = solve_scene(scene, level)
        seconds = time.perf_counter() - start
        pb = solution.problem
        hhat = pb.spaces.friction.edge_lengths().max() if pb.spaces.friction else None
        rows.append({"case": case.name, "level": level, "h": mesh_size(pb.fes.mesh),
                     "htilde": float(pb.spaces.contact.edge_lengths().max()),
                     "hhat": None if hhat is None else float(hhat),
                     "ndof": sum(pb.spaces.dofs().values()),
                     **volume_errors(case, solution), **boundary_errors(case, solution),
                     "seconds": seconds})
    return rows


def convergence_orders(rows: list[dict], key: str) -> list[float | None]:
    """Observed orders of ``key`` between consecutive rows: the one rate of ngdual,
    :func:`ngdual.rates.observed_rates` (the order in h_N = N^{-1/2}, N = ``ndof``); None for
    the first row and where an error is zero or missing."""
    return observed_rates([row["ndof"] for row in rows], [row.get(key) for row in rows])


def format_study(rows: list[dict], quantities=QUANTITIES) -> str:
    """The study as a text table: errors with observed orders per level, then the set
    errors with their grid resolutions in parentheses."""
    if not rows:
        return ""
    orders = {q: convergence_orders(rows, q) for q in quantities}
    sets = [q for q in SETS if any(r.get(q) is not None for r in rows)]
    head = (f"{'lvl':>3} {'ndof':>7} {'h':>6} "
            + " ".join(f"{q:>10} {'ord':>5}" for q in quantities)
            + "".join(f" {q:>17}" for q in sets))
    lines = [f"manufactured case {rows[0]['case']}", head]
    for k, row in enumerate(rows):
        cells = [f"{row[q]:10.3e} " + (f"{orders[q][k]:5.2f}" if orders[q][k] is not None
                                         else f"{'':>5}") for q in quantities]
        for q in sets:
            cells.append(f"{row[q]:8.4f} ({row[q + '_resolution']:6.4f})")
        lines.append(f"{row['level']:3d} {row['ndof']:7d} {row['h']:6.3f} " + " ".join(cells))
    return "\n".join(lines)


def print_study(rows: list[dict]) -> None:
    """Print :func:`format_study`."""
    print(format_study(rows))


# --- the contact pressure near the edge of the contact zone ------------------------------------

def contact_profile(case: ManufacturedCase, solution: Solution) -> dict:
    """Per interior h~ node: x, lambda_n (discrete, exact), and the pressure sigma_n.

    ``pressure`` is the lumped L2 projection of sigma_n^h onto the h~ hats, t_i / m_i with
    t_i = d_Cn(mu_i, sigma^h) = int sigma_n^h mu_i ds and m_i = int mu_i ds (the |sigma_n|
    of the default Coulomb bound, :meth:`ngdual.friction.FrictionForms.coulomb_bound_of`);
    ``pressure_of_exact`` the same projection of the exact sigma_n, ``sigma_n`` the exact
    value at the node.

    At the last contact node the discrete pressure carries a spike: lambda_n^h is linear on
    the first separated h~ edge while the exact gap opens like c d^2, and the kink of
    lambda_n^h (slope jump c theta^2 h~, theta the part of that edge outside the exact
    contact set) is held by a concentrated compressive sigma_n^h on the first fine edge past
    the node, with a tensile one before it. The spike is O(h~) (on the ``frictionless``
    case 2.4, 1.4, 0.70, 0.35 % of the peak pressure on levels 3-6, against an exact
    projection 6-10 times smaller) and grows with theta.
    """
    pb = solution.problem
    contact = pb.spaces.contact
    t = pb.block(pb.sigma, pb.lam_n).T @ solution.x[pb.sigma]
    trace = case.exact.sigma_n.at_y(Y0)
    points, weights = np.polynomial.legendre.leggauss(trace.degree // 2 + 2)
    xs, m, t_exact = [], [], []
    for c, chain in enumerate(contact.chains):
        nodes = contact.nodes[c]
        nx = chain.path_points[nodes][:, 0]
        for position in contact.dof_positions(c):
            k = int(np.flatnonzero(nodes == position)[0])
            moment, mass = 0.0, 0.0
            for a, b in ((nx[k - 1], nx[k]), (nx[k], nx[k + 1])):
                lo, hi = min(a, b), max(a, b)
                cuts = [lo, *(p for p in trace.breaks if lo < p < hi), hi]
                for p, q in zip(cuts[:-1], cuts[1:]):
                    xq = 0.5 * (p + q) + 0.5 * (q - p) * points
                    hat = 1.0 - np.abs(xq - nx[k]) / abs(b - a)
                    moment += 0.5 * (q - p) * np.sum(weights * hat * trace.numpy(xq, 0 * xq))
                mass += 0.5 * abs(b - a)
            xs.append(nx[k])
            m.append(mass)
            t_exact.append(moment)
    xs, m = np.array(xs), np.array(m)
    return {"x": xs, "lam_n": solution.part("lam_n"),
            "lam_n_exact": case.exact.lam_n.numpy(xs, 0 * xs),
            "pressure": t / m, "pressure_of_exact": np.array(t_exact) / m,
            "sigma_n": trace.numpy(xs, 0 * xs)}


# --- the contact pressure and its error -----------------------------------------------------

def contact_pressure(solution: Solution) -> dict:
    """The contact pressure p_h and the raw fine-edge sigma_n^h along Gamma_C.

    p_h = sum_i (t_i / m_i) mu_i over the h~ hats (:func:`ngdual.friction.hat_projection`):
    the discrete contact forces per unit length, zero where the body separates. Returns the
    fine edge end points ``x0``, ``x1`` (x of the start and end vertex), ``p0``, ``p1``
    (p_h there: p_h is linear on every fine edge), ``sigma_n`` (the fine-edge value of
    :func:`ngdual.post.contact_traces`), and per interior h~ node ``node_x``,
    ``node_pressure`` (t_i / m_i) and ``node_lam_n``.
    """
    pb = solution.problem
    gamma_c, prolong = pb.spaces.gamma_c, pb.spaces.prolongations["lam_n"]
    sigma_n = contact_traces(solution).sigma_n
    nodal = hat_projection(gamma_c.hat_means(prolong), gamma_c.lengths, sigma_n)
    fine = prolong @ nodal
    points = np.array([v.point for v in pb.fes.mesh.vertices])
    dof_x = np.concatenate([chain.path_points[pb.spaces.contact.dof_positions(c)][:, 0]
                            for c, chain in enumerate(pb.spaces.contact.chains)])
    return {"x0": points[gamma_c.vertices[:, 0], 0], "x1": points[gamma_c.vertices[:, 1], 0],
            "p0": fine[gamma_c.edge_dofs[:, 0]], "p1": fine[gamma_c.edge_dofs[:, 1]],
            "sigma_n": sigma_n, "node_x": dof_x, "node_pressure": nodal,
            "node_lam_n": solution.part("lam_n")}


def pressure_errors(case: ManufacturedCase, solution: Solution) -> dict:
    """Errors of the contact pressure against the exact sigma_n on Gamma_C.

    ``pressure`` / ``pressure_max``: L2(Gamma_C) and maximum error of p_h
    (:func:`contact_pressure`); ``fine_sigma_n`` / ``fine_sigma_n_max``: the same for the
    raw fine-edge sigma_n^h. Gauss-Legendre on every fine edge, split at the breakpoints
    of the exact trace (the maximum over those points and the edge ends).
    """
    pr = contact_pressure(solution)
    trace = case.exact.sigma_n.at_y(Y0)
    points, weights = np.polynomial.legendre.leggauss(trace.degree // 2 + 4)
    points = np.concatenate([[-1.0], points, [1.0]])
    weights = np.concatenate([[0.0], weights, [0.0]])
    sums = {"pressure": [0.0, 0.0], "fine_sigma_n": [0.0, 0.0]}
    for x0, x1, p0, p1, s in zip(pr["x0"], pr["x1"], pr["p0"], pr["p1"], pr["sigma_n"]):
        lo, hi = min(x0, x1), max(x0, x1)
        cuts = [lo, *(b for b in trace.breaks if lo < b < hi), hi]
        for a, b in zip(cuts[:-1], cuts[1:]):
            xq = 0.5 * (a + b) + 0.5 * (b - a) * points
            exact = trace.numpy(xq, 0.0 * xq)
            for key, vh in (("pressure", p0 + (p1 - p0) * (xq - x0) / (x1 - x0)),
                            ("fine_sigma_n", s + 0.0 * xq)):
                d = vh - exact
                sums[key][0] += 0.5 * (b - a) * np.sum(weights * d * d)
                sums[key][1] = max(sums[key][1], float(np.abs(d).max()))
    return {"pressure": math.sqrt(sums["pressure"][0]), "pressure_max": sums["pressure"][1],
            "fine_sigma_n": math.sqrt(sums["fine_sigma_n"][0]),
            "fine_sigma_n_max": sums["fine_sigma_n"][1]}


def edge_spikes(case: ManufacturedCase, solution: Solution) -> list[dict]:
    """The pressure at every last h~ node in contact (a contact node next to a separated one).

    Per such node: ``x``, ``excess`` = p_h - (the same projection of the exact sigma_n, from
    :func:`contact_profile`; negative = too much compression), ``kink`` = lambda_n^h at the
    separated neighbour over the h~ edge length (the slope jump of lambda_n^h at the node)
    and ``uncovered``: the part theta of that h~ edge outside the exact contact set.
    """
    prof = contact_profile(case, solution)
    order = np.argsort(prof["x"])
    x, lam = prof["x"][order], prof["lam_n"][order]
    excess = (prof["pressure"] - prof["pressure_of_exact"])[order]
    touching = lam <= 1e-12 * np.abs(lam).max(initial=0.0)
    out = []
    for k in np.flatnonzero(touching):
        for j in (k - 1, k + 1):
            if 0 <= j < len(x) and not touching[j]:
                edge = abs(x[j] - x[k])
                inside = max(0.0, *(min(max(x[k], x[j]), hi) - max(min(x[k], x[j]), lo)
                                    for lo, hi in case.contact_set))
                out.append({"x": float(x[k]), "excess": float(excess[k]),
                            "kink": float(lam[j] / edge), "uncovered": 1.0 - inside / edge})
    return out
