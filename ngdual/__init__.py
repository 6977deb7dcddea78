"""ngdual: dual-dual mixed finite elements (PEERS) for frictional contact in 2D elasticity.

The data flow is one way: scene -> mesh -> spaces -> forms -> solver -> estimator ->
marking -> adaptive loop -> post-processing. ``import ngdual as nd`` gives the names a
notebook needs:

>>> import ngdual as nd
>>> scene = nd.load_scene("thesis-3.46-coulomb", ["geometry.level=2"])
>>> solution = nd.solve(scene)                                   # doctest: +SKIP
>>> nd.norms(solution)["sigma_X"]                                # doctest: +SKIP
>>> frictionless = nd.load_scene("thesis-3.46-frictionless", ["contact.ends='consistent'"])
>>> nd.solve(frictionless, 2, order=1)                           # doctest: +SKIP

Scenes: :func:`load_scene`, :func:`validate`, :func:`shipped_scenes`, :class:`Scene`,
:class:`SceneError`. Solving: :func:`solve` (mesh, assemble, solve; Algorithms 3.38/3.41
or the active-set method; ``order=k`` for PEERS of order k, ``multipliers=`` for the family
of the boundary multipliers), :class:`Solution`. Adaptivity (Chapter 4): :func:`adapt` (the
loop SOLVE, ESTIMATE, MARK, REFINE) and its steps, to write the loop by hand:
:func:`build_mesh` and :class:`BoundaryMeshes` (the coarse meshes h~, h^ of its boundary),
:func:`solve_on_mesh`, :func:`estimate` (the indicators of eq. 4.50), :func:`mark`,
:func:`refine_with_boundary`. Post-processing: :func:`fields`, :func:`norms`,
:func:`contact_traces`, :func:`force_balance`, :func:`result_record`. Plotting (each returns
a matplotlib figure): :func:`plot_geometry` (the domain, its boundary parts and the mesh),
:func:`plot_contact_traces`, :func:`plot_element_field`, :func:`plot_von_mises`,
:func:`plot_mesh`, :func:`plot_deformed` (the body moved by u_h, magnified); saving one is the
caller's choice, :func:`save_figure`.

Taking the method apart (the tutorials): :func:`assemble` (the block system of eq. 3.62 on
a mesh), :func:`friction_forms` (the operators of friction on the fine edges of Gamma_C),
:func:`mesh_arrays` (the points and triangles the plots take), :class:`Expression` (a scene
formula in ``x``, ``y`` as a NumPy or NGSolve function), :func:`coefficient` (a formula, or
a vector or matrix of them, as an NGSolve coefficient function: an exact solution),
:func:`l2_norm` (of a field or of its error), :func:`solve_primal` (the standard P_k
displacement method with Nitsche contact, the method PEERS is compared with),
:class:`Lesson` (a tutorial's coarse-or-full setting and where its pictures go),
:mod:`rates` (the observed order in
h_N = N^(-1/2)), :mod:`post` (element values, von Mises stress, the contact summary), and
three subpackages with their modules: :mod:`scene` (the tables of a scene: ``nd.scene.Geometry``,
``nd.scene.Material``, ``nd.scene.Loads``, ``nd.scene.Contact``), :mod:`solvers` (the
algorithms one by one: ``nd.solvers.uzawa`` for Algorithm 3.38, ``nd.solvers.nested`` for
Algorithm 3.41, ``nd.solvers.qp`` the same problems as convex QPs, their settings
``nd.solvers.UzawaSettings``) and :mod:`verification` (exact solutions and checks:
``nd.verification.infsup``, ``nd.verification.corner``, ``nd.verification.overkill``).

The names are loaded lazily (PEP 562): ``import ngdual`` imports neither NGSolve nor
matplotlib, so that the command line starts fast; the first use of a name imports its
module. Every name here needs only the core dependencies (``install_requires``); a study
that needs an extra names it (:func:`ngdual.extras.require`).
"""

from __future__ import annotations

import importlib
import pkgutil

__version__ = "0.1.0"

# public name -> (module, attribute): the one table of the public API
_PUBLIC = {
    "load_scene": ("ngdual.scene", "load_scene"),
    "validate": ("ngdual.scene", "validate"),
    "shipped_scenes": ("ngdual.scene", "shipped_scenes"),
    "Scene": ("ngdual.scene", "Scene"),
    "SceneError": ("ngdual.scene", "SceneError"),
    "solve": ("ngdual.accuracy", "solve"),
    "Solution": ("ngdual.solution", "Solution"),
    "adapt": ("ngdual.afem", "adapt"),
    "build_mesh": ("ngdual.mesh", "build_mesh"),
    "BoundaryMeshes": ("ngdual.boundary", "BoundaryMeshes"),
    "solve_on_mesh": ("ngdual.solvers", "solve_on_mesh"),
    "estimate": ("ngdual.estimator", "estimate"),
    "mark": ("ngdual.marking", "mark"),
    "refine_with_boundary": ("ngdual.afem", "refine_with_boundary"),
    "fields": ("ngdual.quantities", "fields"),
    "norms": ("ngdual.quantities", "norms"),
    "contact_traces": ("ngdual.trace", "contact_traces"),
    "force_balance": ("ngdual.post", "force_balance"),
    "result_record": ("ngdual.post", "result_record"),
    "plot_contact_traces": ("ngdual.plot", "plot_contact_traces"),
    "plot_element_field": ("ngdual.plot", "plot_element_field"),
    "plot_geometry": ("ngdual.plot", "plot_geometry"),
    "plot_mesh": ("ngdual.plot", "plot_mesh"),
    "plot_von_mises": ("ngdual.plot", "plot_von_mises"),
    "plot_deformed": ("ngdual.plot", "plot_deformed"),
    "save_figure": ("ngdual.plot", "save_figure"),
    "assemble": ("ngdual.forms", "assemble"),
    "Expression": ("ngdual.expr", "Expression"),
    "Lesson": ("ngdual.studies.tutorials", "Lesson"),
    "friction_forms": ("ngdual.friction", "build_friction_forms"),
    "mesh_arrays": ("ngdual.mesh", "mesh_arrays"),
    "coefficient": ("ngdual.expr", "coefficient"),
    "l2_norm": ("ngdual.quantities", "l2_norm"),
    "solve_primal": ("ngdual.studies.primal_peer", "primal_solution"),
    # modules, a subpackage with its modules: the scene's tables, the thesis' algorithms
    # one by one, exact solutions and checks, convergence rates
    "scene": ("ngdual.scene", None),
    "solvers": ("ngdual.solvers", None),
    "verification": ("ngdual.verification", None),
    "rates": ("ngdual.rates", None),
    "post": ("ngdual.post", None),
}

__all__ = ["__version__", *_PUBLIC]


def __getattr__(name: str):
    """Import the module of a public name (or a submodule, ``nd.post``) on first use; a
    public subpackage (``nd.solvers``) comes with its modules (``nd.solvers.uzawa``)."""
    if name.startswith("__"):
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    if name in _PUBLIC:
        module, attribute = _PUBLIC[name]
        value = importlib.import_module(module)
        if attribute is None:
            for info in pkgutil.iter_modules(getattr(value, "__path__", [])):
                importlib.import_module(f"{module}.{info.name}")
        else:
            value = getattr(value, attribute)
        globals()[name] = value  # later look-ups do not come back here
        return value
    try:
        return importlib.import_module(f"{__name__}.{name}")
    except ModuleNotFoundError as err:
        if err.name != f"{__name__}.{name}":
            raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
