"""Verification against exact solutions.

:mod:`ngdual.verification.manufactured`: manufactured contact problems (frictionless,
Tresca, Coulomb) whose contact, stick and slip sets are known exactly, and the study of
every error per level with observed orders (:func:`manufactured_study`,
:func:`convergence_orders`, :func:`format_study`).

:mod:`ngdual.verification.analytic`: the half-plane contact solutions (Hertz, the rigid flat
punch, Cattaneo-Mindlin) and the errors of a computed pressure and shear traction against
them (:func:`pressure_errors`, :func:`traction_errors`).
:mod:`ngdual.verification.contact_benchmarks`: those errors per level on the shipped contact
scenes, adaptive runs and the finite-box study; :mod:`ngdual.verification.report`: the
tables of ``ngdual verify``.
"""

from .analytic import (
    CattaneoMindlin,
    FlatPunch,
    HertzContact,
    TractionProfile,
    Wedge,
    cattaneo_mindlin,
    flat_punch,
    hertz,
    mcewen_approach,
    pressure_errors,
    traction_errors,
    traction_profile,
    wedge,
)
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

__all__ = ["CASES", "CattaneoMindlin", "ExactSolution", "FlatPunch", "HertzContact",
           "ManufacturedCase", "Piecewise", "TractionProfile", "Wedge", "boundary_errors",
           "cattaneo_mindlin", "contact_profile", "convergence_orders", "coulomb_case",
           "discrete_sets", "flat_punch", "format_study", "frictionless_case", "hertz",
           "intersection", "manufactured_case", "manufactured_study", "mcewen_approach",
           "pressure_errors", "print_study", "symmetric_difference", "traction_errors",
           "traction_profile", "tresca_case", "volume_errors", "wedge"]
