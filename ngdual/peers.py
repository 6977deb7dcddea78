"""The PEERS triple (X_h, M_h, S_h) of (3.61) on NGSolve spaces, and its family of order k.

X_h: each stress row is a Raviart-Thomas field of order k plus the Curl of an element bubble
in b_T P_k (Arnold, Brezzi, Douglas 1984; Stenberg 1988), b_T the cubic bubble of the
triangle T. At k = 0 (the thesis) that is RT_0 plus the Curl of the cubic bubble.
M_h: discontinuous P_k displacement (two ``L2`` order k components).
S_h: continuous P_{k+1} rotation (``H1`` order k + 1).

NGSolve's ``HDiv(order=k)`` is BDM_k for k >= 1 (full P_k, (k+1)(k+2) shape functions per
triangle); ``RT=True`` adds the divergence-raising functions of degree k + 1 that make it
RT_k ((k+1)(k+3) per triangle). The bubbles b_T P_k are exactly the ``LOCAL_DOF`` dofs of
``H1(order=k+3)`` ((k+1)(k+2)/2 per triangle: polynomials of degree k + 3 vanishing on the
boundary of T); they are selected that way, never by clearing vertex and edge dofs, because
after ``mesh.Refine()`` NGSolve still counts the edges of coarser levels. The edge functions
are left out (``orderedge=1``): at k = 0 the element then has 4 shape functions instead of
10, which is what assembly pays for per triangle.

The Arnold-Falk-Winther triple BDM_{k+1}^2 x P_k^2 x P_k (discontinuous rotation, no
bubbles; Arnold, Falk, Winther 2007) is the family to compare with (:func:`afw_spaces`);
:func:`triple` reads both. All spaces are compressed, so ``ndof`` is the true count of
Table 3.1.
"""

from __future__ import annotations

import functools

import ngsolve as ngs
import numpy as np
from ngsolve.meshes import MakeStructured2DMesh

from .scene import SceneError

STRESS = ("r1", "r2", "b1", "b2")
DISPLACEMENT = ("u1", "u2")
ROTATION = ("eta",)
PEERS = STRESS + DISPLACEMENT + ROTATION  # the order of the unknown vector
AFW = ("r1", "r2") + DISPLACEMENT + ROTATION
FAMILIES = ("peers", "afw")


def _check_order(order) -> int:
    """``order`` as a polynomial order k >= 0 (SceneError naming ``discretisation.order``)."""
    if isinstance(order, bool) or not isinstance(order, int) or order < 0:
        raise SceneError("discretisation.order",
                         f"the polynomial order k must be an integer >= 0, not {order!r}")
    return order


def raviart_thomas(mesh: ngs.Mesh, order: int = 0) -> ngs.FESpace:
    """The Raviart-Thomas space RT_k (``HDiv(order=k, RT=True)``; one dof per edge at k = 0)."""
    return ngs.Compress(ngs.HDiv(mesh, order=_check_order(order), RT=True))


def bubbles(mesh: ngs.Mesh, order: int = 0) -> ngs.FESpace:
    """The element bubbles whose Curls complete RT_k to the PEERS_k stress row: b_T P_k
    without b_T P_{k-2}.

    The LOCAL_DOF dofs of H1(order=k+3, orderedge=1) span b_T P_k. From k = 2 on b_T P_{k-2}
    lies in P_{k+1}, so that its Curls lie in curl P_{k+1} inside RT_k and the sum
    RT_k + Curl(b_T P_k) is not direct: those (k-1)k/2 bubbles per triangle are left out
    (:func:`redundant_bubbles`), which leaves the space of the row unchanged and its basis
    free, 2k + 1 bubbles per triangle.
    """
    h1 = ngs.H1(mesh, order=_check_order(order) + 3, orderedge=1)
    active = ~h1.FreeDofs(coupling=True)
    positions = redundant_bubbles(order)
    if positions:
        # NGSolve numbers the interior dofs triangle by triangle, each triangle's in the
        # order of its GetDofNrs (checked on the first and the last triangle)
        inner = np.flatnonzero(np.array(active, dtype=bool)).reshape(mesh.ne, -1)
        for nr in (0, mesh.ne - 1):
            own = [d for d in h1.GetDofNrs(ngs.ElementId(ngs.VOL, nr)) if active[d]]
            if own != inner[nr].tolist():
                raise RuntimeError("NGSolve's interior H1 dofs are not numbered triangle by "
                                   "triangle")
        for dof in inner[:, list(positions)].ravel().tolist():
            active[dof] = False
    return ngs.Compress(h1, active_dofs=active)


@functools.cache
def redundant_bubbles(order: int) -> tuple[int, ...]:
    """Positions, among the interior dofs of a triangle of H1(order=k+3, orderedge=1), of the
    bubbles in b_T P_{k-2}: those whose L^2 projection onto P_{k+1} leaves nothing.

    NGSolve's interior functions are a hierarchical (Dubiner) basis times b_T in the
    triangle's sorted barycentric coordinates, so these positions are the same on every
    triangle; they are read off a one-triangle mesh.
    """
    if order < 2:
        return ()
    mesh = MakeStructured2DMesh(quads=False, nx=1, ny=1)
    h1 = ngs.H1(mesh, order=order + 3, orderedge=1)
    active = ~h1.FreeDofs(coupling=True)
    inner = [d for d in h1.GetDofNrs(ngs.ElementId(ngs.VOL, 0)) if active[d]]
    shape, projection = ngs.GridFunction(h1), ngs.GridFunction(ngs.L2(mesh, order=order + 1))
    found = []
    for position, dof in enumerate(inner):
        shape.vec[:] = 0
        shape.vec[dof] = 1
        projection.Set(shape)
        norm = ngs.Integrate(shape * shape, mesh, order=2 * order + 6)
        rest = ngs.Integrate((shape - projection) ** 2, mesh, order=2 * order + 6)
        if rest < 1e-20 * norm:
            found.append(position)
    if len(found) != (order - 1) * order // 2:
        raise RuntimeError(f"NGSolve's interior H1 functions of order {order + 3} are not "
                           f"hierarchical: {len(found)} of them lie in P_{order + 1}")
    return tuple(found)


def cubic_bubbles(mesh: ngs.Mesh) -> ngs.FESpace:
    """The cubic element bubbles b_T of PEERS_0 (:func:`bubbles` at k = 0)."""
    return bubbles(mesh, 0)


def peers_spaces(mesh: ngs.Mesh, order: int = 0) -> dict[str, ngs.FESpace]:
    """The component spaces of X_h x M_h x S_h of PEERS_k, keyed by component name.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The triangulation T_h.
    order : int
        The order k: stress rows in RT_k + Curl(b_T P_k), u in discontinuous P_k, the rotation
        in continuous P_{k+1}; k = 0 is the triple (3.61) of the thesis.
    """
    rt, bubble = raviart_thomas(mesh, order), bubbles(mesh, order)
    pk = ngs.L2(mesh, order=order)
    return {"r1": rt, "r2": rt, "b1": bubble, "b2": bubble,
            "u1": pk, "u2": pk, "eta": ngs.H1(mesh, order=order + 1)}


def afw_spaces(mesh: ngs.Mesh, order: int = 0) -> dict[str, ngs.FESpace]:
    """The Arnold-Falk-Winther triple BDM_{k+1}^2 x P_k^2 x P_k (all but BDM discontinuous),
    keyed like :func:`peers_spaces` without the bubbles ``b1``, ``b2``."""
    bdm = ngs.Compress(ngs.HDiv(mesh, order=_check_order(order) + 1))
    pk = ngs.L2(mesh, order=order)
    return {"r1": bdm, "r2": bdm, "u1": pk, "u2": pk, "eta": pk}


def family_spaces(mesh: ngs.Mesh, family: str = "peers", order: int = 0
                  ) -> dict[str, ngs.FESpace]:
    """The spaces of ``family`` (one of :data:`FAMILIES`) of order k on ``mesh``."""
    if family not in FAMILIES:
        raise SceneError("discretisation.family",
                         f"unknown family {family!r}; choose one of {', '.join(FAMILIES)}")
    return (peers_spaces if family == "peers" else afw_spaces)(mesh, order)


def stress_degree(family: str = "peers", order: int = 0) -> int:
    """The polynomial degree of the stress of ``family`` at order k: k + 2 for PEERS_k (the
    Curl of b_T P_k), k + 1 for AFW (BDM_{k+1}). Twice it is the degree of the compliance
    integrand, the highest of the PEERS form."""
    return _check_order(order) + (2 if family == "peers" else 1)


def curl(b) -> ngs.CoefficientFunction:
    """Curl psi = (psi_{,2}, -psi_{,1}) of a scalar function."""
    g = ngs.grad(b)
    return ngs.CF((g[1], -g[0]))


def stress_rows(r1, r2, b1=None, b2=None) -> tuple:
    """The rows r_i + Curl b_i of sigma (r_i alone without bubbles), two vector coefficient
    functions."""
    return (r1, r2) if b1 is None else (r1 + curl(b1), r2 + curl(b2))


def stress(r1, r2, b1=None, b2=None) -> ngs.CoefficientFunction:
    """sigma with rows r_i + Curl b_i (r_i alone without bubbles), as a 2x2 coefficient function."""
    row1, row2 = stress_rows(r1, r2, b1, b2)
    return ngs.CF((row1[0], row1[1], row2[0], row2[1]), dims=(2, 2))


def stress_divergence(r1, r2) -> ngs.CoefficientFunction:
    """div sigma (the Curl bubbles are divergence free)."""
    return ngs.CF((ngs.div(r1), ngs.div(r2)))


def stress_traction(r1, r2) -> ngs.CoefficientFunction:
    """sigma . n on the boundary of trial/test functions (Curl bubbles have zero normal trace)."""
    n = ngs.specialcf.normal(2)
    return ngs.CF((r1.Trace() * n, r2.Trace() * n))


def triple(f: dict):
    """(sigma, div sigma, u, eta) of the PEERS components of a trial or test function ``f``
    (a dict keyed by component name, :func:`peers_spaces`, or without bubbles,
    :func:`afw_spaces`)."""
    return (stress(f["r1"], f["r2"], f.get("b1"), f.get("b2")),
            stress_divergence(f["r1"], f["r2"]),
            ngs.CF((f["u1"], f["u2"])), f["eta"])


def compliance(sigma, lam: float, mu: float) -> ngs.CoefficientFunction:
    """C^{-1} : sigma = (sigma - lam/(2(lam+mu)) tr(sigma) I) / (2 mu), plane strain."""
    return (sigma - lam / (2 * (lam + mu)) * ngs.Trace(sigma) * ngs.Id(2)) / (2 * mu)


def compliance_rows(sigma: tuple, tau: tuple, lam: float, mu: float) -> ngs.CoefficientFunction:
    """(C^{-1} : sigma) : tau of :func:`compliance` from the rows of sigma and tau
    (:func:`stress_rows`), the integrand of a~(sigma, tau) (3.32).

    The same polynomial as ``InnerProduct(compliance(sigma), tau)``, written on the rows
    without the 2x2 matrix, to the same element matrices bit for bit: NGSolve differentiates
    it with respect to the test functions (:func:`ngdual.forms.differentiated_integrands`) in
    0.07 s on 6 465 triangles of hertz-cylinder, the matrix form in 0.10 s.
    """
    (s1, s2), (t1, t2) = sigma, tau
    c = lam / (2 * (lam + mu))
    return (s1 * t1 + s2 * t2 - c * (s1[0] + s2[1]) * (t1[0] + t2[1])) / (2 * mu)


def asym_rows(rows: tuple) -> ngs.CoefficientFunction:
    """:func:`asym` from the rows of sigma (:func:`stress_rows`)."""
    return rows[0][1] - rows[1][0]


def asym(sigma) -> ngs.CoefficientFunction:
    """sigma_12 - sigma_21, the integrand of s(eta, sigma) (3.32)."""
    return sigma[0, 1] - sigma[1, 0]
