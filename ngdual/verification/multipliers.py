"""Boundary multipliers of order k and their discrete inf-sup constants, both families.

The multipliers phi on Gamma_N and (lambda_t, lambda_n) on Gamma_C enter (3.62) through

    d(mu, tau) = int_Gamma mu . (tau n) ds,                                       (3.24)

in Cartesian components on Gamma_N (d_N) and in the components along t and n on Gamma_C
(d_{C,t} + d_{C,n}). At order k the stresses are PEERS_k or AFW_k (:mod:`ngdual.peers`);
two families of multipliers pair with them (issue 27, item 2):

``coarse``
    continuous piecewise polynomials of degree k + 1 on the coarse mesh h~ = ``ratio`` * h,
    zero at the fixed ends (the thesis' C_h~ of (3.61) is k = 0, ratio 2), built on the
    coarse meshes of :class:`ngdual.boundary.CoarseMesh`;
``facet``
    discontinuous P_k on the fine edges, the space of the normal traces of RT_k (the
    hybridisation pairing).

The inf-sup constant is

    beta_h = inf_mu sup_{tau in X_h} d(mu, tau) / (|mu|_{1/2,h} ||tau||_{H(div)}),

and the continuity constant gamma_h the same with sup sup. |.|_{1/2,h} is one norm for both
families: the interpolation norm between L^2(Gamma) and the broken H^1 norm

    |mu|_{1,h}^2 = sum_e ||d mu / ds||_{L^2(e)}^2 + sum_z [mu]_z^2 / h_z,

the second sum over the interior vertices z of the fine edges of every chain and its fixed
ends, where mu jumps to the zero outside the part (H^{1/2}_00; h_z the mean length of the
edges at z, [mu]_z the jump); :func:`ngdual.verification.infsup.half_norm` interpolates. On
continuous multipliers that vanish at the fixed ends the jumps vanish and it is the discrete
H^{1/2} norm of ``ngdual bench infsup``; on discontinuous ones it is the H^{1/2}_00 norm of
the DG literature, which grows like h^{-1/2} ||mu||_{L^2} on a multiplier that alternates
from edge to edge, as sup_tau d(mu, tau) / ||tau||_{H(div)} does (a divergence-free RT_0
field through the boundary triangles). beta_h and gamma_h both bounded say that this
discrete dual norm is uniformly equivalent to |.|_{1/2,h}: the pairing is stable in the
norms of the analysis (Lemma 3.28: H(div) on the stresses), not in a weaker mesh-dependent
one. docs/theory/order.md derives it.

The matrix of d is assembled by NGSolve between the stresses and a host space of
discontinuous P_{k+1} on the fine edges (``SurfaceL2``) and restricted to a family by the
element-wise L^2 projection of its basis onto the host, which is exact (every multiplier is
a polynomial of degree <= k + 1 on every fine edge of a straight boundary part) and checked.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import partial

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.polynomial import legendre

from .. import peers
from ..boundary import CoarseMesh, EndRule, end_rule
from ..geometry import tangent
from ..mesh import build_mesh
from ..scene import SceneError
from ..sparse import to_scipy
from .infsup import dense_singular_values, gram_matrix, half_norm
from .order import unit_square

FAMILIES = ("coarse", "facet")
FRAMES = ("cartesian", "contact")     # phi on Gamma_N; (lambda_t, lambda_n) on Gamma_C


@dataclass(frozen=True)
class Part:
    """A boundary part carrying a vector multiplier: its labels, its components
    (``"cartesian"`` for phi on Gamma_N, ``"contact"`` for lambda_t, lambda_n on Gamma_C)
    and where its chains break and which ends are free (fixed ends carry no coarse dof)."""

    labels: tuple[str, ...]
    frame: str = "contact"
    ends: EndRule = EndRule()

    def __post_init__(self):
        if self.frame not in FRAMES:
            raise SceneError("frame", f"unknown frame {self.frame!r}; choose one of "
                             f"{', '.join(FRAMES)}")


def model_parts() -> list[Part]:
    """Gamma_C = the bottom of the unit square, both ends fixed (clamped sides)."""
    return [Part(("bottom",), "contact")]


def scene_parts(scene, mesh: ngs.Mesh) -> list[Part]:
    """Gamma_N and Gamma_C of ``scene`` with the end rule of its multipliers."""
    parts = []
    if scene.labels("neumann"):
        parts.append(Part(tuple(scene.labels("neumann")), "cartesian",
                          end_rule(scene, mesh, "neumann")))
    if scene.has_contact:
        parts.append(Part(tuple(scene.labels("contact")), "contact",
                          end_rule(scene, mesh, "contact")))
    return parts


@dataclass(frozen=True)
class Basis:
    """A scalar multiplier space on the fine edges of one part, edge by edge.

    ``dofs[e]`` are the dofs living on fine edge e (in the chain order of ``coarse``, the
    :class:`CoarseMesh` the space is built on) and ``coefficients[e]`` their polynomials in
    the edge's own parameter t in [0, 1] (running along the chain), Legendre coefficients
    in 2t - 1, one row per dof.
    """

    coarse: CoarseMesh
    n_dofs: int
    dofs: tuple[np.ndarray, ...]
    coefficients: tuple[np.ndarray, ...]

    def values(self, e: int, t: np.ndarray) -> np.ndarray:
        """The dofs' functions of edge e at the parameters ``t`` (dofs x points)."""
        return legendre.legval(2 * np.asarray(t) - 1, self.coefficients[e].T)

    def slopes(self, e: int, t: np.ndarray, length: float) -> np.ndarray:
        """Their derivatives in arc length at ``t``."""
        derivative = legendre.legder(self.coefficients[e].T) * 2 / length
        return legendre.legval(2 * np.asarray(t) - 1, derivative)


def _to_legendre(values_at: callable, degree: int) -> np.ndarray:
    """Legendre coefficients (in 2t - 1) of the polynomials of degree <= ``degree`` whose
    values at t are the rows of ``values_at(t)``."""
    t = (legendre.leggauss(degree + 1)[0] + 1) / 2
    return legendre.legfit(2 * t - 1, values_at(t).T, degree).T


def _coarse_values(t: np.ndarray, t0: float, t1: float, ends: list[int], order: int
                   ) -> np.ndarray:
    """The hats of the coarse edge's carried ``ends`` (0: its start, 1: its end) and its k
    bubbles, at the parameters ``t`` of the fine edge [t0, t1] of the coarse edge."""
    tau = t0 + (t1 - t0) * np.asarray(t)
    hats = [(1 - tau, tau)[i] for i in ends]
    bubbles = [tau * (1 - tau) * legendre.legval(2 * tau - 1, np.eye(order)[j])
               for j in range(order)]
    return np.array(hats + bubbles).reshape(len(ends) + order, len(tau))


def coarse_basis(coarse: CoarseMesh, order: int) -> Basis:
    """Continuous piecewise polynomials of degree k + 1 on the coarse edges of ``coarse``,
    zero at its fixed ends: the hats of the coarse P1 dofs (:meth:`CoarseMesh.dof_positions`)
    and on every coarse edge the bubbles tau (1 - tau) L_j(2 tau - 1), j < k, of its
    parameter tau."""
    degree = order + 1
    dofs, coefficients, offset = [], [], 0
    bubble = coarse.n_p1_dofs                      # the bubbles' dofs follow the hats'
    for c, chain in enumerate(coarse.chains):
        carriers = coarse.dof_positions(c)
        hat = {int(p): offset + i for i, p in enumerate(carriers)}
        if chain.closed:
            hat[chain.n_edges] = hat[0]
        offset += len(carriers)
        s, nodes = chain.arclength, coarse.nodes[c]
        for e in range(len(nodes) - 1):
            a, b = int(nodes[e]), int(nodes[e + 1])
            owned = [hat[p] for p in (a, b) if p in hat]
            ends = [i for i, p in enumerate((a, b)) if p in hat]
            edge_dofs = np.array(owned + list(range(bubble, bubble + order)), dtype=int)
            bubble += order
            for k in range(a, b):
                t0, t1 = (s[k] - s[a]) / (s[b] - s[a]), (s[k + 1] - s[a]) / (s[b] - s[a])
                dofs.append(edge_dofs)
                coefficients.append(
                    _to_legendre(partial(_coarse_values, t0=t0, t1=t1, ends=ends, order=order),
                                 degree) if len(edge_dofs) else np.zeros((0, degree + 1)))
    return Basis(coarse, bubble, tuple(dofs), tuple(coefficients))


def facet_basis(fine: CoarseMesh, order: int) -> Basis:
    """Discontinuous P_k on the fine edges of ``fine`` (a coarse mesh of ratio 1, for its
    chains): Legendre polynomials L_0 .. L_k of every edge."""
    n_edges = sum(chain.n_edges for chain in fine.chains)
    dofs = tuple(np.arange(e * (order + 1), (e + 1) * (order + 1)) for e in range(n_edges))
    return Basis(fine, n_edges * (order + 1), dofs,
                 tuple(np.eye(order + 1) for _ in range(n_edges)))


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


@dataclass
class Stresses:
    """The stress family of order k on a mesh as a product space (for
    :func:`ngdual.verification.infsup.gram_matrix`)."""

    fes: ngs.FESpace
    names: list[str]

    @classmethod
    def of(cls, mesh: ngs.Mesh, family: str, order: int) -> Stresses:
        spaces = peers.family_spaces(mesh, family, order)
        names = list(spaces)
        return cls(ngs.FESpace([spaces[n] for n in names]), names)

    @property
    def sigma(self) -> np.ndarray:
        ranges = [self.fes.Range(self.names.index(c)) for c in peers.STRESS if c in self.names]
        return np.concatenate([np.arange(r.start, r.stop) for r in ranges])


def multiplier_basis(mesh: ngs.Mesh, part: Part, multipliers: str, order: int,
                     ratio: int = 2) -> Basis:
    """The scalar basis of ``multipliers`` (one of :data:`FAMILIES`) of order k on ``part``:
    ``coarse`` on h~ = ``ratio`` h, ``facet`` on the fine edges (``ratio`` must be 1)."""
    if multipliers not in FAMILIES:
        raise SceneError("contact.multipliers", f"unknown multipliers {multipliers!r}; "
                         f"choose one of {', '.join(FAMILIES)}")
    if multipliers == "facet" and ratio != 1:
        raise SceneError("contact.htilde_factor",
                         f"facet multipliers live on the fine edges (ratio 1), not {ratio}")
    coarse = CoarseMesh.from_fine(mesh, list(part.labels), ratio, part.ends)
    return (coarse_basis if multipliers == "coarse" else facet_basis)(coarse, order)


def constants(mesh: ngs.Mesh, parts: list[Part], multipliers: str = "coarse", order: int = 0,
              ratio: int = 2, family: str = "peers") -> dict:
    """beta_h and gamma_h of ``multipliers`` of order k on ``parts`` against the stresses
    of ``family`` (PEERS_k or AFW_k), H(div) on the stresses and |.|_{1/2,h} on the
    multipliers (:func:`ngdual.verification.infsup.dense_singular_values`).

    Returns
    -------
    dict
        ``multipliers``, ``ratio``, ``family``, ``order``, ``multiplier_dofs``,
        ``stresses``, ``beta``, ``gamma`` and ``seconds``.
    """
    start = time.perf_counter()
    stresses = Stresses.of(mesh, family, order)
    pairings = [pair(multiplier_basis(mesh, part, multipliers, order, ratio), part,
                     stresses.fes, stresses.names, order) for part in parts]
    s = stresses.sigma
    B = sp.hstack([p.B for p in pairings], format="csr")[s].toarray()
    X = gram_matrix(stresses)[s][:, s]
    beta, gamma = dense_singular_values(X, B, sla.block_diag(*[p.norm for p in pairings]),
                                        indices=(0, -1))
    return {"multipliers": multipliers, "ratio": ratio, "family": family, "order": order,
            "multiplier_dofs": int(B.shape[1]), "stresses": int(X.shape[0]),
            "beta": beta, "gamma": gamma, "seconds": time.perf_counter() - start}


def scene_constants(scene, level: int, multipliers: str = "coarse", order: int = 0,
                    ratio: int = 2, family: str = "peers") -> dict:
    """:func:`constants` on Gamma_N and Gamma_C of ``scene`` at mesh ``level``."""
    mesh = build_mesh(scene.geometry, level)
    return {"scene": scene.name, "level": level,
            **constants(mesh, scene_parts(scene, mesh), multipliers, order, ratio, family)}


CHOICES = (("coarse", 2), ("coarse", 1), ("facet", 1))


def table(orders=(0, 1, 2), levels=(1, 2, 3, 4), choices=CHOICES, family: str = "peers"
          ) -> list[dict]:
    """beta_h and gamma_h of every (multipliers, ratio) of ``choices``, order and level on the
    model problem (:func:`unit_square`, :func:`model_parts`), with ``h``."""
    rows = []
    for multipliers, ratio in choices:
        for order in orders:
            for level in levels:
                rows.append({"level": level, "h": 2.0 ** -(level + 1),
                             **constants(unit_square(level), model_parts(), multipliers,
                                         order, ratio, family)})
    return rows


def format_table(rows: list[dict]) -> str:
    """The table as Markdown: one line per stress family, multipliers, h~/h and k; beta_h
    (gamma_h) per level."""
    levels = sorted({r["level"] for r in rows})
    keys = list(dict.fromkeys((r["family"], r["multipliers"], r["ratio"], r["order"])
                              for r in rows))
    cell = {(r["family"], r["multipliers"], r["ratio"], r["order"], r["level"]): r
            for r in rows}
    lines = ["| stresses | multipliers | h~/h | k | "
             + " | ".join(f"level {lv}" for lv in levels) + " |",
             "|---|---|---|---|" + "---|" * len(levels)]
    for key in keys:
        cells = [f"{cell[key + (lv,)]['beta']:.4f} ({cell[key + (lv,)]['gamma']:.2f})"
                 if key + (lv,) in cell else "" for lv in levels]
        lines.append(f"| {key[0].upper()} | {key[1]} | {key[2]} | {key[3]} | "
                     + " | ".join(cells) + " |")
    return "\n".join(lines)
