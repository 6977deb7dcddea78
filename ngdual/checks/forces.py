"""The forces on Gamma_C a physics check measures: the h~ hat moments, the force balance
(:class:`ForceBalance`) and the scales they are measured against.

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
"""

from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np

from .. import peers
from ..expr import Expression
from ..forms import traction_coefficient
from ..friction import FrictionForms, build_friction_forms
from ..solution import Solution

NOISE = 1e-10             # forces below NOISE E U are round-off (module docstring)
CONTACT_TOL = 1e-8        # lambda_n = 0 (in contact) below this fraction of the lambda scale


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
        return ratio(float(np.linalg.norm(self.resultant - self.multiplier_force)), self.scale)

    @property
    def tension(self) -> float:
        tensile = np.sum(np.maximum(self.normal_moments, 0.0)) + np.sum(
            np.maximum(self.end_moments, 0.0))
        return ratio(float(tensile), self.scale)


def ratio(size: float, scale: float) -> float:
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



def displacement_scale(solution: Solution) -> float:
    """U: the largest |u_h| in the body and |lambda_n|, |lambda_t| at the h~ nodes
    (lambda_n = g - u_n: U holds the gap)."""
    parts = [solution.part("u1", "u2"), solution.part("lam_n"), solution.part("lam_t")]
    return max(float(np.max(np.abs(p), initial=0.0)) for p in parts)
