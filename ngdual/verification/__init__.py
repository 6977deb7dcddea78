"""Verification against exact solutions.

:mod:`ngdual.verification.manufactured`: manufactured contact problems (frictionless,
Tresca, Coulomb) whose contact, stick and slip sets are known exactly;
:mod:`ngdual.verification.manufactured_errors`: the study of every error per level with
observed orders (:func:`manufactured_study`, :func:`convergence_orders`,
:func:`format_study`).

:mod:`ngdual.verification.analytic`: the half-plane contact solutions (Hertz, the rigid flat
punch, a blunt wedge, Cattaneo-Mindlin); :mod:`ngdual.verification.traction`: the discrete
pressure and shear traction on Gamma_C and their errors against them
(:func:`traction_profile`, :func:`pressure_errors`, :func:`traction_errors`);
:mod:`ngdual.verification.corner`: Williams' L-shaped corner problem;
:mod:`ngdual.verification.overkill`: where no exact solution is known, true errors against a
solve several levels finer, from the plain arrays both are sampled to.
:mod:`ngdual.verification.contact_benchmarks`: those errors per level on the shipped contact
scenes, adaptive runs and the finite-box study; :mod:`ngdual.verification.report`: the
tables of ``ngdual verify``. :mod:`ngdual.verification.infsup`: the discrete inf-sup constant
of the PEERS triple (Lemma 3.28) as the smallest singular value of b + s.
"""

import importlib
import importlib.util

from .analytic import (
           CattaneoMindlin,
           FlatPunch,
           HertzContact,
           Wedge,
           cattaneo_mindlin,
           flat_punch,
           hertz,
           mcewen_approach,
           wedge,
)
from .manufactured import (
           CASES,
           ExactSolution,
           ManufacturedCase,
           coulomb_case,
           frictionless_case,
           manufactured_case,
           tresca_case,
)
from .manufactured_errors import (
           boundary_errors,
           contact_profile,
           convergence_orders,
           discrete_sets,
           format_study,
           intersection,
           manufactured_study,
           print_study,
           symmetric_difference,
           volume_errors,
)
from .piecewise import Piecewise
from .traction import TractionProfile, pressure_errors, traction_errors, traction_profile

__all__ = ["CASES", "CattaneoMindlin", "ExactSolution", "FlatPunch", "HertzContact",
           "ManufacturedCase", "Piecewise", "TractionProfile", "Wedge", "boundary_errors",
           "cattaneo_mindlin", "contact_profile", "convergence_orders", "coulomb_case",
           "discrete_sets", "flat_punch", "format_study", "frictionless_case", "hertz",
           "intersection", "manufactured_case", "manufactured_study", "mcewen_approach",
           "pressure_errors", "print_study", "symmetric_difference", "traction_errors",
           "traction_profile", "tresca_case", "volume_errors", "wedge"]


def __getattr__(name: str):
    """A module of this package on first use (``nd.verification.corner``), also when another
    module imported the package before ``nd.verification`` was first read (PEP 562)."""
    if name.startswith("__") or importlib.util.find_spec(f"{__name__}.{name}") is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return importlib.import_module(f"{__name__}.{name}")
