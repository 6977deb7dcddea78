"""Solve a scene: build only what it calls for, then run the matching algorithm.

``solver.method = "uzawa"`` (the thesis' algorithms):

no contact boundary  -> one linear saddle-point solve
contact, no friction -> Algorithm 3.38 (Uzawa)
Tresca / Coulomb     -> Algorithm 3.41 / Remark 3.45 (nested Uzawa)

``solver.method = "active-set"`` or ``"auto"`` (default): the hybridised system, one
Cholesky factorisation, and for contact the semismooth Newton method on Gamma_C
(:mod:`ngdual.solvers.fast`): the same discrete solution at about the cost of one linear
solve.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from .forms import DiscreteProblem, assemble
from .mesh import build_mesh
from .scene import Scene
from .solvers.fast import fast_solve
from .solvers.nested import nested_uzawa
from .solvers.result import Solution
from .solvers.uzawa import solve_linear, uzawa


def solve_scene(scene: Scene, level: int | None = None,
                progress: Callable[[int, float], None] | None = None) -> Solution:
    """Mesh, assemble and solve ``scene`` on ``level`` (default: the scene's level)."""
    start = time.perf_counter()
    problem = assemble(scene, build_mesh(scene.geometry, level))
    problem.level = scene.geometry.level if level is None else level
    solution = solve_problem(problem, progress)
    solution.timings["total"] = time.perf_counter() - start
    return solution


def solve_problem(problem: DiscreteProblem,
                  progress: Callable[[int, float], None] | None = None) -> Solution:
    """Run the algorithm the scene of an assembled ``problem`` calls for (any mesh)."""
    scene = problem.scene
    if scene.solver.method in ("auto", "active-set"):
        solution = fast_solve(problem, max_iter=scene.solver.max_iter, metric=scene.solver.metric,
                              progress=progress)
    elif not scene.has_contact:
        solution = solve_linear(problem)
    elif not scene.has_friction:
        s = scene.solver
        solution = uzawa(problem, rho=s.rho, eps=s.eps, max_iter=s.max_iter, metric=s.metric,
                         progress=progress)
    else:
        s = scene.solver
        solution = nested_uzawa(problem, scene.friction.law, mu_f=scene.friction.mu,
                                rho1=s.rho1, rho2=s.rho2, eps1=s.eps1, eps2=s.eps2,
                                max_iter=s.max_iter, metric=s.metric, loop_order=s.loop_order,
                                friction_metric=s.friction_metric,
                                progress=progress)
    return solution
