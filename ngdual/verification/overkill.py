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
* the contact pressure on a horizontal Gamma_C as a P1 function on the h~ mesh: the lumped
  L2 projection of -sigma_n^h onto the h~ hats (:func:`ngdual.verification.traction.
  traction_profile`; the fine-edge values of sigma_n^h oscillate, see there).

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
"""

from __future__ import annotations

import math

import ngsolve as ngs
import numpy as np

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


def nodes_to_samples(x, p, reference: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss samples (points, weights, values) of a P1 candidate with nodes ``x`` and values
    ``p`` on the union of its and the reference's nodes: both are linear on every piece,
    so the squared difference is integrated exactly."""
    breaks = np.unique(np.concatenate([x, reference["x"]]))
    lo, hi = max(np.min(x), reference["x"].min()), min(np.max(x), reference["x"].max())
    breaks = breaks[(breaks >= lo) & (breaks <= hi)]
    points, weights = gauss_samples(breaks[:-1], breaks[1:])
    order = np.argsort(x)
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


def pressure_error(x, w, p, reference: dict, window: float | None = None) -> dict:
    """||p_h - p_ref||_L2 and ||p_ref||_L2 on Gamma_C (or on |x| <= ``window``), from
    Gauss samples of the candidate on pieces where the reference (P1 ``nodes``) is linear;
    ``rel`` their ratio, ``max`` the largest difference at the samples relative to
    max |p_ref|."""
    x, w, p = map(np.asarray, (x, w, p))
    keep = np.ones(len(x), bool) if window is None else np.abs(x) <= window
    ref = _interp(reference, x[keep])
    diff = p[keep] - ref
    l2 = math.sqrt(float(np.sum(w[keep] * diff**2)))
    norm = math.sqrt(float(np.sum(w[keep] * ref**2)))
    scale = float(np.abs(reference["p"]).max()) or 1.0
    return {"l2": l2, "norm": norm, "rel": l2 / norm if norm > 0 else math.nan,
            "max": float(np.abs(diff).max()) / scale}


def _p2_basis(bary: np.ndarray) -> np.ndarray:
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
    """The triangle of ``samples`` holding each point (n, 2) and its P2 basis values there."""
    from matplotlib.tri import Triangulation

    tri = Triangulation(samples["vertices"][:, 0], samples["vertices"][:, 1],
                        samples["triangles"])
    k = tri.get_trifinder()(points[:, 0], points[:, 1])
    if np.any(k < 0):
        raise ValueError(f"{int(np.sum(k < 0))} points lie outside the candidate mesh")
    tri_xy = samples["vertices"][samples["triangles"][k]]
    return k, _p2_basis(_barycentric(tri_xy, points))


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
    return points, (area[:, None] * weights).ravel(), _p2_basis(bary)


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
    the h~ mesh) when the scene has a contact boundary."""
    from ..quantities import fields
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
        coarse = pb.spaces.contact
        fixed = np.concatenate([
            [int(q) not in {int(d) for d in coarse.dof_positions(c)}
             for q in (coarse.nodes[c][:-1] if chain.closed else coarse.nodes[c])]
            for c, chain in enumerate(coarse.chains)])
        pressure[fixed] = 0.0
        order = np.argsort(profile.x, kind="stable")
        out.update(p_nodes=profile.x[order], p=pressure[order])
    return out


def pressure_of(samples: dict) -> dict:
    """The P1 pressure (``x``, ``p``) of a reference's samples."""
    return {"x": samples["p_nodes"], "p": samples["p"]}


def true_errors(candidate: dict, reference: dict, lam: float, mu: float,
                window: float | None = None) -> dict:
    """Every true error of a candidate against a reference (both sample arrays): the field
    errors of :func:`field_errors` and the pressure error (``pressure_rel``: relative L2 on
    Gamma_C, ``pressure_max``). A candidate carries its pressure either as a P1 function
    (``p_nodes``, ``p``: ngdual) or as quadrature samples (``p_x``, ``p_w``, ``p``: any method)."""
    out = field_errors(candidate, reference, lam, mu)
    if "p" in candidate and "p" in reference:
        ref = pressure_of(reference)
        if "p_w" in candidate:
            x, w, p = candidate["p_x"], candidate["p_w"], candidate["p"]
        else:
            x, w, p = nodes_to_samples(candidate["p_nodes"], candidate["p"], ref)
        e = pressure_error(x, w, p, ref, window)
        out.update(pressure_rel=e["rel"], pressure_l2=e["l2"], pressure_max=e["max"])
    return out
