"""The fields of a discrete solution and their norms (Tables 3.2/3.3).

NGSolve views of every unknown on the fine mesh (:func:`fields`) and the norms that the
thesis tabulates (:func:`norms`): what the estimator, the adaptive loop and the
post-processing read from a :class:`ngdual.solution.Solution`; :func:`l2_norm` of any field,
for an error against an exact solution. The rotation is
``eta`` (the thesis' eta in Tables 3.2/3.3); the estimator (4.50) is never called eta in a
record (:mod:`ngdual.afem`).
"""

from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np

from . import peers
from .scene import SceneError, SceneTypeError
from .solution import Solution


def require_solution(value, name: str = "solution") -> Solution:
    """``value`` if it is a :class:`~ngdual.solution.Solution`; a SceneTypeError
    naming the argument ``name`` otherwise (the check of every function of the public API
    that reads a solution)."""
    if not isinstance(value, Solution):
        raise SceneTypeError(name, f"must be an ngdual Solution (see nd.solve), got "
                                   f"{type(value).__name__}")
    return value


def require_contact(value, what: str, name: str = "solution") -> Solution:
    """:func:`require_solution`, and a SceneError naming ``name`` if its scene has no
    contact boundary: there is no ``what`` on Gamma_C (e.g. ``"force balance"``)."""
    solution = require_solution(value, name)
    scene = solution.problem.scene
    if not scene.has_contact:
        raise SceneError(name, f"scene {scene.name!r} has no contact boundary "
                               f"(boundary.contact is empty): no {what} on Gamma_C")
    return solution


@dataclass
class Fields:
    """NGSolve views of a solution on the fine mesh."""

    gf: ngs.GridFunction
    sigma: ngs.CoefficientFunction
    div_sigma: ngs.CoefficientFunction
    u: ngs.CoefficientFunction
    eta: ngs.CoefficientFunction
    phi: ngs.CoefficientFunction | None
    lam_t: ngs.CoefficientFunction | None
    lam_n: ngs.CoefficientFunction | None


def fields(solution: Solution) -> Fields:
    """Fine-mesh GridFunction and coefficient functions of every unknown."""
    pb = require_solution(solution).problem
    gf = ngs.GridFunction(pb.fes)
    gf.vec.FV().NumPy()[:] = pb.to_fine(solution.x)
    c = dict(zip(pb.names, gf.components))
    sigma = peers.stress(c["r1"], c["r2"], c["b1"], c["b2"])
    div_sigma = peers.stress_divergence(c["r1"], c["r2"])
    phi = ngs.CF((c["phi1"], c["phi2"])) if "phi1" in c else None
    return Fields(gf, sigma, div_sigma, ngs.CF((c["u1"], c["u2"])), c["eta"], phi,
                  c.get("lam_t"), c.get("lam_n"))


def _boundary_integral(cf, mesh: ngs.Mesh, labels: list[str]) -> float:
    return float(ngs.Integrate(cf, mesh, ngs.BND, definedon=mesh.Boundaries("|".join(labels))))


def l2_norm(value, mesh: ngs.Mesh, order: int = 10) -> float:
    """||value||_{L^2(Omega)} = (int_Omega value : value dx)^(1/2) on ``mesh``.

    Parameters
    ----------
    value : ngsolve.CoefficientFunction
        A scalar, vector or matrix field: a field of :func:`fields`, an exact solution
        (:func:`ngdual.expr.coefficient`) or their difference, the error.
    mesh : ngsolve.Mesh
        The mesh of the fields, e.g. ``solution.problem.fes.mesh``.
    order : int
        The degree of polynomials the quadrature integrates exactly on every triangle.

    Examples
    --------
    >>> import ngdual as nd
    >>> mesh = nd.build_mesh(nd.load_scene("thesis-3.46-frictionless").geometry, 1)
    >>> round(nd.l2_norm(nd.coefficient(["1", "0"]), mesh) ** 2, 10)  # the area 8 x 2
    16.0
    """
    return float(np.sqrt(ngs.Integrate(ngs.InnerProduct(value, value), mesh, order=order)))


def norms(solution: Solution) -> dict:
    """Norms of Tables 3.2/3.3: ||sigma|| in H(div), the others in L^2."""
    f = fields(require_solution(solution))
    pb = solution.problem
    mesh, scene = pb.fes.mesh, pb.scene
    # |sigma|^2 has degree 2 * stress_degree; NGSolve's default rule (degree 5) is exact up to
    # k = 0 and is kept there, so the norms of Tables 3.2/3.3 are those of the thesis runs
    degree = max(5, 2 * peers.stress_degree("peers", pb.spaces.order))
    out = {
        "sigma_X": np.sqrt(ngs.Integrate(ngs.InnerProduct(f.sigma, f.sigma)
                                         + f.div_sigma * f.div_sigma, mesh, order=degree)),
        "u": np.sqrt(ngs.Integrate(f.u * f.u, mesh, order=degree)),
        "eta": np.sqrt(ngs.Integrate(f.eta * f.eta, mesh, order=degree)),
        "phi": np.sqrt(_boundary_integral(f.phi * f.phi, mesh, scene.labels("neumann")))
        if f.phi is not None else 0.0,
        "lam_t": 0.0, "lam_n": 0.0, "nu": solution.nu_l2,
    }
    if f.lam_n is not None:
        out["lam_t"] = np.sqrt(_boundary_integral(f.lam_t * f.lam_t, mesh,
                                                  scene.labels("contact")))
        out["lam_n"] = np.sqrt(_boundary_integral(f.lam_n * f.lam_n, mesh,
                                                  scene.labels("contact")))
    return {k: (float(v) if v is not None else None) for k, v in out.items()}
