"""The a posteriori error indicators of Chapter 4, eq. (4.50), every term separately.

For a discrete solution of (3.62), with w_h := C^{-1} sigma_h + eta_h (eta_h
read as the skew tensor [[0, eta_h], [-eta_h, 0]], so w_h approximates grad u)
and t = (n_2, -n_1) the tangent of (3.24) and of the proof of Theorem 4.2, the terms,
squared, per element T, are::

    eta_{sigma,T}^2 (4.15)
        ``residual``        ||f + div sigma_h||_T^2
        ``asymmetry``       ||as(sigma_h)||_T^2 (``asymmetry="l2"``, the default, as in
                            Carstensen-Dolzmann [22], Gatica [46]) or ||as(sigma_h)||_{H(div,T)}^2
                            (``"hdiv"``, as printed in (4.15); it does not decrease for PEERS)
        ``curl``            h_T^2 ||curl w_h||_T^2
        ``jump_interior``   sum_{e in E^T, interior}  h_e ||[w_h t]||_e^2
        ``jump_dirichlet``  sum_{e in E^T on Gamma_D} h_e ||w_h t - du_D/dt||_e^2
        ``jump_neumann``    sum_{e in E^T on Gamma_N} h_e ||w_h t + dphi/dt||_e^2
        ``jump_contact``    sum_{e in E^T on Gamma_C}
                            h_e ||w_h t + dlam_t/dt t + d(lam_n-g)/dt n||^2
    eta_{u,T}^2 (4.31)
        ``u_volume``        h_T^2 ||w_h - grad_h u_h||_T^2  (grad_h u_h = 0 at k = 0)
        ``u_dirichlet``     sum h_e ||u_Gamma - u_D||_e^2
        ``u_neumann``       sum h_e ||phi + u_Gamma||_e^2
        ``u_contact``       sum h_e ||lam_t t + (lam_n - g) n + u_Gamma||_e^2
    the friction and Neumann terms of (4.50)
        ``friction``        sum_{e in E^T on A_C} h~_e ||sigma_t - F nu||_e^2,  A_C = supp F
                            (with the facet multipliers h_e ||(|sigma_t| - F)_+||_e^2,
                            :func:`_moment_friction_term`)
        ``neumann``         log(1 + C~_N) sum_{e in E^T on Gamma_N} h~_e ||sigma_h n - t0||_e^2

u_Gamma is the trace on the edge of the element's u_h (4.29): its constant value at
k = 0, a polynomial of degree k at order k. The thesis has u_D = 0; the ``du_D/dt`` and
``- u_D`` parts are the same terms for non-homogeneous Dirichlet data (w_h t approximates
du/dt, and u = u_D on Gamma_D). h_T = diam T and h_e = length(e) stand for the equivalent
patch diameters of (3.60); h~_e is the length of the coarse (h~) edge holding e.

Every term is an NGSolve integral: element integrals, element-boundary
integrals for the interior jumps, and ``ds`` integrals tested with the
piecewise constants on the boundary edges, each edge added to its element.
Every array holds squared contributions per element, so that
eta_{tot,T}^2 = the sum of all terms (4.50).

At order k (PEERS_k, :mod:`ngdual.peers`) the terms are the same. sigma_h has degree
k + 2 and eta_h degree k + 1, so w_h and as(sigma_h) are projected element-wise onto
P_{k+2} (exactly) before they are differentiated, and every integral takes the rule of
:func:`quadrature_bonus`, exact for the squares of the discrete fields (degree 2k + 4).
One term changes form: (4.39) bounds ||u - u_h|| through int w_h : (E_h r - r) with the
equilibrium interpolant E_h onto RT_k, and at k >= 1 int grad_h u_h : (E_h r - r) = 0 too
(integrate by parts on every triangle: div(E_h r - r) is orthogonal to P_k and so are the
normal moments on every edge), so ``u_volume`` is h_T^2 ||w_h - grad_h u_h||^2, the
element residual of C^{-1} sigma + eta = grad u; the thesis' h_T^2 ||w_h||^2 at k = 0.
With h_T^2 ||w_h||^2 the term would stay O(h) at every order (it would be the largest term
of the manufactured contact case at k = 2, docs/theory/estimator.md).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import ngsolve as ngs
import numpy as np

from . import peers
from .contact import gap_coefficient
from .expr import Expression
from .forms import boundary_regex, parallel_tasks, traction_coefficient
from .geometry import tangent
from .mesh import element_diameters
from .quantities import fields, require_solution
from .scene import SceneError, SceneTypeError
from .solution import Solution

SIGMA_TERMS = ("residual", "asymmetry", "curl", "jump_interior", "jump_dirichlet",
               "jump_neumann", "jump_contact")
U_TERMS = ("u_volume", "u_dirichlet", "u_neumann", "u_contact")
OTHER_TERMS = ("friction", "neumann")
TERMS = SIGMA_TERMS + U_TERMS + OTHER_TERMS
ASYMMETRY_NORMS = ("hdiv", "l2")


@dataclass
class Estimate:
    """Per-element indicators of (4.50).

    Attributes
    ----------
    terms : dict[str, numpy.ndarray]
        Squared contribution of every term of :data:`TERMS` on every element.
    h : numpy.ndarray
        Element diameters h_T.
    seconds : float
        Wall time of the estimation.
    asymmetry : str
        The norm of as(sigma_h) used ("hdiv" or "l2").
    edges : BoundaryEdges
        The boundary edges of the mesh and their elements, with the estimate's rule (for
        the pressure goal, :func:`ngdual.goal.goal_estimate`, on the same mesh).
    """

    terms: dict[str, np.ndarray]
    h: np.ndarray
    seconds: float = 0.0
    asymmetry: str = "l2"
    edges: BoundaryEdges | None = field(default=None, repr=False)

    @property
    def eta_sigma(self) -> np.ndarray:
        """eta_{sigma,T} of (4.15)."""
        return np.sqrt(sum(self.terms[k] for k in SIGMA_TERMS))

    @property
    def eta_u(self) -> np.ndarray:
        """eta_{u,T} of (4.31)."""
        return np.sqrt(sum(self.terms[k] for k in U_TERMS))

    @property
    def indicators(self) -> np.ndarray:
        """eta_{tot,T} of (4.50): the indicator that marking uses."""
        return np.sqrt(sum(self.terms[k] for k in TERMS))

    @property
    def total(self) -> float:
        """(sum_T eta_{tot,T}^2)^{1/2}, the global estimator compared with the error."""
        return float(np.sqrt(np.sum(self.indicators**2)))

    @property
    def total_sum(self) -> float:
        """sum_T eta_{tot,T}, the eta_tot of Table 4.4 (Theorem 4.8 bounds the error by it)."""
        return float(np.sum(self.indicators))

    def summed(self) -> dict[str, float]:
        """sum_T of every squared term (their sum is ``total**2``)."""
        return {k: float(np.sum(v)) for k, v in self.terms.items()}


def quadrature_bonus(order: int = 0) -> int:
    """The ``bonus_intorder`` of every integral of the estimator at order k: 2 (k + 2).

    The squares of w_h and as(sigma_h) have degree 2 (k + 2) (:func:`ngdual.peers.stress_degree`).
    NGSolve integrates ``Integrate(cf * dx(bonus_intorder=b))`` (also on the element
    boundaries) exactly to degree 5 + b and a ``ds`` linear form tested with the edge
    constants to degree b + 1 (measured on monomials), so the bonus 2 (k + 2) is exact for
    the squares of the discrete fields on both, with 5 degrees to spare for the data (f,
    u_D, t0, g) in the volume and 1 on the edges; at k = 0 it is the thesis' rule."""
    return 2 * peers.stress_degree("peers", order)


def _interpolate(mesh: ngs.Mesh, cf, order: int = 0) -> ngs.GridFunction:
    """The element-wise L2 projection of the vector-valued ``cf`` onto P_{k+2}^dim (exact for
    the fields of PEERS_k), to differentiate its components.

    One vector-valued projection evaluates the discrete fields behind ``cf`` once per
    integration point; a projection per component would evaluate them once per component
    (five times the work for w_h and as(sigma_h), with coefficients equal to rounding)."""
    space = ngs.L2(mesh, order=peers.stress_degree("peers", order), dim=cf.dim)
    gf = ngs.GridFunction(space)
    with parallel_tasks(mesh):
        gf.Set(cf.Compile())
    return gf


def _element_integrals(cf, mesh: ngs.Mesh, bonus: int) -> np.ndarray:
    with parallel_tasks(mesh):
        return ngs.Integrate(cf.Compile() * ngs.dx(bonus_intorder=bonus), mesh,
                             element_wise=True).NumPy().copy()


class BoundaryEdges:
    """Integrals over the boundary edges, each added to the one element that owns it, with
    the rule of :func:`quadrature_bonus` for the fields of order ``order``."""

    def __init__(self, mesh: ngs.Mesh, order: int = 0):
        self.mesh = mesh
        self.bonus = quadrature_bonus(order)
        self.space = ngs.SurfaceL2(mesh, order=0)
        self.test = self.space.TestFunction()
        self.element = np.zeros(self.space.ndof, dtype=int)
        self.length = np.zeros(self.space.ndof)
        self.dof_of_edge: dict[frozenset, int] = {}
        pts = np.array([v.point for v in mesh.vertices])
        for el in mesh.Elements(ngs.BND):
            dof = self.space.GetDofNrs(el)[0]
            a, b = (v.nr for v in el.vertices)
            self.element[dof] = mesh[el.edges[0]].elements[0].nr
            self.length[dof] = np.linalg.norm(pts[a] - pts[b])
            self.dof_of_edge[frozenset((a, b))] = dof

    def integrals(self, cf, labels: list[str]) -> np.ndarray:
        """int_e cf ds for every boundary edge e (zero off ``labels``), by edge dof."""
        if not labels:
            return np.zeros(self.space.ndof)
        form = ngs.LinearForm(self.space)
        form += cf * self.test * ngs.ds(definedon=self.mesh.Boundaries(boundary_regex(labels)),
                                        bonus_intorder=self.bonus)
        form.Assemble()
        return form.vec.FV().NumPy().copy()

    def to_elements(self, values: np.ndarray) -> np.ndarray:
        return np.bincount(self.element, values, self.mesh.ne)

    def scatter(self, pairs: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Values given per fine edge (vertex ``pairs``) onto the edge dofs, zero elsewhere."""
        out = np.zeros(self.space.ndof)
        out[[self.dof_of_edge[frozenset(map(int, p))] for p in pairs]] = values
        return out

    def coarse_lengths(self, coarse) -> np.ndarray:
        """The length of the coarse edge holding every fine edge of ``coarse``'s chains."""
        pairs, owner = coarse.fine_edges()
        return self.scatter(pairs, coarse.edge_lengths()[owner])


def _interior_edge_lengths(mesh: ngs.Mesh) -> ngs.GridFunction:
    """h_e on interior edges, 0 on boundary edges (a facet function)."""
    space = ngs.FacetFESpace(mesh, order=0)
    v = space.TestFunction()
    both, bnd = ngs.LinearForm(space), ngs.LinearForm(space)
    both += v * ngs.dx(element_boundary=True)   # 2|e| inside, |e| on the boundary
    bnd += v * ngs.ds                            # |e| on the boundary
    both.Assemble()
    bnd.Assemble()
    gf = ngs.GridFunction(space)
    gf.vec.FV().NumPy()[:] = 0.5 * (both.vec.FV().NumPy() - bnd.vec.FV().NumPy())
    return gf


def estimate(solution: Solution, asymmetry: str = "l2") -> Estimate:
    """Every term of eta_{tot,T} (4.50) on every element of the solution's mesh.

    Parameters
    ----------
    solution : Solution
        A discrete solution of (3.62) (with ``nu`` and ``friction_bound`` if
        the scene has friction).
    asymmetry : {"hdiv", "l2"}
        The norm of as(sigma_h): L^2(T) (default), or H(div, T) as printed in
        (4.15). For PEERS ||div as(sigma_h)||_T does not tend to zero (its RT_0
        part has a row divergence of about |f|/4), so with ``"hdiv"`` the
        estimator stops decreasing and the effectivity index grows with the
        level (2.7 -> 17.9 on levels 1-4 of the manufactured problem); with
        ``"l2"`` (Carstensen-Dolzmann, Gatica et al.) it stays in [0.90, 0.94].

    Returns
    -------
    Estimate
    """
    require_solution(solution)
    if not isinstance(asymmetry, str):
        raise SceneTypeError("asymmetry", f"must be one of {', '.join(ASYMMETRY_NORMS)}, got "
                                          f"{type(asymmetry).__name__}")
    if asymmetry not in ASYMMETRY_NORMS:
        raise SceneError("asymmetry", f"unknown norm {asymmetry!r}; use one of "
                                      + ", ".join(ASYMMETRY_NORMS))
    start = time.perf_counter()
    pb = solution.problem
    scene, spaces = pb.scene, pb.spaces
    mesh = pb.fes.mesh
    order, bonus = spaces.order, quadrature_bonus(spaces.order)
    lam, mu = scene.material.lame
    f = fields(solution)
    h = element_diameters(mesh)
    n = ngs.specialcf.normal(2)
    t = tangent(n)

    # w_h = C^{-1} sigma_h + eta_h (row by row) and a_h = (sigma_12 - sigma_21) / 2, as one
    # P_{k+2}^5 function per element; grad_w[j, i] is the x_j derivative of its component i
    w_cf = peers.compliance(f.sigma, lam, mu) + ngs.CF((0, f.eta, -f.eta, 0), dims=(2, 2))
    projected = _interpolate(mesh, ngs.CF((w_cf[0, 0], w_cf[0, 1], w_cf[1, 0], w_cf[1, 1],
                                           0.5 * peers.asym(f.sigma))), order)
    w = ngs.CF(tuple(projected[i] for i in range(4)), dims=(2, 2))
    a = projected[4]
    grad_w = ngs.grad(projected)
    curl_w = ngs.CF((grad_w[0, 1] - grad_w[1, 0], grad_w[0, 3] - grad_w[1, 2]))
    body = ngs.CF(tuple(Expression(e).coefficient() for e in scene.loads.body_force))
    residual = body + f.div_sigma

    terms = dict.fromkeys(TERMS)
    terms["residual"] = _element_integrals(residual * residual, mesh, bonus)
    as_l2 = 2 * a * a                           # |[[0, a], [-a, 0]]|^2
    grad_a = ngs.CF((grad_w[0, 4], grad_w[1, 4]))
    as_div = grad_a * grad_a                    # |div [[0, a], [-a, 0]]|^2 = |grad a|^2
    terms["asymmetry"] = _element_integrals(as_l2 + as_div if asymmetry == "hdiv" else as_l2,
                                            mesh, bonus)
    terms["curl"] = h**2 * _element_integrals(curl_w * curl_w, mesh, bonus)
    components = dict(zip(pb.names, f.gf.components))
    grad_u = ngs.CF((ngs.grad(components["u1"]), ngs.grad(components["u2"])), dims=(2, 2))
    w_u = w - grad_u   # grad_h u_h = 0 at k = 0: the thesis' w_h, to the last bit
    terms["u_volume"] = h**2 * _element_integrals(ngs.InnerProduct(w_u, w_u), mesh, bonus)

    h_int = _interior_edge_lengths(mesh)
    other = projected.Other()
    w_other = ngs.CF(tuple(other[i] for i in range(4)), dims=(2, 2))
    jump = (w - w_other) * t
    terms["jump_interior"] = ngs.Integrate(
        (h_int * (jump * jump)).Compile()
        * ngs.dx(element_boundary=True, bonus_intorder=bonus),
        mesh, element_wise=True).NumPy().copy()

    edges = BoundaryEdges(mesh, order)
    he = edges.length
    w_t = ngs.BoundaryFromVolumeCF(w) * t
    u_gamma = ngs.BoundaryFromVolumeCF(f.u)
    sigma_n = ngs.BoundaryFromVolumeCF(f.sigma) * n

    def squared(vec):
        return vec * vec

    labels_d = scene.labels("dirichlet")
    u_d = ngs.CF(tuple(Expression(e).coefficient() for e in scene.loads.displacement))
    du_d = ngs.CF(tuple(c.Diff(ngs.x) * t[0] + c.Diff(ngs.y) * t[1]
                        for c in (u_d[0], u_d[1])))
    on_edges = {
        "jump_dirichlet": he * edges.integrals(squared(w_t - du_d), labels_d),
        "u_dirichlet": he * edges.integrals(squared(u_gamma - u_d), labels_d),
    }
    labels_n = scene.labels("neumann")
    if f.phi is not None:
        gf = dict(zip(pb.names, f.gf.components))
        dphi = ngs.CF((ngs.grad(gf["phi1"]) * t, ngs.grad(gf["phi2"]) * t))
        t0 = traction_coefficient(scene, mesh)
        on_edges["jump_neumann"] = he * edges.integrals(squared(w_t + dphi), labels_n)
        on_edges["u_neumann"] = he * edges.integrals(squared(f.phi + u_gamma), labels_n)
        on_edges["neumann"] = (np.log(1 + neighbour_ratio(spaces.neumann))
                               * edges.coarse_lengths(spaces.neumann)
                               * edges.integrals(squared(sigma_n - t0), labels_n))
    labels_c = scene.labels("contact")
    if f.lam_n is not None:
        gf = dict(zip(pb.names, f.gf.components))
        g = gap_coefficient(scene)
        dg = g.Diff(ngs.x) * t[0] + g.Diff(ngs.y) * t[1]
        d_mult = (ngs.grad(gf["lam_t"]) * t) * t + (ngs.grad(gf["lam_n"]) * t - dg) * n
        mult = f.lam_t * t + (f.lam_n - g) * n
        on_edges["jump_contact"] = he * edges.integrals(squared(w_t + d_mult), labels_c)
        on_edges["u_contact"] = he * edges.integrals(squared(mult + u_gamma), labels_c)
        if spaces.friction is not None and solution.friction_bound is not None:
            on_edges["friction"] = _friction_term(solution, edges, sigma_n * t, labels_c)
        elif spaces.contact.traces and solution.friction_bound is not None:
            on_edges["friction"] = _moment_friction_term(solution, edges, sigma_n, labels_c)
    for name in ("jump_dirichlet", "jump_neumann", "jump_contact", "u_dirichlet", "u_neumann",
                 "u_contact", "friction", "neumann"):
        values = on_edges.get(name)
        terms[name] = edges.to_elements(values) if values is not None else np.zeros(mesh.ne)
    return Estimate(terms, h, time.perf_counter() - start, asymmetry, edges)


def neighbour_ratio(coarse) -> float:
    """C~_N of Theorem 4.8: the largest ratio of the lengths of neighbouring fine edges."""
    ratio = 1.0
    for chain in coarse.chains:
        ell = np.diff(chain.arclength)
        if chain.closed:
            ell = np.append(ell, ell[0])
        if len(ell) > 1:
            ratio = max(ratio, float(np.max(np.maximum(ell[1:] / ell[:-1], ell[:-1] / ell[1:]))))
    return ratio


def _friction_term(solution: Solution, edges: BoundaryEdges, sigma_t, labels) -> np.ndarray:
    """h~_e ||sigma_t - F nu||_e^2 on the fine Gamma_C edges of A_C = supp F.

    F (``friction_bound``) is given per fine edge of Gamma_C and nu per h^ edge, in the
    order of :class:`ngdual.contact.ContactBoundary`.
    """
    gamma_c = solution.problem.spaces.gamma_c
    bound = np.asarray(solution.friction_bound, dtype=float)
    f_nu = bound * np.asarray(solution.nu, dtype=float)[gamma_c.hhat_edge]
    gf = ngs.GridFunction(edges.space)
    gf.vec.FV().NumPy()[:] = edges.scatter(gamma_c.vertices, f_nu)
    htilde = gamma_c.coarse.edge_lengths()[gamma_c.htilde_edge]
    weight = edges.scatter(gamma_c.vertices, np.where(bound > 0, htilde, 0.0))
    return weight * edges.integrals((sigma_t - gf) * (sigma_t - gf), labels)


def _moment_friction_term(solution: Solution, edges: BoundaryEdges, traction, labels
                          ) -> np.ndarray:
    """h_e ||(|sigma_t| - F)_+||_e^2 on the fine Gamma_C edges of A_C with the facet
    multipliers of order k (``traction``: sigma_h n on the boundary).

    Their friction law holds on the Bernstein moments (:class:`ngdual.friction.MomentFriction`):
    int sigma_t B_i = nu_i int F B_i, so the function F nu whose moments these are is the
    P_k trace sigma_t itself and sigma_t - F nu vanishes. What the moments leave free is
    the pointwise bound |sigma_t| <= F (F = mu_f (-sigma_n)_+ for Coulomb, the trace's
    own pressure, or the given Tresca bound), whose excess is a part of the error as the
    tension of the pressure is (:func:`ngdual.goal.goal_estimate`). A_C: the fine edges
    where ``friction_bound`` (the mean of F on the edge) is positive.
    """
    friction = solution.problem.scene.friction
    n = ngs.specialcf.normal(2)
    sigma_t, sigma_nn = traction * tangent(n), traction * n
    if friction.law == "coulomb":
        bound = friction.mu * ngs.IfPos(-sigma_nn, -sigma_nn, 0)
    else:
        bound = Expression(friction.bound).coefficient()
    excess = ngs.IfPos(sigma_t, sigma_t, -sigma_t) - bound
    gamma_c = solution.problem.spaces.gamma_c
    on_a_c = np.asarray(solution.friction_bound, dtype=float) > 0
    weight = edges.scatter(gamma_c.vertices, np.where(on_a_c, gamma_c.lengths, 0.0))
    return weight * edges.integrals(ngs.IfPos(excess, excess * excess, 0), labels)
