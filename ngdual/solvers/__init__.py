"""Solvers for the discrete problem (3.62) and the one entry point that picks among them.

:func:`solve_scene` meshes, assembles and solves a scene; :func:`solve_problem` runs the
algorithm the settings call for on an assembled problem: the linear solve
(:mod:`.linear`), Uzawa (Algorithm 3.38, :mod:`.uzawa`), nested Uzawa (Algorithm 3.41,
:mod:`.nested`) or the active-set method on Gamma_C (:mod:`.active_set`); the reference
QP (:mod:`.reference`) checks them.
"""

from .dispatch import check_unknowns, solve_problem, solve_scene
from .result import ConvergenceError, Solution

__all__ = ["ConvergenceError", "Solution", "check_unknowns", "solve_problem", "solve_scene"]
