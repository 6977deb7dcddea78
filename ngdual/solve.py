"""Solve a scene: build only what it calls for, then run the matching algorithm.

no contact boundary  -> one linear saddle-point solve
contact, no friction -> Algorithm 3.38 (Uzawa)
"""

from __future__ import annotations

import time
from collections.abc import Callable

from .forms import assemble
from .mesh import build_mesh
from .scene import Scene
from .solvers.result import Solution
from .solvers.uzawa import solve_linear, uzawa


def solve_scene(scene: Scene, level: int | None = None,
                progress: Callable[[int, float], None] | None = None) -> Solution:
    """Mesh, assemble and solve ``scene`` on ``level`` (default: the scene's level)."""
    start = time.perf_counter()
    problem = assemble(scene, build_mesh(scene.geometry, level))
    problem.level = scene.geometry.level if level is None else level
    if not scene.has_contact:
        solution = solve_linear(problem)
    elif not scene.has_friction:
        s = scene.solver
        solution = uzawa(problem, rho=s.rho, eps=s.eps, max_iter=s.max_iter, metric=s.metric,
                         progress=progress)
    else:
        raise NotImplementedError(f"friction law {scene.friction.law!r} is not implemented yet "
                                  "(scene loads and validates; see the friction issue)")
    solution.timings["total"] = time.perf_counter() - start
    return solution
