"""The contact trace of a solution: what every reader of Gamma_C reads.

:func:`contact_traces` gathers, once per solution, the tractions sigma_n, sigma_t on the
fine edges of Gamma_C and sampled along them, the contact pressure p_h and shear q_h that
the contact conditions of (3.62) control (:func:`ngdual.friction.hat_projection` on the
h~ hats; the moments of the facet multipliers), the multipliers, the discrete gap and the
contact, stick and slip sets (:func:`friction_diagnostics`). Post-processing, the plots,
the sweeps and the verification read this one object; :func:`pressure_field` is the same
pressure as a field on the boundary, for the integrals of the pressure goal and of the
verification.

Sign conventions (Theorem 3.10): u is the displacement, lambda_n = g - u_n (so lambda_n -
g = -u_n and lambda_n = 0 where the gap is closed) and lambda_t = -u_t on Gamma_C; p_h =
-sigma_n is positive in compression, q_h is along t = (n_2, -n_1) of (3.24).
"""

from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np

from .checks import friction_forms_of
from .checks import in_contact as _in_contact
from .friction import hat_projection
from .quantities import fields
from .scene import SceneError, SceneTypeError
from .solution import Solution

# the sampled traces are evaluated these shares of |e| inside the triangle of their edge,
# along the edge and across it: NGSolve's point search accepts points within about 1e-8 of
# an element, so a point closer to a vertex may be found in the neighbouring triangle
INSIDE = (1e-4, 1e-6)


@dataclass
class ContactTraces:
    """Traces on Gamma_C, chain by chain concatenated, ordered along the boundary.

    Edge quantities (sigma_n, sigma_t: constant per fine edge for RT_0) are given
    at edge midpoints ``edge_xy``; nodal ones at the fine vertices ``node_xy``.
    ``coarse_*``, ``pressure`` and ``shear`` refer to the h~ nodes with a dof. ``gap`` is
    the gap the discrete problem sees (g_h = I_h~ g by default, ``contact.discrete_gap``),
    so that ``gap - lam_n`` is the discrete normal displacement u_n^h.

    ``pressure`` p_h and ``shear`` q_h are what the discrete contact conditions of (3.62)
    control: the moments d_C(mu_i, sigma) = int sigma_{n,t} mu_i ds over the h~ hats mu_i,
    divided by int mu_i ds (:func:`ngdual.friction.hat_projection`), with p_h = -sigma_n
    positive in compression and q_h along t = (n_2, -n_1) of (3.24). The fine-edge
    sigma_n, sigma_t also carry modes orthogonal to every hat, which nothing in (3.62)
    controls. (3.62) makes p_h >= 0 at every node with a dof; ``end_pressure`` and
    ``end_shear`` are the same projections onto the hats of the fixed ends of Gamma_C
    (``end_xy``, where lambda is prescribed), which no contact condition constrains.
    ``coarse_status``: "separation", "contact" (without friction), "stick" or "slip"
    (:func:`friction_diagnostics`); ``friction``: the scene has a friction law.

    With the facet P_k multipliers (:mod:`ngdual.boundary.facet`, ``node_kind`` "control
    point") the "nodes" are the control points of every fine edge, the k + 1 unknowns of
    lambda_n on it (``coarse_lam_n`` their coefficients, zero where the edge touches there),
    and ``pressure``, ``shear`` the moments t_i = d_C(psi_i, sigma) of (3.62) against the
    basis functions psi_i over int psi_i ds: what the sign conditions of the facet family
    control. ``sigma_n``, ``sigma_t`` are the means of the P_k traces on the fine edges;
    ``trace_xy``, ``trace_sigma_n``, ``trace_sigma_t`` (n_edges, m) sample the traces
    themselves along every edge, end points included, at every order k >= 1 with either
    multiplier family and with the facet multipliers at k = 0 (None with the thesis' hats at
    k = 0, whose hat projections are the profile).
    ``edge_active``: the edges with an unknown in contact.
    """

    edge_xy: np.ndarray
    edge_length: np.ndarray
    sigma_n: np.ndarray
    sigma_t: np.ndarray
    edge_active: np.ndarray
    node_xy: np.ndarray
    lam_n: np.ndarray
    lam_t: np.ndarray
    gap: np.ndarray
    coarse_xy: np.ndarray
    coarse_lam_n: np.ndarray
    coarse_lam_t: np.ndarray
    coarse_in_contact: np.ndarray
    pressure: np.ndarray
    shear: np.ndarray
    end_xy: np.ndarray
    end_pressure: np.ndarray
    end_shear: np.ndarray
    coarse_status: np.ndarray
    friction: bool
    node_kind: str = "h~ node"
    trace_xy: np.ndarray | None = None
    trace_sigma_n: np.ndarray | None = None
    trace_sigma_t: np.ndarray | None = None


def contact_traces(solution: Solution) -> ContactTraces:
    """sigma_n, sigma_t, lambda_n - g, lambda_t, p_h and q_h along Gamma_C (see
    :class:`ContactTraces`), computed once per solution and kept on it."""
    if isinstance(solution, Solution) and solution.trace is not None:
        return solution.trace
    if not isinstance(solution, Solution):
        raise SceneTypeError("solution", "must be an ngdual Solution (see nd.solve), got "
                                         f"{type(solution).__name__}")
    pb = solution.problem
    contact = pb.spaces.contact
    if contact is None:
        raise SceneError("solution", f"scene {pb.scene.name!r} has no contact boundary "
                                     "(boundary.contact is empty): no traces on Gamma_C")
    lam_n_c, lam_t_c = solution.part("lam_n"), solution.part("lam_t")
    in_contact = _in_contact(lam_n_c, lam_t_c)
    # fine nodal values of the coarse P1 multipliers, with the prescribed end values
    fine = pb.to_fine(solution.x)
    rng_n = pb.fes.Range(pb.names.index("lam_n"))
    rng_t = pb.fes.Range(pb.names.index("lam_t"))
    fine_n, fine_t = fine[rng_n.start:rng_n.stop], fine[rng_t.start:rng_t.stop]
    gamma_c = pb.spaces.gamma_c

    active, offset = [], 0
    for c, chain in enumerate(contact.chains):
        interior = contact.dof_positions(c)
        flags = in_contact[offset:offset + len(interior)]
        contact_pos = {int(q) for q, flag in zip(interior, flags) if flag}
        offset += len(interior)
        nodes = contact.nodes[c]
        for k in range(chain.n_edges):
            e = np.searchsorted(nodes, k, side="right") - 1
            active.append(int(nodes[e]) in contact_pos or int(nodes[e + 1]) in contact_pos)
    # sigma_n, sigma_t on every fine edge (constant for RT_0): the solver's fine-edge operators
    forms = friction_forms_of(solution)
    s_n, s_t = forms.T_n @ solution.x, forms.T_t @ solution.x
    node_xy = np.vstack([chain.path_points for chain in contact.chains])
    coarse_xy = contact.node_points()
    projected = []
    for hats in (pb.spaces.prolongations["lam_n"], pb.spaces.end_hats["lam_n"]):
        means = gamma_c.hat_means(hats)
        projected += [-hat_projection(means, gamma_c.lengths, s_n) if means.shape[1]
                      else np.zeros(0),
                      hat_projection(means, gamma_c.lengths, s_t) if means.shape[1]
                      else np.zeros(0)]
    # the traces are polynomials of degree k on every fine edge, sampled wherever they are
    # what the contact conditions control or resolve: at order k >= 1 with either family, and
    # with the facet multipliers (the trace space of RT_k) at every k; the thesis' hats at
    # k = 0 control the hat projections instead
    sampled = pb.spaces.order > 0 or contact.traces
    facet = (dict(zip(("trace_xy", "trace_sigma_n", "trace_sigma_t"), _trace_samples(solution)))
             if sampled else {})
    if contact.traces:
        projected[:2] = _facet_moments(solution)
        active = in_contact.reshape(-1, contact.order + 1).any(axis=1)
        facet["node_kind"] = "control point"
    if solution.nu is not None:
        status = friction_diagnostics(solution).node_status
    else:
        status = np.where(in_contact, "contact", "separation")
    traces = ContactTraces(gamma_c.midpoints, gamma_c.lengths, s_n, s_t,
                           np.array(active, dtype=bool), node_xy,
                           gamma_c.vertex_values(fine_n), gamma_c.vertex_values(fine_t),
                           gamma_c.discrete_gap_at_vertices(pb.spaces.prolongations["lam_n"],
                                                            pb.spaces.end_hats["lam_n"]),
                           coarse_xy, lam_n_c, lam_t_c,
                           in_contact, projected[0], projected[1], contact.end_points(),
                           projected[2], projected[3], status, solution.nu is not None,
                           **facet)
    solution.trace = traces
    return traces


def pressure_field(solution: Solution) -> ngs.CoefficientFunction:
    """p_h = -sigma_n^h = -n . sigma_h n on the boundary, as a CoefficientFunction to
    integrate along Gamma_C: the normal traces of RT_k, P_k on every fine edge (with the
    facet multipliers exactly what the contact conditions control). The node values of p_h
    are :attr:`ContactTraces.pressure`."""
    n = ngs.specialcf.normal(2)
    return -(ngs.BoundaryFromVolumeCF(fields(solution).sigma) * n) * n


def _facet_moments(solution: Solution) -> list[np.ndarray]:
    """[p_h, q_h] at the control points of the facet multipliers: -t_n,i / m_i and
    t_t,i / m_i with the moments t_i = d_C(psi_i, sigma) of (3.62), read off the assembled
    coupling (exact: the traces of RT_k are P_k on every edge), and m_i = int psi_i ds."""
    pb = solution.problem
    gamma_c, sigma = pb.spaces.gamma_c, solution.x[pb.sigma]
    mass = gamma_c.hat_means(pb.spaces.prolongations["lam_n"]).T @ gamma_c.lengths
    return [-(pb.block(pb.lam_n, pb.sigma) @ sigma) / mass,
            (pb.block(pb.index("lam_t"), pb.sigma) @ sigma) / mass]


def _trace_samples(solution: Solution) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(points (n_edges, m, 2), sigma_n, sigma_t (n_edges, m)): the traces of sigma_h at
    4k + 2 points along every fine edge of Gamma_C, end points included."""
    pb = solution.problem
    gamma_c, k = pb.spaces.gamma_c, pb.spaces.order
    t = np.linspace(0.0, 1.0, 4 * k + 2)
    starts = np.vstack([chain.path_points[:-1] for chain in pb.spaces.contact.chains])
    stops = np.vstack([chain.path_points[1:] for chain in pb.spaces.contact.chains])
    points = starts[:, None, :] + t[None, :, None] * (stops - starts)[:, None, :]
    # evaluated in the one triangle of every edge, away from the vertices, which the
    # neighbouring triangles share (INSIDE)
    shrunk = 0.5 + (1.0 - INSIDE[0]) * (t - 0.5)
    inside = starts[:, None, :] + shrunk[None, :, None] * (stops - starts)[:, None, :] \
        - (INSIDE[1] * gamma_c.lengths)[:, None, None] * gamma_c.normals[:, None, :]
    mesh = pb.fes.mesh
    flat = inside.reshape(-1, 2)
    sigma = np.asarray(fields(solution).sigma(mesh(flat[:, 0], flat[:, 1])))
    traction = np.einsum("eqij,ej->eqi", sigma.reshape(*points.shape[:2], 2, 2),
                         gamma_c.normals)
    return (points, np.einsum("eqi,ei->eq", traction, gamma_c.normals),
            np.einsum("eqi,ei->eq", traction, gamma_c.tangents))


@dataclass
class FrictionDiagnostics:
    """Contact / separation and stick / slip on Gamma_C, as arrays for tables and plots.

    Per h~ node (interior, ``node_xy``): lambda_n, lambda_t, the hat moments
    ``t_n`` = int sigma_n mu_i and ``t_t`` = int sigma_t mu_i, their ratio
    ``traction_ratio`` = |t_t| / |t_n| (the hat-weighted |sigma_t| / |sigma_n|) and
    ``node_status``: "separation" (lambda_n > 0), "stick" (every h^ edge under the
    hat has |nu| < 1) or "slip" (also where no friction acts under the hat). The
    discrete problem bounds |t_t| by int F mu_i (``sigma_t_bound``), not by mu_f |t_n|:
    F is the h^-mean of mu_f |sigma_n|, so at the last node of the contact zone, where
    |sigma_n| drops to zero within one h~ edge, the ratio can exceed mu_f (about 3 mu_f
    for Example 3.46); inside the zone it stays below mu_f.
    Per h^ edge (``edge_xy`` midpoints): nu, ``sign_lam_t`` = sign(Q_F lambda_t),
    ``F`` (mean over the edge) and ``edge_status``: "free" (F = 0), "stick"
    (|nu| < 1) or "slip" (|nu| = 1, nu = sign lambda_t).
    """

    node_xy: np.ndarray
    lam_n: np.ndarray
    lam_t: np.ndarray
    t_n: np.ndarray
    t_t: np.ndarray
    traction_ratio: np.ndarray
    node_status: np.ndarray
    edge_xy: np.ndarray
    nu: np.ndarray
    sign_lam_t: np.ndarray
    F: np.ndarray
    edge_status: np.ndarray


def friction_diagnostics(solution: Solution, slip_tol: float = 1e-6) -> FrictionDiagnostics:
    """Stick / slip / separation of a frictional ``solution`` (see :class:`FrictionDiagnostics`)."""
    from .friction import build_friction_forms

    pb = solution.problem
    # the solver's own forms; a solution assembled elsewhere builds them once here
    forms = solution.friction_forms or build_friction_forms(pb)
    sigma = solution.x[pb.sigma]
    t_n = pb.block(pb.sigma, pb.lam_n).T @ sigma
    t_t = pb.block(pb.sigma, pb.index("lam_t")).T @ sigma
    lam_n, lam_t = solution.part("lam_n"), solution.part("lam_t")
    F_hat = forms.per_hat_edge(solution.friction_bound)
    Q = forms.q_matrix(solution.friction_bound)
    nu = solution.nu
    edge_status = np.where(F_hat <= 0, "free", np.where(np.abs(nu) >= 1 - slip_tol, "slip",
                                                         "stick"))
    under_hat = (Q.T.tocsr() != 0).astype(float)
    slips = under_hat @ (edge_status == "slip")
    held = under_hat @ np.ones(forms.n_nu)  # no F under the hat: the node slides freely
    node_status = np.where(_in_contact(lam_n, lam_t),
                           np.where((slips > 0) | (held == 0), "slip", "stick"), "separation")
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(t_n != 0, np.abs(t_t) / np.abs(t_n), np.inf)
    hat_mid = np.array([forms.midpoints[forms.edge_of == j].mean(axis=0)
                        for j in range(forms.n_nu)])
    return FrictionDiagnostics(pb.spaces.contact.node_points(), lam_n, lam_t, t_n, t_t, ratio,
                               node_status, hat_mid, nu, np.sign(Q @ lam_t), F_hat, edge_status)
