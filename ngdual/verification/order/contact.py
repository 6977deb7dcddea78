"""PEERS of order k on frictionless contact: the manufactured case's errors, pressure and
contact set, and the order of sigma that theory predicts.

:func:`contact_study` solves the manufactured frictionless contact problem of
:mod:`ngdual.verification.manufactured` (Example 3.46's box, contact on [-2, 2], sigma_n and
lambda_n starting like d^2 from its ends) at order k with the multipliers of its default
family and measures the errors of the elasticity study and the contact set. Its ``gap``
names the normal displacement u_n on Gamma_C. The quadratic one is represented by the gap's P_k
interpolant on the contact zone (k >= 2), so the case measures the method alone and
:func:`~ngdual.verification.order.order_check` holds sigma's observed orders within
:data:`~ngdual.verification.order.ORDER_SLACK` of k + 1 on the last two levels. The
quartic one, the general case, sees the interpolant's error: at even k >= 2 an odd saw of
amplitude h^3 on every edge, which limits sigma to order k + 1/2 and the pressure to k
asymptotically (docs/theory/order.md, "What limits k = 2: the interpolated gap");
:func:`expected_order` states that prediction and ``order_check(rows, expected=...)``
fails only below it. :func:`~ngdual.verification.order.set_check` asks for the exact
contact set on the last two levels.
"""

from __future__ import annotations

import math
import time

import ngsolve as ngs
import numpy as np

from ...expr import Expression
from ...rates import observed_rates
from ...solvers import solve_scene
from ...trace import pressure_field
from ..manufactured import ONSET, frictionless_case
from ..manufactured_errors import discrete_sets, symmetric_difference, volume_errors
from .elasticity import QUANTITIES


def contact_set(solution) -> list[tuple[float, float]]:
    """The discrete contact set of a solution on Example 3.46's box, as intervals of x.

    With the coarse multipliers the h~ edges on which lambda_n^h vanishes
    (:func:`ngdual.verification.manufactured_errors.discrete_sets`); with the facet ones the
    fine edges all of whose Bernstein coefficients of lambda_n vanish (to 1e-9 of the
    largest): there the P_k function lambda_n^h is zero.
    """
    problem = solution.problem
    spaces = problem.spaces
    if not spaces.contact.traces:
        return discrete_sets(solution)["contact"]
    lam = solution.part("lam_n").reshape(-1, spaces.order + 1)
    touching = np.all(np.abs(lam) <= 1e-9 * np.abs(lam).max(initial=0.0), axis=1)
    gamma_c = problem.spaces.gamma_c
    mid, half = gamma_c.midpoints[touching, 0], 0.5 * gamma_c.lengths[touching]
    return [(float(a), float(b)) for a, b in zip(mid - half, mid + half)]


def pressure_error(case, solution) -> float:
    """||sigma_n^h - sigma_n||_{L^2(Gamma_C)}: the normal stress of the discrete solution on
    Gamma_C (n . sigma_h n, the normal traces of the stress rows: P_k on every fine edge)
    against the exact one of a manufactured ``case``, integrated exactly (Gamma_C's breaks
    x = +-2 are mesh vertices)."""
    mesh = solution.problem.fes.mesh
    exact = case.exact.sigma_n
    # sigma_n^h = -p_h, the pressure of the solution's trace as a field
    error = -pressure_field(solution) - Expression(exact.text()).coefficient()
    degree = 2 * max(solution.problem.spaces.order, exact.degree) + 2
    region = mesh.Boundaries("|".join(solution.problem.scene.labels("contact")))
    return math.sqrt(max(ngs.Integrate(error * error, mesh, ngs.BND, order=degree,
                                       definedon=region), 0.0))


def contact_study(order: int = 0, levels=(1, 2, 3), onset: int = ONSET,
                  gap: str = "quartic") -> list[dict]:
    """The manufactured frictionless contact case solved at order k on uniform levels.

    ``onset`` and ``gap`` are the p and the u_n of
    :func:`ngdual.verification.manufactured.frictionless_case` (sigma_n, lambda_n like d^p
    from the contact ends x = +-2, which are mesh lines; u_n quartic or quadratic): the
    default p = 2 is the one whose contact set every order recovers exactly, the
    quadratic u_n the one whose gap the multipliers represent on the contact zone.

    Returns
    -------
    list of dict
        One row per level: ``problem`` ("contact"), ``gap``, ``order``, ``level``, ``ndof`` (every
        unknown), ``seconds`` (meshing, assembly and solve), the L^2 errors of
        :data:`~ngdual.verification.order.QUANTITIES` with their observed orders
        ``<quantity>_order`` (None on the first level), the pressure's error ``pressure``
        (:func:`pressure_error`) with its order, and ``contact_set``: the length of the
        symmetric difference between :func:`contact_set` and the exact contact set [-2, 2].
    """
    case = frictionless_case(2.0, "frictionless", onset, gap)
    scene = case.scene(order=order)
    rows = []
    for level in levels:
        start = time.perf_counter()
        solution = solve_scene(scene, level)
        seconds = time.perf_counter() - start
        errors = volume_errors(case, solution)
        rows.append({"problem": "contact", "gap": gap, "order": order, "level": level,
                     "ndof": solution.problem.fes.ndof, "seconds": seconds,
                     **{q: errors[q] for q in QUANTITIES},
                     "pressure": pressure_error(case, solution),
                     "contact_set": symmetric_difference(contact_set(solution),
                                                         case.contact_set)})
    for q in (*QUANTITIES, "pressure"):
        for row, rate in zip(rows, observed_rates([r["ndof"] for r in rows],
                                                  [r[q] for r in rows])):
            row[q + "_order"] = rate
    return rows


def expected_order(order: int, gap: str) -> float:
    """The order of sigma that theory predicts for the manufactured contact case of order k
    with the normal displacement ``gap`` (:func:`contact_study`), as h -> 0.

    k + 1 where the P_k interpolant of the gap costs nothing: at k = 0 and odd k (its
    error is even about every edge's midpoint) and where it is exact on the contact zone
    (the quadratic u_n at k >= 2); k + 1/2 at even k >= 2 with the quartic u_n, whose
    interpolation error is an odd saw of amplitude h^3 on every fine edge (docs/theory/
    order.md, "What limits k = 2: the interpolated gap"; the derivation in
    :func:`ngdual.verification.manufactured.frictionless_case`).

    >>> [expected_order(k, "quartic") for k in (0, 1, 2)]
    [1, 2, 2.5]
    >>> expected_order(2, "quadratic")
    3
    """
    exact_on_zone = gap == "quadratic" and order >= 2
    if order == 0 or order % 2 == 1 or exact_on_zone:
        return order + 1
    return order + 0.5
