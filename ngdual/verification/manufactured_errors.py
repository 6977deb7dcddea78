"""The exact errors of a discrete solution of a manufactured case (:mod:`ngdual.verification.
manufactured`): fields in the volume, multipliers and sets on Gamma_C, the contact pressure
near the edge of the contact zone, and the study per level with observed orders."""

from __future__ import annotations

import math
import time

import ngsolve as ngs
import numpy as np

from ..expr import Expression
from ..mesh import mesh_size
from ..quantities import fields
from ..rates import observed_rates
from ..solution import Solution
from ..solvers import solve_scene
from ..trace import contact_traces, friction_diagnostics
from .integrate import PiecewiseQuadrature
from .manufactured import (
    QUANTITIES,
    SETS,
    Y0,
    ManufacturedCase,
    manufactured_case,
)
from .piecewise import Piecewise

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
    :func:`ngdual.trace.contact_traces`; the ends of Gamma_C, where lambda_n^h is fixed to
    zero, count as in contact). Stick: the h^ edges where the discrete friction variable
    sticks, |nu| < 1 with F > 0 (``edge_status == "stick"`` in
    :func:`ngdual.trace.friction_diagnostics`; there (Q_F lambda_t^h) = 0), within the
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

    p_h = sum_i (t_i / m_i) mu_i over the h~ hats, the pressure of the solution's contact
    trace (:func:`ngdual.trace.contact_traces`, signed here as sigma_n):
    the discrete contact forces per unit length, zero where the body separates. Returns the
    fine edge end points ``x0``, ``x1`` (x of the start and end vertex), ``p0``, ``p1``
    (p_h there: p_h is linear on every fine edge), ``sigma_n`` (the fine-edge value of
    :func:`ngdual.trace.contact_traces`), and per interior h~ node ``node_x``,
    ``node_pressure`` (t_i / m_i) and ``node_lam_n``.
    """
    pb = solution.problem
    gamma_c, prolong = pb.spaces.gamma_c, pb.spaces.prolongations["lam_n"]
    traces = contact_traces(solution)
    sigma_n, nodal = traces.sigma_n, -traces.pressure
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
