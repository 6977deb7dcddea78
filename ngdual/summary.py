"""What a solution says about the contact, in the scene's units: the summary a student reads.

:func:`solution_summary` gathers from the contact trace (:func:`ngdual.trace.contact_traces`)
and the force balance (:func:`ngdual.post.force_balance`) the extent of the contact zone, the
peak pressure, the total normal and tangential force and, where friction acts, the stick and
slip zones; given the analytic solution of the scene's ``[benchmark]``
(:mod:`ngdual.verification.analytic`, for the forces this solution carries), also the analytic
values beside them and the relative differences. The command line prints it
(:func:`ngdual.cli.output.summary_table`) and keeps it in ``result.json``.

Positions are measured along Gamma_C's contact plane: the foundation line where the scene
has one, else the line across the mean inward normal of Gamma_C (x_1 for a flat bottom).
"""

from __future__ import annotations

import numpy as np

from .geometry import tangent
from .post import force_balance
from .scene import foundation_line
from .solution import Solution
from .trace import contact_traces

ROUND_OFF = 1e-12  # relative to the extent of Gamma_C: a position below it is zero


def contact_directions(solution: Solution) -> tuple[np.ndarray, np.ndarray]:
    """(n, t): the unit normal of the contact plane towards the body and its tangent
    t = (n_2, -n_1) of (3.24) (x_1 for a foundation y = const below the body): the
    directions of the normal force P and the tangential force Q."""
    scene = solution.problem.scene
    if scene.contact.foundation is not None:
        normal = foundation_line(scene.contact)[1]
    else:
        gamma_c = solution.problem.spaces.gamma_c
        outward = gamma_c.lengths @ gamma_c.normals
        normal = -outward / np.linalg.norm(outward)
    return normal, tangent(normal)


def _intervals(along: np.ndarray, members: np.ndarray) -> list[list[float]]:
    """[first, last] of every run of consecutive ``members`` among the nodes sorted by
    ``along`` (several nodes at one position, the control points of the facet family,
    form one run if any of them belongs)."""
    positions = np.unique(along)
    inside = np.array([members[along == p].any() for p in positions])
    runs, start = [], None
    for k, flag in enumerate(inside):
        if flag and start is None:
            start = k
        if start is not None and (not flag or k == len(inside) - 1):
            stop = k if flag else k - 1
            runs.append([float(positions[start]), float(positions[stop])])
            start = None
    return runs


def _half_width(runs: list[list[float]]) -> float:
    return 0.5 * (max(b for _, b in runs) - min(a for a, _ in runs)) if runs else 0.0


def _spacing(along: np.ndarray, runs: list[list[float]]) -> float:
    """The largest distance from an end of the zone to the next node outside it: the
    resolution of the zone's extent (its edge lies in between)."""
    positions = np.unique(along)
    lo, hi = min(a for a, _ in runs), max(b for _, b in runs)
    below, above = positions[positions < lo], positions[positions > hi]
    return float(max(lo - below.max() if len(below) else 0.0,
                     above.min() - hi if len(above) else 0.0))


def analytic_values(exact) -> dict:
    """The values of an analytic solution of :mod:`ngdual.verification.analytic` that the
    summary compares: ``half_width`` a, ``peak_pressure`` p0 (not for the flat punch and
    the wedge, whose pressure is unbounded), for Cattaneo-Mindlin ``stick_half_width`` c
    and ``peak_shear``, the largest |q|: at |x| = c, mu_f p0 sqrt(1 - c^2/a^2).

    >>> from ngdual.verification.analytic import hertz
    >>> values = analytic_values(hertz(P=100.0, R=10.0, E=2e5, nu=0.3))
    >>> round(values["half_width"], 6), round(values["peak_pressure"], 1)
    (0.076113, 836.4)
    """
    contact = getattr(exact, "hertz", exact)
    values = {"half_width": float(contact.a)}
    peak = float(exact.pressure(np.array([0.0]))[0])
    if np.isfinite(peak) and not exact.singular:
        values["peak_pressure"] = peak
    if hasattr(exact, "shear"):
        values["stick_half_width"] = float(exact.c)
        values["peak_shear"] = float(abs(exact.shear(np.array([exact.c]))[0]))
    return values


def solution_summary(solution: Solution, exact=None, name: str | None = None) -> dict:
    """The contact of ``solution`` in the scene's units (plain JSON data).

    ``method``: scene, level, PEERS order, multiplier family, solver and whether it
    converged. With a contact boundary: ``half_width`` (half the extent of the nodes in
    contact, p_h's nodes of :class:`ngdual.trace.ContactTraces`) and ``resolution`` (the
    node spacing at its ends: the zone's edge lies within it), ``centre``,
    ``peak_pressure`` max p_h and where (``peak_at``), ``normal_force`` P and
    ``tangential_force`` Q: the contact force the discrete contact conditions see, the
    moments of sigma n over the hats with a dof (``multiplier_force`` of
    :func:`ngdual.post.force_balance`: it equals the resultant of sigma n unless singular
    corners at fixed ends of Gamma_C pull on it), along n and t of
    :func:`contact_directions`: the force the foundation exerts on the body
    (``directions``: n and t). With friction also
    ``peak_shear`` max |q_h|, the ``stick`` and ``slip`` zones as intervals [first node,
    last node] and ``stick_half_width``. ``exact`` (an analytic solution of
    :mod:`ngdual.verification.analytic` for these forces) adds ``benchmark``: its
    ``name`` and ``values`` (:func:`analytic_values`) and ``difference``, computed /
    analytic - 1 for every value both have.
    """
    pb = solution.problem
    scene = pb.scene
    summary = {"method": {"scene": scene.name, "level": pb.level,
                          "order": pb.spaces.order, "multipliers": pb.spaces.family,
                          "solver": solution.method, "converged": bool(solution.converged)},
               "units": {"length": scene.units.length, "stress": scene.units.stress,
                         "force": scene.units.force},
               "contact": pb.spaces.contact is not None}
    if pb.spaces.contact is None:
        return summary
    tr = contact_traces(solution)
    normal, along_dir = contact_directions(solution)
    along = tr.coarse_xy @ along_dir
    # positions that are zero up to round-off (the middle of a symmetric scene) read as zero
    along[np.abs(along) <= ROUND_OFF * np.ptp(along)] = 0.0
    contact = _intervals(along, tr.coarse_in_contact)
    force = force_balance(solution).multiplier_force
    peak = int(np.argmax(tr.pressure)) if len(tr.pressure) else None
    summary.update(
        friction=scene.friction.law if tr.friction else None,
        contact_zones=contact, half_width=_half_width(contact),
        centre=0.5 * (contact[0][0] + contact[-1][1]) + 0.0 if contact else None,
        resolution=_spacing(along, contact) if contact else None,
        peak_pressure=float(tr.pressure[peak]) if peak is not None else 0.0,
        peak_at=float(along[peak]) if peak is not None else None,
        normal_force=float(force @ normal), tangential_force=float(force @ along_dir),
        directions={"normal": normal.tolist(), "tangent": along_dir.tolist()})
    if tr.friction:
        touching = tr.coarse_status != "separation"
        summary.update(peak_shear=float(np.max(np.abs(tr.shear[touching]), initial=0.0)),
                       stick=_intervals(along, tr.coarse_status == "stick"),
                       slip=_intervals(along, tr.coarse_status == "slip"))
        summary["stick_half_width"] = _half_width(summary["stick"])
    if exact is not None:
        values = analytic_values(exact)
        summary["benchmark"] = {
            "name": name or type(exact).__name__, "values": values,
            "difference": {key: summary[key] / value - 1.0 for key, value in values.items()
                           if summary.get(key) is not None and value != 0}}
    return summary
