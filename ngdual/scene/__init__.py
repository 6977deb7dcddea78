"""Scene description: geometry, material, loads, contact, friction, solver settings.

A scene is a TOML file (or the equivalent :class:`Scene` object). Every user
error is detected here, by :func:`validate`, and reported as one
:class:`SceneError` whose message names the offending field, e.g.
``material.nu: Poisson's ratio must lie in (-1, 0.5), got 0.5``; several problems
in one scene are reported together, one line each. Types, ranges, formulas
(:mod:`ngdual.expr`: bounded, finite and integrable where they act) and the geometry
(no repeated points, zero-length or crossing sides) are all checked before anything
is meshed.

The schema (all tables optional except ``geometry``, whose ``kind`` must be given, and
``boundary``: a scene states its domain, it never defaults to the thesis rectangle)::

    name = "thesis-3.46-frictionless"
    [geometry]   kind = "thesis-3.46" | "polygon", level, points, labels, maxh, arcs
    [boundary]   dirichlet = [labels], neumann = [labels], contact = [labels]
    [material]   E, nu                                   (plane strain)
    [loads]      body_force = [fx, fy], displacement = [ux, uy], traction = [tx, ty]
                 (every Gamma_N side) | {label = [tx, ty], ...} (per side, the others free)
    [contact]    gap | foundation = {point, normal}, htilde_factor (h~/h),
                 hhat_factor (h^/h~: 1 or 2), ends = "consistent" | "thesis"
    [friction]   law = "none" | "tresca" | "coulomb", mu, bound (Tresca F),
                 normal_stress = "hat-projection" | "fine-edges" (the |sigma_n| of F)
    [solver]     method, metric, rho, eps, max_iter, rho1, rho2, eps1, eps2, loop_order,
                 friction_metric, condensed
    [units]      length = "m" | "mm" | ..., stress = "Pa" | "MPa" | ...  (labels of plots)
    [benchmark]  kind = "none" | "hertz" | "flat-punch" | "cattaneo-mindlin" | "wedge",
                 radius, half_width, slope, center  (the analytic solution of the pictures)

Loads, gap and bound are formulas in ``x`` and ``y`` (see :mod:`ngdual.expr`).

The package: :mod:`.tables` (the tables, their defaults, SceneError), :mod:`.load` (TOML,
shipped scenes, overrides), :mod:`.values` (single values), :mod:`.domain` (the polygon,
its boundary parts and the formulas on them), :mod:`.contact` (Gamma_C: junctions, foundation
line, gap, round-off, and its checks) and :mod:`.validate` (the whole scene).
"""

from .contact import (
    contact_junctions,
    contact_samples,
    foundation_line,
    gap_at,
)
from .domain import (
    role_of,
    validate_geometry,
)
from .errors import SceneError, SceneTypeError
from .load import (
    apply_overrides,
    load_scene,
    read_toml,
    scene_from_dict,
    shipped_scenes,
)
from .tables import (
    BENCHMARK_KINDS,
    CONTACT_ENDS,
    DISCRETE_GAPS,
    FRICTION_LAWS,
    FRICTION_METRICS,
    GEOMETRY_KINDS,
    LENGTH_UNITS,
    LOOP_ORDERS,
    METRICS,
    MULTIPLIER_FAMILIES,
    NORMAL_STRESSES,
    ORDERS,
    ROLES,
    SECTIONS,
    SOLVER_METHODS,
    STRESS_UNITS,
    Benchmark,
    Contact,
    Discretisation,
    Friction,
    Geometry,
    Loads,
    Material,
    Scene,
    Solver,
    Units,
)
from .validate import (
    check_level,
    ensure_valid,
    given_keys,
    validate,
)
from .values import (
    FORMULAS,
)

__all__ = ["BENCHMARK_KINDS", "Benchmark", "CONTACT_ENDS", "Contact", "DISCRETE_GAPS",
           "Discretisation", "FORMULAS",
           "FRICTION_LAWS", "FRICTION_METRICS", "Friction", "GEOMETRY_KINDS", "Geometry",
           "LENGTH_UNITS", "LOOP_ORDERS", "Loads", "METRICS", "MULTIPLIER_FAMILIES", "Material",
           "NORMAL_STRESSES", "ORDERS",
           "ROLES", "SECTIONS", "SOLVER_METHODS", "STRESS_UNITS", "Scene", "SceneError",
           "SceneTypeError", "Solver", "Units", "apply_overrides", "check_level",
           "contact_junctions", "contact_samples", "ensure_valid", "foundation_line", "gap_at",
           "given_keys", "load_scene", "read_toml", "role_of", "scene_from_dict",
           "shipped_scenes", "validate", "validate_geometry"]
