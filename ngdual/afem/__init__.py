"""The adaptive loop SOLVE -> ESTIMATE -> MARK -> REFINE of Section 4.2.

:func:`adapt` solves the scene on its initial mesh (:func:`ngdual.solve_on_mesh`), computes
the indicators eta_{tot,T} of (4.50) (:mod:`ngdual.estimator`), measures them by its goal
(:mod:`ngdual.goal`: the stress goal, the thesis' (4.50), or the pressure goal on Gamma_C or
a window of it), marks with one of the strategies of :mod:`ngdual.marking` (with a ``tol``, at
least the triangles that grow the unknowns by :data:`GROWTH_TOL`), refines the marked
triangles with netgen's bisection (plus its conforming closure) and carries the coarse
boundary meshes h~, h^ over to the new mesh (:func:`refine_with_boundary`). Each step adds
one plain record to the returned history (:func:`step_record`). Uniform refinement is
``marking="max", theta=0``.

It runs at the order k of the scene's ``[discretisation]``. Given a tolerance ``tol`` it
stops as soon as the goal's relative estimate (:func:`relative_estimate`) is below it,
``steps`` being then only a bound. Every way a run ends is a stop rule
(:mod:`ngdual.afem.stops`), named in the last record's ``stopped_by``: its tolerance, its
steps, a stall, the resolution, a goal whose error is not finite, a window without contact,
or the memory the next refinement would need.

Modules: :mod:`~ngdual.afem.loop` (the loop), :mod:`~ngdual.afem.stops` (its stop rules),
:mod:`~ngdual.afem.refinement` (REFINE), :mod:`~ngdual.afem.records` (the history),
:mod:`~ngdual.afem.arguments` (the checks of the arguments).
"""

from __future__ import annotations

from .loop import (
    GROWTH,
    GROWTH_TOL,
    LEVEL_TOL,
    MARKING,
    STEPS,
    STEPS_TOL,
    THETA,
    THETA_TOL,
    AdaptWarning,
    ToleranceWarning,
    adapt,
    growth_default,
    loop_defaults,
)
from .records import reference_norms, relative_estimate, step_record
from .refinement import RESOLUTION, refine, refine_graded, refine_towards, refine_with_boundary
from .stops import STALL_STEPS

__all__ = ["GROWTH", "GROWTH_TOL", "LEVEL_TOL", "MARKING", "RESOLUTION", "STALL_STEPS", "STEPS",
           "STEPS_TOL", "THETA", "THETA_TOL", "AdaptWarning", "ToleranceWarning", "adapt",
           "growth_default", "loop_defaults",
           "reference_norms", "refine", "refine_graded", "refine_towards", "refine_with_boundary",
           "relative_estimate", "step_record"]
