"""Physics checks of a discrete solution: what a user should not believe, one line each.

:func:`physics_checks` runs every check on a solution and returns a
:class:`~ngdual.solution.CheckWarning` per failed one; :func:`~ngdual.solvers.solve_problem`
stores them in ``Solution.warnings`` and :func:`~ngdual.solvers.solve_scene` (``nd.solve``)
also issues each as a Python warning (:class:`~ngdual.solution.PhysicsWarning`).
Each message is one line naming the cause, its size and the remedy. Unlike the solvers,
the checks read the scene: what meets Gamma_C at its ends and which end values it sets.

Modules: :mod:`~ngdual.checks.forces` (what is measured on Gamma_C: the hat moments, the
force balance and the force scale F_ref), :mod:`~ngdual.checks.ends` (the clamped ends of
Gamma_C and the thesis' end values there), :mod:`~ngdual.checks.physics` (every check, its
tolerance and its message).
"""

from __future__ import annotations

from .ends import END_GAP_TOL, thesis_ends_outside_l2
from .forces import (
    CONTACT_TOL,
    NOISE,
    ForceBalance,
    applied_load,
    contact_forces,
    displacement_scale,
    friction_forms_of,
    in_contact,
    stress_rms,
)
from .physics import (
    FORCE_BALANCE_TOL,
    FRICTION_TOL,
    LOAD_SHARE_TOL,
    PENETRATION_TOL,
    TENSION_TOL,
    physics_checks,
)

__all__ = ["CONTACT_TOL", "END_GAP_TOL", "FORCE_BALANCE_TOL", "FRICTION_TOL",
           "LOAD_SHARE_TOL", "NOISE", "PENETRATION_TOL", "TENSION_TOL", "ForceBalance",
           "applied_load", "contact_forces", "displacement_scale", "friction_forms_of",
           "in_contact", "physics_checks", "stress_rms", "thesis_ends_outside_l2"]
