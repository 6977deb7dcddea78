"""Post-processing: contact counts, force balance, records, VTK output.

The fields of a solution and their norms (Tables 3.2/3.3) are in :mod:`ngdual.quantities`,
its traces on Gamma_C (p_h, q_h, the contact, stick and slip sets) in :mod:`ngdual.trace`.

Sign conventions (Theorem 3.10): u is the displacement, phi = -u on Gamma_N,
lambda_n = g - u_n (so lambda_n - g = -u_n and lambda_n = 0 where the gap is
closed) and lambda_t = -u_t on Gamma_C.
"""

from __future__ import annotations

from dataclasses import asdict

import ngsolve as ngs
import numpy as np

from .checks import ForceBalance, contact_forces
from .geometry import tangent
from .io import versions
from .quantities import fields, norms, require_contact
from .solution import Solution
from .trace import contact_traces, friction_diagnostics


def von_mises(sigma, nu: float) -> ngs.CoefficientFunction:
    """Plane-strain von Mises stress (Section 3.4, below Fig. 3.11), sigma_12 symmetrised."""
    s11, s22, s12 = sigma[0, 0], sigma[1, 1], 0.5 * (sigma[0, 1] + sigma[1, 0])
    return ngs.sqrt((nu**2 - nu + 1) * (s11**2 + s22**2) + (2 * nu**2 - 2 * nu - 1) * s11 * s22
                    + 3 * s12**2)


def element_values(mesh: ngs.Mesh, cf) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertex coordinates, triangles and the value of ``cf`` at every centroid (for plots)."""
    from .mesh import mesh_arrays

    points, triangles = mesh_arrays(mesh)
    centroids = points[triangles].mean(axis=1)
    mips = mesh(centroids[:, 0], centroids[:, 1])
    return points, triangles, np.asarray(cf(mips)).ravel()


def contact_summary(solution: Solution) -> dict:
    """Nodes in contact (lambda_n = 0 on the h~ mesh), stick/slip among them, and F_abs.

    F_abs = int_{A_C} |sigma_n| + |sigma_t| ds over the active part A_C: the
    h~ edges with a node in contact. Stick / slip as in :func:`friction_diagnostics`
    (all contact nodes count as slip without friction); with friction also the
    largest hat-weighted ratio |sigma_t| / |sigma_n| over the contact nodes.
    ``resultant``, ``multiplier_force``, ``force_mismatch`` and ``tension`` are those of
    :func:`force_balance` (the last two relative to its force scale).
    """
    if solution.problem.spaces.contact is None:
        return {"nodes_in_contact": 0, "stick_nodes": 0, "slip_nodes": 0, "F_abs": 0.0}
    tr = contact_traces(solution)
    f_abs = np.sum(tr.edge_length * (np.abs(tr.sigma_n) + np.abs(tr.sigma_t)) * tr.edge_active)
    summary = {"nodes_in_contact": int(tr.coarse_in_contact.sum()), "stick_nodes": 0,
               "slip_nodes": int(tr.coarse_in_contact.sum()), "F_abs": float(f_abs)}
    balance = force_balance(solution)
    summary.update(resultant=[float(v) for v in balance.resultant],
                   multiplier_force=[float(v) for v in balance.multiplier_force],
                   force_mismatch=balance.mismatch, tension=balance.tension)
    if solution.nu is not None:
        diag = friction_diagnostics(solution)
        summary.update(stick_nodes=int(np.sum(diag.node_status == "stick")),
                       slip_nodes=int(np.sum(diag.node_status == "slip")),
                       stick_edges=int(np.sum(diag.edge_status == "stick")),
                       slip_edges=int(np.sum(diag.edge_status == "slip")),
                       max_traction_ratio=float(np.max(diag.traction_ratio[
                           diag.node_status != "separation"], initial=0.0)))
    return summary


def force_balance(solution: Solution) -> ForceBalance:
    """The forces on Gamma_C of a contact solution: the resultant of sigma n against the
    multiplier force, their mismatch and the tension in the h~ hat moments, relative to
    a force scale that does not vanish when nothing touches
    (:class:`ngdual.checks.ForceBalance`)."""
    solution = require_contact(solution, "force balance")
    return contact_forces(solution)


def result_record(solution: Solution) -> dict:
    """The result record of ``ngdual solve`` (``result.json``, plain JSON-serialisable data):
    scene, level, method, DOFs, the norms of Tables 3.2/3.3, the contact summary, iterations,
    residuals, timings and versions; ``warnings`` lists the failed physics checks (code,
    message, value, tolerance; :mod:`ngdual.checks`); ``accuracy`` the method, estimate,
    solves and time of a solve to a tolerance (:mod:`ngdual.accuracy`)."""
    pb = solution.problem
    t = solution.timings
    # four phases, assemble, factorize, solve and total: the Gamma_C condensation is part of
    # the contact solve
    timings = {"assemble": float(t.get("assemble", 0.0)),
               "factorize": float(t.get("factorize", 0.0)),
               "solve": float(t.get("solve", 0.0) + t.get("condense", 0.0)),
               "total": float(t.get("total", 0.0))}
    record = {
        "scene": pb.scene.name,
        "level": pb.level,
        "converged": bool(solution.converged),
        "method": solution.method,
        "dofs": pb.spaces.dofs(),
        "norms": norms(solution),
        "contact": contact_summary(solution),
        "iterations": {k: int(v) for k, v in solution.iterations.items()},
        "residuals": {k: float(v) for k, v in solution.residuals.items()},
        "warnings": [asdict(w) for w in solution.warnings],
        "timings_s": timings,
        "parameters": pb.scene.to_dict(),
        "versions": versions(),
    }
    if solution.accuracy is not None:  # a solve to a tolerance: how it was reached
        record["accuracy"] = dict(solution.accuracy)
    return record


def write_vtk(solution: Solution, filename: str) -> list[str]:
    """Write the solution for ParaView; returns the files written.

    ``filename.vtu``: sigma (components), the displacement ``u`` as a 3-vector (z = 0, so
    that Warp By Vector applies it), the rotation eta and the von Mises stress. With a
    contact boundary also ``filename_contact.vtu``: Gamma_C as line cells, at its fine
    vertices the multiplier ``lambda`` = lambda_n n + lambda_t t as a 3-vector, its
    components, the gap g, the normal n and the boundary displacement ``u`` = (g -
    lambda_n) n - lambda_t t (Theorem 3.10: lambda_n = g - u_n, lambda_t = -u_t); per
    fine edge sigma_n, sigma_t and the traction sigma n = sigma_n n + sigma_t t.
    """
    f = fields(solution)
    pb = solution.problem
    nu = pb.scene.material.nu
    out = ngs.VTKOutput(pb.fes.mesh,
                        coefs=[f.sigma[0, 0], f.sigma[0, 1], f.sigma[1, 0], f.sigma[1, 1],
                               ngs.CoefficientFunction((f.u[0], f.u[1], 0)), f.eta,
                               von_mises(f.sigma, nu)],
                        names=["sigma_11", "sigma_12", "sigma_21", "sigma_22", "u", "eta",
                               "von_mises"],
                        filename=str(filename), subdivision=0)
    out.Do()
    written = [str(filename) + ".vtu"]
    if pb.spaces.contact is not None:
        written.append(_write_contact_vtu(solution, str(filename) + "_contact.vtu"))
    return written


def _write_contact_vtu(solution: Solution, path: str) -> str:
    """Gamma_C with the contact multipliers and tractions as VTK vectors (ASCII XML)."""
    import os

    tr = contact_traces(solution)
    gamma_c = solution.problem.spaces.gamma_c
    n_node = gamma_c.vertex_normals()
    t_node = tangent(n_node)
    lam = tr.lam_n[:, None] * n_node + tr.lam_t[:, None] * t_node
    u = (tr.gap - tr.lam_n)[:, None] * n_node - tr.lam_t[:, None] * t_node
    traction = tr.sigma_n[:, None] * gamma_c.normals + tr.sigma_t[:, None] * gamma_c.tangents
    lines, first = [], 0
    for chain in solution.problem.spaces.contact.chains:
        lines += [(first + k, first + k + 1) for k in range(chain.n_edges)]
        first += chain.n_edges + 1

    def array(name, values):
        values = np.asarray(values, float)
        values = values.reshape(len(values), -1)
        if values.shape[1] == 2:  # ParaView's vector filters want three components
            values = np.column_stack([values, np.zeros(len(values))])
        body = " ".join(f"{v:.17g}" for v in values.ravel())
        return (f'<DataArray type="Float64" Name="{name}" NumberOfComponents='
                f'"{values.shape[1]}" format="ascii">{body}</DataArray>')

    points = array("Points", tr.node_xy)
    node_data = [array("lambda", lam), array("lambda_n", tr.lam_n), array("lambda_t", tr.lam_t),
                 array("gap", tr.gap), array("normal", n_node), array("u", u)]
    edge_data = [array("sigma_n", tr.sigma_n), array("sigma_t", tr.sigma_t),
                 array("traction", traction)]
    connectivity = " ".join(f"{a} {b}" for a, b in lines)
    offsets = " ".join(str(2 * (k + 1)) for k in range(len(lines)))
    text = "\n".join([
        '<?xml version="1.0"?>',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">',
        "<UnstructuredGrid>",
        f'<Piece NumberOfPoints="{len(tr.node_xy)}" NumberOfCells="{len(lines)}">',
        "<Points>", points, "</Points>",
        "<Cells>",
        f'<DataArray type="Int64" Name="connectivity" format="ascii">{connectivity}</DataArray>',
        f'<DataArray type="Int64" Name="offsets" format="ascii">{offsets}</DataArray>',
        f'<DataArray type="UInt8" Name="types" format="ascii">{" ".join(["3"] * len(lines))}'
        "</DataArray>",
        "</Cells>",
        '<PointData Vectors="lambda">', *node_data, "</PointData>",
        '<CellData Vectors="traction">', *edge_data, "</CellData>",
        "</Piece>", "</UnstructuredGrid>", "</VTKFile>", ""])
    tmp = path + ".part"
    with open(tmp, "w") as handle:
        handle.write(text)
    os.replace(tmp, path)
    return path


