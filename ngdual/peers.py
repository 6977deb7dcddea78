"""The PEERS triple (X_h, M_h, S_h) of (3.61) on NGSolve spaces.

X_h: each stress row is a lowest-order Raviart-Thomas field (NGSolve ``HDiv``
order 0) plus the Curl of the cubic element bubble b_T. The cubic bubbles are
exactly the ``LOCAL_DOF`` dofs of ``H1(order=3)`` (one per triangle); they are
selected that way, never by clearing vertex and edge dofs, because after
``mesh.Refine()`` NGSolve still counts the edges of coarser levels. The edge
functions are left out (``orderedge=1``): the element then has 4 shape functions
instead of 10, which is what assembly pays for per triangle.
M_h: piecewise constant displacement (two ``L2`` order 0 components).
S_h: continuous piecewise linear rotation (``H1`` order 1).
All spaces are compressed, so ``ndof`` is the true count of Table 3.1.
"""

from __future__ import annotations

import ngsolve as ngs

STRESS = ("r1", "r2", "b1", "b2")
DISPLACEMENT = ("u1", "u2")
ROTATION = ("eta",)
PEERS = STRESS + DISPLACEMENT + ROTATION  # the order of the unknown vector


def raviart_thomas(mesh: ngs.Mesh) -> ngs.FESpace:
    """Lowest-order Raviart-Thomas space RT_0 (one dof per edge)."""
    return ngs.Compress(ngs.HDiv(mesh, order=0))


def cubic_bubbles(mesh: ngs.Mesh) -> ngs.FESpace:
    """The cubic element bubbles b_T: the LOCAL_DOF dofs of H1(order=3, orderedge=1)."""
    h1 = ngs.H1(mesh, order=3, orderedge=1)
    return ngs.Compress(h1, active_dofs=~h1.FreeDofs(coupling=True))


def peers_spaces(mesh: ngs.Mesh) -> dict[str, ngs.FESpace]:
    """The component spaces of X_h x M_h x S_h, keyed by component name."""
    rt, bubble = raviart_thomas(mesh), cubic_bubbles(mesh)
    p0 = ngs.L2(mesh, order=0)
    return {"r1": rt, "r2": rt, "b1": bubble, "b2": bubble,
            "u1": p0, "u2": p0, "eta": ngs.H1(mesh, order=1)}


def curl(b) -> ngs.CoefficientFunction:
    """Curl psi = (psi_{,2}, -psi_{,1}) of a scalar function."""
    g = ngs.grad(b)
    return ngs.CF((g[1], -g[0]))


def stress(r1, r2, b1, b2) -> ngs.CoefficientFunction:
    """sigma with rows r_i + Curl b_i, as a 2x2 coefficient function."""
    row1, row2 = r1 + curl(b1), r2 + curl(b2)
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
    (a dict keyed by component name, :func:`peers_spaces`)."""
    return (stress(f["r1"], f["r2"], f["b1"], f["b2"]), stress_divergence(f["r1"], f["r2"]),
            ngs.CF((f["u1"], f["u2"])), f["eta"])


def compliance(sigma, lam: float, mu: float) -> ngs.CoefficientFunction:
    """C^{-1} : sigma = (sigma - lam/(2(lam+mu)) tr(sigma) I) / (2 mu), plane strain."""
    return (sigma - lam / (2 * (lam + mu)) * ngs.Trace(sigma) * ngs.Id(2)) / (2 * mu)


def asym(sigma) -> ngs.CoefficientFunction:
    """sigma_12 - sigma_21, the integrand of s(eta, sigma) (3.32)."""
    return sigma[0, 1] - sigma[1, 0]
