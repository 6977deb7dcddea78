"""The fine component spaces of (3.62), the boundary meshes of the multipliers and their
prolongations (:class:`Spaces`): all that DOF counting needs, nothing assembled.

The one place outside :mod:`ngdual.scene` that reads the order k and the multiplier family
of a scene's ``[discretisation]`` (:func:`variant_of`); the rest of the code asks the
:class:`Variant` or the :class:`Spaces` built from it."""

from __future__ import annotations

from dataclasses import dataclass, field

import ngsolve as ngs
import scipy.sparse as sp

from .. import peers
from ..boundary import BoundaryMeshes, CoarseMesh, FacetMesh, end_rule, host_space
from ..boundary.coarse_order import CoarseOrderMesh
from ..contact import ContactBoundary, trace_space
from ..scene import Scene


@dataclass(frozen=True)
class Variant:
    """The variant of the method a scene asks for: PEERS_k of order ``order`` with the
    multipliers of ``family`` (``"coarse"``: continuous on the h~ meshes, ``"facet"``: P_k on
    the fine edges of T_h).

    The thesis' triple (3.61) is order 0 with the coarse family (``thesis``): its spaces
    are built by :meth:`Spaces.build` itself, every other variant's by
    :meth:`Spaces._order_k`. Every variant is solved by the same methods.

    >>> Variant(0, "coarse").thesis, Variant(0, "facet").thesis, Variant(1).thesis
    (True, False, False)
    """

    order: int = 0
    family: str = "coarse"

    @property
    def traces(self) -> bool:
        """Whether the multipliers are the traces of RT_k themselves, P_k on every fine edge
        (the facet family; the spaces' ``traces``)."""
        return self.family == "facet"

    @property
    def thesis(self) -> bool:
        """Whether this is the thesis' triple (3.61): PEERS_0 with the P1 hats on h~ (and nu
        on h^ with friction)."""
        return self.family == "coarse" and self.order == 0


def variant_of(scene: Scene) -> Variant:
    """The order k and the multiplier family of ``scene``'s ``[discretisation]`` (its
    ``multipliers = "auto"`` resolved at that order).

    >>> from ngdual.scene import load_scene
    >>> variant_of(load_scene("hertz-cylinder", ["discretisation.order=1"]))
    Variant(order=1, family='facet')
    """
    disc = scene.discretisation
    return Variant(disc.order, disc.family)


def declared_variant(scene: Scene) -> Variant | None:
    """The variant ``scene`` declares (``discretisation.order`` or ``.multipliers`` set in
    its document or overrides), None where it leaves both to their defaults."""
    from ..scene import given_keys

    if given_keys(scene, "discretisation") & {"order", "multipliers"}:
        return variant_of(scene)
    return None


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
        variant = variant_of(scene)
        if not variant.thesis:
            return cls._order_k(scene, mesh, coarse, variant)
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
    def _order_k(cls, scene: Scene, mesh: ngs.Mesh, coarse: BoundaryMeshes | None,
                 variant: Variant) -> Spaces:
        """PEERS_k with the multipliers of its family: the facet P_k on the fine edges (no
        end is fixed, so nothing is lifted), or the coarse P_{k+1} on the h~ meshes
        (``coarse``, or grouped afresh), fixed at the fixed ends as the P1 hats are."""
        order, family = variant.order, variant.family
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
