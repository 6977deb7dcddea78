"""The size of a run before it starts: elements, unknowns and memory against the machine.

A mesh is never built blind: :func:`estimate` predicts the number of triangles of a
scene's geometry on a level (exactly for Example 3.46, ``32 * 4**(level-1)``; for a
netgen polygon from its area and ``maxh``, plus the graded strips along sides with a
smaller ``side_maxh``), the unknowns of (3.62) at the order k of PEERS_k
(:func:`unknowns_per_element`: 7.5 per triangle at k = 0, Table 3.1 has X = 680 + M = 256
+ S = 81 + ... on 128 triangles; 24 at k = 1, 47.5 at k = 2) and the peak memory of a
solve. Every order and multiplier family is solved by the same hybridised system
(:mod:`ngdual.solvers.hybrid`), whose peak per unknown :data:`BYTES_PER_UNKNOWN_ORDER`
grows with the size of its element blocks: about 2.5 kB at k = 0 (Example 3.46 with
Coulomb friction on level 8, 3.9e6 unknowns: 9 GB; level 6 0.70 GB, the same as the
thesis' own hybridisation that the solver replaced). The Uzawa algorithms and their
saddle-point factorisation peak at 8.5 kB per unknown (0.6 GB on level 5 and 2.2 GB on
level 6).
:func:`check` refuses a run whose estimate exceeds the memory this process may use
(:func:`available_memory`: the smallest of the machine's available memory, the address
space left under ``ulimit -v`` and the room left in the process's cgroup), with the
estimate in the message; ``allow_large=True`` (the CLI's ``--allow-large``) runs it anyway.

>>> from ngdual.scene import Geometry
>>> estimate(Geometry(), level=2).elements   # Example 3.46: 32 * 4 triangles
128.0
"""

from __future__ import annotations

import math
import os
import resource
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from . import geometry
from .forms.spaces import variant_of
from .scene import Geometry, Scene, SceneError

UNKNOWNS_PER_ELEMENT = 7.5    # PEERS_0 (3.61): unknowns_per_element(0)
# peak per unknown of the Uzawa algorithms at order 0 (their saddle-point factorisation)
BYTES_PER_UNKNOWN = {"uzawa": 8500.0}
# peak of a solve of order k per unknown (either family): the hybridised system;
# measured peaks of nd.solve on Example 3.46 without friction, consistent
# ends (tests/test_budget_order.py): k = 0 facet level 5 0.36 GB; k = 1 level 4 0.37 GB,
# level 5 0.79 GB; k = 2 level 4 0.69 GB, level 5 1.97 GB, level 6 7.9 GB (4.9 kB per
# unknown); hertz-cylinder k = 2 level 4 3.2-3.4 GB (4.3 kB)
BYTES_PER_UNKNOWN_ORDER = {0: 2500.0, 1: 3000.0, 2: 5500.0}
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


def unknowns_per_element(order: int = 0) -> float:
    """Unknowns of PEERS_k per triangle on a large mesh (3 edges and 1/2 vertex each).

    Per stress row RT_k, k + 1 dofs per edge and k (k + 1) inside, plus the 2k + 1 bubbles
    of :func:`ngdual.peers.bubbles`; u in discontinuous P_k, (k + 1)(k + 2) / 2 per
    component; the rotation in continuous P_{k+1}, one dof per vertex, k per edge and
    k (k - 1) / 2 inside. The boundary multipliers grow like the square root of the
    triangles and are left out.

    >>> [unknowns_per_element(k) for k in (0, 1, 2)]
    [7.5, 24.0, 47.5]
    """
    row = 1.5 * (order + 1) + order * (order + 1) + 2 * order + 1
    displacement = (order + 1) * (order + 2)
    rotation = 0.5 + 1.5 * order + order * (order - 1) / 2
    return 2 * row + displacement + rotation


def _mesh_lengths(geo: Geometry) -> dict[str, float]:
    """Length of every side label of ``geo``."""
    lengths: dict[str, float] = {}
    for c in geo.curves():
        xy = c.sample(65)[0] if c.is_arc else np.array([c.start, c.end])
        lengths[c.label] = lengths.get(c.label, 0.0) + float(
            np.linalg.norm(np.diff(xy, axis=0), axis=1).sum())
    return lengths


def estimate(geo: Geometry, level: int | None = None, method: str = "auto", order: int = 0,
             multipliers: str = "coarse") -> Estimate:
    """The predicted size of the mesh of ``geo`` on ``level`` (default: its own level) and
    of a solve with ``method`` (``solver.method``) of PEERS_``order`` with the multiplier
    family ``multipliers`` (``discretisation.family``: "coarse" or "facet")."""
    level = geo.level if level is None else level
    refinements = 4.0 ** min(level - 1, 400)  # beyond, the estimate is "too large" anyway
    if geo.kind == "thesis-3.46":
        elements = 32.0 * refinements
    else:
        area = geometry.signed_area(geometry.outline(geo.curves()))
        elements = max(area / (math.sqrt(3) / 4 * geo.maxh ** 2), 2.0)
        lengths = _mesh_lengths(geo)
        for label, h in geo.side_maxh.items():
            if h < geo.maxh:
                # netgen grades from h to maxh: a strip of about log2(maxh/h) layers
                elements += 4.0 * lengths[label] / h * max(1.0, math.log2(geo.maxh / h))
        elements *= refinements
    unknowns = unknowns_per_element(order) * elements
    memory = solve_memory(elements, method, order, multipliers)
    mesh_memory = BASE_BYTES + BYTES_PER_ELEMENT_MESH * elements * (
        unknowns_per_element(order) / UNKNOWNS_PER_ELEMENT)
    return Estimate(elements, unknowns, memory, mesh_memory)


def solve_memory(elements: float, method: str = "auto", order: int = 0,
                 multipliers: str = "coarse") -> float:
    """Predicted peak bytes of a solve with ``method`` of PEERS_``order`` on a mesh of
    ``elements`` triangles. Both multiplier families (``multipliers``) are solved by the
    same hybridised system, whose peak per unknown depends on the order; the Uzawa
    algorithms factorise the saddle-point system instead (measured at order 0; at least
    the hybridised system's peak at order k)."""
    per_unknown = BYTES_PER_UNKNOWN_ORDER[order]
    if method == "uzawa":
        per_unknown = max(BYTES_PER_UNKNOWN["uzawa"], per_unknown)
    return BASE_BYTES + per_unknown * unknowns_per_element(order) * elements


CGROUP = Path("/sys/fs/cgroup")  # where the cgroup file system is mounted


def available_memory() -> float:
    """Bytes this process may hold at the peak of a run: the smallest of three limits.

    The estimates of :func:`solve_memory` are the peak resident memory of the whole
    process, so each limit counts what the process holds already as usable:

    * the machine: the available memory (psutil's estimate) plus this process's resident
      memory;
    * the address space (``ulimit -v``, ``prlimit --as``, RLIMIT_AS): the limit minus the
      address space the process has reserved without using it (thread stacks, allocator
      arenas: 1.2-1.5 GiB with NGSolve loaded, measured), which a run keeps reserved;
      beyond the limit an allocation fails and the sparse factorisations crash;
    * the cgroup (a container's or a batch job's ``memory.max``, version 1
      ``memory.limit_in_bytes``): the limit minus what the rest of the group uses.
    """
    return min(_memory_limits().values())


def _memory_limits() -> dict[str, float]:
    """Bytes usable under each limit that applies, by its name in a message."""
    resident, reserved = _process_memory()
    limits = {"this machine has available": _machine_available() + resident}
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        limits["the address-space limit (ulimit -v) leaves"] = float(soft) - (reserved - resident)
    group = _cgroup_memory()
    if group is not None:
        limit, used = group
        limits["the cgroup's memory limit leaves"] = limit - (used - resident)
    return limits


def _machine_available() -> float:
    """Bytes of memory the machine has available: psutil's estimate (a core dependency; an
    environment without it falls back to the kernel's MemAvailable, else the physical
    size)."""
    try:
        import psutil

        return float(psutil.virtual_memory().available)
    except ImportError:
        pass
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return float(line.split()[1]) * 1024  # kB
    except OSError:  # pragma: no cover - not Linux
        pass
    return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))


def _process_memory() -> tuple[float, float]:
    """Resident memory and address space (bytes) of this process (Linux; else zero)."""
    try:
        status = Path("/proc/self/status").read_text()
    except OSError:  # pragma: no cover - not Linux
        return 0.0, 0.0
    values = {}
    for line in status.splitlines():
        key, _, rest = line.partition(":")
        if key in ("VmRSS", "VmSize"):
            values[key] = float(rest.split()[0]) * 1024  # kB
    return values.get("VmRSS", 0.0), values.get("VmSize", 0.0)


def _cgroup_memory() -> tuple[float, float] | None:
    """``(limit, usage)`` in bytes of this process's cgroup, None without a limit.

    The group's own directory is tried first, then the mount point itself (inside a
    container the group is mounted there); version 2 (``memory.max``) before version 1.
    """
    try:
        lines = Path("/proc/self/cgroup").read_text().splitlines()
    except OSError:
        lines = []
    v2 = [line.split(":", 2)[2] for line in lines if line.startswith("0::")]
    v1 = [line.split(":", 2)[2] for line in lines
          if "memory" in line.split(":", 2)[1].split(",")]
    candidates = [(CGROUP / path.lstrip("/"), "memory.max", "memory.current") for path in v2]
    candidates.append((CGROUP, "memory.max", "memory.current"))
    candidates += [(CGROUP / "memory" / path.lstrip("/"), "memory.limit_in_bytes",
                    "memory.usage_in_bytes") for path in v1]
    candidates.append((CGROUP / "memory", "memory.limit_in_bytes", "memory.usage_in_bytes"))
    for folder, limit_file, usage_file in candidates:
        try:
            limit = (folder / limit_file).read_text().strip()
            usage = float((folder / usage_file).read_text().strip())
        except (OSError, ValueError):
            continue
        # "max" (version 2) or a page-rounded 2^63 (version 1): no limit
        if limit == "max" or float(limit) >= 2.0**62:
            return None
        return float(limit), usage
    return None


def describe_available(have: float | None = None) -> str:
    """``have`` bytes (default: :func:`available_memory`) and the limit they come from, for
    messages: e.g. ``"the 1.2 GiB the address-space limit (ulimit -v) leaves"``."""
    limits = _memory_limits()
    source = min(limits, key=limits.get)
    return f"the {_gib(limits[source] if have is None else have)} {source}"


def check(geo: Geometry, level: int | None = None, field_name: str = "geometry.level",
          allow_large: bool = False, mesh_only: bool = False, method: str = "auto",
          order: int = 0, multipliers: str = "coarse") -> Estimate:
    """The estimate of ``geo`` on ``level`` (:func:`estimate`, with ``method``, ``order``,
    ``multipliers``); a SceneError naming ``field_name`` if it does not fit
    in the available memory (unless ``allow_large``)."""
    size = estimate(geo, level, method, order, multipliers)
    need = size.mesh_memory if mesh_only else size.memory
    have = available_memory()
    if need > have and not allow_large:
        where = f"level {geo.level if level is None else level}"
        remedy = "a coarser level or maxh"
        if geo.kind == "polygon":
            where += f" with maxh = {geo.maxh:g}" + "".join(
                f", side_maxh.{label} = {h:g}" for label, h in geo.side_maxh.items())
            first = estimate(geo, 1, method, order, multipliers)
            if (first.mesh_memory if mesh_only else first.memory) > have:
                # too fine before any refinement: blame the size that makes it so
                field_name, remedy = _finest_size(geo)
        raise SceneError(field_name, f"{where} needs {size.describe(mesh_only)}, more than "
                                     f"{describe_available(have)}; choose {remedy}, or pass "
                                     "--allow-large (allow_large=True) to try anyway")
    return size


def check_scene(scene: Scene, level: int | None = None, field_name: str = "geometry.level",
                allow_large: bool = False, mesh_only: bool = False) -> Estimate:
    """:func:`check` for the run ``scene`` asks for: its geometry, ``solver.method``, the
    order k and the multiplier family of ``[discretisation]``."""
    variant = variant_of(scene)
    return check(scene.geometry, level, field_name, allow_large, mesh_only,
                 scene.solver.method, variant.order, variant.family)


def _finest_size(geo: Geometry) -> tuple[str, str]:
    """The field whose mesh size makes the initial mesh of ``geo`` largest, and the remedy:
    ``geometry.maxh``, or ``geometry.side_maxh.<label>`` where that side's graded strip
    (:func:`estimate`) holds more triangles than the rest of the domain."""
    without = estimate(replace(geo, side_maxh={}), 1).elements
    strips = {label: estimate(replace(geo, side_maxh={label: h}), 1).elements - without
              for label, h in geo.side_maxh.items()}
    if strips and max(strips.values()) > without:
        label = max(strips, key=strips.get)
        return f"geometry.side_maxh.{label}", f"a larger side_maxh on {label!r}"
    return "geometry.maxh", "a larger maxh"


def _gib(nbytes: float) -> str:
    return f"{nbytes / 2**30:.3g} GiB"
