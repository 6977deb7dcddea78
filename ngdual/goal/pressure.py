"""The pressure goal: ||p - p_h||_{L2(W)} on Gamma_C or on a window W of it.

:class:`PressureGoal` measures a solution by the indicators of :func:`goal_estimate`
(:mod:`ngdual.goal.indicators`) and answers the loop's other questions from the solution's
contact set, the vertices of Gamma_C where lambda_n = g - u_n vanishes
(:func:`contact_vertices`): a window that holds none has no pressure to aim at
(:meth:`PressureGoal.nothing_to_measure`), and a contact zone that reaches a free end of
Gamma_C leaves p outside L2 there (:func:`singular_free_ends`).
"""

from __future__ import annotations

import time

import numpy as np
from scipy.spatial import cKDTree

from ..checks import displacement_scale, thesis_ends_outside_l2
from ..estimator import Estimate
from ..forms.spaces import variant_of
from ..scene import Scene, contact_junctions
from ..scene.contact import KINK_ANGLE
from ..solution import Solution
from .base import Goal, Measure, points_text, thesis_ends_reason
from .contact_ends import CONTACT_SHARE, kink_points
from .indicators import goal_estimate, in_window

# The pressure goal's effectivity where Gamma_C has a kink, at which the pressure is
# log-singular, with the thesis' multipliers (their hat projection has no term for the apex
# edges): its estimate / the true error over the tolerance runs of order 0 to 0.01-0.02 on the
# wedge and the two wedges of ngdual.studies.effectivity (docs/theory/effectivity.md). With
# the facet multipliers the apex has its term (goal.contact_ends.kink_distances).
KINK_EFFECTIVITY = (0.10, 0.49)


class PressureGoal(Goal):
    """||p - p_h||_{L2(W)} relative to ||p_h||_{L2(W)}, W = Gamma_C or its part whose x lies
    in ``window`` = (lo, hi) (:func:`ngdual.goal.goal_estimate`).

    >>> PressureGoal((-0.125, 0.125)).window
    (-0.125, 0.125)
    """

    name = "pressure"
    size_name = "||p_h||"
    zero_size_reason = ("no contact where the goal measures the pressure; a window inside the "
                        "contact zone can be measured")

    def __init__(self, window: tuple[float, float] | None = None):
        self.window = None if window is None else (float(window[0]), float(window[1]))

    def measure(self, solution: Solution, estimated: Estimate, norms: dict) -> Measure:
        """The indicators of ||p - p_h||_{L2(W)} and ||p_h||_{L2(W)} (``norms`` unused)."""
        start = time.perf_counter()
        pressure = goal_estimate(solution, estimated, self.window)
        return Measure(pressure.indicators, pressure.total, pressure.size, pressure.whole,
                       pressure.summed(), time.perf_counter() - start)

    def nothing_to_measure(self, solution: Solution, measured: Measure) -> str | None:
        """Why W holds no contact (None where it does): no vertex of Gamma_C in W is in the
        solution's contact set (:func:`contact_vertices`) and ||p_h||_W (``measured.size``)
        is round-off against ||p_h|| on all of Gamma_C, at most CONTACT_SHARE of it. Then
        p = 0 on W, and no relative estimate is defined against ||p_h||_W. (The pressure of
        the thesis' multipliers, a projection onto the hats of h~, reaches an h~ edge beyond
        the vertices in contact: a window there holds pressure, not round-off.)"""
        points, contact = contact_vertices(solution)
        inside = in_window(points[:, 0], self.window)
        if np.any(contact & inside) or measured.size > CONTACT_SHARE * measured.whole:
            return None
        where = ("all of Gamma_C" if self.window is None
                 else f"the window {self.window[0]:g} <= x <= {self.window[1]:g}")
        if not contact.any():
            zone = "Gamma_C is nowhere in contact (lambda_n > 0 at every vertex)"
        else:
            xs = points[contact, 0]
            zone = f"the contact zone lies in {xs.min():.4g} <= x <= {xs.max():.4g}"
        return (f"no contact in {where}: lambda_n = g - u_n > 0 at each of its vertices, so its "
                f"pressure is 0 and ||p_h|| there is round-off, relative to which no estimate "
                f"is defined; {zone}" + ("; choose a window inside it (window=(lo, hi), ngdual "
                                         "adapt --window)" if contact.any() else ""))

    def infinite_error(self, solution: Solution) -> str | None:
        """Why ||p - p_h||_{L2(W)} is infinite (None where it is finite): the contact zone
        reaches a free end of Gamma_C in W (:func:`singular_free_ends`), or the thesis' ends
        leave sigma outside L2 at a clamped end in W."""
        ends = singular_free_ends(solution, self.window)
        if len(ends):
            return _not_in_l2(ends)
        clamped = thesis_ends_outside_l2(solution)
        return thesis_ends_reason(clamped[in_window(clamped[:, 0], self.window)], window=True)

    def caution(self, scene: Scene) -> str | None:
        """At a kink of Gamma_C in W the estimate with the thesis' multipliers is too small by
        a constant (:data:`KINK_EFFECTIVITY`): an estimate below tol leaves the error above
        it. (The facet multipliers' estimate has a term for the kink.)"""
        if variant_of(scene).traces:
            return None
        kinks = kink_points(scene)
        kinks = kinks[in_window(kinks[:, 0], self.window)]
        if not len(kinks):
            return None
        low, high = KINK_EFFECTIVITY
        return (f"Gamma_C has a kink at {points_text(kinks)}, where the pressure goal's "
                f"estimate with the thesis' multipliers is too small by a constant "
                f"({low:g}-{high:g} of the true error on wedges; docs/theory/effectivity.md): "
                f"the pressure error may be several times tol; the facet multipliers "
                f"(discretisation.order >= 1) estimate it")


def contact_vertices(solution: Solution) -> tuple[np.ndarray, np.ndarray]:
    """The fine vertices of Gamma_C, chain by chain (n, 2), and which of them are in contact:
    lambda_n = g - u_n at most CONTACT_SHARE of the larger of max |lambda_n| and the
    displacement scale (:func:`ngdual.checks.displacement_scale`), so that round-off counts
    as contact and a Gamma_C in contact everywhere (lambda_n = 0 to round-off) is."""
    pb = solution.problem
    gamma_c = pb.spaces.gamma_c
    fine = pb.to_fine(solution.x)
    rng = pb.fes.Range(pb.names.index("lam_n"))
    lam_n = gamma_c.vertex_values(fine[rng.start:rng.stop])
    points = np.vstack([chain.path_points for chain in gamma_c.coarse.chains])
    scale = max(float(np.max(np.abs(lam_n), initial=0.0)), displacement_scale(solution))
    return points, lam_n <= CONTACT_SHARE * scale


def free_straight_ends(scene: Scene) -> np.ndarray:
    """The ends of Gamma_C (points, (n, 2)) where a free or loaded side begins running
    straight on or turning re-entrant: where the pressure is not in L2 if the contact zone
    reaches them (:func:`singular_free_ends`)."""
    return np.array([point for point, kind, angle in contact_junctions(scene)
                     if kind == "neumann" and angle <= KINK_ANGLE], dtype=float).reshape(-1, 2)


def singular_free_ends(solution: Solution,
                       window: tuple[float, float] | None = None) -> np.ndarray:
    """The ends of Gamma_C where the contact pressure is not in L2: an array of points (n, 2),
    those in ``window`` (abscissa) if one is given.

    At an end of Gamma_C where a traction-free or loaded side begins (a ``"neumann"``
    junction of :func:`ngdual.scene.contact_junctions`) and the contact zone reaches it, the
    normal traction drops from the contact pressure to the side's. Mirrored across the
    frictionless contact side, the body's corner of interior angle phi (pi less the
    boundary's turning angle there) is a free wedge of angle 2 phi, whose symmetric stress
    modes r^(lambda - 1) solve lambda sin(2 phi) + sin(2 lambda phi) = 0 (Williams): lambda
    = 1 at phi = pi/2 (a block on a plane: bounded), 1/2 at phi = pi (a flat punch's edge,
    the boundary running straight on: p ~ d^(-1/2)), below 1/2 beyond. So p is not in
    L2(Gamma_C) where the boundary runs straight on or turns re-entrant (turning angle at
    most KINK_ANGLE), and ||p - p_h||_{L2(Gamma_C)} has no finite value for the pressure
    goal to reach (with friction the exponent moves off 1/2 with the friction coefficient,
    to either side; the test is the frictionless one). Contact at an end: its vertex is in
    the contact set (:func:`contact_vertices`)."""
    ends = free_straight_ends(solution.problem.scene)
    ends = ends[in_window(ends[:, 0], window)]
    if not len(ends):
        return ends
    points, contact = contact_vertices(solution)
    _, nearest = cKDTree(points).query(ends)
    return ends[contact[nearest]]


def _not_in_l2(ends: np.ndarray) -> str:
    """Why the pressure goal's error is infinite where p is not in L2 at ``ends`` of Gamma_C
    (:func:`singular_free_ends`)."""
    one = len(ends) == 1
    return (f"the contact zone reaches Gamma_C's {'end' if one else 'ends'} at "
            f"{points_text(ends)}, where a free side begins, and the pressure is singular there "
            f"(like d^(-1/2) at a flat punch's edge, d the distance to the end), not in L2: its "
            f"L2 error on Gamma_C is infinite and the goal's estimate measures none; a window "
            f"away from the {'end' if one else 'ends'} has a finite one (window=(lo, hi), "
            f"ngdual adapt --window)")
