"""The PEERS family of order k verified: convergence on elasticity and on contact, inf-sup.

Modules: :mod:`~ngdual.verification.order.elasticity` (a smooth manufactured displacement on
the unit square: the triple of :mod:`ngdual.peers` alone, its orders and its inf-sup
constant), :mod:`~ngdual.verification.order.contact` (the manufactured frictionless contact
problem at order k: errors, pressure and contact set, and the order theory predicts) and
:mod:`~ngdual.verification.order.checks` (whether a study's observed orders and contact
set reach their targets).
"""

from __future__ import annotations

from .checks import ORDER_SLACK, SET_TOLERANCE, order_check, set_check
from .contact import contact_set, contact_study, expected_order, pressure_error
from .elasticity import (
    LAME,
    QUANTITIES,
    ElasticitySystem,
    ExactElasticity,
    assemble_elasticity,
    component_indices,
    convergence_study,
    format_rows,
    infsup_constants,
    l2_errors,
    solve_elasticity,
    unit_square,
)

__all__ = ["LAME", "ORDER_SLACK", "QUANTITIES", "SET_TOLERANCE", "ElasticitySystem",
           "ExactElasticity", "assemble_elasticity", "component_indices", "contact_set",
           "contact_study", "convergence_study", "expected_order", "format_rows",
           "infsup_constants", "l2_errors", "order_check", "pressure_error", "set_check",
           "solve_elasticity", "unit_square"]
