"""The primal peer adapting as a primal user would: Kelly's indicator drives netgen's bisection.

deal.II's step-42 adapts its contact problem by Kelly's indicator, the jumps of the normal
derivative across faces; here the jumps of the normal stress sigma(u_h) n, weighted by h:

    eta_T^2 = sum_{E in T, interior} h_T / 2 ||[sigma(u_h) n]||_E^2
              + sum_{E in T, on the boundary but Gamma_D} h_T ||sigma(u_h) n - t_E||_E^2,

with t_E the applied traction on Gamma_N, the Nitsche traction -p_h n + lambda_t t on
Gamma_C (:class:`~.result.PrimalResult`) and 0 on a free side (:func:`kelly_indicators`).
:func:`adapt_primal` is the loop: SOLVE (:func:`~.scenes.primal_solution`), ESTIMATE,
MARK (Dörfler, :func:`ngdual.marking.mark`), REFINE (:func:`ngdual.afem.refine`, the
bisection the adaptive loop of ngdual refines with), from the same initial mesh and with the
same theta as a tolerance run of :func:`ngdual.adapt`.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import ngsolve as ngs
import numpy as np

from ...loop_defaults import LEVEL_TOL, STEPS_TOL, THETA_TOL
from .nitsche import _vector
from .result import PrimalResult
from .scenes import primal_arguments, primal_solution, taylor_hood


def boundary_tractions(scene, mesh: ngs.Mesh, result: PrimalResult) -> dict[str, ngs.CF]:
    """The traction sigma n should equal on every boundary label but Gamma_D's: the scene's
    traction on Gamma_N, the Nitsche traction -p_h n + lambda_t t on Gamma_C, 0 on a free
    side."""
    args = primal_arguments(scene)
    n = ngs.specialcf.normal(2)
    t = ngs.CF((n[1], -n[0]))
    out = {label: ngs.CF((0.0, 0.0)) for label in dict.fromkeys(mesh.GetBoundaries())
           if label not in args["dirichlet"]}
    out.update({label: _vector(args["traction"]) for label in args["neumann"]})
    out.update({label: -result.pressure_cf * n + result.traction_cf * t
                for label in args["contact"]})
    return out


def kelly_indicators(scene, result: PrimalResult) -> np.ndarray:
    """Kelly's indicator eta_T of the module docstring, one per triangle of the peer's mesh.

    The squared jumps are integrated edge by edge (a skeleton integral, both sides of an
    interior edge), spread evenly along each edge and integrated again over the boundary of
    every triangle, weighted by its h_T.
    """
    mesh = result.u.space.mesh
    n, h = ngs.specialcf.normal(2), ngs.specialcf.mesh_size
    sigma = result.sigma
    facets = ngs.FacetFESpace(mesh, order=0)
    w = facets.TestFunction()
    jump = (sigma - sigma.Other()) * n
    squared, length = ngs.LinearForm(facets), ngs.LinearForm(facets)
    squared += 0.5 * ngs.InnerProduct(jump, jump) * w * ngs.dx(skeleton=True)
    length += w * ngs.dx(skeleton=True)
    # a skeleton integral evaluates from the volume side, so one per boundary part
    for label, traction in boundary_tractions(scene, mesh, result).items():
        residual = sigma * n - traction
        squared += ngs.InnerProduct(residual, residual) * w * ngs.ds(
            skeleton=True, definedon=mesh.Boundaries(label))
    length += w * ngs.ds(skeleton=True)
    squared.Assemble()
    length.Assemble()
    mean = ngs.GridFunction(facets)
    mean.vec.FV().NumPy()[:] = squared.vec.FV().NumPy() / length.vec.FV().NumPy()
    cells = ngs.L2(mesh, order=0)
    eta2 = ngs.LinearForm(cells)
    eta2 += h * mean * cells.TestFunction() * ngs.dx(element_boundary=True)
    eta2.Assemble()
    return np.sqrt(np.maximum(eta2.vec.FV().NumPy(), 0.0))


StepCallback = Callable[[dict, PrimalResult], None]


def adapt_primal(scene, order: int, theta: float = THETA_TOL, level: int = LEVEL_TOL,
                 steps: int = STEPS_TOL, on_step: StepCallback | None = None,
                 **settings) -> list[dict]:
    """Adapt the primal peer of degree ``order`` on ``scene``: SOLVE, ESTIMATE (Kelly),
    MARK (Dörfler ``theta``), REFINE, ``steps`` solves from the mesh of ``level``.

    Parameters
    ----------
    scene : ngdual.Scene
        As for :func:`~.scenes.primal_solution` (consistent ends of Gamma_C).
    order : int
        The degree of the displacements; the Taylor-Hood form where
        :func:`~.scenes.taylor_hood` asks for it.
    theta, level, steps : float, int, int
        Dörfler's parameter, the initial level and the number of solves: those of a
        tolerance run of :func:`ngdual.adapt` by default.
    on_step : callable, optional
        ``on_step(record, result)`` after ESTIMATE; an exception it raises ends the run (and
        reaches the caller). Its time is not the loop's.
    **settings
        Nitsche's parameters and Newton's tolerance (:func:`~.nitsche.solve_primal`).

    Returns
    -------
    list of dict
        Per step ``step``, ``ndof``, ``elements``, ``newton_iterations``, ``estimate``
        ((sum_T eta_T^2)^(1/2)) and ``solved_s``, the wall time from the start to the step's
        solution (every step before in full, this one's SOLVE), as :func:`ngdual.adapt`
        records it.
    """
    from ...afem import refine
    from ...marking import mark
    from ...mesh import build_mesh

    start = time.perf_counter()
    paused = 0.0
    mixed = taylor_hood(scene, order)
    mesh = build_mesh(scene.geometry, level)
    history = []
    for step in range(steps):
        # SOLVE
        result = primal_solution(scene, order=order, mesh=mesh, mixed=mixed, **settings)
        solved = time.perf_counter() - start - paused
        # ESTIMATE
        eta = kelly_indicators(scene, result)
        record = {"step": step, "ndof": int(result.ndof), "elements": mesh.ne,
                  "newton_iterations": result.newton_iterations,
                  "estimate": float(np.sqrt(np.sum(eta**2))), "solved_s": solved}
        history.append(record)
        if on_step is not None:
            before = time.perf_counter()
            try:
                on_step(record, result)
            finally:
                paused += time.perf_counter() - before
        if step == steps - 1:
            break
        # MARK
        marked = mark(eta, theta, "dorfler")
        # REFINE
        mesh = refine(mesh, marked)
    return history
