"""The field arrays of a solve record: what Figs. 3.11-3.28 plot, as plain arrays."""

from __future__ import annotations

import numpy as np


def field_arrays(solution) -> dict[str, np.ndarray]:
    """Everything Figs. 3.11-3.28 plot, as plain arrays (no NGSolve objects).

    Element values at the centroids of the fine mesh (``points``, ``triangles``):
    ``von_mises`` (plane strain, Section 3.4), ``u1``, ``u2``, ``eta``. On
    Gamma_N at the fine vertices: ``phi_x``, ``phi1``, ``phi2``. On Gamma_C
    (:func:`ngdual.trace.contact_traces`): per fine edge ``edge_x``,
    ``sigma_n``, ``sigma_t``, ``edge_active``; per fine vertex ``node_x``,
    ``lam_n``, ``lam_t``, ``gap``; per h~ node ``coarse_x``, ``in_contact`` and the
    pressure and shear traction the contact conditions see, ``hat_x`` (coordinate along the
    foundation), ``hat_pressure``, ``hat_shear``
    (:func:`ngdual.verification.traction.traction_profile`).
    With friction (:func:`ngdual.trace.friction_diagnostics`): per h~ node
    ``hat_ratio`` (|int sigma_t mu_i| / |int sigma_n mu_i|), ``bound_ratio``
    (|int sigma_t mu_i| / int F mu_i, at most 1 by (3.62): the discrete Coulomb
    condition) and ``node_status`` (0 separation, 1 stick, 2 slip); per h^ edge
    ``nu``, ``nu_start``, ``nu_end`` (x-interval), ``F`` and ``nu_status``
    (0 free, 1 stick, 2 slip).
    """
    import ngsolve as ngs

    from ... import post, quantities, trace

    pb = solution.problem
    mesh = pb.fes.mesh
    f = quantities.fields(solution)
    out = {}
    cfs = {"von_mises": post.von_mises(f.sigma, pb.scene.material.nu), "u1": f.u[0],
           "u2": f.u[1], "eta": f.eta}
    for name, cf in cfs.items():
        out["points"], out["triangles"], out[name] = post.element_values(mesh, cf)
    if f.phi is not None:
        xy = []
        for chain in pb.spaces.neumann.chains:
            xy.append(chain.path_points)
        xy = np.vstack(xy)
        xy = xy[np.argsort(xy[:, 0])]
        values = np.asarray(f.phi(mesh(xy[:, 0], xy[:, 1], VOL_or_BND=ngs.BND)))
        out.update(phi_x=xy[:, 0], phi1=values[:, 0], phi2=values[:, 1])
    if pb.spaces.contact is not None:
        tr = trace.contact_traces(solution)
        out.update(edge_x=tr.edge_xy[:, 0], edge_length=tr.edge_length, sigma_n=tr.sigma_n,
                   sigma_t=tr.sigma_t, edge_active=tr.edge_active, node_x=tr.node_xy[:, 0],
                   lam_n=tr.lam_n, lam_t=tr.lam_t, gap=tr.gap, coarse_x=tr.coarse_xy[:, 0],
                   in_contact=tr.coarse_in_contact)
        from ...verification.traction import traction_profile

        profile = traction_profile(solution)
        out.update(hat_x=profile.x, hat_pressure=profile.pressure, hat_shear=profile.shear)
    if solution.nu is not None:
        from ...friction import build_friction_forms

        diag = trace.friction_diagnostics(solution)
        forms = solution.friction_forms or build_friction_forms(pb)
        bound = forms.q_matrix(solution.friction_bound).T @ np.ones(len(solution.nu))
        out["bound_ratio"] = np.where(bound > 0, np.abs(diag.t_t) / np.where(bound > 0, bound,
                                                                            1.0), 0.0)
        codes = {"separation": 0, "free": 0, "stick": 1, "slip": 2}
        hat = pb.spaces.friction
        start = np.concatenate([ch.path_points[n[:-1], 0] for ch, n in zip(hat.chains,
                                                                            hat.nodes)])
        end = np.concatenate([ch.path_points[n[1:], 0] for ch, n in zip(hat.chains, hat.nodes)])
        out.update(hat_node_x=diag.node_xy[:, 0], hat_ratio=diag.traction_ratio,
                   node_status=np.array([codes[s] for s in diag.node_status]),
                   nu=diag.nu, nu_start=np.minimum(start, end), nu_end=np.maximum(start, end),
                   F=diag.F, nu_status=np.array([codes[s] for s in diag.edge_status]))
    return out
