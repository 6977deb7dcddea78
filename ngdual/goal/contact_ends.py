"""The error of the order-k pressure at the ends of the contact zone: its distance to the
square-root profiles.

Where a body separates smoothly from the foundation the exact pressure vanishes like the
square root of the distance s to the end of the contact zone,

    p(s) = A s_+^(1/2) (1 + O(s))        (Hertz: p0 (1 - x^2/a^2)^(1/2), A = p0 (2/a)^(1/2)),

and the gap opens like s^(3/2) beyond it. The edge that holds the end carries a square-root
kink that no polynomial follows: its P_k pressure misses a share of the pressure that
depends on where the end falls in the edge (the best L2 approximation of degree 1 leaves
0.2-1.1 % of A^2 h^2, degree 2 0.04-0.4 %, over the positions of the end), and the edge
beyond carries the pressure the discrete contact zone spreads past the end. On the scenes of
Hertz type the ends hold nearly all of the pressure error of order k until they are resolved
(docs/theory/effectivity.md).

:func:`end_distances` estimates that error by the profile itself, as a recovery estimator
does with a smoother field: on the patch of every end (:func:`patches`: INSIDE edges on the
contact side of its last vertex in contact, OUTSIDE beyond) it takes the profile
p* = A s_+^(1/2) closest to p_h in L2 over A and the position of the end, and returns
||p* - p_h||^2 per edge (:func:`closest_profile`). A contact zone of one or two edges is one
patch with both ends, p* = A ((t - t_l)_+ (t_r - t)_+)^(1/2), Hertz's ellipse. The exact
pressure is such a profile to O(s^(3/2)), so the distance is the error of p_h on the patch
less the part of it that two parameters can follow: no constant is fitted.

At a kink of Gamma_C (the wedge's apex, where two contact sides meet at an angle) the
pressure is log-singular, p = b + c ln(1/r) + O(r) (c = E* tan(alpha) / pi for flanks of
slope tan(alpha)): :func:`kink_distances` takes the closest such profile on KINK_EDGES edges
either side of it in the same way.
"""

from __future__ import annotations

import ngsolve as ngs
import numpy as np

from ..mesh import boundary_segments
from ..scene import contact_junctions

# the edges of the patch of an end of the contact zone, whose last vertex in contact is z:
# on the contact side of z, and beyond it (where p_h may spread past the end)
INSIDE, OUTSIDE = 1, 2
# candidate positions of an end tried before the golden-section refinement
CANDIDATES = 17
GOLDEN_STEPS = 20
# Gauss-Legendre points per piece of an edge (the integrands are smooth in sqrt(s))
POINTS = 12
_X, _W = np.polynomial.legendre.leggauss(POINTS)
_X, _W = (_X + 1) / 2, _W / 2


def edge_values(p: ngs.CoefficientFunction, mesh: ngs.Mesh, gamma_c, ts) -> np.ndarray:
    """p_h (``p``) on every fine edge of Gamma_C (chain by chain, ``path_points`` order) at
    the local parameters ``ts`` in [0, 1], 0 the edge's start: (n_edges, len(ts)).

    Every boundary segment is sampled at 0, 1, ``ts`` and 1 - ``ts`` of its reference
    interval, each point mapped into the segment's own triangle (no point search); the
    points 0 and 1 tell which end of the reference interval is the fine edge's start.
    """
    ts = np.asarray(ts, float)
    m = len(ts)
    local = (0.0, 1.0, *ts, *(1 - ts))
    rule = ngs.IntegrationRule([(t,) for t in local], [0.0] * len(local))
    points = mesh.MapToAllElements(rule, ngs.BND)
    values = np.asarray(p(points)).reshape(-1, len(local))
    at = np.column_stack([np.asarray(ngs.x(points)).ravel(),
                          np.asarray(ngs.y(points)).ravel()]).reshape(-1, len(local), 2)
    _, number = boundary_segments(mesh)
    nr = np.array([number[frozenset(pair)] for pair in gamma_c.vertices.tolist()])
    start = np.vstack([chain.path_points[:-1] for chain in gamma_c.coarse.chains])
    off = np.linalg.norm(at[nr, :2] - start[:, None, :], axis=2)
    if np.any(off.min(axis=1) > 1e-8 * gamma_c.lengths):
        raise RuntimeError("NGSolve's boundary elements are not netgen's segments")
    first = off[:, 0] < off[:, 1]
    return np.where(first[:, None], values[nr, 2:2 + m], values[nr, 2 + m:])


def end_distances(p: ngs.CoefficientFunction, mesh: ngs.Mesh, gamma_c, order: int,
                  contact: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """||p* - p_h||^2 per fine edge of Gamma_C on the patches of the ends of the contact
    zone, and which edges lie in a patch.

    Parameters
    ----------
    p : ngsolve.CoefficientFunction
        p_h = -sigma_n^h, P_``order`` on every fine edge (:func:`ngdual.trace.pressure_field`).
    mesh : ngsolve.Mesh
    gamma_c : ngdual.contact.ContactBoundary
        The fine edges of Gamma_C.
    order : int
    contact : numpy.ndarray of bool
        Which fine vertices are in contact, chain by chain (``path_points`` order).

    Returns
    -------
    distances, in_patch : numpy.ndarray
        Per fine edge: the squared distance of p_h to the closest profile on the patch it
        lies in (:func:`patches`, :func:`closest_profile`), and whether it lies in one.
    """
    n = len(gamma_c.lengths)
    out, in_patch = np.zeros(n), np.zeros(n, bool)
    found = patches(gamma_c, contact)
    if not found:
        return out, in_patch
    coefficients = _edge_polynomials(p, mesh, gamma_c, order)
    for edges, ends in found:
        lengths = gamma_c.lengths[edges]
        t0 = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
        origin = np.concatenate([[0.0], np.cumsum(gamma_c.lengths)])[edges[0]]
        shifted = [(side, (lo - origin, hi - origin)) for side, (lo, hi) in ends]
        out[edges] += closest_profile(coefficients[edges], t0, lengths, shifted)
        in_patch[edges] = True
    return out, in_patch


def patches(gamma_c, contact: np.ndarray) -> list[tuple[np.ndarray, list]]:
    """The patches of the ends of the contact zone: (their fine edges, their ends), each end
    (side, (lo, hi)): the side of the contact zone (+1 towards larger arc length t, -1
    towards smaller) and the interval of t (along all of Gamma_C, chain after chain) in
    which it lies, the edges either side of its last vertex in contact.

    Every run of vertices in contact inside a chain has an end where a vertex beyond it
    separates (a run that reaches the end of its chain has none there: its pressure does not
    vanish there). A run of three or more vertices has a patch per end, INSIDE edges on the
    contact side and OUTSIDE beyond; a shorter one, which the profile of one end cannot
    follow across, one patch for both ends."""
    t = np.concatenate([[0.0], np.cumsum(gamma_c.lengths)])   # every edge's start, and the end
    out, first_edge, first_vertex = [], 0, 0
    for chain in gamma_c.coarse.chains:
        m = chain.n_edges
        flags = contact[first_vertex:first_vertex + m + 1]
        at = t[first_edge:first_edge + m + 1]   # t of the chain's vertices (edge starts + end)
        v = 0
        while v <= m:
            if not flags[v]:
                v += 1
                continue
            w = v
            while w + 1 <= m and flags[w + 1]:
                w += 1
            ends = []
            if v > 0:    # the contact zone begins in edge v - 1 or v
                ends.append((1, (at[v - 1], at[min(v + 1, m)]), v - OUTSIDE, v + INSIDE))
            if w < m:    # and ends in edge w - 1 or w
                ends.append((-1, (at[max(w - 1, 0)], at[w + 1]), w - INSIDE, w + OUTSIDE))
            if len(ends) == 2 and w - v < 2:
                (_, (lo, _), a, _), (_, (_, hi), _, b) = ends
                middle = 0.5 * (at[v] + at[w])
                ends = [(1, (lo, middle), a, b), (-1, (middle, hi), a, b)]
                spans = [(a, b)]
            else:
                spans = [(a, b) for _, _, a, b in ends]
            for a, b in spans:
                edges = first_edge + np.arange(max(a, 0), min(b, m))
                inside = [(side, span) for side, span, lo, hi in ends if (lo, hi) == (a, b)]
                out.append((edges, inside))
            v = w + 1
        first_edge += m
        first_vertex += m + 1
    return out


def closest_profile(coefficients: np.ndarray, t0: np.ndarray, lengths: np.ndarray,
                    ends: list) -> np.ndarray:
    """||p* - p_h||_e^2 on every edge e of a patch (its edges start at ``t0`` and have
    ``lengths``; p_h on each a polynomial with ``coefficients`` in the local parameter), p*
    the profile closest to p_h in L2(patch): A s^(1/2) with one end (side, (lo, hi)) in
    ``ends``, s = side (t - t_end)_+ the distance into the contact zone; A ((t - t_l)_+
    (t_r - t)_+)^(1/2) with two, the contact zone between them (Hertz's ellipse).

    For given ends the closest A is a quotient of two integrals; each end is the best of
    CANDIDATES in its interval, refined by golden sections (in turn, with two ends)."""
    spans = [span for _, span in ends]

    def fit(positions):
        t, w, e = _quadrature(t0, lengths, positions)
        xi = (t - t0[e]) / lengths[e]
        ph = np.sum(coefficients[e] * xi[:, None] ** np.arange(coefficients.shape[1]), axis=1)
        if len(positions) == 1:
            profile = np.sqrt(np.maximum(ends[0][0] * (t - positions[0]), 0.0))
        else:
            profile = np.sqrt(np.maximum(t - positions[0], 0.0)
                              * np.maximum(positions[1] - t, 0.0))
        norm = float(w @ profile**2)
        a = float(w @ (profile * ph)) / norm if norm > 0 else 0.0
        residual = w * (a * profile - ph) ** 2
        return float(residual.sum()), np.bincount(e, residual, len(lengths))

    positions = [0.5 * (lo + hi) for lo, hi in spans]
    for _ in range(2 if len(spans) == 2 else 1):
        for j, span in enumerate(spans):
            positions[j] = _golden(
                lambda x, j=j: fit([*positions[:j], x, *positions[j + 1:]])[0], span)
    return fit(positions)[1]


def _golden(f, span: tuple[float, float]) -> float:
    """The best of CANDIDATES points of ``span`` for ``f``, refined by golden sections
    between its neighbours."""
    grid = np.linspace(*span, CANDIDATES)
    values = [f(x) for x in grid]
    best = int(np.argmin(values))
    a, b = grid[max(best - 1, 0)], grid[min(best + 1, CANDIDATES - 1)]
    ratio = (np.sqrt(5) - 1) / 2
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(GOLDEN_STEPS):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - ratio * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + ratio * (b - a)
            fd = f(d)
    return min([(values[best], grid[best]), (fc, c), (fd, d)])[1]


def _quadrature(t0: np.ndarray, lengths: np.ndarray, positions) -> tuple:
    """Gauss points (t, weight, edge) on every edge of a patch, split at the profile's ends
    ``positions`` and, on a piece that ends at one of them, graded in the square root of the
    distance to it (in which the profile is smooth on either side)."""
    cuts = sorted(positions)
    if len(cuts) == 2:   # a piece between the two ends is graded towards both
        cuts.insert(1, 0.5 * (cuts[0] + cuts[1]))
    ts, ws, es = [], [], []
    for e, (a, h) in enumerate(zip(t0, lengths)):
        points = [a, *(c for c in cuts if a < c < a + h), a + h]
        for lo, hi in zip(points[:-1], points[1:]):
            if hi - lo <= 0:
                continue
            near = lo if lo in positions else hi if hi in positions else None
            if near is None:
                t, w = lo + (hi - lo) * _X, (hi - lo) * _W
            else:
                far = hi if near == lo else lo
                root = np.sqrt(abs(far - near))
                sigma = root * _X
                t, w = near + np.sign(far - near) * sigma**2, _W * root * 2 * sigma
            ts.append(t)
            ws.append(w)
            es.append(np.full(len(t), e))
    return np.concatenate(ts), np.concatenate(ws), np.concatenate(es)


# the edges of the patch of a kink of Gamma_C on either chain that meets there
KINK_EDGES = 2


def kink_distances(p: ngs.CoefficientFunction, mesh: ngs.Mesh, gamma_c, order: int,
                   kinks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """||p* - p_h||^2 per fine edge of Gamma_C on the patches of the ``kinks`` of Gamma_C
    (points (n, 2) where two chains meet at an angle), and which edges lie in a patch.

    The patch of a kink is KINK_EDGES edges of either chain that meets there, and p* =
    b + c ln(1/r) the profile closest to p_h on it in L2 over (b, c)
    (:func:`closest_log_profile`), r the distance to the kink along Gamma_C.
    """
    n = len(gamma_c.lengths)
    out, in_patch = np.zeros(n), np.zeros(n, bool)
    if not len(kinks):
        return out, in_patch
    coefficients = _edge_polynomials(p, mesh, gamma_c, order)
    starts = np.cumsum([0] + [chain.n_edges for chain in gamma_c.coarse.chains])
    for point in np.asarray(kinks, float).reshape(-1, 2):
        edges, near, far, forward = [], [], [], []
        for c, chain in enumerate(gamma_c.coarse.chains):
            scale = gamma_c.lengths[starts[c]:starts[c + 1]].min()
            for at_start in (True, False):
                if np.linalg.norm(chain.path_points[0 if at_start else -1] - point) > 1e-6 * scale:
                    continue
                m = min(KINK_EDGES, chain.n_edges)
                idx = (starts[c] + np.arange(m) if at_start
                       else starts[c + 1] - 1 - np.arange(m))
                r = np.concatenate([[0.0], np.cumsum(gamma_c.lengths[idx])])
                edges += idx.tolist()
                near += r[:-1].tolist()
                far += r[1:].tolist()
                forward += [at_start] * m
        if not edges:
            continue
        edges = np.array(edges)
        out[edges] += closest_log_profile(coefficients[edges], np.array(near), np.array(far),
                                          np.array(forward))
        in_patch[edges] = True
    return out, in_patch


def closest_log_profile(coefficients: np.ndarray, near: np.ndarray, far: np.ndarray,
                        forward: np.ndarray) -> np.ndarray:
    """||p* - p_h||_e^2 on every edge e of a kink's patch, e at the distances [``near``,
    ``far``] from the kink (``forward``: its local parameter runs away from the kink; p_h
    on it a polynomial with ``coefficients``), p* = b + c ln(1/r) closest to p_h in
    L2(patch): b and c solve 2 x 2 normal equations."""
    rs, ws, es = [], [], []
    for e, (a, b) in enumerate(zip(near, far)):
        if a == 0.0:   # graded towards the kink, where ln r is singular
            r, w = b * _X**3, _W * 3 * b * _X**2
        else:
            r, w = a + (b - a) * _X, (b - a) * _W
        rs.append(r)
        ws.append(w)
        es.append(np.full(len(r), e))
    r, w, e = np.concatenate(rs), np.concatenate(ws), np.concatenate(es)
    xi = np.where(forward[e], (r - near[e]) / (far[e] - near[e]),
                  (far[e] - r) / (far[e] - near[e]))
    ph = np.sum(coefficients[e] * xi[:, None] ** np.arange(coefficients.shape[1]), axis=1)
    basis = np.column_stack([np.ones_like(r), -np.log(r)])
    gram = basis.T @ (w[:, None] * basis)
    fit = np.linalg.solve(gram, basis.T @ (w * ph))
    return np.bincount(e, w * (basis @ fit - ph) ** 2, len(near))


def _edge_polynomials(p: ngs.CoefficientFunction, mesh: ngs.Mesh, gamma_c, order: int
                      ) -> np.ndarray:
    """p_h on every fine edge of Gamma_C as the coefficients (n_edges, k + 1) of a
    polynomial of degree k = ``order`` in the local parameter (exact: p_h is P_k there),
    from its values at the k + 1 Chebyshev points (:func:`edge_values`)."""
    nodes = 0.5 - 0.5 * np.cos(np.pi * (np.arange(order + 1) + 0.5) / (order + 1))
    return np.linalg.solve(np.vander(nodes, order + 1, increasing=True),
                           edge_values(p, mesh, gamma_c, nodes).T).T


# lambda_n below this share of its largest value on Gamma_C is contact
CONTACT_SHARE = 1e-6


def kink_points(scene) -> np.ndarray:
    """The kinks of Gamma_C, where two contact sides meet at an angle: points (n, 2)."""
    return np.array([point for point, kind, _ in contact_junctions(scene) if kind == "kink"],
                    dtype=float).reshape(-1, 2)


def in_contact(lam_n: np.ndarray) -> np.ndarray:
    """Which vertices are in contact: lambda_n at most CONTACT_SHARE of its largest value."""
    return lam_n <= CONTACT_SHARE * np.max(np.abs(lam_n), initial=0.0)


def kink_opening(gamma_c, opening: np.ndarray, lam_n: np.ndarray, starts: np.ndarray,
           weight: np.ndarray) -> np.ndarray:
    """The kink term of the thesis' multipliers: weight_e [d(opening)/dt]^2 / 2 on both fine
    edges at every last contact node.

    ``opening`` = g_h - lambda_n = u_n^h at the vertices; a last contact node is an interior
    vertex of a chain in contact (:func:`in_contact`) next to one that separates.
    """
    slope = (opening[starts + 1] - opening[starts]) / gamma_c.lengths
    contact = in_contact(lam_n)
    out = np.zeros(len(starts))
    first = 0
    for chain in gamma_c.coarse.chains:
        for e in range(first + 1, first + chain.n_edges):   # vertex between e - 1 and e
            here = starts[e]
            if contact[here] and not (contact[here - 1] and contact[here + 1]):
                jump = (slope[e] - slope[e - 1])**2
                out[e - 1] += 0.5 * jump * weight[e - 1]
                out[e] += 0.5 * jump * weight[e]
        first += chain.n_edges
    return out
