"""The physics checks of a discrete solution (:func:`physics_checks`), each with its
tolerance and a one-line message that names the cause, its size and the remedy.

Tolerances
----------
``TENSION_TOL``, ``FORCE_BALANCE_TOL`` (fractions of F_ref): a discretisation error, not
round-off, sits in the fixed-end hats of a clamped Gamma_C with consistent end values
(Example 3.46 with ``contact.ends = "consistent"``: force mismatch 8.7 %, 0.31 %, 0.76 %,
0.63 %, 0.42 %, 0.26 % of F_ref on levels 1-6, the corner singularity's rate; tension
8.6 % on level 1, round-off from level 2 on); the thesis' ends give a mismatch and a
tension of about 38 % on every level (1980 of tension in the two corner cells). 5 % lies
between, a decade from each from level 2 on; level 1 (h~ = 1/2) warns rightly.
``PENETRATION_TOL`` (of the displacement scale: the largest |u_h|, |lambda_n|,
|lambda_t|) and ``FRICTION_TOL`` (of F_ref): the sign and friction conditions hold to the
solver's tolerance (active set: round-off, Uzawa: its increments of 1e-8); 1e-6 is a
failed solve. ``END_GAP_TOL``: g - u_D.n at a clamped end counts as zero below 1e-8 of the
displacement scale (round-off of the gap and the data).

``LOAD_SHARE_TOL`` (of the applied load |int_{Gamma_N} t_0 ds + int_Omega f dx|): below it
Gamma_C carries a small share of the load and its force is the small difference between the
body's free sag and the gap, which magnifies the compliance error of the body. Order 0 with
the facet multipliers, which impose the tractions on every fine edge, has the largest
(PEERS_0 is softer than the body, docs/theory/order.md): punch-on-foundation's share is
4.5-8.6 % and its force 114.3 / 80.3 / 65.6 / 59.7 on levels 2-5 against 57; Example 3.46
(consistent ends) puts 64-72 % on Gamma_C, and its force is within 4.2 / 1.1 / 0.3 % on
levels 2-4. A quarter lies between.
"""

from __future__ import annotations

import numpy as np

from ..friction import FrictionForms
from ..scene import Contact
from ..solution import CheckWarning, Solution
from .ends import END_GAP_TOL, clamped_ends, inconsistent_thesis_ends, thesis_gap_is_curved
from .forces import (
    NOISE,
    ForceBalance,
    applied_load,
    contact_forces,
    displacement_scale,
    friction_forms_of,
    in_contact,
    ratio,
)

TENSION_TOL = 0.05        # tensile hat force, of F_ref
FORCE_BALANCE_TOL = 0.05  # |int sigma n - sum_i t_i over the hats with a dof|, of F_ref
PENETRATION_TOL = 1e-6    # -lambda_n at an h~ node, of the displacement scale
FRICTION_TOL = 1e-6       # |t_t,i| beyond int F mu_i, of F_ref
LOAD_SHARE_TOL = 0.25     # contact force, of the applied load (facet multipliers, k = 0)


def physics_checks(solution: Solution) -> list[CheckWarning]:
    """Every physics check of ``solution`` that fails, as one :class:`CheckWarning` each.

    On Gamma_C (:mod:`ngdual.checks.forces`): tension in the h~ hat moments, the force balance
    between int sigma n ds and the multiplier force, penetration (lambda_n < 0 at an h~
    node), the friction bound |d_Ct(mu_i, sigma)| <= int F mu_i, a contact zone that runs
    into a clamped end, and ``contact.ends = "thesis"`` where g - u_D.n is not zero at a
    clamped end (sigma not in L^2 there). A solution without Gamma_C passes.
    """
    pb = solution.problem
    if pb.spaces.gamma_c is None:
        return []
    forms = friction_forms_of(solution)
    balance = contact_forces(solution, forms)
    clamped = clamped_ends(solution)
    inconsistent = inconsistent_thesis_ends(solution, clamped)
    curved = thesis_gap_is_curved(solution)
    found = [_tension(balance, pb.spaces.contact.node_points(), inconsistent,
                      pb.scene.contact, curved),
             _force_balance(balance, inconsistent, pb.scene.contact, curved),
             _penetration(solution),
             _friction_bound(solution, forms, balance),
             _contact_at_clamped_end(solution, clamped)]
    if inconsistent:
        found.append(_thesis_ends_warning(inconsistent, displacement_scale(solution)))
    found.append(_load_share(solution, balance))
    return [w for w in found if w is not None]


def _load_share(solution: Solution, balance: ForceBalance) -> CheckWarning | None:
    """Order 0 with the facet multipliers where Gamma_C carries a small share of the load:
    the contact force is a small difference that magnifies the compliance error of PEERS_0
    with the tractions on every fine edge (module docstring, ``LOAD_SHARE_TOL``)."""
    spaces = solution.problem.spaces
    if spaces.order != 0 or not spaces.contact.traces:
        return None
    if not np.any(in_contact(solution.part("lam_n"), solution.part("lam_t"))):
        return None
    load = float(np.linalg.norm(applied_load(solution)))
    force = float(np.linalg.norm(balance.resultant))
    if load <= NOISE * balance.scale or force >= LOAD_SHARE_TOL * load:
        return None
    return CheckWarning(
        "load-share", f"Gamma_C carries {force:.4g} = {100 * force / load:.3g} % of the applied "
                      f"load {load:.4g}, the rest Gamma_D: the contact force is the small "
                      "difference between the body's free sag and the gap, and it magnifies "
                      'the compliance error of discretisation.order = 0 with multipliers = '
                      '"facet" (the tractions on every fine edge make PEERS_0 too soft: '
                      "punch-on-foundation +100 % on level 2, +5 % on level 5); use "
                      "discretisation.order = 1, or refine", force / load, LOAD_SHARE_TOL)


def _point(xy) -> str:
    return f"({xy[0]:.4g}, {xy[1]:.4g})"


def _vector(v) -> str:
    return f"({v[0]:.4g}, {v[1]:.4g})"


def _end_cause(inconsistent: list, contact: Contact, curved: bool) -> str:
    """Why the fixed-end hats carry force, and the remedy (``curved``: the thesis' discrete
    gap acts where g is not affine on the h~ edges)."""
    if inconsistent:
        point, gap = inconsistent[0]
        return (f'contact.ends = "thesis" forces u_n = g at the clamped ends of Gamma_C '
                f"(g - u_D.n = {gap:.3g} at {_point(point)}; sigma not in L2 there); use "
                f'contact.ends = "consistent"')
    if contact.ends == "thesis":
        return ('contact.ends = "thesis" fixes lambda = 0 at every end of Gamma_C; use '
                'contact.ends = "consistent"')
    if curved:
        return ('contact.discrete_gap = "thesis" imposes the part of g that is not affine '
                'on the h~ edges like a displacement, and the fixed-end hats carry the '
                'force it makes; use contact.discrete_gap = "nodal"')
    return ("the h~ edges at the clamped ends of Gamma_C carry it (the corner singularity, "
            "not resolved); refine towards those ends (ngdual adapt) or let Gamma_C end at a "
            "free side")


def _tension(balance: ForceBalance, nodes: np.ndarray, inconsistent: list, contact: Contact,
             curved: bool) -> CheckWarning | None:
    """Tensile hat moments; ``nodes``: the h~ nodes with a dof."""
    if balance.tension <= TENSION_TOL:
        return None
    moments = np.concatenate([balance.end_moments, balance.normal_moments])
    where = int(np.argmax(moments))
    at_end = where < len(balance.end_moments)
    point = balance.end_points[where] if at_end else nodes[where - len(balance.end_moments)]
    cause = _end_cause(inconsistent, contact, curved) if at_end else (
        "(3.62) forbids it at a node with a dof: the contact solve did not reach (3.62); "
        'tighten solver.eps or use solver.method = "active-set"')
    return CheckWarning(
        "tension", f"tension on Gamma_C: the h~ hats carry a tensile force of "
                   f"{balance.tension * balance.scale:.4g} = {100 * balance.tension:.3g} % of "
                   f"the force scale {balance.scale:.4g}, most at the "
                   f"{'fixed end' if at_end else 'h~ node'} {_point(point)}; {cause}",
        balance.tension, TENSION_TOL)


def _force_balance(balance: ForceBalance, inconsistent: list, contact: Contact,
                   curved: bool) -> CheckWarning | None:
    if balance.mismatch <= FORCE_BALANCE_TOL:
        return None
    seen = float(np.linalg.norm(balance.multiplier_force))
    times = (f" ({np.linalg.norm(balance.resultant - balance.multiplier_force) / seen:.3g}x "
             "the multiplier force)") if seen > FORCE_BALANCE_TOL * balance.scale else ""
    return CheckWarning(
        "force-balance",
        f"force balance on Gamma_C: the sides carry {_vector(balance.resultant)}, the "
        f"multipliers see {_vector(balance.multiplier_force)}: a mismatch of "
        f"{100 * balance.mismatch:.3g} % of the force scale {balance.scale:.4g}{times}; "
        f"{_end_cause(inconsistent, contact, curved)}", balance.mismatch, FORCE_BALANCE_TOL)


def _penetration(solution: Solution) -> CheckWarning | None:
    lam_n = solution.part("lam_n")
    depth = float(-np.min(lam_n, initial=0.0))
    scale = displacement_scale(solution)
    if depth <= PENETRATION_TOL * scale:
        return None
    where = solution.problem.spaces.contact.node_points()[int(np.argmin(lam_n))]
    return CheckWarning(
        "penetration", f"penetration on Gamma_C: u_n exceeds the gap by {depth:.3g} "
                       f"(lambda_n = g - u_n < 0) at {_point(where)}, {depth / scale:.3g} of "
                       "the displacement scale: the contact solve did not reach (3.62); "
                       'tighten solver.eps or use solver.method = "active-set"',
        depth / scale, PENETRATION_TOL)


def _friction_bound(solution: Solution, forms: FrictionForms, balance: ForceBalance
                    ) -> CheckWarning | None:
    """|t_{t,i}| = |d_Ct(mu_i, sigma)| against int F mu_i at every h~ node: the bound the
    discrete problem imposes (F is the h^ mean of mu_f |p_h|, so |t_t| / |t_n| may exceed
    mu_f at the last node of a contact zone, :class:`ngdual.trace.FrictionDiagnostics`)."""
    if solution.friction_bound is None:
        return None
    pb = solution.problem
    bound = np.asarray(forms.q_matrix(solution.friction_bound).sum(axis=0)).ravel()
    excess = np.abs(balance.tangential_moments) - bound
    worst = int(np.argmax(excess))
    size = ratio(max(float(excess[worst]), 0.0), balance.scale)
    if size <= FRICTION_TOL:
        return None
    where = pb.spaces.contact.node_points()[worst]
    return CheckWarning(
        "friction-bound", f"friction bound on Gamma_C: |int sigma_t mu_i| exceeds "
                          f"int F mu_i by {excess[worst]:.3g} = {size:.3g} of the force scale "
                          f"at {_point(where)}: the friction solve did not reach (3.62); "
                          "tighten solver.eps1 and solver.eps2 or use "
                          'solver.method = "active-set"', size, FRICTION_TOL)


def _contact_at_clamped_end(solution: Solution, clamped: list) -> CheckWarning | None:
    touching = in_contact(solution.part("lam_n"), solution.part("lam_t"))
    points = [point for point, node in clamped if touching[node]]
    if not points:
        return None
    return CheckWarning(
        "contact-at-clamped-end",
        f"contact at a clamped end of Gamma_C: the h~ node next to {_point(points[0])}"
        f"{f' (and {len(points) - 1} more)' if len(points) > 1 else ''} is in contact, so "
        "the contact zone runs into the clamped corner, where sigma is singular and the "
        "pressure is not resolved; read the pressure away from the corner, or refine "
        "towards it (ngdual adapt)", float(len(points)), 0.0)


def _thesis_ends_warning(inconsistent: list, scale: float) -> CheckWarning:
    point, gap = max(inconsistent, key=lambda item: abs(item[1]))
    return CheckWarning(
        "thesis-ends", f'contact.ends = "thesis" with g - u_D.n = {gap:.3g} at the clamped '
                       f"end {_point(point)} of Gamma_C: lambda = 0 there forces u_n = g "
                       "against u = u_D, so sigma is not in L2 there and its norms grow with "
                       'the level; use contact.ends = "consistent" (the thesis scenes keep '
                       '"thesis" to reproduce the thesis tables)',
        abs(gap) / scale if scale > 0 else float("inf"), END_GAP_TOL)
