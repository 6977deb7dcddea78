"""Solve a scene: build only what it calls for, then run the matching algorithm.

:func:`solve_scene` meshes a scene on a level; :func:`solve_on_mesh` is the SOLVE step on
any mesh (the adaptive loop's too); :func:`solve_problem` runs the algorithm the settings
call for:

``solver.method = "uzawa"`` (the thesis' algorithms):

no contact boundary  -> one linear saddle-point solve
contact, no friction -> Algorithm 3.38 (Uzawa)
Tresca / Coulomb     -> Algorithm 3.41 / Remark 3.45 (nested Uzawa)

``solver.method = "active-set"`` or ``"auto"`` (default): the hybridised system of broken
RT_k rows with the contact multipliers last (:mod:`ngdual.solvers.hybrid`), one Cholesky
factorisation, and for contact the semismooth Newton method on the contact multipliers
(:mod:`ngdual.solvers.active_set`): the same discrete solution at about the cost of one
linear solve, for every order and multiplier family. :mod:`ngdual.solvers.conforming`
solves the same problem on the conforming K, the independent check of the tests.
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from collections.abc import Callable

import ngsolve as ngs
import numpy as np

from .. import budget, checks
from ..boundary import BoundaryMeshes
from ..forms import DiscreteProblem, assemble
from ..mesh import build_mesh
from ..quadrature_check import check_formulas
from ..scene import Scene, SceneError, SceneTypeError, check_level, ensure_valid, validate
from ..scene.values import show
from ..solution import ConvergenceError, PhysicsWarning, Solution
from .active_set import active_set_solve
from .linear import solve_linear
from .nested import nested_uzawa
from .settings import (
    ActiveSetSettings,
    LinearSettings,
    NestedUzawaSettings,
    Settings,
    UzawaSettings,
    solver_settings,
)
from .start import ContactStart
from .uzawa import uzawa


def solve_scene(scene: Scene, level: int | None = None,
                progress: Callable[[int, float], None] | None = None,
                allow_large: bool = False,
                status: Callable[[str], None] | None = None, *,
                order: int | None = None, multipliers: str | None = None) -> Solution:
    """Mesh ``scene`` on ``level`` (default: the scene's level) and solve it there.

    The scene is validated (once: a scene from :func:`ngdual.scene.load_scene` is not
    checked again unless it was changed) and the size of the mesh is estimated and refused
    if it would not fit in memory (``allow_large=True`` tries anyway,
    :mod:`ngdual.budget`); then :func:`solve_on_mesh` solves. Bad input raises
    :class:`ngdual.scene.SceneError` naming the argument or field; a solve that fails
    raises :class:`ngdual.solution.ConvergenceError`. ``progress(iteration,
    increment)`` is called after every iteration of the contact solver, ``status(phase)``
    when a phase begins (meshing, assembling, factorising and solving), e.g. for a
    progress display. Every failed physics check (``solution.warnings``,
    :mod:`ngdual.checks`) is also issued as a Python warning of category
    :class:`~ngdual.solution.PhysicsWarning`, so a notebook shows it.

    ``order`` and ``multipliers`` solve with the polynomial order k of PEERS_k and the
    multiplier family in place of the scene's ``[discretisation]`` entries
    (:func:`with_discretisation`; ``scene`` itself is not changed, ``solution.problem.scene``
    is the scene solved).

    >>> import ngdual as nd
    >>> scene = nd.load_scene("thesis-3.46-frictionless", ["geometry.level=2"])
    >>> nd.solve(scene, order=1).problem.scene.discretisation.family   # doctest: +SKIP
    'facet'
    """
    start = time.perf_counter()
    scene = with_discretisation(scene, order, multipliers)
    level = check_level(level, "level", optional=True)
    if progress is not None and not callable(progress):
        raise SceneTypeError("progress", f"must be a callable progress(iteration, "
                                         f"increment), got {type(progress).__name__}")
    if not isinstance(allow_large, bool):
        raise SceneTypeError("allow_large", f"must be True or False, got {allow_large!r}")
    budget.check_scene(scene, level, "level", allow_large)
    level = scene.geometry.level if level is None else level
    if status is not None:
        status(f"meshing level {level}")
    mesh = build_mesh(scene.geometry, level)
    solution = solve_on_mesh(scene, mesh, level=level, progress=progress, status=status)
    solution.timings["total"] = time.perf_counter() - start
    for found in solution.warnings:
        warnings.warn(found.message, PhysicsWarning, stacklevel=2)
    return solution


def with_discretisation(scene: Scene, order: int | None = None,
                        multipliers: str | None = None) -> Scene:
    """The valid ``scene`` with ``order`` and ``multipliers`` in place of its
    ``[discretisation]`` entries (None keeps the scene's); ``scene`` itself is unchanged.

    ``order`` is the k of PEERS_k (0, 1, 2; 0 is the thesis' triple (3.61)),
    ``multipliers`` the family of phi, lambda_n, lambda_t (``"auto"``, ``"coarse"``,
    ``"facet"``: :class:`ngdual.scene.Discretisation`). The changed scene is validated as a
    whole; a problem of either entry raises a :class:`~ngdual.scene.SceneError` naming the
    argument (``order``, ``multipliers``), one that the entries cause elsewhere (the thesis'
    end values with the facet multipliers) names the scene's field (``contact.ends``).
    """
    ensure_valid(scene)
    given = {name: value for name, value in (("order", order), ("multipliers", multipliers))
             if value is not None}
    if not given:
        return scene
    if "order" in given and (isinstance(order, bool)
                             or not isinstance(order, (int, np.integer))):
        raise SceneTypeError("order", f"must be an integer k (0, 1 or 2) or None, got "
                                      f"{show(order)}")
    if "multipliers" in given and not isinstance(multipliers, str):
        raise SceneTypeError("multipliers", f"must be a string (\"auto\", \"coarse\" or "
                                            f"\"facet\") or None, got {show(multipliers)}")
    if "order" in given:
        given["order"] = int(order)
    changed = dataclasses.replace(
        scene, discretisation=dataclasses.replace(scene.discretisation, **given))
    try:
        validate(changed)
    except SceneError as err:
        renamed = {f"discretisation.{name}": name for name in given}
        problems = [(renamed.get(f, f), m) for f, m in err.problems]
        raise SceneError(problems[0][0], problems[0][1], problems) from None
    return changed


def solve_on_mesh(scene: Scene, mesh: ngs.Mesh, coarse: BoundaryMeshes | None = None, *,
                  level: int | None = None, settings: Settings | None = None,
                  progress: Callable[[int, float], None] | None = None,
                  status: Callable[[str], None] | None = None,
                  start: ContactStart | None = None) -> Solution:
    """The SOLVE step on a given mesh: assemble (3.62) for a valid ``scene`` and solve it.

    The formulas are checked on the mesh's quadrature points before assembly
    (:mod:`ngdual.quadrature_check`), coarse boundary meshes that leave a multiplier without
    unknowns are refused (:func:`check_unknowns`), and :func:`solve_problem` runs the
    algorithm and the physics checks. :func:`solve_scene` and the adaptive loop
    (:func:`ngdual.afem.adapt`) both solve through here.

    Parameters
    ----------
    scene : Scene
        A validated scene (:func:`ngdual.scene.ensure_valid`).
    mesh : ngsolve.Mesh
    coarse : BoundaryMeshes, optional
        The h~/h^ meshes on ``mesh`` (default: built for the mesh); the adaptive loop
        passes those that followed the refinement.
    level : int, optional
        The level ``mesh`` was built on (None for a locally refined mesh): recorded as
        ``problem.level`` and named in the error messages.
    settings : Settings, optional
        Default :func:`~ngdual.solvers.settings.solver_settings` of ``scene``.
    progress, status : callable, optional
        As for :func:`solve_scene`.
    start : ContactStart, optional
        The contact multipliers of a solution on a coarser mesh (the adaptive loop's
        previous step), to start the active-set method's contact iteration from; see
        :func:`solve_problem`.
    """
    check_formulas(scene, mesh)
    if status is not None:
        status(f"assembling on {mesh.ne} triangles")
    problem = assemble(scene, mesh, coarse)
    problem.level = level
    check_unknowns(problem)
    if status is not None:
        status(f"factorising and solving, {problem.fes.ndof} unknowns")
    return solve_problem(problem, settings, progress, start)


def check_unknowns(problem: DiscreteProblem) -> None:
    """Refuse coarse boundary meshes that leave a multiplier without unknowns.

    With h~ = ``htilde_factor`` h longer than a whole contact (or Neumann) chain, the
    multipliers, zero at the chain's ends, have no unknown left and the contact or
    traction condition would silently not be imposed.
    """
    scene, dofs = problem.scene, problem.spaces.dofs()
    mesh = "this mesh" if problem.level is None else f"level {problem.level}"
    factor = scene.contact.htilde_factor
    for key, role, name in (("C", "contact", "lambda on Gamma_C"),
                            ("N", "neumann", "phi on Gamma_N")):
        if scene.labels(role) and dofs[key] == 0:
            raise SceneError("contact.htilde_factor", f"h~ = {factor} h leaves {name} without "
                             f"unknowns on {mesh}: Gamma_{role[0].upper()} has too few edges; "
                             "choose a smaller htilde_factor or a finer level or maxh")
    if scene.has_friction and problem.spaces.friction is not None and dofs["L"] == 0:
        raise SceneError("contact.hhat_factor", f"h^ leaves nu without unknowns on {mesh}; "
                                                "choose hhat_factor = 1 or a finer level")


def solve_problem(problem: DiscreteProblem, settings: Settings | None = None,
                  progress: Callable[[int, float], None] | None = None,
                  start: ContactStart | None = None) -> Solution:
    """Run the algorithm ``settings`` describe on an assembled ``problem`` (any mesh).

    ``settings`` (:mod:`ngdual.solvers.settings`) defaults to those of the problem's scene,
    :func:`~ngdual.solvers.settings.solver_settings`: the one place where a solve reads
    the scene. A solution with a non-finite value or residual is never returned as a
    solution: it raises :class:`ngdual.solution.ConvergenceError` with the history.
    ``start`` warm-starts the active-set method (:class:`~.start.ContactStart`); the
    Uzawa algorithms of the thesis start from zero and refuse it (ValueError).
    """
    if settings is None:
        settings = solver_settings(problem.scene)
    if start is not None and not isinstance(settings, ActiveSetSettings):
        raise ValueError(f"a warm start is for the active-set method, not "
                         f"{type(settings).__name__}")
    if isinstance(settings, ActiveSetSettings):
        solution = active_set_solve(problem, settings, progress=progress, start=start)
    elif isinstance(settings, LinearSettings):
        solution = solve_linear(problem)
    elif isinstance(settings, UzawaSettings):
        solution = uzawa(problem, settings, progress=progress)
    elif isinstance(settings, NestedUzawaSettings):
        solution = nested_uzawa(problem, settings, progress=progress)
    else:
        raise TypeError(f"settings must be one of the settings of ngdual.solvers.settings, "
                        f"got {type(settings).__name__}")
    solution.settings = settings
    _check_finite(solution)
    start = time.perf_counter()
    solution.warnings = checks.physics_checks(solution)
    solution.timings["checks"] = time.perf_counter() - start
    return solution


def _check_finite(solution: Solution) -> None:
    """Non-finite unknowns or residuals (overflow, a singular factor) are a failed solve."""
    bad = [] if np.all(np.isfinite(solution.x)) else ["the unknowns"]
    if solution.nu is not None and not np.all(np.isfinite(solution.nu)):
        bad.append("nu")
    bad += [f"residual {k}" for k, v in solution.residuals.items()
            if isinstance(v, float) and not np.isfinite(v)]
    if bad:
        solution.converged = False
        raise ConvergenceError(f"{solution.method}: {', '.join(bad)} are not finite (inf or "
                               "nan): the problem overflows double precision or is singular; "
                               "check the units of material.E and the loads",
                               list(solution.history))
