"""Verification against exact solutions.

:mod:`ngdual.verification.manufactured`: manufactured contact problems (frictionless,
Tresca, Coulomb) whose contact, stick and slip sets are known exactly, and the study of
every error per level with observed orders (:func:`manufactured_study`,
:func:`convergence_orders`, :func:`format_study`).
"""

from .manufactured import (
    CASES,
    ExactSolution,
    ManufacturedCase,
    boundary_errors,
    contact_profile,
    convergence_orders,
    coulomb_case,
    discrete_sets,
    format_study,
    frictionless_case,
    intersection,
    manufactured_case,
    manufactured_study,
    print_study,
    symmetric_difference,
    tresca_case,
    volume_errors,
)
from .piecewise import Piecewise

__all__ = ["CASES", "ExactSolution", "ManufacturedCase", "Piecewise", "boundary_errors",
           "contact_profile", "convergence_orders", "coulomb_case", "discrete_sets",
           "format_study", "frictionless_case", "intersection", "manufactured_case",
           "manufactured_study", "print_study", "symmetric_difference", "tresca_case",
           "volume_errors"]
