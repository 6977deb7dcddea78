"""The scene's formulas evaluated on the mesh they are about to be assembled on.

:func:`ngdual.scene.validate` samples the boundary data on the exact sides; this
module checks, once a mesh exists and before anything is assembled, that every
formula is finite where the forms of (3.62) evaluate it: the body force f on the
quadrature points and vertices of every triangle, the traction t0, the prescribed
displacement u_D, the gap g and a Tresca bound F on those of the edges of
Gamma_N, Gamma_D and Gamma_C. A formula such as ``log(0*x)`` or ``sqrt(-1-x*x)``
is refused there with its field and a point, instead of surfacing as NaNs in a
factorisation.
"""

from __future__ import annotations

import ngsolve as ngs
import numpy as np

from .expr import Expression, quote
from .forms import LOAD_ORDER, TRACE_ORDER, boundary_regex
from .scene import Scene, SceneError

# the rules of assembly (ngdual.forms): f on the triangles, u_D, t0, g and F on the edges
ORDER = {ngs.TRIG: LOAD_ORDER, ngs.SEGM: TRACE_ORDER}


def _rule(element: ngs.ET) -> ngs.IntegrationRule:
    """Gauss points of ``element`` plus its vertices (where the traces are evaluated)."""
    gauss = ngs.IntegrationRule(element, ORDER[element])
    vertices = [(0.0,), (1.0,)] if element == ngs.SEGM else [(0.0, 0.0), (1.0, 0.0),
                                                             (0.0, 1.0)]
    return ngs.IntegrationRule([*(p for p in gauss.points), *vertices],
                               [*(w for w in gauss.weights), *(0.0 for _ in vertices)])


def formulas_on_mesh(scene: Scene) -> list[tuple[str, Expression, str | None]]:
    """``(field, formula, role)`` of every non-constant formula the forms evaluate;
    ``role`` None means the whole domain."""
    out = [(f"loads.body_force[{i}]", Expression(e), None)
           for i, e in enumerate(scene.loads.body_force)]
    if scene.labels("neumann"):
        if isinstance(scene.loads.traction, dict):  # a pair per side (Scene.tractions)
            out += [(f"loads.traction.{label}[{i}]", Expression(e), "neumann")
                    for label, both in scene.tractions().items() for i, e in enumerate(both)]
        else:
            out += [(f"loads.traction[{i}]", Expression(e), "neumann")
                    for i, e in enumerate(scene.loads.traction)]
    out += [(f"loads.displacement[{i}]", Expression(e), "dirichlet")
            for i, e in enumerate(scene.loads.displacement)]
    if scene.has_contact and scene.contact.foundation is None:
        out.append(("contact.gap", Expression(scene.contact.gap_formula), "contact"))
    if scene.has_contact and scene.friction.law == "tresca":
        out.append(("friction.bound", Expression(scene.friction.bound), "contact"))
    return [item for item in out if item[1].constant is None]


def check_formulas(scene: Scene, mesh: ngs.Mesh) -> None:
    """Raise a :class:`SceneError` for every formula that is not finite somewhere on the
    quadrature points (or vertices) of ``mesh`` where it is integrated."""
    problems = []
    for field_name, expr, role in formulas_on_mesh(scene):
        if role is None:
            points = mesh.MapToAllElements(_rule(ngs.TRIG), ngs.VOL)
        else:
            region = mesh.Boundaries(boundary_regex(scene.labels(role)))
            points = mesh.MapToAllElements(_rule(ngs.SEGM), region)
        with np.errstate(all="ignore"):
            values = np.asarray(expr.coefficient()(points)).ravel()
        bad = ~np.isfinite(values)
        if bad.any():
            i = int(np.argmax(bad))
            xy = np.asarray(ngs.CF((ngs.x, ngs.y))(points[i:i + 1])).ravel()
            where = "the mesh" if role is None else f"the {role} edges"
            problems.append((field_name, f"{quote(expr.text)} is not finite at the quadrature "
                                         f"point ({xy[0]:.4g}, {xy[1]:.4g}) of {where} "
                                         f"(value {values[i]})"))
    if problems:
        raise SceneError("", "", problems)
