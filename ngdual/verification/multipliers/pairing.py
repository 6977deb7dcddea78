"""The pairing d(mu, tau) of (3.24) between a multiplier basis and the stresses of order k
(:func:`pair`), with the norm |.|_{1/2,h} of the multipliers.

|.|_{1/2,h} is one norm for both families: the interpolation norm between L^2(Gamma) and
the broken H^1 norm

    |mu|_{1,h}^2 = sum_e ||d mu / ds||_{L^2(e)}^2 + sum_z [mu]_z^2 / h_z,

the second sum over the interior vertices z of the fine edges of every chain and its fixed
ends, where mu jumps to the zero outside the part (H^{1/2}_00; h_z the mean length of the
edges at z, [mu]_z the jump); :func:`ngdual.verification.infsup.half_norm` interpolates. On
continuous multipliers that vanish at the fixed ends the jumps vanish and it is the discrete
H^{1/2} norm of ``ngdual bench infsup``; on discontinuous ones it is the H^{1/2}_00 norm of
the DG literature, which grows like h^{-1/2} ||mu||_{L^2} on a multiplier that alternates
from edge to edge, as sup_tau d(mu, tau) / ||tau||_{H(div)} does (a divergence-free RT_0
field through the boundary triangles).

The matrix of d is assembled by NGSolve between the stresses and a host space of
discontinuous P_{k+1} on the fine edges (``SurfaceL2``) and restricted to a family by the
element-wise L^2 projection of its basis onto the host, which is exact (every multiplier is
a polynomial of degree <= k + 1 on every fine edge of a straight boundary part) and checked.
"""

from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ... import peers
from ...geometry import tangent
from ...sparse import to_scipy
from ..infsup import half_norm
from .bases import Basis, Part


@dataclass
class PartPairing:
    """The columns of d (3.24) of one part: ``B`` (stress dofs x 2 n_dofs, the two
    components one after the other) and the mass and broken stiffness of the scalar space."""

    B: sp.csr_matrix
    mass: np.ndarray
    stiff: np.ndarray

    @property
    def norm(self) -> np.ndarray:
        """|.|_{1/2,h} of the vector multiplier: :func:`half_norm` on both components."""
        n = half_norm(self.mass, self.stiff)
        return sla.block_diag(n, n)


def _boundary_elements(mesh: ngs.Mesh, labels) -> dict[tuple[int, int], int]:
    """The boundary element of every fine edge of ``labels``, by its (sorted) vertex pair."""
    return {tuple(sorted(v.nr for v in el.vertices)): el.nr
            for el in mesh.Elements(ngs.BND) if el.mat in labels}


def _host_shapes(host: ngs.FESpace, labels, rule: ngs.IntegrationRule):
    """NGSolve's own quadrature points of ``rule`` on every boundary element (elements x
    points x 2), the shape functions of the element-wise ``host`` there (elements x shapes x
    points) and the host's dofs of the elements of ``labels``."""
    mesh = host.mesh
    points = mesh.MapToAllElements(rule, ngs.BND)
    size = (mesh.GetNE(ngs.BND), len(rule.weights))
    xy = np.stack([np.asarray(ngs.x(points)).reshape(size),
                   np.asarray(ngs.y(points)).reshape(size)], axis=-1)
    host_dofs = {el.nr: np.array(host.GetDofNrs(ngs.ElementId(ngs.BND, el.nr)))
                 for el in mesh.Elements(ngs.BND) if el.mat in labels}
    shape = ngs.GridFunction(host)
    psi = []
    # the i-th shape function of every element at once: the host is discontinuous
    for i in range(len(next(iter(host_dofs.values())))):
        shape.vec[:] = 0
        for dofs in host_dofs.values():
            shape.vec[int(dofs[i])] = 1
        psi.append(np.asarray(shape(points)).reshape(size))
    return xy, np.stack(psi, axis=1), host_dofs


def pair(basis: Basis, part: Part, fes: ngs.FESpace, names: list[str], order: int
         ) -> PartPairing:
    """d(mu, tau) of (3.24) between ``basis`` (both components of ``part``) and the stresses
    of ``fes`` (components ``names``), with the mass and broken stiffness of ``basis``.

    Raises
    ------
    RuntimeError
        If the host projection is not exact (a curved fine edge).
    """
    mesh = fes.mesh
    degree = order + 1
    region = mesh.Boundaries("|".join(part.labels))
    host = ngs.Compress(ngs.SurfaceL2(mesh, order=degree, definedon=region))
    test = dict(zip(names, fes.TestFunction()))
    traction = peers.stress_traction(test["r1"], test["r2"])
    n = ngs.specialcf.normal(2)
    components = ((traction[0], traction[1]) if part.frame == "cartesian"
                  else (tangent(n) * traction, n * traction))
    rule = ngs.IntegrationRule(ngs.SEGM, 2 * degree + 2)
    D = []
    for component in components:
        form = ngs.BilinearForm(trialspace=host, testspace=fes)
        form += host.TrialFunction() * component * ngs.ds(definedon=region,
                                                           intrules={ngs.SEGM: rule})
        form.Assemble()
        D.append(to_scipy(form.mat))
    xy, psi, host_dofs = _host_shapes(host, part.labels, rule)
    element_of = _boundary_elements(mesh, part.labels)
    pairs, _ = basis.coarse.fine_edges()
    mass = np.zeros((basis.n_dofs, basis.n_dofs))
    stiff = np.zeros_like(mass)
    rows, cols, vals = [], [], []
    edge_ends = []                                            # values at t = 0, 1
    for e, (a, b) in enumerate(pairs):
        el = element_of[tuple(sorted((int(a), int(b))))]
        pa, pb = np.array(mesh[ngs.NodeId(ngs.VERTEX, int(a))].point), \
            np.array(mesh[ngs.NodeId(ngs.VERTEX, int(b))].point)
        length = float(np.linalg.norm(pb - pa))
        t = (xy[el] - pa) @ (pb - pa) / length ** 2
        w = np.array(rule.weights) * length
        phi, slope = basis.values(e, t), basis.slopes(e, t, length)
        dofs = basis.dofs[e]
        mass[np.ix_(dofs, dofs)] += (phi * w) @ phi.T
        stiff[np.ix_(dofs, dofs)] += (slope * w) @ slope.T
        gram = (psi[el] * w) @ psi[el].T
        coefficients = np.linalg.solve(gram, (psi[el] * w) @ phi.T)   # host shapes x dofs
        if np.abs(coefficients.T @ psi[el] - phi).max() > 1e-9 * max(1.0, np.abs(phi).max()):
            raise RuntimeError(f"the multipliers are not polynomials of degree {degree} on "
                               f"the fine edge {a}-{b} (a curved edge?)")
        r, c = np.meshgrid(host_dofs[el], dofs, indexing="ij")
        rows.append(r.ravel())
        cols.append(c.ravel())
        vals.append(coefficients.ravel())
        edge_ends.append((dofs, basis.values(e, np.array([0.0, 1.0])), length))
    stiff += _jump_penalty(basis, edge_ends)
    P = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(host.ndof, basis.n_dofs))
    B = sp.hstack([d @ P for d in D], format="csr")
    return PartPairing(B, mass, stiff)


def _jump_penalty(basis: Basis, ends: list) -> np.ndarray:
    """sum_z [mu]_z^2 / h_z over the interior vertices z of every chain and its fixed ends
    (where mu jumps to the zero outside the part), h_z the mean length of the edges at z,
    from the values of every edge's dofs at its two ends."""
    penalty = np.zeros((basis.n_dofs, basis.n_dofs))
    first = 0
    for chain, (free_first, free_last) in zip(basis.coarse.chains, basis.coarse.free):
        edges = list(range(first, first + chain.n_edges))
        first += chain.n_edges
        joints = list(zip(edges[:-1], edges[1:]))
        if chain.closed:
            joints.append((edges[-1], edges[0]))
        else:
            joints += [(None, edges[0])] * (not free_first) + [(edges[-1], None)] * (not free_last)
        for left, right in joints:
            jump, lengths = np.zeros(basis.n_dofs), []
            if left is not None:
                dofs, values, length = ends[left]
                jump[dofs] += values[:, 1]
                lengths.append(length)
            if right is not None:
                dofs, values, length = ends[right]
                jump[dofs] -= values[:, 0]
                lengths.append(length)
            penalty += np.outer(jump, jump) / np.mean(lengths)
    return penalty
