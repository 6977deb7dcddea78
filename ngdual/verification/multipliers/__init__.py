"""Boundary multipliers of order k and their discrete inf-sup constants, both families.

The multipliers phi on Gamma_N and (lambda_t, lambda_n) on Gamma_C enter (3.62) through

    d(mu, tau) = int_Gamma mu . (tau n) ds,                                       (3.24)

in Cartesian components on Gamma_N (d_N) and in the components along t and n on Gamma_C
(d_{C,t} + d_{C,n}). At order k the stresses are PEERS_k or AFW_k (:mod:`ngdual.peers`);
two families of multipliers pair with them:

``coarse``
    continuous piecewise polynomials of degree k + 1 on the coarse mesh h~ = ``ratio`` * h,
    zero at the fixed ends (the thesis' C_h~ of (3.61) is k = 0, ratio 2), built on the
    coarse meshes of :class:`ngdual.boundary.CoarseMesh`;
``facet``
    discontinuous P_k on the fine edges, the space of the normal traces of RT_k (the
    hybridisation pairing).

Modules: :mod:`~ngdual.verification.multipliers.bases` (the two families, edge by edge),
:mod:`~ngdual.verification.multipliers.pairing` (the matrix of d and the norm |.|_{1/2,h}),
:mod:`~ngdual.verification.multipliers.constants` (beta_h and gamma_h, and their table).
"""

from __future__ import annotations

from .bases import (
    FAMILIES,
    FRAMES,
    Basis,
    Part,
    coarse_basis,
    facet_basis,
    model_parts,
    multiplier_basis,
    scene_parts,
)
from .constants import CHOICES, Stresses, constants, format_table, scene_constants, table
from .pairing import PartPairing, pair

__all__ = ["CHOICES", "FAMILIES", "FRAMES", "Basis", "Part", "PartPairing", "Stresses",
           "coarse_basis", "constants", "facet_basis", "format_table", "model_parts",
           "multiplier_basis", "pair", "scene_constants", "scene_parts", "table"]
