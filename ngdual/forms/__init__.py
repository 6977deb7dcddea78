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

Modules: :mod:`~ngdual.forms.spaces` (the component spaces and prolongations),
:mod:`~ngdual.forms.peers_block` (the PEERS form and its block, element by element),
:mod:`~ngdual.forms.couplings` (the boundary couplings d_N, d_C, the right-hand side and the
known multiplier values), :mod:`~ngdual.forms.assembly` (:func:`assemble`),
:mod:`~ngdual.forms.problem` (:class:`DiscreteProblem`, what it returns),
:mod:`~ngdual.forms.rules` (the quadrature rules) and :mod:`~ngdual.forms.integrators`
(how NGSolve runs an assembly).
"""

from __future__ import annotations

from .assembly import assemble
from .couplings import traction_coefficient
from .integrators import PARALLEL_ELEMENTS, differentiated_integrands, parallel_tasks
from .peers_block import BrokenPeers, broken_peers, conforming_peers, peers_form
from .problem import DiscreteProblem
from .rules import (
    EXACT_VOLUME_RULES,
    LOAD_ORDER,
    LOAD_RULES,
    TRACE_ORDER,
    TRACE_RULES,
    volume_rules,
)
from .spaces import Spaces, boundary_regex

__all__ = ["EXACT_VOLUME_RULES", "LOAD_ORDER", "LOAD_RULES", "PARALLEL_ELEMENTS", "TRACE_ORDER",
           "TRACE_RULES", "BrokenPeers", "DiscreteProblem", "Spaces", "assemble",
           "boundary_regex", "broken_peers", "conforming_peers", "differentiated_integrands",
           "parallel_tasks", "peers_form", "traction_coefficient", "volume_rules"]
