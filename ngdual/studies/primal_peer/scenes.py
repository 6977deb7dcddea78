"""The primal peer on an ngdual scene: the same mesh, material, loads, gap and friction law."""

from __future__ import annotations

import time
from functools import partial

import numpy as np

from .nitsche import solve_primal
from .result import PrimalResult

# from this Poisson ratio on (lam / mu >= 9) the P2 (and higher) peer solves the Taylor-Hood
# displacement-pressure form: the displacement form's contact pressure degrades with lam / mu
# (hertz-cylinder P2 level 3: 3.6 % at nu = 0.3, 5.2 % at nu = 0.4999) and with friction
# and shear does not converge at all (cattaneo-mindlin, nu = 0.4999, see solve_primal)
NEARLY_INCOMPRESSIBLE = 0.45


def _scene_gap(contact):
    """The scene's gap for :func:`~.nitsche.solve_primal`: its formula, or the distance to
    the foundation line along the outward normal of Gamma_C as a function of the point and
    the normal (:func:`ngdual.scene.contact.foundation_gap`, the gap ngdual's own forms use),
    so that on a curved or kinked Gamma_C every edge sees the gap along its own normal."""
    from ...scene.contact import foundation_gap

    if contact.foundation is None:
        return contact.gap_formula
    return partial(foundation_gap, contact)


def primal_arguments(scene) -> dict:
    """The scene as the keyword arguments of :func:`~.nitsche.solve_primal` (all but the
    mesh and the order): material, boundary labels, loads, gap and friction law. Tresca
    bounds and free ends are the scene's; "thesis" end values of Gamma_C (lambda = 0 at a
    clamped end) have no primal counterpart and are refused."""
    if scene.has_contact and scene.contact.ends == "thesis":
        raise ValueError("the peer solves the consistent problem: set contact.ends = "
                         "\"consistent\" (the thesis' end values contradict u = u_D)")
    law = scene.friction.law
    return dict(
        E=scene.material.E, nu=scene.material.nu, dirichlet=scene.labels("dirichlet"),
        neumann=scene.labels("neumann"), contact=scene.labels("contact"),
        body_force=scene.loads.body_force, traction=scene.loads.traction,
        displacement=scene.loads.displacement, gap=_scene_gap(scene.contact), law=law,
        mu_f=scene.friction.mu if law == "coulomb" else 0.0,
        tresca_bound=scene.friction.bound if law == "tresca" else None)


def primal_solution(scene, level: int | None = None, order: int = 1, *, mesh=None,
                    mixed: bool = False, **settings) -> PrimalResult:
    """Solve ``scene`` by the primal method: P``order`` Lagrange displacements, Nitsche contact.

    The standard displacement method, the one PEERS is compared with: find u_h in
    P_order with u_h = u_D on Gamma_D and

        int_Omega 2 mu eps(u_h) : eps(v) + lambda div u_h div v dx + (Nitsche terms on Gamma_C)
            = int_Omega f . v dx + int_Gamma_N t_0 . v ds

    for all v vanishing on Gamma_D, with sigma_h = 2 mu eps(u_h) + lambda div u_h I
    (:func:`~.nitsche.solve_primal`, which states the Nitsche terms; without Gamma_C the
    problem is linear elasticity). The scene's material, loads, gap and friction law are
    used as they are (:func:`primal_arguments`).

    Parameters
    ----------
    scene : ngdual.Scene
        A valid scene; its ``contact.ends`` must be "consistent" if it has a Gamma_C.
    level : int, optional
        The mesh level (default: the scene's level); ignored when ``mesh`` is given.
    order : int
        The polynomial degree of the displacement, 1 to 4.
    mesh : ngsolve.Mesh, optional
        Solve on this mesh, e.g. the one of a PEERS solution to compare with.
    mixed : bool
        The Taylor-Hood displacement-pressure form (order >= 2), which does not lock.
    **settings
        The Nitsche parameters and Newton's tolerance of :func:`~.nitsche.solve_primal`
        (``gamma0``, ``theta``, ``tol``, ``max_newton``).

    Returns
    -------
    PrimalResult
        ``u`` the displacement (an NGSolve GridFunction), ``sigma`` its stress, the contact
        forces and the pressure on Gamma_C.

    Examples
    --------
    >>> import ngdual as nd
    >>> scene = nd.load_scene("hertz-cylinder")
    >>> p1 = nd.solve_primal(scene, 2)                                  # doctest: +SKIP
    >>> p1.contact_force                                                # doctest: +SKIP
    """
    from ...mesh import build_mesh

    mesh = build_mesh(scene.geometry, level) if mesh is None else mesh
    return solve_primal(mesh, **primal_arguments(scene), order=order, mixed=mixed, **settings)


def taylor_hood(scene, order: int) -> bool:
    """Whether the peer of degree ``order`` solves ``scene`` in the Taylor-Hood form
    (P``order`` - P``order-1``): for order >= 2 and nu >= :data:`NEARLY_INCOMPRESSIBLE`."""
    return order >= 2 and scene.material.nu >= NEARLY_INCOMPRESSIBLE


def solve_scene_primal(scene, level: int, order: int, **kw) -> tuple[PrimalResult, float]:
    """Solve an ngdual scene (its mesh on ``level``, :func:`primal_solution`) by the peer
    with P``order`` elements, in the Taylor-Hood form where :func:`taylor_hood` asks for it;
    returns the result and the wall time, meshing included."""
    start = time.perf_counter()
    result = primal_solution(scene, level, order, mixed=taylor_hood(scene, order), **kw)
    return result, time.perf_counter() - start


def primal_samples(scene, result: PrimalResult, subdivisions: int = 1) -> dict:
    """The peer's solution as sample arrays (:mod:`ngdual.verification.overkill`): sigma
    and u at the P2 nodes of every triangle (exact for P1 and P2), and the pressure at
    3-point Gauss points of every Gamma_C edge split into ``subdivisions`` equal parts in x
    (``p_x``; ``p_w`` the arc-length weights, ``p``), so that on a straight Gamma_C each
    part lies in one edge of a reference ``log2(subdivisions)`` levels finer (on an arc the
    refined vertices move onto the arc, a part may straddle a reference node and the
    quadrature of the reference's kink there is then accurate to O(h^2) instead of exact).
    Gamma_C must be a graph over x (:func:`ngdual.verification.overkill.graph_over_x`)."""
    from ...verification.overkill import edge_samples, element_samples

    mesh = result.u.space.mesh
    out = element_samples(mesh, {"sigma": result.sigma, "u": result.u})
    edges = result._edges
    xy, w = edge_samples(np.stack([edges.p0, edges.p1], axis=1), subdivisions)
    out.update(p_x=xy[:, 0], p_w=w, p=result.pressure(xy))
    return out
