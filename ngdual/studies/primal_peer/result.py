"""What the primal peer returns: its solution, its cost and the edges of Gamma_C."""

from __future__ import annotations

from dataclasses import dataclass, field

import ngsolve as ngs
import numpy as np

from ...geometry import right_normal, tangent


@dataclass
class ContactEdges:
    """The boundary edges of Gamma_C: end points, lengths, outward normals, tangents."""

    p0: np.ndarray
    p1: np.ndarray
    length: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray

    @classmethod
    def none(cls) -> ContactEdges:
        """No edges: a problem without Gamma_C."""
        empty = np.zeros((0, 2))
        return cls(empty, empty, np.zeros(0), empty, empty)

    @classmethod
    def of(cls, mesh: ngs.Mesh, labels: list[str]) -> ContactEdges:
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
        n = right_normal(d)
        flip = np.einsum("ij,ij->i", n, 0.5 * (p0 + p1) - cen) < 0
        n[flip] *= -1
        return cls(p0, p1, length, n, tangent(n))

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
    there (tangent t = (n_y, -n_x), i.e. +x on a side with outward normal +y). ``u`` is the
    displacement and ``sigma`` the discrete stress (of u, or of u and the pressure in the
    Taylor-Hood form).
    """

    u: ngs.GridFunction
    sigma: ngs.CoefficientFunction = field(repr=False)
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
    _edges: ContactEdges = field(repr=False)
    _pointwise: object = field(repr=False)

    def pressure(self, points) -> np.ndarray:
        """p = -[P_n(u_h)]_- at points of Gamma_C (array (N, 2)), h of the edge they lie on."""
        return self._pointwise(np.atleast_2d(np.asarray(points, float)))[0]

    def traction(self, points) -> np.ndarray:
        """lambda_t = [P_t(u_h)]_s at points of Gamma_C (array (N, 2))."""
        return self._pointwise(np.atleast_2d(np.asarray(points, float)))[1]
