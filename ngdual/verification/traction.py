"""The discrete contact pressure and shear traction on Gamma_C, and their exact errors against
the analytic solutions of :mod:`ngdual.verification.analytic`.

Which discrete pressure is compared. In the dual-dual formulation lambda_n = g - u_n is a
gap (a displacement), not a pressure; the pressure is -sigma_n^h. The fine-edge values of
sigma_n^h (constant per fine edge for RT_0) are not what the contact conditions control:
(3.62) tests sigma_n^h only against the P1 hats mu_i of the coarse h~ mesh,
d_Cn(mu_i, sigma^h) = int sigma_n^h mu_i ds, and the part of sigma_n^h orthogonal to those
hats (one free value per h~ edge, since h~ = 2h) is set by the elasticity alone and
oscillates from fine edge to fine edge (on hertz-cylinder even tensile values inside the
contact zone). The compared pressure is therefore the lumped L2 projection of -sigma_n^h
onto the h~ hats, p_i = -int sigma_n^h mu_i ds / int mu_i ds, as a P1 function on the h~
mesh (:func:`traction_profile`): the pressure the discrete contact conditions see and the
one the default Coulomb bound is built from. Its integral is the total force exactly (the
hats sum to one where the ends of Gamma_C are free).

Norms. The errors are integrated exactly up to quadrature round-off: every h~ edge is cut at
the points where the exact profile is not smooth (+-a, +-c), and each piece is integrated
with Gauss-Legendre in the variable t of x = m - r cos(pi t), which turns both square-root
behaviours sqrt(a - x) and 1/sqrt(a - x) at a piece's end into smooth integrands.

* Hertz and Cattaneo-Mindlin: relative L2 errors over all of Gamma_C (the exact traction
  is in L2) and the relative max error at the h~ nodes (against p0, resp. max |q|).
* Flat punch: p is not in L2 (p^2 ~ 1/(a - |x|)), so an L2 error over the contact zone is
  infinite for every discrete pressure. Two measures are reported instead. The relative
  L1 error ||p_h - p||_L1 / P: p is in L1, and the L1 error bounds the error of the force
  on every subset of Gamma_C (|int_S p_h - int_S p| <= ||p_h - p||_L1), so it is the
  natural force-type measure; it decays like h^(1/2) at best, limited by the edge
  singularity. And the relative L2 and max errors on the core |x - x0| < a/2 (``core``),
  away from the singular edges, where p is smooth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..friction import hat_projection
from ..geometry import tangent
from ..post import force_balance
from ..scene import Scene, foundation_line
from ..solution import Solution
from ..trace import contact_traces
from .analytic import CattaneoMindlin

GAUSS_POINTS = 24          # per piece, after the cosine map (smooth integrands)
CORE = 0.5                 # the flat punch's core |x - x0| < CORE * a


# --- the discrete traction on Gamma_C ------------------------------------------------------------

@dataclass(frozen=True)
class TractionProfile:
    """The computed pressure and shear traction on Gamma_C as P1 functions on the h~ mesh.

    ``x``: coordinate of the h~ nodes along the contact plane (the foundation line, else x),
    chain by chain, nodes in chain order; ``chain_starts`` the first node of each chain;
    ``pressure`` p_i = -int sigma_n^h mu_i / int mu_i and ``shear``
    q_i = s int sigma_t^h mu_i / int mu_i, s = +-1 so that q points along +x (t of (3.24) is
    (n_2, -n_1)); ``in_contact`` lambda_n = 0 at the node (fixed ends: False).
    """

    x: np.ndarray
    chain_starts: np.ndarray
    pressure: np.ndarray
    shear: np.ndarray
    in_contact: np.ndarray

    def edge_nodes(self):
        """(k, k + 1) node pairs of every h~ edge."""
        stops = [*self.chain_starts[1:], len(self.x)]
        for start, stop in zip(self.chain_starts, stops):
            for k in range(start, stop - 1):
                yield k, k + 1

    def edges(self):
        """(x_left, x_right, p_left, p_right, q_left, q_right) of every h~ edge."""
        for k0, k1 in self.edge_nodes():
            yield (self.x[k0], self.x[k1], self.pressure[k0], self.pressure[k1],
                   self.shear[k0], self.shear[k1])

    def integral(self, values: np.ndarray, lo: float = -np.inf, hi: float = np.inf) -> float:
        """int_{lo}^{hi} of the P1 function with node ``values``, exactly."""
        total = 0.0
        for k0, k1 in self.edge_nodes():
            x0, x1, f0, f1 = self.x[k0], self.x[k1], values[k0], values[k1]
            left, right = sorted((x0, x1))
            a, b = max(left, lo), min(right, hi)
            if b > a:
                fa = f0 + (f1 - f0) * (a - x0) / (x1 - x0)
                fb = f0 + (f1 - f0) * (b - x0) / (x1 - x0)
                total += 0.5 * (b - a) * (fa + fb)
        return total

    @property
    def force(self) -> float:
        """P = int p_h dx."""
        return self.integral(self.pressure)

    @property
    def tangential_force(self) -> float:
        """Q = int q_h dx."""
        return self.integral(self.shear)

    def centroid_of(self, values: np.ndarray) -> float:
        """int x f dx / int f dx of the P1 function f with node ``values``, exactly."""
        moment = 0.0
        for k0, k1 in self.edge_nodes():
            x0, x1, f0, f1 = self.x[k0], self.x[k1], values[k0], values[k1]
            # int of x (f0 + (f1 - f0) s) over the edge, x = x0 + (x1 - x0) s
            moment += (x1 - x0) * (x0 * (f0 + f1) / 2 + (x1 - x0) * (f0 / 6 + f1 / 3))
        return moment / self.integral(values)

    @property
    def centroid(self) -> float:
        """int x p_h dx / P: the line of action of the normal force."""
        return self.centroid_of(self.pressure)

    def contact_interval(self) -> tuple[float, float]:
        """(x_min, x_max) of the h~ nodes in contact."""
        x = self.x[self.in_contact]
        return (float(x.min()), float(x.max())) if len(x) else (0.0, 0.0)


def _plane_coordinate(solution: Solution, points: np.ndarray) -> np.ndarray:
    contact = solution.problem.scene.contact
    if contact.foundation is None:
        return points[:, 0].copy()
    point, _ = foundation_line(contact)
    return (points - point) @ plane_direction(solution.problem.scene)


def traction_profile(solution: Solution) -> TractionProfile:
    """The lumped L2 projections of -sigma_n^h and sigma_t^h onto the h~ hats (see the module
    docstring for why these are the compared tractions) with the thesis' hats at k = 0; the
    traces themselves (:func:`_facet_profile`) wherever the contact trace samples them (order
    k >= 1, and the facet multipliers at every k)."""
    pb = solution.problem
    gamma_c, coarse = pb.spaces.gamma_c, pb.spaces.contact
    traces = contact_traces(solution)
    if traces.trace_xy is not None:   # the traces themselves are the profile
        return _facet_profile(solution, traces)
    hats = gamma_c.hat_means(pb.spaces.prolongations["lam_n"])          # dof hats
    end_hats = gamma_c.hat_means(pb.spaces.end_hats["lam_n"])           # fixed-end hats
    length = gamma_c.lengths
    along = np.sign(gamma_c.tangents @ plane_direction(solution.problem.scene))
    sigma_n = -np.concatenate([traces.pressure, traces.end_pressure])
    sigma_t = np.concatenate([hat_projection(h, length, along * traces.sigma_t)
                              for h in (hats, end_hats)])
    contact = np.concatenate([traces.coarse_in_contact, np.zeros(end_hats.shape[1], bool)])
    # column of every h~ node, chain by chain in chain order
    xs, columns, starts = [], [], []
    dof, end = 0, hats.shape[1]
    for c, chain in enumerate(coarse.chains):
        positions = coarse.nodes[c][:-1] if chain.closed else coarse.nodes[c]
        dofs = set(int(p) for p in coarse.dof_positions(c))
        starts.append(len(columns))
        for p in positions:
            if int(p) in dofs:
                columns.append(dof)
                dof += 1
            else:
                columns.append(end)
                end += 1
        xs.append(chain.path_points[positions])
    columns = np.array(columns)
    x = _plane_coordinate(solution, np.vstack(xs))
    return TractionProfile(x, np.array(starts), -sigma_n[columns], sigma_t[columns],
                          contact[columns])


def _facet_profile(solution: Solution, traces) -> TractionProfile:
    """The traces -sigma_n^h, sigma_t^h of order k as the profile: the facet multipliers are
    the trace space of RT_k, so the traces are what the contact conditions control, with
    nothing orthogonal to project away; the coarse ones of degree k + 1 control moments on
    h~ and leave no profile at the h~ nodes (their unknowns are Bernstein coefficients),
    so they are measured by the same traces. Linear between the samples of
    :func:`ngdual.trace.contact_traces` (4k + 2 per fine edge, end points included: exact at
    k <= 1); every edge is a piece of its own (the traces are discontinuous)."""
    pb = solution.problem
    gamma_c = pb.spaces.gamma_c
    samples = traces.trace_xy.shape[1]
    along = np.sign(gamma_c.tangents @ plane_direction(pb.scene))
    x = _plane_coordinate(solution, traces.trace_xy.reshape(-1, 2))
    return TractionProfile(x, samples * np.arange(len(gamma_c)), -traces.trace_sigma_n.ravel(),
                           (along[:, None] * traces.trace_sigma_t).ravel(),
                           np.repeat(traces.edge_active, samples))


def plane_direction(scene: Scene) -> np.ndarray:
    """The unit tangent of the foundation line (x_1 without a foundation line): the
    direction of the analytic profile's coordinate and of a positive Q."""
    if scene.contact.foundation is None:
        return np.array([1.0, 0.0])
    _, n_f = foundation_line(scene.contact)
    return tangent(n_f)


# --- exact integration of P1 minus an exact profile ------------------------------------------

def _pieces(profile: TractionProfile, breaks, lo: float = -np.inf, hi: float = np.inf):
    """(a, b, f_a, f_b, which) pieces of the h~ edges within [lo, hi], cut at ``breaks``."""
    for x0, x1, p0, p1, q0, q1 in profile.edges():
        left, right = sorted((x0, x1))
        a, b = max(left, lo), min(right, hi)
        if b <= a:
            continue
        cuts = [a, *sorted(t for t in breaks if a < t < b), b]
        for s, e in zip(cuts[:-1], cuts[1:]):
            yield s, e, (x0, x1, p0, p1, q0, q1)


def _linear(edge, which: str, x: np.ndarray) -> np.ndarray:
    x0, x1, p0, p1, q0, q1 = edge
    f0, f1 = (p0, p1) if which == "pressure" else (q0, q1)
    return f0 + (f1 - f0) * (x - x0) / (x1 - x0)


_T, _W = np.polynomial.legendre.leggauss(GAUSS_POINTS)


def _nodes(a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """Points and weights on [a, b] of Gauss-Legendre in t, x = m - r cos(pi t), t in [0, 1]:
    exact-to-round-off for integrands with sqrt(x - a) or 1/sqrt(x - a) at either end."""
    t = 0.5 * (_T + 1.0)
    m, r = 0.5 * (a + b), 0.5 * (b - a)
    return m - r * np.cos(np.pi * t), 0.5 * _W * r * np.pi * np.sin(np.pi * t)


def _integrate_abs(f, a: float, b: float) -> float:
    """int_a^b |f|, split at the sign changes of f (located on the quadrature points)."""
    x, _ = _nodes(a, b)
    values = f(x)
    cuts = [a]
    for k in np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0):
        cuts.append(brentq(lambda s: float(f(np.array([s]))[0]), x[k], x[k + 1]))
    cuts.append(b)
    total = 0.0
    for s, e in zip(cuts[:-1], cuts[1:]):
        xs, ws = _nodes(s, e)
        total += abs(float(np.dot(ws, f(xs))))
    return total


def _errors(profile: TractionProfile, exact_fn, breaks, which: str, x0: float,
            lo: float = -np.inf, hi: float = np.inf, l2: bool = True) -> dict:
    """Absolute L2 and L1 errors and L2, L1 norms of the exact profile on [lo, hi]."""
    err2 = norm2 = err1 = norm1 = 0.0
    for a, b, edge in _pieces(profile, [t + x0 for t in breaks], lo, hi):
        def diff(x, edge=edge):
            return _linear(edge, which, x) - exact_fn(x - x0)
        xs, ws = _nodes(a, b)
        ex = exact_fn(xs - x0)
        if l2:
            err2 += float(np.dot(ws, diff(xs) ** 2))
            norm2 += float(np.dot(ws, ex**2))
        err1 += _integrate_abs(diff, a, b)
        norm1 += float(np.dot(ws, np.abs(ex)))
    return {"l2": math.sqrt(err2), "norm_l2": math.sqrt(norm2), "l1": err1, "norm_l1": norm1}


def _node_max(profile: TractionProfile, exact_fn, which: str, x0: float, lo: float, hi: float,
              scale: float) -> float:
    values = profile.pressure if which == "pressure" else profile.shear
    inside = (profile.x >= lo) & (profile.x <= hi)
    if not inside.any():
        return float("nan")
    return float(np.max(np.abs(values[inside] - exact_fn(profile.x[inside] - x0))) / scale)


def pressure_errors(solution: Solution, exact, *, x0: float = 0.0) -> dict:
    """Errors of the computed contact pressure against ``exact.pressure(x - x0)``.

    ``exact``: :class:`HertzContact`, :class:`FlatPunch`, :class:`Wedge` or
    :class:`CattaneoMindlin` (its Hertz pressure). The discrete pressure is the h~-hat
    projection of -sigma_n^h (:func:`traction_profile`; the module docstring says why).
    Returns

    * ``l2``: ||p_h - p||_L2(Gamma_C) / ||p||_L2 (None for the flat punch: p is not in L2),
    * ``l1``: ||p_h - p||_L1 / ||p||_L1, the force-type measure (bounds the relative error of
      the force on every subset of Gamma_C),
    * ``max``: max over the h~ nodes of |p_h - p| / max p (flat punch: over the core nodes,
      against p(0); None for the wedge, whose p is unbounded at the apex),
    * ``l2_core``, ``max_core``: the same on the core |x - x0| < a/2, away from the edges,
    * ``force`` P_h = int p_h, ``resultant`` the normal component of int sigma^h n ds,
      ``force_core`` int_{|x - x0| < a/2} p_h and ``force_core_exact``,
    * ``half_width``: half the extent of the h~ nodes in contact, ``centre`` their midpoint,
      ``centroid`` int x p_h / P_h, ``a`` the exact half-width, ``htilde`` the longest h~
      edge meeting the contact zone (the resolution of ``half_width``).
    """
    profile = traction_profile(solution)
    a = getattr(exact, "hertz", exact).a
    core = (x0 - CORE * a, x0 + CORE * a)
    whole = _errors(profile, exact.pressure, exact.breaks, "pressure", x0,
                    l2=not exact.singular)
    inner = _errors(profile, exact.pressure, exact.breaks, "pressure", x0, *core)
    peak = float(exact.pressure(np.array([0.0]))[0])
    if not math.isfinite(peak):   # the wedge's apex: no maximum norm
        max_all = max_core = None
    elif exact.singular:
        max_all = max_core = _node_max(profile, exact.pressure, "pressure", x0, *core, peak)
    else:
        max_all = _node_max(profile, exact.pressure, "pressure", x0, -np.inf, np.inf, peak)
        max_core = _node_max(profile, exact.pressure, "pressure", x0, *core, peak)
    lo, hi = profile.contact_interval()
    balance = force_balance(solution)
    return {
        "l2": whole["l2"] / whole["norm_l2"] if not exact.singular else None,
        "l1": whole["l1"] / whole["norm_l1"],
        "max": max_all,
        "l2_core": inner["l2"] / inner["norm_l2"],
        "max_core": max_core,
        "force": profile.force,
        "resultant": float(balance.resultant @ _normal_direction(solution)),
        "force_core": profile.integral(profile.pressure, *core),
        "force_core_exact": inner["norm_l1"],
        "half_width": 0.5 * (hi - lo),
        "centre": 0.5 * (hi + lo),
        "centroid": profile.centroid,
        "a": a,
        "htilde": _htilde_near(profile, lo, hi),
    }


def _normal_direction(solution: Solution) -> np.ndarray:
    contact = solution.problem.scene.contact
    if contact.foundation is None:
        return np.array([0.0, 1.0])
    return foundation_line(contact)[1]


def _htilde_near(profile: TractionProfile, lo: float, hi: float) -> float:
    """The longest h~ edge with a node in [lo, hi] (all of Gamma_C if no node is in contact)."""
    longest = 0.0
    for x0, x1, *_ in profile.edges():
        if hi < lo or (max(x0, x1) >= lo and min(x0, x1) <= hi):
            longest = max(longest, abs(x1 - x0))
    return longest


def traction_errors(solution: Solution, exact: CattaneoMindlin, *, x0: float = 0.0) -> dict:
    """Errors of the computed shear traction against ``exact.shear(x - x0)`` and the stick zone.

    The discrete shear is the h~-hat projection of sigma_t^h along +x
    (:func:`traction_profile`). Returns ``l2`` and ``l1`` (relative, over Gamma_C), ``max``
    (at the h~ nodes, relative to max |q|), ``tangential_force`` Q_h = int q_h, the stick
    zone of the h^ mesh (the h^ edges with |nu| < 1 and F > 0 inside the contact set:
    ``stick_half_width`` c_h and ``stick_centre``), ``stick_centroid`` the centroid of the
    slip reserve mu_f p_h - |q_h| (exact: an ellipse over the stick zone, so this locates its
    centre below the h^ resolution), ``c`` the exact stick half-width and
    ``hhat`` the longest h^ edge (the friction cell) meeting the stick zone.
    """
    from .manufactured_errors import discrete_sets

    profile = traction_profile(solution)
    err = _errors(profile, exact.shear, exact.breaks, "shear", x0)
    xs = np.linspace(-exact.hertz.a, exact.hertz.a, 2001)
    peak = float(np.max(np.abs(exact.shear(xs))))
    stick = discrete_sets(solution)["stick"]
    if stick:
        lo, hi = min(s for s, _ in stick), max(e for _, e in stick)
    else:
        lo = hi = float("nan")
    friction = solution.problem.spaces.friction
    hhat = 0.0
    for chain, nodes in zip(friction.chains, friction.nodes):
        px = _plane_coordinate(solution, chain.path_points[nodes])
        for s, e in zip(px[:-1], px[1:]):
            if not stick or (max(s, e) >= lo and min(s, e) <= hi):
                hhat = max(hhat, abs(e - s))
    # mu_f p - |q| is mu_f p0 (c/a) sqrt(1 - (x - x0)^2/c^2)_+ exactly: its centroid locates
    # the stick zone below the h^ resolution
    reserve = np.where(profile.in_contact, np.maximum(
        exact.mu_f * profile.pressure - np.abs(profile.shear), 0.0), 0.0)
    return {"l2": err["l2"] / err["norm_l2"], "l1": err["l1"] / err["norm_l1"],
            "stick_centroid": profile.centroid_of(reserve),
            "max": _node_max(profile, exact.shear, "shear", x0, -np.inf, np.inf, peak),
            "tangential_force": profile.tangential_force,
            "stick_half_width": 0.5 * (hi - lo), "stick_centre": 0.5 * (hi + lo),
            "c": exact.c, "hhat": hhat}
