"""The primal peer on an ngdual scene: the same mesh, material, loads, gap and friction law."""

from __future__ import annotations

import time

import ngsolve as ngs
import numpy as np

from .nitsche import scalar_cf, solve_primal, stress
from .result import ContactEdges, PrimalResult


def _scene_gap(contact, mesh: ngs.Mesh, labels: list[str]) -> ngs.CoefficientFunction:
    """The scene's gap as a CF (a formula, or the distance to the foundation line along the
    outward normal of Gamma_C, :func:`ngdual.scene.contact.foundation_gap`). The CF is also
    evaluated inside the body (the pressure at points), where no normal exists: a foundation
    line needs a straight Gamma_C, whose normal is then a constant."""
    from ...scene.contact import foundation_gap

    if contact.foundation is None:
        return scalar_cf(contact.gap_formula)
    normals = ContactEdges.of(mesh, labels).normal
    if np.ptp(normals, axis=0).max() > 1e-12:
        raise ValueError("a foundation line needs a straight Gamma_C for the peer")
    return foundation_gap(contact, ngs.x, ngs.y, float(normals[0, 0]), float(normals[0, 1]))


def solve_scene_primal(scene, level: int, order: int, **kw) -> tuple[PrimalResult, float]:
    """Solve an ngdual scene (its mesh on ``level``, material, loads, gap, friction law) by
    the peer with P``order`` elements; returns the result and the wall time, meshing
    included. Tresca bounds and free ends are the scene's; "thesis" end values of Gamma_C
    (lambda = 0 at a clamped end) have no primal counterpart and are refused."""
    from ...mesh import build_mesh

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
    """The peer's solution as sample arrays (:mod:`ngdual.verification.overkill`): sigma
    and u at the P2 nodes of every triangle (exact for P1 and P2), and the pressure at
    3-point Gauss points of every Gamma_C edge split into ``subdivisions`` parts (``p_x``,
    ``p_w``, ``p``), so that each part lies in one edge of a reference ``log2(subdivisions)``
    levels finer."""
    from ...verification.overkill import element_samples, gauss_samples

    lam, mu = scene.material.lame
    mesh = result.u.space.mesh
    out = element_samples(mesh, {"sigma": stress(result.u, mu, lam), "u": result.u})
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
