"""The quadrature rules of the forms of (3.62): the data on the triangles and the edges, and the
volume rule that integrates the PEERS form of order k exactly."""

from __future__ import annotations

import ngsolve as ngs

from .. import peers

# The data f, u_D, t0 and g may be any formula: f is integrated with the rule of degree 6 on
# every triangle and u_D, t0, g with that of degree 12 on every edge (twice the order 3 of the
# cubic bubbles, plus 6 on the edges); quadrature_check evaluates the formulas on the same
# points.
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
