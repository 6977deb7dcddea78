"""True errors against an overkill solve, or any finer nested one.

Where no exact solution is known, the error of a discrete solution is measured against a
solve several uniform levels finer (the overkill solution, the *reference* of the error).
Both are reduced to plain arrays, so that solves in different processes (a sweep's records)
can be compared later:

* :func:`element_samples`: the mesh (vertices, triangles) and fields at the six P2 nodes of
  every triangle. PEERS stresses (RT_0 + Curl of cubic bubbles), the P0 displacement and
  the P1 rotation are polynomials of degree <= 2 on each triangle, so the P2 interpolant
  at these nodes *is* the field, triangle by triangle (values taken inside the triangle,
  discontinuities kept).
* the contact pressure on Gamma_C as a P1 function on the h~ mesh: the lumped L2
  projection of -sigma_n^h onto the h~ hats (:func:`ngdual.verification.traction.
  traction_profile`; the fine-edge values of sigma_n^h oscillate, see there).

The pressure on Gamma_C. Gamma_C must be a graph over x (every contact boundary of the
shipped scenes is: the straight bottoms, Hertz's arc, the wedge's V); the pressure is a
function of x, compared at the same x, and integrated in arc length, ds = (|e| / |dx_e|) dx
on every edge e of the mesh's Gamma_C (exact: the edges are straight, also on an arc, whose
refined vertices netgen places on the arc). A P1 pressure on the h~ mesh is taken linear in
x between its nodes (along an arc it is linear in arc length, which differs by
O(h~ slope / R) relative, far below the errors measured). Where two chains of Gamma_C meet at
a kink the pressure may jump: the left chain's value holds on the left, the right chain's on
the right. A Gamma_C that is not a graph over x (a vertical edge, edges overlapping in x)
raises a ValueError (:func:`graph_over_x`).

Errors (:func:`field_errors`, :func:`pressure_error`) are integrals over the reference's
triangles and edges. For uniform candidates the meshes are nested (red refinement of one
coarse mesh), so each reference triangle lies in one candidate triangle, the integrand is a
polynomial of degree 4 there and the 6-point Gauss rule is exact. Adaptive meshes
(bisection) are not sub-meshes of a red-refined reference: a candidate edge may cross a
reference triangle, and the rule then integrates a jump, a relative quadrature error of
about h_ref / h in the squared error. On Gamma_C every mesh is a dyadic bisection of the
coarse edges, so the pressure error is exact on the union of both edge sets.

>>> import numpy as np
>>> ref = {"x": np.array([0.0, 0.5, 1.0]), "p": np.array([0.0, 1.0, 0.0])}
>>> x, w, p = nodes_to_samples(np.array([0.0, 1.0]), np.array([0.0, 0.0]), ref)
>>> round(pressure_error(x, w, p, ref)["l2"] ** 2, 12)  # int of the hat squared
0.333333333333
>>> v = np.array([[[0.0, 1.0], [0.5, 0.0]], [[0.5, 0.0], [1.0, 1.0]]])  # a V: |e| = 1.118
>>> x, w, p = nodes_to_samples(np.array([0.0, 1.0]), np.array([0.0, 0.0]), ref, v)
>>> round(pressure_error(x, w, p, ref)["l2"] ** 2 / math.sqrt(5), 12)  # ds = sqrt(5) dx
0.333333333333
"""

from __future__ import annotations

import math

import ngsolve as ngs
import numpy as np

from ..goal import in_window as goal_in_window
from ..mesh import mesh_arrays

# reference coordinates of the P2 nodes: vertices 0, 1, 2 of NGSolve's reference triangle
# (barycentric l_0 = x, l_1 = y, l_2 = 1 - x - y), then the midpoints of edges 01, 12, 20
P2_NODES = ((1.0, 0.0), (0.0, 1.0), (0.0, 0.0), (0.5, 0.5), (0.0, 0.5), (0.5, 0.0))
# Dunavant's degree-4 rule: barycentric points and weights (summing to 1)
_A, _B = 0.445948490915965, 0.091576213509771
GAUSS_4 = (np.array([[_A, _A, 1 - 2 * _A], [_A, 1 - 2 * _A, _A], [1 - 2 * _A, _A, _A],
                     [_B, _B, 1 - 2 * _B], [_B, 1 - 2 * _B, _B], [1 - 2 * _B, _B, _B]]),
           np.array([0.223381589678011] * 3 + [0.109951743655322] * 3))
GAUSS_1D = (np.array([0.5 - math.sqrt(15) / 10, 0.5, 0.5 + math.sqrt(15) / 10]),
            np.array([5 / 18, 8 / 18, 5 / 18]))


def element_samples(mesh: ngs.Mesh, fields: dict[str, ngs.CoefficientFunction]) -> dict:
    """``vertices`` (n, 2), ``triangles`` (ne, 3) and, per field, its values at the six P2
    nodes of every triangle (ne, 6, dim), evaluated inside the triangle."""
    ir = ngs.IntegrationRule(list(P2_NODES), [0.0] * 6)
    mips = mesh.MapToAllElements(ir, ngs.VOL)
    vertices, triangles = mesh_arrays(mesh)
    out = {"vertices": vertices, "triangles": triangles}
    xy = np.asarray(ngs.CF((ngs.x, ngs.y))(mips)).reshape(mesh.ne, 6, 2)
    if not np.allclose(xy[:, :3], out["vertices"][out["triangles"]], atol=1e-12):
        raise RuntimeError("NGSolve's reference vertex order changed: P2_NODES must follow it")
    for name, cf in fields.items():
        out[name] = np.asarray(cf(mips)).reshape(mesh.ne, 6, -1)
    return out


def _interp(nodes: dict, x: np.ndarray) -> np.ndarray:
    return np.interp(x, nodes["x"], nodes["p"])


def graph_over_x(edges) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The edges of Gamma_C (m, 2, 2: start and end point of every edge) as a graph over x.

    Returns
    -------
    x0, x1 : numpy.ndarray
        The x interval of every edge, x0 < x1, in the order of ``edges``.
    y0, y1 : numpy.ndarray
        y at x0 and at x1.

    Raises
    ------
    ValueError
        If an edge is vertical (|dx| <= 1e-9 |e|) or two edges overlap in x (then Gamma_C
        is not a graph over x and a pressure over x means nothing).
    """
    edges = np.asarray(edges, float)
    d = edges[:, 1] - edges[:, 0]
    if np.any(np.abs(d[:, 0]) <= 1e-9 * np.hypot(d[:, 0], d[:, 1])):
        raise ValueError("Gamma_C has a vertical edge: it is not a graph over x")
    left = np.where((d[:, 0] > 0)[:, None], edges[:, 0], edges[:, 1])
    right = np.where((d[:, 0] > 0)[:, None], edges[:, 1], edges[:, 0])
    order = np.argsort(left[:, 0], kind="stable")
    overlap = left[order[1:], 0] - right[order[:-1], 0]
    if np.any(overlap < -1e-9 * (right[:, 0] - left[:, 0]).min()):
        raise ValueError("edges of Gamma_C overlap in x: it is not a graph over x")
    return left[:, 0], right[:, 0], left[:, 1], right[:, 1]


def edge_samples(edges, subdivisions: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """3-point Gauss points (N, 2) on every edge of Gamma_C (m, 2, 2), each edge split into
    ``subdivisions`` equal parts in x, and their arc-length weights: the dx weights of
    :func:`gauss_samples` times |e| / |dx_e| (Gamma_C a graph over x, :func:`graph_over_x`),
    so that the weights of an edge sum to its length.

    >>> edges = np.array([[[0.0, 0.0], [3.0, 4.0]]])
    >>> xy, w = edge_samples(edges, 2)
    >>> round(float(w.sum()), 12), xy[1].tolist()
    (5.0, [0.75, 1.0])
    """
    x0, x1, y0, y1 = graph_over_x(edges)
    x, w = gauss_samples(x0, x1, subdivisions)
    per_edge = len(x) // len(x0)
    stretch = np.hypot(x1 - x0, y1 - y0) / (x1 - x0)
    slope = (y1 - y0) / (x1 - x0)
    start = np.repeat(x0, per_edge)
    y = np.repeat(y0, per_edge) + np.repeat(slope, per_edge) * (x - start)
    return np.column_stack([x, y]), w * np.repeat(stretch, per_edge)


def nodes_to_samples(x, p, reference: dict, edges=None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss samples (points, weights, values) of a P1 candidate with nodes ``x`` and values
    ``p`` on the union of its and the reference's nodes: both are linear on every piece,
    so the squared difference is integrated exactly.

    ``edges`` (m, 2, 2): the fine edges of the candidate's Gamma_C. The weights are then in
    arc length, dx times |e| / |dx_e| of the edge holding the point, and the pieces are cut
    where that factor changes too (the vertices of a curved or kinked Gamma_C). Without
    ``edges`` Gamma_C is taken horizontal (ds = dx).
    """
    breaks = [x, reference["x"]]
    if edges is not None:
        x0, x1, y0, y1 = graph_over_x(edges)
        order = np.argsort(x0)
        x0, stretch = x0[order], (np.hypot(x1 - x0, y1 - y0) / (x1 - x0))[order]
        breaks.append(x0[1:][stretch[1:] != stretch[:-1]])
    breaks = np.unique(np.concatenate(breaks))
    lo, hi = max(np.min(x), reference["x"].min()), min(np.max(x), reference["x"].max())
    breaks = breaks[(breaks >= lo) & (breaks <= hi)]
    points, weights = gauss_samples(breaks[:-1], breaks[1:])
    if edges is not None:
        k = np.clip(np.searchsorted(x0, points, side="right") - 1, 0, len(x0) - 1)
        weights = weights * stretch[k]
    order = np.argsort(x, kind="stable")
    return points, weights, np.interp(points, np.asarray(x)[order], np.asarray(p)[order])


def gauss_samples(x0, x1, subdivisions: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """3-point Gauss points and weights on every cell [x0, x1], split into ``subdivisions``
    equal parts (so that a reference cell of a finer dyadic level holds whole parts)."""
    t, w = GAUSS_1D
    s = np.arange(subdivisions)
    x0, x1 = np.asarray(x0, float), np.asarray(x1, float)
    h = (x1 - x0)[:, None] / subdivisions * np.ones(subdivisions)
    x = (x0[:, None] + h * s)[..., None] + h[..., None] * t
    return x.ravel(), np.broadcast_to(h[..., None] * w, x.shape).ravel()


def in_window(x: np.ndarray, window) -> np.ndarray:
    """Which abscissae ``x`` lie in ``window``: |x| <= window for a number, lo <= x <= hi
    for a pair (lo, hi), all for None (the goal's :func:`ngdual.goal.in_window`, which
    also takes a half-width here).

    >>> in_window(np.array([-2.0, 0.5, 1.5]), 1.0), in_window(np.array([0.5, 1.5]), (1, 2))
    (array([False,  True, False]), array([False,  True]))
    """
    if window is not None and np.ndim(window) == 0:
        window = (-window, window)
    return goal_in_window(np.asarray(x), window)


def pressure_error(x, w, p, reference: dict, window=None) -> dict:
    """||p_h - p_ref||_L2 and ||p_ref||_L2 on Gamma_C (or on its part ``window``: |x| <= window
    for a number, lo <= x <= hi for a pair, :func:`in_window`), from Gauss samples of the
    candidate (points x, arc-length weights w) on pieces where the reference (P1 in x, ``x``
    and ``p``) is linear; ``rel`` their ratio, ``max`` the largest difference at the samples
    relative to max |p_ref|."""
    x, w, p = map(np.asarray, (x, w, p))
    keep = in_window(x, window)
    ref = _interp(reference, x[keep])
    diff = p[keep] - ref
    l2 = math.sqrt(float(np.sum(w[keep] * diff**2)))
    norm = math.sqrt(float(np.sum(w[keep] * ref**2)))
    scale = float(np.abs(reference["p"]).max()) or 1.0
    return {"l2": l2, "norm": norm, "rel": l2 / norm if norm > 0 else math.nan,
            "max": float(np.abs(diff).max()) / scale}


def p2_basis(bary: np.ndarray) -> np.ndarray:
    """The P2 Lagrange basis at barycentric points (..., 3), in the order of P2_NODES."""
    l0, l1, l2 = bary[..., 0], bary[..., 1], bary[..., 2]
    return np.stack([l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1),
                     4 * l0 * l1, 4 * l1 * l2, 4 * l2 * l0], axis=-1)


def _barycentric(tri_xy: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Barycentric coordinates of ``points`` (n, 2) in triangles ``tri_xy`` (n, 3, 2)."""
    a, b, c = tri_xy[:, 0], tri_xy[:, 1], tri_xy[:, 2]
    m = np.stack([a - c, b - c], axis=-1)
    l01 = np.linalg.solve(m, (points - c)[..., None])[..., 0]
    return np.column_stack([l01, 1 - l01.sum(axis=1)])


def locate(samples: dict, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The triangle of ``samples`` holding each point (n, 2) and its P2 basis values there.

    On a curved boundary the candidate's edges are chords of the finer reference's: a point
    in the sliver between them takes the triangle with the nearest centroid (its polynomials
    extended), a geometric error of the candidate like any other. A point farther from
    every centroid than that triangle's longest edge lies outside the candidate's domain:
    a ValueError."""
    from matplotlib.tri import Triangulation
    from scipy.spatial import cKDTree

    tri = Triangulation(samples["vertices"][:, 0], samples["vertices"][:, 1],
                        samples["triangles"])
    k = tri.get_trifinder()(points[:, 0], points[:, 1])
    outside = k < 0
    if np.any(outside):
        corners = samples["vertices"][samples["triangles"]]
        distance, k[outside] = cKDTree(corners.mean(axis=1)).query(points[outside])
        edges = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
        if np.any(distance > edges[k[outside]]):
            raise ValueError(f"{int(np.sum(distance > edges[k[outside]]))} points lie "
                             "outside the candidate mesh")
    tri_xy = samples["vertices"][samples["triangles"][k]]
    return k, p2_basis(_barycentric(tri_xy, points))


def evaluate(samples: dict, name: str, located: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """Field ``name`` of ``samples`` at located points (:func:`locate`), from the P2
    interpolant of the triangle each point lies in."""
    k, basis = located
    return np.einsum("nj,njd->nd", basis, samples[name][k])


def quadrature(samples: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (ne * 6, 2), weights and the P2 basis values (6, 6) of the degree-4 rule on
    every triangle of ``samples``."""
    bary, weights = GAUSS_4
    tri_xy = samples["vertices"][samples["triangles"]]
    a, b, c = tri_xy[:, 0], tri_xy[:, 1], tri_xy[:, 2]
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
                        - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    points = np.einsum("qi,nid->nqd", bary, tri_xy).reshape(-1, 2)
    return points, (area[:, None] * weights).ravel(), p2_basis(bary)


def field_errors(candidate: dict, reference: dict, lam: float, mu: float,
                 names=("sigma", "u", "eta")) -> dict:
    """L2 norms of reference - candidate for each field in ``names`` present in both, and
    the compliance (energy) norm of the stress, (int A tau : tau)^(1/2) with
    A tau = (tau - lam / (2 (lam + mu)) tr(tau) I) / (2 mu) (plane strain, as
    :func:`ngdual.peers.compliance`); ``<name>_norm`` the reference's norms, ``sigma_energy``
    and ``sigma_energy_norm`` the stress in the compliance norm."""
    points, weights, basis = quadrature(reference)
    located = locate(candidate, points)
    out = {}
    for name in names:
        if name not in candidate or name not in reference:
            continue
        ref = np.einsum("qj,njd->nqd", basis, reference[name]).reshape(len(points), -1)
        diff = evaluate(candidate, name, located) - ref
        out[name] = math.sqrt(float(weights @ np.sum(diff**2, axis=1)))
        out[f"{name}_norm"] = math.sqrt(float(weights @ np.sum(ref**2, axis=1)))
        if name == "sigma":
            for key, tau in (("sigma_energy", diff), ("sigma_energy_norm", ref)):
                trace = tau[:, 0] + tau[:, 3]
                density = (np.sum(tau**2, axis=1) - lam / (2 * (lam + mu)) * trace**2) / (2 * mu)
                out[key] = math.sqrt(max(float(weights @ density), 0.0))
    return out


def solution_samples(solution) -> dict:
    """A discrete ngdual solution as arrays: :func:`element_samples` of sigma (4 components,
    row-major), u and the rotation eta, and the Gamma_C pressure (``p_nodes``, ``p``: P1 on
    the h~ mesh; at order k >= 1, either multiplier family, linear between the trace samples
    of every fine edge, discontinuous from edge to edge; ``p_edges``: the fine edges of
    Gamma_C, (m, 2, 2), for the arc-length weights) when the scene has a contact
    boundary."""
    from ..quantities import fields
    from ..trace import contact_traces
    from .traction import traction_profile

    f = fields(solution)
    pb = solution.problem
    out = element_samples(pb.fes.mesh, {"sigma": f.sigma, "u": f.u, "eta": f.eta})
    if pb.spaces.contact is not None:
        profile = traction_profile(solution)
        pressure = profile.pressure.copy()
        # an h~ node with a prescribed lambda (a clamped end of Gamma_C) has no contact
        # condition: its hat moment is the support's reaction, not a pressure; the scenes
        # measured here leave a gap open at their clamped ends, so the pressure there is 0
        # (where the profile is the traces, no multiplier prescribes them)
        coarse = pb.spaces.contact
        if contact_traces(solution).trace_xy is None:   # the profile is the hat moments
            fixed = np.concatenate([
                [int(q) not in {int(d) for d in coarse.dof_positions(c)}
                 for q in (coarse.nodes[c][:-1] if chain.closed else coarse.nodes[c])]
                for c, chain in enumerate(coarse.chains)])
            pressure[fixed] = 0.0
        # a node shared by two chains (a kink of Gamma_C) appears once per chain, with that
        # chain's value: the chain lying further left comes first, so that np.interp takes
        # each side's value on its side
        stops = [*profile.chain_starts[1:], len(profile.x)]
        side = np.concatenate([np.full(stop - start, profile.x[start:stop].mean())
                               for start, stop in zip(profile.chain_starts, stops)])
        order = np.lexsort((side, profile.x))
        edges = np.concatenate([np.stack([chain.path_points[:-1], chain.path_points[1:]], 1)
                                for chain in coarse.chains])
        out.update(p_nodes=profile.x[order], p=pressure[order], p_edges=edges)
    return out


def pressure_of(samples: dict) -> dict:
    """The P1 pressure (``x``, ``p``) of a reference's samples."""
    return {"x": samples["p_nodes"], "p": samples["p"]}


def true_errors(candidate: dict, reference: dict, lam: float, mu: float,
                window: float | None = None) -> dict:
    """Every true error of a candidate against a reference (both sample arrays): the field
    errors of :func:`field_errors` and the pressure error (``pressure_rel``: relative L2 on
    Gamma_C, ``pressure_max``). A candidate carries its pressure either as a P1 function
    (``p_nodes``, ``p`` and ``p_edges`` if Gamma_C is not horizontal: ngdual) or as
    quadrature samples in x with arc-length weights (``p_x``, ``p_w``, ``p``: any method)."""
    out = field_errors(candidate, reference, lam, mu)
    if "p" in candidate and "p" in reference:
        out.update(pressure_errors(candidate, reference, window))
    return out


def pressure_errors(candidate: dict, reference: dict, window: float | None = None) -> dict:
    """The pressure error of a candidate against a reference (sample arrays, as for
    :func:`true_errors`) on Gamma_C (on |x| <= ``window``): ``pressure_rel`` (relative
    L2), ``pressure_l2`` and ``pressure_max`` (:func:`pressure_error`)."""
    ref = pressure_of(reference)
    if "p_w" in candidate:
        x, w, p = candidate["p_x"], candidate["p_w"], candidate["p"]
    else:
        x, w, p = nodes_to_samples(candidate["p_nodes"], candidate["p"], ref,
                                   candidate.get("p_edges"))
    e = pressure_error(x, w, p, ref, window)
    return {"pressure_rel": e["rel"], "pressure_l2": e["l2"], "pressure_max": e["max"]}
