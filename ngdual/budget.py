"""The size of a run before it starts: elements, unknowns and memory against the machine.

A mesh is never built blind: :func:`estimate` predicts the number of triangles of a
scene's geometry on a level (exactly for Example 3.46, ``32 * 4**(level-1)``; for a
netgen polygon from its area and ``maxh``, plus the graded strips along sides with a
smaller ``side_maxh``), the unknowns of (3.62) (about 7.5 per triangle: Table 3.1 has
X = 680 + M = 256 + S = 81 + ... on 128 triangles) and the peak memory of a solve
(about 2.5 kB per unknown: Example 3.46 with Coulomb friction on level 8, 3.9e6
unknowns, peaks at 9 GB with the active-set solver; the Uzawa algorithms, with the
saddle-point factorisation, need about 8.5 kB per unknown: 0.6 GB on level 5 and 2.2 GB on
level 6 of Example 3.46 with Coulomb friction).
:func:`check` refuses a run whose estimate exceeds the memory the machine has
available, with the estimate in the message; ``allow_large=True`` (the CLI's
``--allow-large``) runs it anyway.

>>> from ngdual.scene import Geometry
>>> estimate(Geometry(), level=2).elements   # Example 3.46: 32 * 4 triangles
128.0
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from . import geometry
from .scene import Geometry, SceneError

UNKNOWNS_PER_ELEMENT = 7.5
# peak of a solve per unknown (factorisation, condensation, records), by solver.method
BYTES_PER_UNKNOWN = {"auto": 2500.0, "active-set": 2500.0, "uzawa": 8500.0}
BYTES_PER_ELEMENT_MESH = 2000.0  # mesh and spaces only (``ngdual dofs``)
BASE_BYTES = 400e6              # Python, NGSolve, SciPy, cvxpy loaded


@dataclass(frozen=True)
class Estimate:
    """Predicted size of one mesh level and of its solve."""

    elements: float
    unknowns: float
    memory: float       # bytes, a whole solve
    mesh_memory: float  # bytes, mesh and spaces only

    def describe(self, mesh_only: bool = False) -> str:
        memory = self.mesh_memory if mesh_only else self.memory
        return (f"about {self.elements:.3g} triangles, {self.unknowns:.3g} unknowns and "
                f"{_gib(memory)} of memory")


def estimate(geo: Geometry, level: int | None = None, method: str = "auto") -> Estimate:
    """The predicted size of the mesh of ``geo`` on ``level`` (default: its own level) and
    of a solve with ``method`` (``solver.method``)."""
    level = geo.level if level is None else level
    refinements = 4.0 ** min(level - 1, 400)  # beyond, the estimate is "too large" anyway
    if geo.kind == "thesis-3.46":
        elements = 32.0 * refinements
    else:
        curves = geo.curves()
        area = geometry.signed_area(geometry.outline(curves))
        elements = max(area / (math.sqrt(3) / 4 * geo.maxh ** 2), 2.0)
        lengths = {c.label: 0.0 for c in curves}
        for c in curves:
            xy = c.sample(65)[0] if c.is_arc else np.array([c.start, c.end])
            lengths[c.label] += float(np.linalg.norm(np.diff(xy, axis=0), axis=1).sum())
        for label, h in geo.side_maxh.items():
            if h < geo.maxh:
                # netgen grades from h to maxh: a strip of about log2(maxh/h) layers
                elements += 4.0 * lengths[label] / h * max(1.0, math.log2(geo.maxh / h))
        elements *= refinements
    return Estimate(elements, UNKNOWNS_PER_ELEMENT * elements, solve_memory(elements, method),
                    BASE_BYTES + BYTES_PER_ELEMENT_MESH * elements)


def solve_memory(elements: float, method: str = "auto") -> float:
    """Predicted peak bytes of a solve with ``method`` on a mesh of ``elements`` triangles."""
    per_unknown = BYTES_PER_UNKNOWN.get(method, max(BYTES_PER_UNKNOWN.values()))
    return BASE_BYTES + per_unknown * UNKNOWNS_PER_ELEMENT * elements


def available_memory() -> float:
    """Bytes of memory available to a new run (psutil's estimate, else the physical size)."""
    try:
        import psutil

        return float(psutil.virtual_memory().available)
    except ImportError:  # pragma: no cover - psutil comes with dask.distributed
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))


def check(geo: Geometry, level: int | None = None, field_name: str = "geometry.level",
          allow_large: bool = False, mesh_only: bool = False, method: str = "auto") -> Estimate:
    """The estimate of ``geo`` on ``level``; a SceneError naming ``field_name`` if it does
    not fit in the available memory (unless ``allow_large``)."""
    size = estimate(geo, level, method)
    need = size.mesh_memory if mesh_only else size.memory
    have = available_memory()
    if need > have and not allow_large:
        where = f"level {geo.level if level is None else level}"
        if geo.kind == "polygon":
            where += f" with maxh = {geo.maxh:g}"
            first = estimate(geo, 1, method)
            if (first.mesh_memory if mesh_only else first.memory) > have:
                field_name = "geometry.maxh"  # too fine before any refinement
        raise SceneError(field_name, f"{where} needs {size.describe(mesh_only)}, more than "
                                     f"the {_gib(have)} this machine has available; choose a "
                                     "coarser level or maxh, or pass --allow-large "
                                     "(allow_large=True) to try anyway")
    return size


def _gib(nbytes: float) -> str:
    return f"{nbytes / 2**30:.3g} GiB"
