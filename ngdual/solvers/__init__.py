"""Solvers for the discrete problem (3.62) and the one entry point that picks among them.

:func:`solve_scene` meshes, assembles and solves a scene; :func:`solve_on_mesh` assembles
and solves it on a given mesh; :func:`solve_problem` runs the algorithm its settings call
for on an assembled problem: the linear solve (:mod:`.linear`), Uzawa (Algorithm 3.38,
:mod:`.uzawa`), nested Uzawa (Algorithm 3.41, :mod:`.nested`) or the active-set method on
Gamma_C (:mod:`.active_set`); the same discrete problems as convex QPs (:mod:`.qp`) check
them. The settings (:mod:`.settings`) are built once from the scene; no solver reads the
scene itself.
"""

from ..solution import ConvergenceError, Solution
from .dispatch import check_unknowns, solve_on_mesh, solve_problem, solve_scene
from .settings import (
    ActiveSetSettings,
    LinearSettings,
    Model,
    NestedUzawaSettings,
    UzawaSettings,
    solver_settings,
)

__all__ = ["ActiveSetSettings", "ConvergenceError", "LinearSettings", "Model",
           "NestedUzawaSettings", "Solution", "UzawaSettings", "check_unknowns",
           "solve_on_mesh", "solve_problem", "solve_scene", "solver_settings"]
