"""The two families of boundary multipliers of order k as scalar bases on the fine edges of
a boundary part (:class:`Basis`), in Legendre coefficients edge by edge:

``coarse``
    continuous piecewise polynomials of degree k + 1 on the coarse mesh h~ = ``ratio`` * h,
    zero at the fixed ends (the thesis' C_h~ of (3.61) is k = 0, ratio 2), built on the
    coarse meshes of :class:`ngdual.boundary.CoarseMesh`;
``facet``
    discontinuous P_k on the fine edges, the space of the normal traces of RT_k (the
    hybridisation pairing).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import ngsolve as ngs
import numpy as np
from numpy.polynomial import legendre

from ...boundary import CoarseMesh, EndRule, end_rule
from ...scene import SceneError

FAMILIES = ("coarse", "facet")
FRAMES = ("cartesian", "contact")     # phi on Gamma_N; (lambda_t, lambda_n) on Gamma_C


@dataclass(frozen=True)
class Part:
    """A boundary part carrying a vector multiplier: its labels, its components
    (``"cartesian"`` for phi on Gamma_N, ``"contact"`` for lambda_t, lambda_n on Gamma_C)
    and where its chains break and which ends are free (fixed ends carry no coarse dof)."""

    labels: tuple[str, ...]
    frame: str = "contact"
    ends: EndRule = EndRule()

    def __post_init__(self):
        if self.frame not in FRAMES:
            raise SceneError("frame", f"unknown frame {self.frame!r}; choose one of "
                             f"{', '.join(FRAMES)}")


def model_parts() -> list[Part]:
    """Gamma_C = the bottom of the unit square, both ends fixed (clamped sides)."""
    return [Part(("bottom",), "contact")]


def scene_parts(scene, mesh: ngs.Mesh) -> list[Part]:
    """Gamma_N and Gamma_C of ``scene`` with the end rule of its multipliers."""
    parts = []
    if scene.labels("neumann"):
        parts.append(Part(tuple(scene.labels("neumann")), "cartesian",
                          end_rule(scene, mesh, "neumann")))
    if scene.has_contact:
        parts.append(Part(tuple(scene.labels("contact")), "contact",
                          end_rule(scene, mesh, "contact")))
    return parts


@dataclass(frozen=True)
class Basis:
    """A scalar multiplier space on the fine edges of one part, edge by edge.

    ``dofs[e]`` are the dofs living on fine edge e (in the chain order of ``coarse``, the
    :class:`CoarseMesh` the space is built on) and ``coefficients[e]`` their polynomials in
    the edge's own parameter t in [0, 1] (running along the chain), Legendre coefficients
    in 2t - 1, one row per dof.
    """

    coarse: CoarseMesh
    n_dofs: int
    dofs: tuple[np.ndarray, ...]
    coefficients: tuple[np.ndarray, ...]

    def values(self, e: int, t: np.ndarray) -> np.ndarray:
        """The dofs' functions of edge e at the parameters ``t`` (dofs x points)."""
        return legendre.legval(2 * np.asarray(t) - 1, self.coefficients[e].T)

    def slopes(self, e: int, t: np.ndarray, length: float) -> np.ndarray:
        """Their derivatives in arc length at ``t``."""
        derivative = legendre.legder(self.coefficients[e].T) * 2 / length
        return legendre.legval(2 * np.asarray(t) - 1, derivative)


def _to_legendre(values_at: callable, degree: int) -> np.ndarray:
    """Legendre coefficients (in 2t - 1) of the polynomials of degree <= ``degree`` whose
    values at t are the rows of ``values_at(t)``."""
    t = (legendre.leggauss(degree + 1)[0] + 1) / 2
    return legendre.legfit(2 * t - 1, values_at(t).T, degree).T


def _coarse_values(t: np.ndarray, t0: float, t1: float, ends: list[int], order: int
                   ) -> np.ndarray:
    """The hats of the coarse edge's carried ``ends`` (0: its start, 1: its end) and its k
    bubbles, at the parameters ``t`` of the fine edge [t0, t1] of the coarse edge."""
    tau = t0 + (t1 - t0) * np.asarray(t)
    hats = [(1 - tau, tau)[i] for i in ends]
    bubbles = [tau * (1 - tau) * legendre.legval(2 * tau - 1, np.eye(order)[j])
               for j in range(order)]
    return np.array(hats + bubbles).reshape(len(ends) + order, len(tau))


def coarse_basis(coarse: CoarseMesh, order: int) -> Basis:
    """Continuous piecewise polynomials of degree k + 1 on the coarse edges of ``coarse``,
    zero at its fixed ends: the hats of the coarse P1 dofs (:meth:`CoarseMesh.dof_positions`)
    and on every coarse edge the bubbles tau (1 - tau) L_j(2 tau - 1), j < k, of its
    parameter tau."""
    degree = order + 1
    dofs, coefficients, offset = [], [], 0
    bubble = coarse.n_p1_dofs                      # the bubbles' dofs follow the hats'
    for c, chain in enumerate(coarse.chains):
        carriers = coarse.dof_positions(c)
        hat = {int(p): offset + i for i, p in enumerate(carriers)}
        if chain.closed:
            hat[chain.n_edges] = hat[0]
        offset += len(carriers)
        s, nodes = chain.arclength, coarse.nodes[c]
        for e in range(len(nodes) - 1):
            a, b = int(nodes[e]), int(nodes[e + 1])
            owned = [hat[p] for p in (a, b) if p in hat]
            ends = [i for i, p in enumerate((a, b)) if p in hat]
            edge_dofs = np.array(owned + list(range(bubble, bubble + order)), dtype=int)
            bubble += order
            for k in range(a, b):
                t0, t1 = (s[k] - s[a]) / (s[b] - s[a]), (s[k + 1] - s[a]) / (s[b] - s[a])
                dofs.append(edge_dofs)
                coefficients.append(
                    _to_legendre(partial(_coarse_values, t0=t0, t1=t1, ends=ends, order=order),
                                 degree) if len(edge_dofs) else np.zeros((0, degree + 1)))
    return Basis(coarse, bubble, tuple(dofs), tuple(coefficients))


def facet_basis(fine: CoarseMesh, order: int) -> Basis:
    """Discontinuous P_k on the fine edges of ``fine`` (a coarse mesh of ratio 1, for its
    chains): Legendre polynomials L_0 .. L_k of every edge."""
    n_edges = sum(chain.n_edges for chain in fine.chains)
    dofs = tuple(np.arange(e * (order + 1), (e + 1) * (order + 1)) for e in range(n_edges))
    return Basis(fine, n_edges * (order + 1), dofs,
                 tuple(np.eye(order + 1) for _ in range(n_edges)))


def multiplier_basis(mesh: ngs.Mesh, part: Part, multipliers: str, order: int,
                     ratio: int = 2) -> Basis:
    """The scalar basis of ``multipliers`` (one of :data:`FAMILIES`) of order k on ``part``:
    ``coarse`` on h~ = ``ratio`` h, ``facet`` on the fine edges (``ratio`` must be 1)."""
    if multipliers not in FAMILIES:
        raise SceneError("contact.multipliers", f"unknown multipliers {multipliers!r}; "
                         f"choose one of {', '.join(FAMILIES)}")
    if multipliers == "facet" and ratio != 1:
        raise SceneError("contact.htilde_factor",
                         f"facet multipliers live on the fine edges (ratio 1), not {ratio}")
    coarse = CoarseMesh.from_fine(mesh, list(part.labels), ratio, part.ends)
    return (coarse_basis if multipliers == "coarse" else facet_basis)(coarse, order)
