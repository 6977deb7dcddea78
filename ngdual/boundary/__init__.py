"""Boundary meshes: the fine boundary edges in chains and the coarse meshes h~, h^ of the
multipliers on Gamma_N, Gamma_C and A_C, with their P1 spaces (Section 3.2), and the fine
edges as the mesh of the facet P_k multipliers of order k (:mod:`.facet`)."""

from .chains import Chain, EndRule, boundary_chains, edge_normals, end_rule, nearest_vertex
from .coarse import BoundaryMeshes, CoarseMesh
from .facet import FacetMesh, host_space

__all__ = ["BoundaryMeshes", "Chain", "CoarseMesh", "EndRule", "FacetMesh", "boundary_chains",
           "edge_normals", "end_rule", "host_space", "nearest_vertex"]
