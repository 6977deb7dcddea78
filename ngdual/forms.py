"""The bilinear and linear forms of (3.62) and the assembled block system (3.97)/(3.103).

All forms are NGSolve integrals on the fine mesh T_h; the multipliers phi,
lambda_t, lambda_n are assembled in the fine P1 trace spaces and restricted to
their coarse meshes by the prolongation of :mod:`ngdual.boundary`
(``K = P^T K_fine P``); at order k (``[discretisation]``) the facet P_k multipliers are
assembled in the same way on their host space and mapped from their Bernstein
coefficients (:mod:`ngdual.boundary.facet`), and the coarse multipliers of degree k + 1
from theirs on the h~ mesh (:mod:`ngdual.boundary.coarse_order`). The unknown vector is
ordered

    [sigma | u, eta, phi, lambda_t | lambda_n]

so that, with the index sets of :class:`DiscreteProblem`,
``A = K[sigma, sigma]``, ``B = K[sigma, mult]``, ``C_n = K[sigma, lam_n]`` and
the right-hand side is ``(g, b)`` as in (3.103).
"""

from __future__ import annotations

import contextlib
import time
from dataclasses import dataclass, field

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from . import peers
from .boundary import BoundaryMeshes, CoarseMesh, FacetMesh, end_rule, host_space
from .boundary.coarse_order import CoarseOrderMesh
from .contact import ContactBoundary, curve_normal, gap_coefficient, trace_space
from .expr import Expression
from .geometry import length_scale, tangent
from .scene import Scene
from .sparse import to_scipy

# The data f, u_D, t0 and g may be any formula: f is integrated with the rule of degree 6 on
# every triangle and u_D, t0, g with that of degree 12 on every edge, the rules NGSolve
# chose for these forms when the cubic bubble element still had edge functions (twice its
# order 3, plus 6 on the edges); quadrature_check evaluates the formulas on the same points.
LOAD_ORDER, TRACE_ORDER = 6, 12
LOAD_RULES = {ngs.TRIG: ngs.IntegrationRule(ngs.TRIG, LOAD_ORDER)}
TRACE_RULES = {ngs.SEGM: ngs.IntegrationRule(ngs.SEGM, TRACE_ORDER)}
# The volume integrands of a~, b and s are polynomials of degree <= 4 on every (affine)
# triangle: sigma, tau are RT_0 (degree 1) plus Curl of a cubic bubble (degree 2), u is
# constant, eta linear. The 6-point rule of degree 4 integrates them exactly; NGSolve's
# default (degree 6, twice the order 3 of the bubble space) gives the same matrix to
# round-off with twice the points. At order k the stress has degree k + 2 (k + 1 for AFW)
# and the compliance integrand twice that (:func:`volume_rules`).
EXACT_VOLUME_RULES = {ngs.TRIG: ngs.IntegrationRule(ngs.TRIG, 4)}


def volume_rules(order: int = 0, family: str = "peers") -> dict:
    """The rule of degree 2 * :func:`ngdual.peers.stress_degree` on every triangle, which
    integrates the PEERS form of order k exactly (:data:`EXACT_VOLUME_RULES` at k = 0)."""
    degree = 2 * peers.stress_degree(family, order)
    return EXACT_VOLUME_RULES if degree == 4 else {ngs.TRIG: ngs.IntegrationRule(ngs.TRIG,
                                                                                 degree)}
# NGSolve's task manager wakes and synchronises its threads in every parallel loop: on a
# 2-core machine with the other core busy a loop waits up to ~0.1 s for the descheduled
# worker whatever its size (d.Assemble of hertz-cylinder, 28 000 unknowns: 0.11 s in the
# task manager, 0.003 s without). It pays only for the volume forms from this many elements
# on (level 5 of Example 3.46, twice as fast on an idle machine); the boundary forms are
# always assembled in one thread. Both assemble the same matrices bit for bit.
PARALLEL_ELEMENTS = 8192


def parallel_tasks(mesh: ngs.Mesh):
    """NGSolve's task manager for a volume assembly on ``mesh`` from
    :data:`PARALLEL_ELEMENTS` triangles on, else a context that does nothing."""
    return ngs.TaskManager() if mesh.ne >= PARALLEL_ELEMENTS else contextlib.nullcontext()


@contextlib.contextmanager
def differentiated_integrands():
    """NGSolve's symbolic integrators added to a form and assembled inside (both: an integrator
    made inside and assembled outside gives another matrix) take their element matrices from
    the derivatives of the integrand with respect to the test functions
    (``ngsglobals.symbolic_integrator_uses_diff``), instead of evaluating the integrand once
    per pair of trial and test function components: the broken PEERS block
    (:func:`broken_peers`) of hertz-cylinder, level 5, assembles in 1.2 s instead of 1.6 s
    (one thread), to the same bits (every shipped scene at k = 0, hertz-cylinder at k = 1)."""
    default = ngs.ngsglobals.symbolic_integrator_uses_diff
    ngs.ngsglobals.symbolic_integrator_uses_diff = True
    try:
        yield
    finally:
        ngs.ngsglobals.symbolic_integrator_uses_diff = default


def peers_form(trial: dict, test: dict, lame: tuple[float, float], order: int = 0,
               family: str = "peers") -> ngs.comp.SumOfIntegrals:
    """The PEERS block of (3.62) on T_h, with its exact volume rule (:func:`volume_rules`):

        a~(sigma, tau) + b(u, tau) + b(v, sigma) + s(eta, tau) + s(xi, sigma),

    a~ the compliance form (3.32) for Lame's ``lame = (lambda, mu)``, b(u, tau) =
    int u . div tau dx and s(eta, tau) = int eta as(tau) dx.

    Parameters
    ----------
    trial, test : dict
        Trial and test functions keyed by the names of :data:`ngdual.peers.PEERS`, from
        any product space that holds the PEERS triple (the broken one of
        :func:`broken_peers`, the conforming one of :mod:`ngdual.verification`).
    lame : tuple of float
        Lame's constants (lambda, mu).
    order, family : int, str
        The order k and the family of the spaces (:func:`ngdual.peers.family_spaces`), which
        fix the degree of the rule.
    """
    lam, mu = lame
    sig, tau = (peers.stress_rows(f["r1"], f["r2"], f.get("b1"), f.get("b2"))
                for f in (trial, test))
    dx = ngs.dx(intrules=volume_rules(order, family))
    # three integrals, each compiled on its own: the element matrices of a~, b, s are summed
    # in this order in every assembly. Each is written on the rows of sigma and tau, not on
    # the 2x2 matrices of peers.triple: the same element matrices bit for bit, and the whole
    # form assembles in 0.08 s instead of 0.13 s on 6 465 triangles (hertz-cylinder,
    # adaptive step 3, one thread)
    return (peers.compliance_rows(sig, tau, lam, mu).Compile() * dx                   # a~
            + sum(trial[u] * ngs.div(test[r]) + test[u] * ngs.div(trial[r])
                  for u, r in (("u1", "r1"), ("u2", "r2"))).Compile() * dx           # b
            + (trial["eta"] * peers.asym_rows(tau)
               + test["eta"] * peers.asym_rows(sig)).Compile() * dx)                  # s


def boundary_regex(labels: list[str]) -> str:
    return "|".join(labels)


def _trace_space(mesh: ngs.Mesh, labels: list[str]) -> ngs.FESpace:
    """Fine P1 trace space on the boundary part ``labels`` (compressed)."""
    return ngs.Compress(ngs.H1(mesh, order=1, definedon=mesh.Boundaries(boundary_regex(labels))))


@dataclass
class Spaces:
    """Fine component spaces, the boundary meshes of the multipliers and their prolongations.

    Building this object assembles nothing: it is all that DOF counting needs. ``order`` is
    the order k of PEERS_k, ``family`` that of the multipliers (``discretisation``: the
    thesis' P1 on h~ at k = 0 and continuous P_{k+1} on h~ at k >= 1 in the Bernstein basis,
    ``"coarse"``, :mod:`ngdual.boundary.coarse_order`; or P_k on the fine edges in the
    Bernstein basis, ``"facet"``, :mod:`ngdual.boundary.facet`).
    """

    mesh: ngs.Mesh
    components: dict[str, ngs.FESpace]
    neumann: CoarseMesh | None
    contact: CoarseMesh | None
    friction: CoarseMesh | None
    prolongations: dict[str, sp.csr_matrix] = field(default_factory=dict)
    end_hats: dict[str, sp.csr_matrix] = field(default_factory=dict)
    gamma_c: ContactBoundary | None = None
    order: int = 0
    family: str = "coarse"

    @classmethod
    def build(cls, scene: Scene, mesh: ngs.Mesh, coarse: BoundaryMeshes | None = None) -> Spaces:
        """Spaces on ``mesh``; ``coarse`` carries coarse meshes over from an adaptive step
        (the facet multipliers live on the fine edges of ``mesh`` and need none)."""
        if scene.discretisation.family == "facet" or scene.discretisation.order > 0:
            return cls._order_k(scene, mesh, coarse)
        comps = peers.peers_spaces(mesh)
        coarse = coarse or BoundaryMeshes.for_scene(scene, mesh)
        neumann = contact = friction = None
        prolong, end_hats = {}, {}
        if scene.labels("neumann"):
            neumann = coarse.neumann
            space = _trace_space(mesh, scene.labels("neumann"))
            comps["phi1"] = comps["phi2"] = space
            edge_dofs = neumann.fine_edge_dofs(space)
            prolong["phi1"] = prolong["phi2"] = neumann.p1_prolongation(edge_dofs, space.ndof)
            end_hats["phi1"] = end_hats["phi2"] = neumann.p1_prolongation(edge_dofs, space.ndof,
                                                                          ends=True)
        gamma_c = None
        if scene.has_contact:
            contact = coarse.contact
            space = trace_space(mesh, scene.labels("contact"))
            comps["lam_t"] = comps["lam_n"] = space
            if scene.has_friction:
                friction = coarse.friction
            gamma_c = ContactBoundary.build(scene, contact, friction, space)
            prolong["lam_t"] = prolong["lam_n"] = gamma_c.prolongation(space.ndof)
            end_hats["lam_t"] = end_hats["lam_n"] = gamma_c.prolongation(space.ndof, ends=True)
        return cls(mesh, comps, neumann, contact, friction, prolong, end_hats, gamma_c)

    @classmethod
    def _order_k(cls, scene: Scene, mesh: ngs.Mesh, coarse: BoundaryMeshes | None) -> Spaces:
        """PEERS_k with the multipliers of its family: the facet P_k on the fine edges (no
        end is fixed, so nothing is lifted), or the coarse P_{k+1} on the h~ meshes
        (``coarse``, or grouped afresh), fixed at the fixed ends as the P1 hats are."""
        order, family = scene.discretisation.order, scene.discretisation.family
        comps = peers.peers_spaces(mesh, order)
        if family == "coarse":
            coarse = coarse or BoundaryMeshes.for_scene(scene, mesh)
        meshes, prolong, end_hats = {}, {}, {}
        for role, names in (("neumann", ("phi1", "phi2")), ("contact", ("lam_t", "lam_n"))):
            labels = scene.labels(role)
            if not labels:
                continue
            if family == "facet":
                meshes[role] = FacetMesh.on_fine(mesh, labels, order, end_rule(scene, mesh, role))
                space = host_space(mesh, labels, order)
                ends = sp.csr_matrix((space.ndof, 0))
            else:
                meshes[role] = CoarseOrderMesh.of(getattr(coarse, role), order + 1)
                space = host_space(mesh, labels, order + 1)
                ends = meshes[role].prolongation(space, labels, ends=True)
            p = meshes[role].prolongation(space, labels)
            for name in names:
                comps[name], prolong[name], end_hats[name] = space, p, ends
        gamma_c = None
        if "contact" in meshes:
            gamma_c = ContactBoundary.build(scene, meshes["contact"], None, comps["lam_n"])
        return cls(mesh, comps, meshes.get("neumann"), meshes.get("contact"), None, prolong,
                   end_hats, gamma_c, order, family)

    def coarse_ndof(self, name: str) -> int:
        if name in self.prolongations:
            return self.prolongations[name].shape[1]
        return self.components[name].ndof

    def dofs(self) -> dict[str, int]:
        """Degrees of freedom per space, named as in Table 3.1 (L: nu on h^)."""
        n = self.coarse_ndof
        return {"X": sum(n(c) for c in peers.STRESS),
                "M": n("u1") + n("u2"),
                "S": n("eta"),
                "N": n("phi1") + n("phi2") if self.neumann else 0,
                "C": n("lam_n") if self.contact else 0,
                "L": self.friction.n_edges if self.friction else 0}


@dataclass
class BrokenPeers:
    """The PEERS block of (3.62), assembled once, element by element.

    The Raviart-Thomas rows of sigma are broken (every triangle has its own RT_k
    functions); the bubbles, u and eta are those of the conforming space. The element matrices
    of a~ + b + s are the same as on the conforming space, but no two triangles share a
    stress unknown, so ``matrix`` keeps every triangle's matrix apart: the conforming PEERS
    block is K = E^T K_b E (:meth:`summed`), E the 0/1 map from conforming to broken
    unknowns, and the hybridisation (:class:`ngdual.solvers.hybrid.HybridSystem`,
    :class:`ngdual.solvers.hybrid_order.OrderHybridSystem`) eliminates the element-local
    unknowns from the same matrix.

    Attributes
    ----------
    fes : ngsolve.FESpace
        The broken product space, components :data:`ngdual.peers.PEERS`.
    form : ngsolve.BilinearForm
        The assembled form, which owns the arrays of ``matrix``.
    matrix : scipy.sparse.csr_matrix
        K_b, with NGSolve's sparsity pattern (every pair of unknowns of a triangle, explicit
        zeros included).
    conforming : numpy.ndarray
        The conforming PEERS unknown that every broken unknown restricts (E as an index map).
    """

    fes: ngs.FESpace
    form: ngs.BilinearForm
    matrix: sp.csr_matrix
    conforming: np.ndarray

    def summed(self, size: int) -> sp.csr_matrix:
        """K = E^T K_b E, the PEERS block of (3.62), as the leading block of a ``size`` x
        ``size`` matrix (the PEERS unknowns come first).

        Every entry is the sum of at most two element entries (an edge has two triangles),
        so it equals the conforming assembly's bit for bit, whatever the order of the sum.
        """
        n_broken = self.matrix.shape[0]
        E = sp.csr_matrix((np.ones(n_broken), self.conforming, np.arange(n_broken + 1)),
                          shape=(n_broken, size))
        return E.T.tocsr() @ (self.matrix @ E)

    def apply(self, x: np.ndarray, size: int) -> np.ndarray:
        """K x = E^T (K_b (E x)) for the PEERS block of :meth:`summed` (a vector of length
        ``size``), without forming K: the same products up to the order of the sums."""
        return np.bincount(self.conforming, self.matrix @ x[self.conforming], minlength=size)

    def apply_magnitudes(self, magnitudes: np.ndarray, size: int) -> np.ndarray:
        """E^T |K_b| E m for m = ``magnitudes`` >= 0 (a vector of length ``size``): every
        element entry's magnitude times m. With m = |x| this is, row by row, the size of the
        terms whose sum is (K x)_i, and at least (|K| |x|)_i (an entry of K is the sum of at
        most two element entries)."""
        return np.bincount(self.conforming, abs(self.matrix) @ magnitudes[self.conforming],
                           minlength=size)

    def to_conforming(self, values: np.ndarray) -> np.ndarray:
        """The conforming PEERS coefficients of broken ones whose normal fluxes agree across
        every edge (up to rounding): the mean of the two triangles' values."""
        count = np.bincount(self.conforming)
        return np.bincount(self.conforming, values, minlength=len(count)) / count


def broken_peers(spaces: Spaces, lame: tuple[float, float]) -> BrokenPeers:
    """Assemble the PEERS block of (3.62) of order ``spaces.order`` with broken
    Raviart-Thomas rows (:class:`BrokenPeers`): ``HDiv(order=k, RT=True, discontinuous=True)``,
    every triangle with its own RT_k functions."""
    mesh, order = spaces.mesh, spaces.order
    broken_rt = ngs.HDiv(mesh, order=0, discontinuous=True) if order == 0 else ngs.HDiv(
        mesh, order=order, RT=True, discontinuous=True)
    comps = {name: broken_rt if name in ("r1", "r2") else spaces.components[name]
             for name in peers.PEERS}
    fes = ngs.FESpace(list(comps.values()))
    a = ngs.BilinearForm(fes)
    with differentiated_integrands():
        a += peers_form(dict(zip(peers.PEERS, fes.TrialFunction())),
                        dict(zip(peers.PEERS, fes.TestFunction())), lame, order)
        with parallel_tasks(mesh):
            a.Assemble()
    edge = _edge_of_broken(spaces.components["r1"], broken_rt) if order == 0 else \
        _restricted_dofs(spaces.components["r1"], broken_rt)
    conforming, offset = [], 0
    for name in peers.PEERS:
        own = edge if name in ("r1", "r2") else np.arange(comps[name].ndof)
        conforming.append(offset + own)
        offset += spaces.components[name].ndof
    return BrokenPeers(fes, a, to_scipy(a.mat, copy=False), np.concatenate(conforming))


def conforming_peers(spaces: Spaces, lame: tuple[float, float], size: int) -> sp.csr_matrix:
    """The PEERS block of (3.62) of order ``spaces.order``, assembled on the conforming
    spaces, as the leading block of a ``size`` x ``size`` matrix."""
    comps = [spaces.components[name] for name in peers.PEERS]
    fes = ngs.FESpace(comps)
    a = ngs.BilinearForm(fes)
    with differentiated_integrands():
        a += peers_form(dict(zip(peers.PEERS, fes.TrialFunction())),
                        dict(zip(peers.PEERS, fes.TestFunction())), lame, spaces.order)
        with parallel_tasks(spaces.mesh):
            a.Assemble()
    K = to_scipy(a.mat).tocoo()
    return sp.csr_matrix((K.data, (K.row, K.col)), shape=(size, size))


def _restricted_dofs(rt: ngs.FESpace, broken_rt: ngs.FESpace) -> np.ndarray:
    """The RT_k function (of ``rt``) whose restriction to its triangle every broken one is.

    A discontinuous NGSolve space has the element's own shape functions, in the element's
    order, with the orientation of the global edges: the broken dofs of a triangle restrict
    its conforming dofs position by position.
    """
    # GetDofNrs of the base space is eight times faster than through the compression
    base = rt.GetBaseSpace() if isinstance(rt, ngs.comp.Compress) else rt
    edge = np.full(broken_rt.ndof, -1, dtype=np.int64)
    for nr in range(rt.mesh.ne):  # ElementId by number: five times faster than Elements()
        el = ngs.ElementId(ngs.VOL, nr)
        edge[list(broken_rt.GetDofNrs(el))] = base.GetDofNrs(el)
    if base is not rt:
        edge = np.where(edge >= 0, _compressed_numbers(rt)[edge], -1)
    if np.any(edge < 0):
        raise RuntimeError("NGSolve's broken Raviart-Thomas functions are not restrictions "
                           "of the continuous ones")
    return edge


def _compressed_numbers(space: ngs.comp.Compress) -> np.ndarray:
    """The dof of the compressed ``space`` every dof of its base space is (-1: removed), read
    from NGSolve's embedding of the one into the other."""
    embedding = space.Embedding()
    numbers, base = embedding.CreateRowVector(), embedding.CreateColVector()
    numbers.FV().NumPy()[:] = np.arange(1, space.ndof + 1)
    base.data = embedding * numbers
    return np.rint(base.FV().NumPy()).astype(np.int64) - 1


def _edge_of_broken(rt: ngs.FESpace, broken_rt: ngs.FESpace, tol: float = 1e-8) -> np.ndarray:
    """The RT_0 function (of ``rt``) whose restriction to its triangle every broken one is.

    Read from M[i, j] = sum_T int_{dT} (psi_j . n)(psi~_i . n) ds: the normal trace of an
    RT_0 function vanishes on all edges but its own, so every row of M has one nonzero,
    positive where the broken function has the continuous one's orientation.
    """
    n = ngs.specialcf.normal(2)
    form = ngs.BilinearForm(trialspace=rt, testspace=broken_rt)
    form += (rt.TrialFunction() * n) * (broken_rt.TestFunction() * n) * ngs.dx(
        element_boundary=True, intrules={ngs.SEGM: ngs.IntegrationRule(ngs.SEGM, 0)})
    with parallel_tasks(rt.mesh):   # a fifth of the PEERS block's time on one thread
        form.Assemble()
    M = to_scipy(form.mat, copy=False)
    counts = np.diff(M.indptr)
    rows = np.repeat(np.arange(M.shape[0]), counts)
    # relative to each row's largest entry: M[i, j] ~ 1/|e|, which spans the mesh's grading
    magnitude = np.abs(M.data)
    row_max = np.zeros(M.shape[0])
    np.maximum.at(row_max, rows, magnitude)
    own = magnitude > tol * row_max[rows]
    if not (np.array_equal(np.bincount(rows[own], minlength=M.shape[0]),
                           np.ones(M.shape[0], dtype=int)) and np.all(M.data[own] > 0)):
        raise RuntimeError("NGSolve's broken Raviart-Thomas functions are not restrictions "
                           "of the continuous ones")
    edge = np.empty(M.shape[0], dtype=np.int64)
    edge[rows[own]] = M.indices[own]
    return edge


@dataclass
class DiscreteProblem:
    """The assembled discrete problem (3.62) without friction terms.

    Attributes
    ----------
    K : scipy.sparse.csr_matrix
        Symmetric matrix of all unknowns (sigma, u, eta, phi, lambda_t, lambda_n): its PEERS
        block summed from ``broken`` plus ``boundary``, formed on first use. The hybridised
        solvers never form it: they read the multipliers' rows from ``boundary``, K x from
        :meth:`apply` and the size of its terms from :meth:`terms` (Example 3.46 with
        PEERS_1, 50 017 unknowns: a solve 10 % faster than with K and its blocks formed).
    boundary : scipy.sparse.csr_matrix
        P^T D P: the couplings d_N, d_C of the boundary multipliers with sigma (K less its
        PEERS block; zero without Gamma_N and Gamma_C).
    rhs : numpy.ndarray
        Right-hand side (g, -f, 0, t0, 0, 0).
    lift : numpy.ndarray
        Fine coefficients of the known end values phi = -u_D at the ends of
        Gamma_N (zero for the homogeneous Dirichlet data of the thesis).
    blocks : dict[str, slice]
        Position of every component in the unknown vector.
    broken : BrokenPeers
        The PEERS block element by element, from which K's PEERS block is summed (the
        input of the hybridised solvers, :mod:`ngdual.solvers.hybrid` and
        :mod:`ngdual.solvers.hybrid_order`).
    """

    scene: Scene
    spaces: Spaces
    fes: ngs.FESpace
    names: list[str]
    P: sp.csr_matrix
    boundary: sp.csr_matrix
    rhs: np.ndarray
    blocks: dict[str, slice]
    lift: np.ndarray
    broken: BrokenPeers
    assemble_seconds: float
    level: int | None = None
    _K: sp.csr_matrix | None = field(default=None, init=False, repr=False)

    @property
    def K(self) -> sp.csr_matrix:
        """The matrix of (3.62), formed on first use (see the attributes)."""
        if self._K is None:
            # the PEERS unknowns come first and are not prolonged
            K = self.broken.summed(self.n) + self.boundary
            K.eliminate_zeros()
            self._K = K
        return self._K

    @property
    def n(self) -> int:
        """The number of unknowns (rows of K)."""
        return len(self.rhs)

    @property
    def n_peers(self) -> int:
        """The number of PEERS unknowns (sigma, u, eta: they come first; K's PEERS block)."""
        return max(self.blocks[name].stop for name in peers.PEERS if name in self.blocks)

    @property
    def units(self) -> tuple[float, float]:
        """(E*, L): the plane-strain modulus E / (1 - nu^2) and the body's length scale
        (:func:`ngdual.geometry.length_scale`), the units in which a solver judges its
        residuals (:class:`ngdual.solvers.scales.Scales`)."""
        material = self.scene.material
        return (material.E / (1.0 - material.nu ** 2),
                length_scale(self.scene.geometry.curves()))

    def apply(self, x: np.ndarray) -> np.ndarray:
        """K x, without forming K if it is not formed yet (:meth:`BrokenPeers.apply`)."""
        if self._K is not None:
            return self._K @ x
        return self.broken.apply(x, self.n) + self.boundary @ x

    def terms(self, x: np.ndarray) -> np.ndarray:
        """The size of the terms of K x row by row, from the element matrices and the
        boundary couplings (:meth:`BrokenPeers.apply_magnitudes`, |boundary| |x|), without
        forming K: at least |K| |x| entry by entry, equal where no two element entries of
        K cancel."""
        magnitudes = np.abs(x)
        return self.broken.apply_magnitudes(magnitudes, self.n) + abs(self.boundary) @ magnitudes

    def index(self, *names: str) -> np.ndarray:
        """Indices of the listed components in the unknown vector."""
        present = [n for n in names if n in self.blocks]
        if not present:
            return np.zeros(0, dtype=int)
        return np.concatenate([np.arange(self.blocks[n].start, self.blocks[n].stop)
                               for n in present])

    @property
    def sigma(self) -> np.ndarray:
        return self.index(*peers.STRESS)

    @property
    def mult(self) -> np.ndarray:
        """u, eta, phi, lambda_t: the unknowns of the fixed saddle-point matrix."""
        return self.index("u1", "u2", "eta", "phi1", "phi2", "lam_t")

    @property
    def lam_n(self) -> np.ndarray:
        return self.index("lam_n")

    @property
    def saddle(self) -> np.ndarray:
        """sigma followed by mult: the rows and columns of [[A, B], [B^T, 0]]."""
        return np.concatenate([self.sigma, self.mult])

    def block(self, rows: np.ndarray, cols: np.ndarray) -> sp.csr_matrix:
        """K[rows][:, cols]; from ``boundary`` alone where the rows or the columns are all
        multipliers (the PEERS block has none of their entries)."""
        if self._K is None and (np.min(rows, initial=self.n) >= self.n_peers
                                or np.min(cols, initial=self.n) >= self.n_peers):
            return self.boundary[rows][:, cols].tocsr()
        return self.K[rows][:, cols].tocsr()

    def to_fine(self, x: np.ndarray) -> np.ndarray:
        """Coefficients of the fine product space from a coarse unknown vector."""
        return self.P @ x + self.lift


def traction_coefficient(scene: Scene, mesh: ngs.Mesh) -> ngs.CoefficientFunction:
    """The traction t0 on Gamma_N as one vector coefficient: the formula pair of each
    Gamma_N side on that side (:meth:`~ngdual.scene.Scene.tractions`), zero elsewhere.

    >>> from ngdual.mesh import build_mesh
    >>> from ngdual.scene import load_scene
    >>> scene = load_scene("hertz-cylinder", ['loads.traction={left = ["1", "0"]}'])
    >>> mesh = build_mesh(scene.geometry, 1)
    >>> t0 = traction_coefficient(scene, mesh)
    >>> gamma_n = mesh.Boundaries("left|right")          # the sides are 4 long, right is free
    >>> [round(v, 6) for v in ngs.Integrate(t0, mesh, ngs.BND, definedon=gamma_n)]
    [4.0, 0.0]
    """
    pairs = {label: tuple(both) for label, both in scene.tractions().items()}
    if len(set(pairs.values())) == 1:  # one formula pair on every side: no per-side switch
        return ngs.CF(tuple(Expression(e).coefficient() for e in next(iter(pairs.values()))))
    return mesh.BoundaryCF({label: ngs.CF(tuple(Expression(e).coefficient() for e in both))
                            for label, both in pairs.items()}, default=ngs.CF((0.0, 0.0)))


def _forms(scene: Scene, fes: ngs.FESpace, names: list[str]):
    """The forms of (3.62) besides the PEERS block (:func:`broken_peers`): the couplings d_N,
    d_C with the boundary multipliers (None without Gamma_N and Gamma_C) and the right-hand
    side.

    The PEERS block is a form of its own, so that the large volume matrix never meets the
    prolongation of the multipliers (:func:`assemble`).
    """
    mesh = fes.mesh
    trial = dict(zip(names, fes.TrialFunction()))
    test = dict(zip(names, fes.TestFunction()))
    n = ngs.specialcf.normal(2)
    t = tangent(n)
    trac_sig = peers.stress_traction(trial["r1"], trial["r2"])
    trac_tau = peers.stress_traction(test["r1"], test["r2"])
    v = ngs.CF((test["u1"], test["u2"]))
    d = ngs.BilinearForm(fes) if {"phi1", "lam_n"} & set(names) else None
    rhs = ngs.LinearForm(fes)
    f = ngs.CF(tuple(Expression(e).coefficient() for e in scene.loads.body_force))
    rhs += -f * v * ngs.dx(intrules=LOAD_RULES)                               # -f(v)
    ds_d = ngs.ds(definedon=mesh.Boundaries(boundary_regex(scene.labels("dirichlet"))),
                  intrules=TRACE_RULES)
    u_d = ngs.CF(tuple(Expression(e).coefficient() for e in scene.loads.displacement))
    rhs += u_d * trac_tau * ds_d                                              # u = u_D on Gamma_D
    if "phi1" in names:
        ds_n = ngs.ds(definedon=mesh.Boundaries(boundary_regex(scene.labels("neumann"))),
                      intrules=TRACE_RULES)
        phi, psi = ngs.CF((trial["phi1"], trial["phi2"])), ngs.CF((test["phi1"], test["phi2"]))
        d += (phi * trac_tau + psi * trac_sig) * ds_n                         # d_N(phi, tau)
        rhs += traction_coefficient(scene, mesh) * psi * ds_n                 # t0(psi)
    if "lam_n" in names:
        ds_c = ngs.ds(definedon=mesh.Boundaries(boundary_regex(scene.labels("contact"))),
                      intrules=TRACE_RULES)
        if scene.discretisation.family == "facet" or scene.discretisation.order > 0:
            # the normal and tangent of the boundary curve, not of its chords (curve_normal)
            n = curve_normal(scene, mesh)
            t = tangent(n)
        d += (trial["lam_t"] * (t * trac_tau) + test["lam_t"] * (t * trac_sig)) * ds_c  # d_Ct
        d += (trial["lam_n"] * (n * trac_tau) + test["lam_n"] * (n * trac_sig)) * ds_c  # d_Cn
        if scene.contact.discrete_gap == "thesis":
            rhs += gap_coefficient(scene) * (n * trac_tau) * ds_c             # g(tau)
    return d, rhs


def assemble(scene: Scene, mesh: ngs.Mesh, coarse: BoundaryMeshes | None = None
             ) -> DiscreteProblem:
    """Assemble the block system of (3.62) for ``scene`` on ``mesh`` (``coarse``: see Spaces)."""
    start = time.perf_counter()
    spaces = Spaces.build(scene, mesh, coarse)
    names = list(spaces.components)
    fes = ngs.FESpace([spaces.components[n] for n in names])
    broken = broken_peers(spaces, scene.material.lame)
    d, rhs = _forms(scene, fes, names)
    for form in (d, rhs):
        if form is not None:
            form.Assemble()
    P, blocks = _prolongation(spaces, names)
    lift = _end_lift(scene, spaces, fes, names)
    F = P.T @ rhs.vec.FV().NumPy()
    if d is not None:
        D = to_scipy(d.mat)
        boundary = (P.T @ D @ P).tocsr()
        # a has no entries in the multipliers' columns, where lift and the gap live
        F -= P.T @ (D @ (lift - _discrete_gap(scene, spaces, fes, names)))
    else:
        boundary = sp.csr_matrix((P.shape[1], P.shape[1]))
    boundary.eliminate_zeros()
    return DiscreteProblem(scene, spaces, fes, names, P, boundary, F, blocks, lift, broken,
                           time.perf_counter() - start)


def _prolongation(spaces: Spaces, names: list[str]) -> tuple[sp.csr_matrix, dict[str, slice]]:
    """P (fine unknowns x coarse unknowns): the identity on a component without a
    prolongation, ``spaces.prolongations[name]`` on the others, block by block in the order
    of ``names``; and every component's columns.

    A run of components without a prolongation is one identity block (one sparse matrix
    instead of one per component: the same P).
    """
    parts, blocks, offset, identity = [], {}, 0, 0
    for name in names:
        p = spaces.prolongations.get(name)
        width = spaces.components[name].ndof if p is None else p.shape[1]
        blocks[name] = slice(offset, offset + width)
        offset += width
        if p is None:
            identity += width
            continue
        if identity:
            parts.append(sp.identity(identity, format="csr"))
            identity = 0
        parts.append(p)
    if identity:
        parts.append(sp.identity(identity, format="csr"))
    return sp.block_diag(parts, format="csr"), blocks


def _discrete_gap(scene: Scene, spaces: Spaces, fes: ngs.FESpace, names: list[str]
                  ) -> np.ndarray:
    """g_h = I_h~ g in the lambda_n block of the fine unknowns (``contact.discrete_gap =
    "nodal"``; zero for ``"thesis"``, whose g(tau) is the integral of g in :func:`_forms`).

    g(tau) = d_Cn(g_h, tau): the gap enters like a known part of lambda_n, so that
    lambda_n - g_h = -u_n lies in the multiplier space
    (:meth:`ngdual.contact.ContactBoundary.gap_interpolant`).
    """
    gap = np.zeros(fes.ndof)
    if spaces.gamma_c is None or scene.contact.discrete_gap == "thesis":
        return gap
    rng = fes.Range(names.index("lam_n"))
    gap[rng.start:rng.stop] = spaces.gamma_c.gap_interpolant(spaces.prolongations["lam_n"],
                                                             spaces.end_hats["lam_n"])
    return gap


def _end_lift(scene: Scene, spaces: Spaces, fes: ngs.FESpace, names: list[str]) -> np.ndarray:
    """The known values at the fixed ends of the coarse P1 spaces, where they have no dofs.

    phi = -u_D where Gamma_N meets Gamma_D; lambda_n = g - u_D.n and lambda_t = -u_D.t
    where Gamma_C meets Gamma_D (zero with ``contact.ends = "thesis"``,
    :meth:`ContactBoundary.end_values`).
    """
    values = {}
    if spaces.neumann is not None:
        ends = spaces.neumann.end_points()
        for comp, formula in zip(("phi1", "phi2"), scene.loads.displacement):
            values[comp] = -Expression(formula).numpy(ends[:, 0], ends[:, 1])
    if spaces.gamma_c is not None:
        values["lam_n"], values["lam_t"] = spaces.gamma_c.end_values(scene.loads.displacement)
    lift = np.zeros(fes.ndof)
    for comp, value in values.items():
        rng = fes.Range(names.index(comp))
        lift[rng.start:rng.stop] = spaces.end_hats[comp] @ value
    return lift
