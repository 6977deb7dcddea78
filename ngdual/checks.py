"""Physics checks of a discrete solution: what a user should not believe, one line each.

:func:`physics_checks` runs every check on a solution and returns a
:class:`~ngdual.solution.CheckWarning` per failed one; :func:`~ngdual.solvers.solve_problem`
stores them in ``Solution.warnings`` and :func:`~ngdual.solvers.solve_scene` (``nd.solve``)
also issues each as a Python warning (:class:`~ngdual.solution.PhysicsWarning`).
Each message is one line naming the cause, its size and the remedy. Unlike the solvers,
the checks read the scene: what meets Gamma_C at its ends and which end values it sets.

What is measured on Gamma_C
---------------------------
The discrete contact conditions of (3.62) act on the h~ hat moments
t_i = d_C(mu_i, sigma_h) = int_{Gamma_C} sigma_h n mu_i ds (normal part t_{n,i} <= 0,
t_{n,i} lambda_{n,i} = 0; tangential part bounded by int F mu_i), not on the traction of
sigma_h on single fine edges: with h~ = 2h the fine-edge sigma_n carries modes orthogonal
to every hat (alternating from edge to edge), which nothing in (3.62) controls and which
peak where the contact zone ends (the wedge on level 3: sigma_n = +3900 next to -740 on
the fine edges at |x| = 0.15, a quarter of int |sigma_n| in tension, while no hat moment
is). Tension and force balance are therefore measured on the hat moments, over every h~
hat: those with a dof and the hats of the fixed ends of Gamma_C, whose values the
contact conditions do not constrain (:func:`contact_forces`). Where every end is free the
hats sum to one along Gamma_C, every tensile moment is a sign condition of (3.62) that
the solve violated, and the force balance holds exactly; at a fixed end the end hat
carries the force the prescribed end value causes.

With the facet multipliers of order k (``discretisation.multipliers = "facet"``) the "hats"
are the k + 1 Bernstein functions B_i of every fine edge and the "nodes" their control
points. The moments are read, as for the hats, through the means of the B_i on their edge
(1 / (k + 1)) against int_e sigma n ds: each is the mean of the edge's moments
d_C(B_i, sigma) (the B_i sum to one), so a moment that (3.62) keeps compressive stays
compressive and the force balance is exact, while the tension check sees the edge's
average rather than each B_i alone. No end is fixed (the multipliers are discontinuous),
so no clamped-end check applies.

Sizes are relative to the force scale F_ref = max(sum_i |t_i|, |Gamma_C| sigma_rms,
NOISE E U): the total force on the h~ hats, or, where that is smaller (always when nothing
touches), the force Gamma_C would carry at the body's RMS stress sigma_rms =
(int |sigma_h|^2 / |Omega|)^{1/2}; never below the force that round-off of the data can
cause, NOISE E U with U the displacement scale (the largest |u_h|, |lambda_n| = |g - u_n|,
|lambda_t|: it holds the gap). Without that floor a stress-free solution compares round-off
with round-off: hertz-cylinder without load has hat moments of 3e-11 (2e-16 E U), with its
foundation 1e6 away 6e-4 (3e-15 E U). A zero size over a zero scale counts as zero.

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

from dataclasses import dataclass, replace

import ngsolve as ngs
import numpy as np

from . import peers
from .expr import Expression
from .forms import traction_coefficient
from .friction import FrictionForms, build_friction_forms
from .geometry import round_off
from .scene import Contact, contact_junctions
from .solution import CheckWarning, Solution

TENSION_TOL = 0.05        # tensile hat force, of F_ref
FORCE_BALANCE_TOL = 0.05  # |int sigma n - sum_i t_i over the hats with a dof|, of F_ref
PENETRATION_TOL = 1e-6    # -lambda_n at an h~ node, of the displacement scale
FRICTION_TOL = 1e-6       # |t_t,i| beyond int F mu_i, of F_ref
END_GAP_TOL = 1e-8        # |g - u_D.n| at a clamped end, of the displacement scale
NOISE = 1e-10             # forces below NOISE E U are round-off (module docstring)
CONTACT_TOL = 1e-8        # lambda_n = 0 (in contact) below this fraction of the lambda scale
LOAD_SHARE_TOL = 0.25     # contact force, of the applied load (facet multipliers, k = 0)


def in_contact(lam_n: np.ndarray, lam_t: np.ndarray) -> np.ndarray:
    """Where lambda_n = 0 on the h~ mesh: at most ``CONTACT_TOL`` of the multipliers' scale
    (not of max lambda_n alone, which is round-off itself when every node touches)."""
    scale = max(float(np.max(np.abs(lam_n), initial=0.0)),
                float(np.max(np.abs(lam_t), initial=0.0)), 1e-300)
    return lam_n <= CONTACT_TOL * scale


@dataclass
class ForceBalance:
    """The forces on Gamma_C: the resultant of sigma n against what the multipliers see.

    ``resultant`` = int_{Gamma_C} sigma n ds (exact: sigma n is constant on every fine
    edge for RT_0, the Curl bubbles have no normal trace). ``multiplier_force`` =
    sum_i t_i over the h~ hats mu_i with a dof, t_i = int sigma n mu_i ds: the contact
    force the discrete contact conditions see (the moments d_C(mu_i, sigma) of (3.62)).
    ``normal_moments`` and ``tangential_moments`` are the t_{n,i}, t_{t,i} = d_Ct(mu_i,
    sigma) of those hats, ``end_moments`` the normal moments
    of the hats at the fixed ends (no dof, their value prescribed), ``end_points`` where
    these sit. ``scale`` is F_ref (module docstring); ``mismatch`` = |resultant -
    multiplier_force| / F_ref, the force the end hats carry; ``tension`` = sum of the
    positive normal moments of all hats / F_ref.
    """

    resultant: np.ndarray
    multiplier_force: np.ndarray
    normal_moments: np.ndarray
    tangential_moments: np.ndarray
    end_moments: np.ndarray
    end_points: np.ndarray
    scale: float

    @property
    def mismatch(self) -> float:
        return _ratio(float(np.linalg.norm(self.resultant - self.multiplier_force)), self.scale)

    @property
    def tension(self) -> float:
        tensile = np.sum(np.maximum(self.normal_moments, 0.0)) + np.sum(
            np.maximum(self.end_moments, 0.0))
        return _ratio(float(tensile), self.scale)


def _ratio(size: float, scale: float) -> float:
    """size / scale, zero for a zero size (also over a zero scale)."""
    return 0.0 if size == 0.0 else size / scale


def friction_forms_of(solution: Solution) -> FrictionForms:
    """The fine-edge operators on Gamma_C the solver built, or built once here."""
    return solution.friction_forms or build_friction_forms(solution.problem)


def contact_forces(solution: Solution, forms: FrictionForms | None = None) -> ForceBalance:
    """:class:`ForceBalance` of a solution with a contact boundary (``forms``: its
    :class:`~ngdual.friction.FrictionForms`, built if not given)."""
    pb = solution.problem
    gamma_c = pb.spaces.gamma_c
    forms = forms or friction_forms_of(solution)
    traction = (forms.T_n @ solution.x)[:, None] * gamma_c.normals \
        + (forms.T_t @ solution.x)[:, None] * gamma_c.tangents
    force = gamma_c.lengths[:, None] * traction  # int_e sigma n ds per fine edge
    hats = forms.midpoint_hats  # the means of the h~ hats of lambda_n on the fine edges
    ends = gamma_c.hat_means(pb.spaces.end_hats["lam_n"])
    moments, end_moments = hats.T @ force, ends.T @ force  # (hats, 2): int sigma n mu_i
    normal = hats.T @ (force * gamma_c.normals).sum(axis=1)
    tangential = hats.T @ (force * gamma_c.tangents).sum(axis=1)
    end_normal = ends.T @ (force * gamma_c.normals).sum(axis=1)
    total = float(np.sum(np.linalg.norm(moments, axis=1))
                  + np.sum(np.linalg.norm(end_moments, axis=1)))
    noise = NOISE * pb.scene.material.E * displacement_scale(solution)
    scale = max(total, float(np.sum(gamma_c.lengths)) * stress_rms(solution), noise)
    return ForceBalance(force.sum(axis=0), moments.sum(axis=0), normal, tangential, end_normal,
                        gamma_c.coarse.end_points(), scale)


def stress_rms(solution: Solution) -> float:
    """sigma_rms = (int_Omega |sigma_h|^2 dx / |Omega|)^{1/2}, the body's RMS stress."""
    pb = solution.problem
    gf = ngs.GridFunction(pb.fes)
    gf.vec.FV().NumPy()[:] = pb.to_fine(solution.x)
    c = dict(zip(pb.names, gf.components))
    sigma = peers.stress(c["r1"], c["r2"], c["b1"], c["b2"])
    mesh = pb.fes.mesh
    return float(np.sqrt(ngs.Integrate(ngs.InnerProduct(sigma, sigma), mesh)
                         / ngs.Integrate(ngs.CF(1.0), mesh)))


def physics_checks(solution: Solution) -> list[CheckWarning]:
    """Every physics check of ``solution`` that fails, as one :class:`CheckWarning` each.

    On Gamma_C (module docstring): tension in the h~ hat moments, the force balance
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
    clamped = _clamped_ends(solution)
    inconsistent = _inconsistent_thesis_ends(solution, clamped)
    curved = _thesis_gap_is_curved(solution)
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


def applied_load(solution: Solution) -> np.ndarray:
    """int_{Gamma_N} t_0 ds + int_Omega f dx: the resultant of the loads of the scene."""
    scene, mesh = solution.problem.scene, solution.problem.fes.mesh

    def field(formulas):
        return ngs.CF(tuple(Expression(e).coefficient() for e in formulas))

    load = np.array(ngs.Integrate(field(scene.loads.body_force), mesh, order=6))
    if scene.labels("neumann"):
        region = mesh.Boundaries("|".join(scene.labels("neumann")))
        load = load + np.array(ngs.Integrate(traction_coefficient(scene, mesh), mesh, ngs.BND,
                                             order=6, definedon=region))
    return load


def _load_share(solution: Solution, balance: ForceBalance) -> CheckWarning | None:
    """Order 0 with the facet multipliers where Gamma_C carries a small share of the load:
    the contact force is a small difference that magnifies the compliance error of PEERS_0
    with the tractions on every fine edge (module docstring, ``LOAD_SHARE_TOL``)."""
    disc = solution.problem.scene.discretisation
    if disc.order != 0 or disc.family != "facet":
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


def displacement_scale(solution: Solution) -> float:
    """U: the largest |u_h| in the body and |lambda_n|, |lambda_t| at the h~ nodes
    (lambda_n = g - u_n: U holds the gap)."""
    parts = [solution.part("u1", "u2"), solution.part("lam_n"), solution.part("lam_t")]
    return max(float(np.max(np.abs(p), initial=0.0)) for p in parts)


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
    size = _ratio(max(float(excess[worst]), 0.0), balance.scale)
    if size <= FRICTION_TOL:
        return None
    where = pb.spaces.contact.node_points()[worst]
    return CheckWarning(
        "friction-bound", f"friction bound on Gamma_C: |int sigma_t mu_i| exceeds "
                          f"int F mu_i by {excess[worst]:.3g} = {size:.3g} of the force scale "
                          f"at {_point(where)}: the friction solve did not reach (3.62); "
                          "tighten solver.eps1 and solver.eps2 or use "
                          'solver.method = "active-set"', size, FRICTION_TOL)


def _thesis_gap_is_curved(solution: Solution) -> bool:
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


def _clamped_ends(solution: Solution) -> list[tuple[np.ndarray, int]]:
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


def _inconsistent_thesis_ends(solution: Solution, clamped: list) -> list:
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
    solution's ``"thesis-ends"`` check (:func:`physics_checks`)."""
    if not any(w.code == "thesis-ends" for w in solution.warnings):
        return np.zeros((0, 2))
    inconsistent = _inconsistent_thesis_ends(solution, _clamped_ends(solution))
    return np.array([point for point, _ in inconsistent], dtype=float).reshape(-1, 2)


def _thesis_ends_warning(inconsistent: list, scale: float) -> CheckWarning:
    point, gap = max(inconsistent, key=lambda item: abs(item[1]))
    return CheckWarning(
        "thesis-ends", f'contact.ends = "thesis" with g - u_D.n = {gap:.3g} at the clamped '
                       f"end {_point(point)} of Gamma_C: lambda = 0 there forces u_n = g "
                       "against u = u_D, so sigma is not in L2 there and its norms grow with "
                       'the level; use contact.ends = "consistent" (the thesis scenes keep '
                       '"thesis" to reproduce the thesis tables)',
        abs(gap) / scale if scale > 0 else float("inf"), END_GAP_TOL)
