"""PEERS of order k on smooth linear elasticity: convergence and inf-sup.

A smooth manufactured displacement on the unit square Omega = (0, 1)^2 (plane strain,
:data:`LAME`), clamped to its exact values on Gamma_D = left and bottom and loaded with its
exact traction on Gamma_N = right and top, with f = -div sigma. No contact and no boundary
multiplier: sigma n = t0 on Gamma_N is imposed on the normal dofs of the stress rows (the
L^2 projection of t0 onto the normal traces, P_k on every edge), so that what is measured is
the triple (X_h, M_h, S_h) of :mod:`ngdual.peers` alone. The system is the PEERS block of
(3.62) -- ``ngdual.forms.peers_form``, the one PEERS form -- with the right-hand side

    -f(v) + <u_D, tau n>_{Gamma_D},

the Dirichlet datum entering naturally as in (3.62). At order k the PEERS stress has degree
k + 2, so that the compliance integrand has degree 2k + 4; ``peers_form`` integrates it with
the rule of that degree (:func:`ngdual.forms.volume_rules`).

A priori (Arnold, Brezzi, Douglas 1984; Stenberg 1988; Arnold, Falk, Winther 2007) sigma, u
and the rotation converge like h^{k+1} in L^2 for both families; :func:`convergence_study`
measures it with the one rate of ngdual (:func:`ngdual.rates.observed_rates`, the order in
h_N = N^{-1/2}). :func:`infsup_constants` computes the Babuska-Brezzi constant of
b(tau, (v, xi)) = (div tau, v) + s(xi, tau) in the H(div) x L^2 x L^2 norms on the clamped
square with the machinery of :mod:`ngdual.verification.infsup`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
from ngsolve.meshes import MakeStructured2DMesh

from ... import peers
from ...forms import peers_form
from ...rates import observed_rates
from ...solvers.linear import Factorization
from ...sparse import to_scipy
from ..infsup import gram_matrix, smallest_singular_values

E, NU = 1.0, 0.3
LAME = (E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU)))    # plane strain (lambda, mu)
DIRICHLET, NEUMANN = "left|bottom", "right|top"
QUANTITIES = ("sigma", "u", "eta")


def unit_square(level: int) -> ngs.Mesh:
    """The structured unit square with 2^(level+1) cells a side, each cut into two triangles
    (boundaries ``left``, ``bottom``, ``right``, ``top``)."""
    n = 2 ** (level + 1)
    return MakeStructured2DMesh(quads=False, nx=n, ny=n)


@dataclass(frozen=True)
class ExactElasticity:
    """The manufactured solution: u, sigma = C eps(u), eta = (u_{1,2} - u_{2,1}) / 2 (the
    rotation of (3.62), s(eta, tau) = int eta (tau_12 - tau_21) dx) and f = -div sigma."""

    lame: tuple[float, float] = LAME

    @property
    def u(self) -> ngs.CoefficientFunction:
        x, y, pi = ngs.x, ngs.y, math.pi
        return ngs.CF((ngs.sin(pi * x) * ngs.cos(pi * y / 2) + x * y * y / 4,
                       ngs.exp(x / 2) * ngs.sin(pi * y) + x * x / 8))

    def gradient(self) -> ngs.CoefficientFunction:
        u = self.u
        return ngs.CF(tuple(u[i].Diff(z) for i in range(2) for z in (ngs.x, ngs.y)),
                      dims=(2, 2))

    @property
    def sigma(self) -> ngs.CoefficientFunction:
        lam, mu = self.lame
        grad = self.gradient()
        eps = 0.5 * (grad + grad.trans)
        return lam * ngs.Trace(eps) * ngs.Id(2) + 2 * mu * eps

    @property
    def eta(self) -> ngs.CoefficientFunction:
        grad = self.gradient()
        return 0.5 * (grad[0, 1] - grad[1, 0])

    @property
    def f(self) -> ngs.CoefficientFunction:
        s = self.sigma
        return -ngs.CF(tuple(s[i, 0].Diff(ngs.x) + s[i, 1].Diff(ngs.y) for i in range(2)))


def component_indices(fes: ngs.FESpace, names: list[str], *components: str) -> np.ndarray:
    """Indices in the product space ``fes`` (components ``names``) of the listed components
    that it has."""
    ranges = [fes.Range(names.index(c)) for c in components if c in names]
    return np.concatenate([np.arange(r.start, r.stop) for r in ranges])


@dataclass
class ElasticitySystem:
    """The PEERS block of (3.62) of one family and order on one mesh, with its load.

    ``K`` and ``rhs`` hold every unknown in the order of ``names``; ``fixed`` are the normal
    dofs of the stress rows on Gamma_N and ``values`` their prescribed coefficients.
    """

    mesh: ngs.Mesh
    family: str
    order: int
    names: list[str]
    fes: ngs.FESpace
    K: sp.csr_matrix
    rhs: np.ndarray
    fixed: np.ndarray
    values: np.ndarray
    seconds: float

    def index(self, *names: str) -> np.ndarray:
        """Indices of the listed components in the unknown vector."""
        return component_indices(self.fes, self.names, *names)

    @property
    def sigma(self) -> np.ndarray:
        return self.index(*peers.STRESS)

    @property
    def mult(self) -> np.ndarray:
        """u and eta: the unknowns b + s pairs with the stress."""
        return self.index(*peers.DISPLACEMENT, *peers.ROTATION)

    def block(self, rows: np.ndarray, cols: np.ndarray) -> sp.csr_matrix:
        return self.K[rows][:, cols].tocsr()


def assemble_elasticity(mesh: ngs.Mesh, family: str = "peers", order: int = 0,
                        exact: ExactElasticity | None = None,
                        dirichlet: str = DIRICHLET, neumann: str = NEUMANN) -> ElasticitySystem:
    """The PEERS block of (3.62) with -f(v) + <u_D, tau n>_{Gamma_D} on the right and
    sigma n = t0 on Gamma_N (``neumann``, a regex of boundary labels; "" for none).

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The triangulation.
    family, order : str, int
        The spaces (:func:`ngdual.peers.family_spaces`).
    exact : ExactElasticity, optional
        The data u_D, t0 and f are the traces and load of this solution (default: the
        manufactured one).
    dirichlet, neumann : str
        The boundary parts, as regexes of NGSolve's boundary labels.
    """
    start = time.perf_counter()
    exact = exact or ExactElasticity()
    spaces = peers.family_spaces(mesh, family, order)
    names = list(spaces)
    fes = ngs.FESpace([spaces[n] for n in names])
    trial = dict(zip(names, fes.TrialFunction()))
    test = dict(zip(names, fes.TestFunction()))
    a = ngs.BilinearForm(fes)
    a += peers_form(trial, test, exact.lame, order, family)
    a.Assemble()
    v = peers.triple(test)[2]
    trac_tau = peers.stress_traction(test["r1"], test["r2"])
    load = ngs.LinearForm(fes)
    load += -exact.f * v * ngs.dx(bonus_intorder=4)
    load += exact.u * trac_tau * ngs.ds(definedon=mesh.Boundaries(dirichlet), bonus_intorder=4)
    load.Assemble()
    fixed = np.zeros(0, dtype=int)
    values = np.zeros(fes.ndof)
    if neumann:
        region = mesh.Boundaries(neumann)
        on_neumann = np.flatnonzero(np.array(fes.GetDofs(region), dtype=bool))
        fixed = np.intersect1d(on_neumann, component_indices(fes, names, "r1", "r2"))
        lift = ngs.GridFunction(fes)
        for i, r in enumerate(("r1", "r2")):
            row = ngs.CF((exact.sigma[i, 0], exact.sigma[i, 1]))
            lift.components[names.index(r)].Set(row, ngs.BND, definedon=region)
        values[fixed] = lift.vec.FV().NumPy()[fixed]
    return ElasticitySystem(mesh, family, order, names, fes, to_scipy(a.mat),
                            load.vec.FV().NumPy().copy(), fixed, values,
                            time.perf_counter() - start)


def solve_elasticity(system: ElasticitySystem) -> tuple[ngs.GridFunction, float]:
    """The discrete solution (a GridFunction of ``system.fes``) and the seconds of its
    factorisation and solve (UMFPACK, :class:`ngdual.solvers.linear.Factorization`)."""
    start = time.perf_counter()
    free = np.setdiff1d(np.arange(system.K.shape[0]), system.fixed)
    x = system.values.copy()
    rhs = system.rhs - system.K @ system.values
    x[free] = Factorization(system.K[free][:, free]).solve(rhs[free])
    gf = ngs.GridFunction(system.fes)
    gf.vec.FV().NumPy()[:] = x
    return gf, time.perf_counter() - start


def l2_errors(system: ElasticitySystem, gf: ngs.GridFunction,
              exact: ExactElasticity | None = None) -> dict[str, float]:
    """||sigma - sigma_h||, ||u - u_h|| and ||eta - eta_h|| in L^2(Omega)."""
    exact = exact or ExactElasticity()
    sigma, _, u, eta = peers.triple(dict(zip(system.names, gf.components)))
    degree = 2 * peers.stress_degree(system.family, system.order) + 4

    def norm(e):
        return math.sqrt(ngs.Integrate(ngs.InnerProduct(e, e), system.mesh, order=degree))

    return {"sigma": norm(sigma - exact.sigma), "u": norm(u - exact.u),
            "eta": norm(eta - exact.eta)}


def convergence_study(family: str = "peers", order: int = 0, levels=(0, 1, 2, 3),
                      exact: ExactElasticity | None = None) -> list[dict]:
    """Errors, unknowns and seconds per uniform level of the unit square, with the observed
    orders ``<quantity>_order`` (None on the first level).

    Returns
    -------
    list of dict
        One row per level: ``family``, ``order``, ``level``, ``h``, ``ndof``, ``seconds``
        (assembly + factorisation + solve), the errors of :data:`QUANTITIES` and their
        orders.
    """
    rows = []
    for level in levels:
        system = assemble_elasticity(unit_square(level), family, order, exact)
        gf, solve_seconds = solve_elasticity(system)
        rows.append({"family": family, "order": order, "level": level, "h": 2.0 ** -(level + 1),
                     "ndof": system.fes.ndof, "seconds": system.seconds + solve_seconds,
                     **l2_errors(system, gf, exact)})
    for q in QUANTITIES:
        for row, rate in zip(rows, observed_rates([r["ndof"] for r in rows],
                                                  [r[q] for r in rows])):
            row[q + "_order"] = rate
    return rows


def infsup_constants(family: str = "peers", order: int = 0, levels=(0, 1, 2, 3)
                     ) -> list[dict]:
    """The discrete inf-sup constant beta_h of b + s (Lemma 3.28) per level on the unit
    square clamped all round, in the H(div) x L^2 x L^2 norms
    (:func:`ngdual.verification.infsup.smallest_singular_values`).

    Returns
    -------
    list of dict
        ``family``, ``order``, ``level``, ``h``, ``ndof`` and ``beta``.
    """
    rows = []
    for level in levels:
        system = assemble_elasticity(unit_square(level), family, order,
                                     dirichlet="left|bottom|right|top", neumann="")
        G = gram_matrix(system)
        s, m = system.sigma, system.mult
        beta = smallest_singular_values(G[s][:, s], system.block(s, m), G[m][:, m], k=1)[0]
        rows.append({"family": family, "order": order, "level": level,
                     "h": 2.0 ** -(level + 1), "ndof": system.fes.ndof, "beta": float(beta)})
    return rows


def format_rows(rows: list[dict], quantities=QUANTITIES) -> str:
    """The study as a text table (errors with their observed orders)."""
    head = (f"{'family':>6} {'k':>2} {'lvl':>3} {'ndof':>7} {'sec':>7} "
            + " ".join(f"{q:>10} {'ord':>5}" for q in quantities))
    lines = [head]
    for row in rows:
        cells = [f"{row[q]:10.3e} " + (f"{row[q + '_order']:5.2f}"
                                        if row.get(q + "_order") is not None else f"{'':>5}")
                 for q in quantities]
        lines.append(f"{row['family']:>6} {row['order']:2d} {row['level']:3d} {row['ndof']:7d} "
                     f"{row['seconds']:7.3f} " + " ".join(cells))
    return "\n".join(lines)
