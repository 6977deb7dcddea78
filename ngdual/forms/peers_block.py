"""The PEERS block of (3.62): the form a~ + b + s (:func:`peers_form`), assembled element by
element with broken Raviart-Thomas rows (:class:`BrokenPeers`) or on the conforming spaces."""

from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from .. import peers
from ..mesh import triangles_at
from ..sparse import to_scipy
from .integrators import differentiated_integrands, parallel_tasks
from .rules import volume_rules
from .spaces import Spaces


def peers_form(trial: dict, test: dict, lame: tuple[float, float], order: int = 0,
               family: str = "peers", elements: ngs.BitArray | None = None
               ) -> ngs.comp.SumOfIntegrals:
    """The PEERS block of (3.62) on T_h, with its exact volume rule
    (:func:`~ngdual.forms.rules.volume_rules`):

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
    elements : ngsolve.BitArray, optional
        The triangles to integrate over (NGSolve's ``definedonelements``); default all.
    """
    lam, mu = lame
    sig, tau = (peers.stress_rows(f["r1"], f["r2"], f.get("b1"), f.get("b2"))
                for f in (trial, test))
    dx = ngs.dx(intrules=volume_rules(order, family)) if elements is None else ngs.dx(
        intrules=volume_rules(order, family), definedonelements=elements)
    # three integrals, each compiled on its own: the element matrices of a~, b, s are summed
    # in this order in every assembly. Each is written on the rows of sigma and tau, not on
    # the 2x2 matrices of peers.triple: the same element matrices bit for bit, and the whole
    # form assembles in 0.08 s on 6 465 triangles of hertz-cylinder (one thread), where the
    # matrix form takes 0.13 s
    return (peers.compliance_rows(sig, tau, lam, mu).Compile() * dx                   # a~
            + sum(trial[u] * ngs.div(test[r]) + test[u] * ngs.div(trial[r])
                  for u, r in (("u1", "r1"), ("u2", "r2"))).Compile() * dx           # b
            + (trial["eta"] * peers.asym_rows(tau)
               + test["eta"] * peers.asym_rows(sig)).Compile() * dx)                  # s

@dataclass
class BrokenPeers:
    """The PEERS block of (3.62), assembled once, element by element.

    The Raviart-Thomas rows of sigma are broken (every triangle has its own RT_k
    functions); the bubbles, u and eta are those of the conforming space. The element matrices
    of a~ + b + s are the same as on the conforming space, but no two triangles share a
    stress unknown, so ``matrix`` keeps every triangle's matrix apart: the conforming PEERS
    block is K = E^T K_b E (:meth:`summed`), E the 0/1 map from conforming to broken
    unknowns, and the hybridisation (:class:`ngdual.solvers.hybrid.HybridSystem`)
    eliminates the element-local unknowns from the same matrix.

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
    lame : tuple of float
        Lame's constants (lambda, mu) of the form.
    coupled : numpy.ndarray
        The triangles with an edge on Gamma_N or Gamma_C (by number), whose broken functions
        the boundary multipliers couple.
    """

    fes: ngs.FESpace
    form: ngs.BilinearForm
    matrix: sp.csr_matrix
    conforming: np.ndarray
    lame: tuple[float, float]
    coupled: np.ndarray

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
        m = self.matrix   # |K_b| on K_b's own index arrays (abs() would copy them too)
        magnitude = sp.csr_matrix((np.abs(m.data), m.indices, m.indptr), shape=m.shape,
                                  copy=False)
        return np.bincount(self.conforming, magnitude @ magnitudes[self.conforming],
                           minlength=size)

    def to_conforming(self, values: np.ndarray) -> np.ndarray:
        """The conforming PEERS coefficients of broken ones whose normal fluxes agree across
        every edge (up to rounding): the mean of the two triangles' values."""
        count = np.bincount(self.conforming)
        return np.bincount(self.conforming, values, minlength=len(count)) / count


def broken_peers(spaces: Spaces, lame: tuple[float, float], coupled: list[str] = ()
                 ) -> BrokenPeers:
    """Assemble the PEERS block of (3.62) of order ``spaces.order`` with broken
    Raviart-Thomas rows (:class:`BrokenPeers`): ``HDiv(order=k, RT=True, discontinuous=True)``,
    every triangle with its own RT_k functions; ``coupled`` are the labels of the boundary
    parts whose multipliers couple them (Gamma_N, Gamma_C)."""
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
    return BrokenPeers(fes, a, to_scipy(a.mat, copy=False), np.concatenate(conforming),
                       tuple(lame), triangles_at(mesh, list(coupled)))


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
