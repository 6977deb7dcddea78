"""The ends of Gamma_C a physics check reads from the scene: the fixed ends where Gamma_C
meets Gamma_D, the end values ``contact.ends = "thesis"`` sets there against the data, and a
thesis gap that P1(h~) does not represent."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..geometry import round_off
from ..scene import contact_junctions
from ..solution import Solution
from .forces import displacement_scale

END_GAP_TOL = 1e-8        # |g - u_D.n| at a clamped end, of the displacement scale


def thesis_gap_is_curved(solution: Solution) -> bool:
    """``contact.discrete_gap = "thesis"`` with a g that P1(h~) does not represent: at some
    fine vertex g differs from its h~ interpolant g_h by more than END_GAP_TOL of U."""
    pb = solution.problem
    if pb.scene.contact.discrete_gap != "thesis":
        return False
    gamma_c = pb.spaces.gamma_c
    g = gamma_c.gap_at_vertices()
    g_h = gamma_c.vertex_values(gamma_c.gap_interpolant(pb.spaces.prolongations["lam_n"],
                                                         pb.spaces.end_hats["lam_n"]))
    return float(np.max(np.abs(g - g_h))) > END_GAP_TOL * max(displacement_scale(solution),
                                                               float(np.max(np.abs(g))))


def clamped_ends(solution: Solution) -> list[tuple[np.ndarray, int]]:
    """(point, index of the neighbouring h~ dof) for every fixed end of Gamma_C where it
    meets Gamma_D."""
    pb = solution.problem
    contact, scene = pb.spaces.contact, pb.scene
    dirichlet = [p for p, kind, _ in contact_junctions(scene) if kind == "dirichlet"]
    tolerance = round_off(scene.geometry.curves())
    out, offset = [], 0
    for c, chain in enumerate(contact.chains):
        dofs = len(contact.dof_positions(c))
        if not chain.closed and dofs:
            for end, free, neighbour in ((0, contact.free[c][0], offset),
                                         (-1, contact.free[c][1], offset + dofs - 1)):
                point = chain.points[contact.nodes[c][end]]
                if not free and any(np.linalg.norm(point - q) <= tolerance
                                    for q in dirichlet):
                    out.append((point, neighbour))
        offset += dofs
    return out


def inconsistent_thesis_ends(solution: Solution, clamped: list) -> list:
    """(point, g - u_D.n) at the clamped ends where the thesis' lambda = 0 contradicts the
    data (``contact.ends = "thesis"`` only)."""
    pb = solution.problem
    scene = pb.scene
    if scene.contact.ends != "thesis" or not clamped:
        return []
    # the values consistent ends would prescribe there: one formula, in ContactBoundary
    consistent = replace(scene, contact=replace(scene.contact, ends="consistent"))
    values, _ = replace(pb.spaces.gamma_c, scene=consistent).end_values(
        scene.loads.displacement)
    gaps = pb.spaces.gamma_c.gap_at_vertices()
    tol = END_GAP_TOL * max(displacement_scale(solution), float(np.max(np.abs(gaps))))
    points = pb.spaces.contact.end_points()
    out = []
    for point, _ in clamped:
        k = int(np.argmin(np.linalg.norm(points - point, axis=1)))
        if abs(values[k]) > tol:
            out.append((point, float(values[k])))
    return out


def thesis_ends_outside_l2(solution: Solution) -> np.ndarray:
    """The clamped ends of Gamma_C (points, (n, 2)) where ``contact.ends = "thesis"`` sets
    lambda = 0 against g - u_D.n != 0, so that sigma is not in L2 there: those of the
    solution's ``"thesis-ends"`` check (:func:`~ngdual.checks.physics.physics_checks`)."""
    if not any(w.code == "thesis-ends" for w in solution.warnings):
        return np.zeros((0, 2))
    inconsistent = inconsistent_thesis_ends(solution, clamped_ends(solution))
    return np.array([point for point, _ in inconsistent], dtype=float).reshape(-1, 2)
