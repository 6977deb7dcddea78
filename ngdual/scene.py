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
    [loads]      body_force = [fx, fy], traction = [tx, ty], displacement = [ux, uy]
    [contact]    gap | foundation = {point, normal}, htilde_factor (h~/h),
                 hhat_factor (h^/h~: 1 or 2), ends = "consistent" | "thesis"
    [friction]   law = "none" | "tresca" | "coulomb", mu, bound (Tresca F),
                 normal_stress = "hat-projection" | "fine-edges" (the |sigma_n| of F)
    [solver]     method, metric, rho, eps, max_iter, rho1, rho2, eps1, eps2, loop_order,
                 friction_metric
    [units]      length = "m" | "mm" | ..., stress = "Pa" | "MPa" | ...  (labels of plots)

Loads, gap and bound are formulas in ``x`` and ``y`` (see :mod:`ngdual.expr`).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import re
from contextlib import contextmanager
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from . import geometry
from .expr import Expression, ExpressionError, quote

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib

FRICTION_LAWS = ("none", "tresca", "coulomb")
NORMAL_STRESSES = ("hat-projection", "fine-edges")
METRICS = ("h12", "euclidean")
LOOP_ORDERS = ("friction-outer", "contact-outer")
FRICTION_METRICS = ("jacobi", "mass")
SOLVER_METHODS = ("auto", "uzawa", "active-set")
GEOMETRY_KINDS = ("thesis-3.46", "polygon")
LENGTH_UNITS = ("m", "cm", "mm", "um", "km", "in", "ft")
STRESS_UNITS = ("Pa", "kPa", "MPa", "GPa", "N/mm^2", "psi", "ksi")


class SceneError(ValueError):
    """A scene that cannot be solved; ``field`` names the offending entry.

    Several problems found together are one error: ``problems`` lists every
    ``(field, message)`` pair, ``field`` is the first of them and the message has one
    line per problem.
    """

    def __init__(self, field_name: str, message: str,
                 problems: list[tuple[str, str]] | None = None):
        self.problems = list(problems or [(field_name, message)])
        self.field = self.problems[0][0]
        if len(self.problems) == 1:
            text = f"{self.field}: {self.problems[0][1]}"
        else:
            text = (f"{len(self.problems)} problems in the scene:\n"
                    + "\n".join(f"  {f}: {m}" for f, m in self.problems))
        super().__init__(text)

    @property
    def fields(self) -> list[str]:
        """The fields of every problem, in the order found."""
        return [f for f, _ in self.problems]


class _Problems:
    """Collects the :class:`SceneError` s of independent checks, to report them together."""

    def __init__(self):
        self.found: list[tuple[str, str]] = []

    @contextmanager
    def check(self):
        """Run the checks in the ``with`` block; a SceneError there is recorded, not raised."""
        try:
            yield
        except SceneError as err:
            self.found.extend(err.problems)

    def add(self, field_name: str, message: str) -> None:
        self.found.append((field_name, message))

    def run(self, check, *args, value: bool = False, **kwargs):
        """Call ``check``; on a SceneError record it and return False (None with ``value``),
        else return True (the result with ``value``)."""
        try:
            result = check(*args, **kwargs)
        except SceneError as err:
            self.found.extend(err.problems)
            return None if value else False
        return result if value else True

    def raise_any(self) -> None:
        if self.found:
            raise SceneError("", "", self.found)


@dataclass
class Geometry:
    """A polygonal domain whose sides carry boundary labels.

    ``kind = "thesis-3.46"`` is the rectangle [-4,4]x[-1,1] of Example 3.46
    with the structured mesh of Table 3.1 (sides ``bottom``, ``right``,
    ``top``, ``left``); ``kind = "polygon"`` is meshed by netgen with ``maxh``.
    Side ``i`` runs from ``points[i]`` to ``points[i+1]`` (cyclically).
    ``level`` k means k-1 uniform refinements of the initial mesh (new boundary
    vertices lie on the curves). ``arcs`` maps a side label to a centre [x, y]: those
    sides are the shorter circular arcs around it between their end points
    (:mod:`ngdual.geometry`). ``side_maxh`` maps a side label to a smaller mesh size
    on those sides (netgen grades the mesh from there to ``maxh``).
    """

    kind: str = "thesis-3.46"
    level: int = 4
    points: list = field(default_factory=list)
    labels: list = field(default_factory=list)
    maxh: float = 0.5
    arcs: dict = field(default_factory=dict)
    side_maxh: dict = field(default_factory=dict)

    def curves(self) -> list[geometry.Side]:
        """Every side as a segment or a circular arc (``arcs``: label -> centre), in order."""
        if self.kind == "thesis-3.46":
            return geometry.sides([(-4.0, -1.0), (4.0, -1.0), (4.0, 1.0), (-4.0, 1.0)],
                                  ["bottom", "right", "top", "left"])
        return geometry.sides(self.points, self.labels, self.arcs)

    def sides(self) -> list[tuple[str, np.ndarray, np.ndarray]]:
        """``(label, start, end)`` of every side, counter-clockwise."""
        return [(c.label, c.start, c.end) for c in self.curves()]


@dataclass
class Material:
    """Isotropic linear elasticity in plane strain."""

    E: float = 200000.0
    nu: float = 0.25

    @property
    def lame(self) -> tuple[float, float]:
        """Lamé constants (lambda, mu)."""
        lam = self.E * self.nu / ((1 + self.nu) * (1 - 2 * self.nu))
        return lam, self.E / (2 * (1 + self.nu))

    @property
    def plane_strain_modulus(self) -> float:
        """E* = E / (1 - nu^2), the modulus of the half-plane Steklov-Poincare map."""
        return self.E / (1 - self.nu**2)


@dataclass
class Loads:
    """Body force f, traction t0 on Gamma_N, prescribed displacement on Gamma_D."""

    body_force: list = field(default_factory=lambda: ["0", "0"])
    traction: list = field(default_factory=lambda: ["0", "0"])
    displacement: list = field(default_factory=lambda: ["0", "0"])


CONTACT_ENDS = ("consistent", "thesis")


@dataclass
class Contact:
    """Rigid foundation at gap g >= 0; coarse multiplier meshes h~ and h^; end conditions.

    The foundation is given either by a ``gap`` formula g(x, y) (the distance to it along
    the outward normal n of Gamma_C), or as a straight line, ``foundation = {point = [x,
    y], normal = [nx, ny]}`` with ``normal`` pointing from the foundation towards the
    body; then g(x) = d(x) / (-n . n_F), d(x) = (x - point) . n_F the distance from the
    line, which is the distance from x to the line along the body's normal (the u_n of
    the Signorini condition u_n <= g). Without either, g = 0.

    ``ends`` says what the contact multipliers lambda_n = g - u_n, lambda_t = -u_t do at
    the ends of Gamma_C. ``"consistent"`` (default): where Gamma_C meets Gamma_D they take
    the values the data prescribe, g - u_D.n and -u_D.t; where it meets Gamma_N, or
    another contact side at a kink, they are free. ``"thesis"``: zero at every end
    (C_h~ of (3.61)), as in the thesis; it is consistent only where g = u_D.n at the
    ends (with g(+-4) = 0.01 and u_D = 0 in Example 3.46 it is not: the solution is
    forced to u_n = g at the clamped corners, so that the thesis scenes, which set it,
    reproduce the thesis tables, tension included).
    """

    gap: str | None = None
    htilde_factor: int = 2
    hhat_factor: int = 2
    ends: str = "consistent"
    foundation: dict | None = None

    @property
    def gap_formula(self) -> str:
        """The gap formula (``"0"`` when neither a gap nor a foundation is given)."""
        return "0" if self.gap is None else self.gap


@dataclass
class Friction:
    """Friction law on Gamma_C: none, Tresca with bound F, Coulomb with coefficient mu.

    ``normal_stress`` says which |sigma_n| enters the Coulomb bound F of (3.123):
    ``"hat-projection"`` (default) the lumped L^2 projection of sigma_n onto the
    h~ hats, built from the moments d_Cn(mu_i, sigma) that the contact
    conditions constrain, so F vanishes exactly where the body separates
    (A_C = supp F is the discrete contact zone); ``"fine-edges"`` the values of
    sigma_n on the fine edges, (3.123) literally. With h~ = 2h those oscillate
    at the fine scale even where the moments vanish, which puts friction where
    there is no contact (e.g. g = |x1|: F ~ 1e5 on separated edges, the body is
    glued tangentially, and with h^ = h~ the nested Uzawa loop stagnates).
    """

    law: str = "none"
    mu: float = 0.0
    bound: str = "0"
    normal_stress: str = "hat-projection"


@dataclass
class Solver:
    """Which algorithm solves the scene, and the parameters of Algorithms 3.38 / 3.41.

    ``method``: ``"uzawa"`` runs the thesis' Algorithm 3.38 / 3.41 (Remark 3.45 for
    Coulomb); ``"active-set"`` condenses onto Gamma_C and solves the contact problem
    there by semismooth Newton (:mod:`ngdual.solvers.active_set`: the same discrete solution
    at about the cost of one linear solve); ``"auto"`` (default) picks the active-set
    solver, which is faster on every level measured (``ngdual bench``). The parameters
    below are those of the Uzawa iterations; the active-set solver needs none (it
    iterates to round-off) except ``max_iter``, its bound on Coulomb fixed-point steps.
    ``rho`` (and ``rho1``, ``rho2``) are dimensionless: the metric of the
    projection carries the plane-strain modulus, so the same values work for
    E = 2e5 and E = 2e11. ``rho2`` is relative to the stability bound of the nu
    iteration and must lie in (0, 2). ``friction_metric`` is the diagonal metric
    of the nu projection P^Lambda: ``"mass"`` (Remark 3.44) or ``"jacobi"`` (the
    mass matrix weighted by the diagonal of the nu operator, so that h^ edges
    with a small friction bound F converge as fast as the others).
    """

    method: str = "auto"
    metric: str = "h12"
    rho: float = 1.0
    eps: float = 1e-8
    max_iter: int = 2000
    rho1: float = 1.0
    rho2: float = 1.0
    eps1: float = 1e-8
    eps2: float = 1e-6
    loop_order: str = "friction-outer"
    friction_metric: str = "jacobi"


@dataclass
class Units:
    """The units the numbers of the scene are in, for the labels of plots and records.

    The solver never reads them (it computes in whatever consistent units the scene is
    written in: lengths in ``length``, E, tractions and stresses in ``stress``); plots
    label their axes with them. Not given: labels name the quantity without a unit.
    """

    length: str | None = None
    stress: str | None = None


@dataclass
class Scene:
    """Everything needed to set up and solve one problem."""

    name: str
    geometry: Geometry
    boundary: dict
    material: Material = field(default_factory=Material)
    loads: Loads = field(default_factory=Loads)
    contact: Contact = field(default_factory=Contact)
    friction: Friction = field(default_factory=Friction)
    solver: Solver = field(default_factory=Solver)
    units: Units = field(default_factory=Units)

    @property
    def has_contact(self) -> bool:
        return bool(self.boundary.get("contact"))

    @property
    def has_friction(self) -> bool:
        return self.has_contact and self.friction.law != "none"

    def labels(self, role: str) -> list[str]:
        """Boundary labels with the given role (dirichlet, neumann, contact)."""
        return list(self.boundary.get(role, []))

    def to_dict(self) -> dict:
        """The scene as plain data (for result records)."""
        return dataclasses.asdict(self)


_SECTIONS = {"geometry": Geometry, "material": Material, "loads": Loads,
             "contact": Contact, "friction": Friction, "solver": Solver, "units": Units}
_ROLES = ("dirichlet", "neumann", "contact")


def shipped_scenes() -> list[str]:
    """Names of the scenes shipped in :mod:`ngdual.scenes`."""
    folder = resources.files("ngdual.scenes")
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def _read_toml(source: str | Path) -> tuple[str, dict]:
    if isinstance(source, bool) or not isinstance(source, (str, Path)):
        raise SceneTypeError("scene", f"must be a path or a shipped scene name, got "
                                      f"{type(source).__name__}")
    path = Path(source)
    if path.is_dir():
        raise SceneError("scene", f"{repr(str(path))} is a directory; give a TOML scene file "
                                  "inside it or the name of a shipped scene")
    if path.suffix == ".toml" or path.exists():
        if not path.is_file():
            raise SceneError("scene", f"no such scene file {repr(str(path))}")
        try:
            text, default_name = path.read_text(encoding="utf-8"), path.stem
        except (OSError, UnicodeDecodeError) as err:
            raise SceneError("scene", f"cannot read {repr(str(path))}: "
                                      f"{getattr(err, 'strerror', None) or err}") from None
    else:
        name = str(source)
        if name not in shipped_scenes():
            raise SceneError("scene", f"unknown scene {_show(name)}; shipped scenes: "
                                      + ", ".join(shipped_scenes()))
        text = resources.files("ngdual.scenes").joinpath(name + ".toml").read_text()
        default_name = name
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError("scene", f"invalid TOML in {repr(str(source))}: {err}") from None
    return default_name, data


def _parse_value(text: str):
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_overrides(data: dict, overrides: list[str] | None) -> dict:
    """Apply ``--set section.key=value`` overrides (values parsed as TOML, else strings)."""
    if overrides is not None and (isinstance(overrides, str)
                                  or not all(isinstance(o, str) for o in overrides)):
        raise SceneTypeError("overrides", "must be a list of 'section.key=value' strings, got "
                                      f"{_show(overrides)}")
    data = copy.deepcopy(data)
    for item in overrides or []:
        if "=" not in item:
            raise SceneError(item, "an override must read key=value, e.g. friction.mu=0.5")
        key, value = (s.strip() for s in item.split("=", 1))
        parts = key.split(".")
        if len(parts) == 1 and parts[0] == "name":
            data["name"] = value
            continue
        if len(parts) != 2 or (parts[0] not in _SECTIONS and parts[0] != "boundary"):
            raise SceneError(key, "unknown key; use section.key with section in "
                                  + ", ".join(["boundary", *_SECTIONS]))
        section = data.setdefault(parts[0], {})
        if not isinstance(section, dict):
            raise SceneError(parts[0], f"must be a table, got {_show(section)}")
        section[parts[1]] = _parse_value(value)
    return data


GEOMETRY_REQUIRED = ('give kind = "thesis-3.46" (the rectangle [-4,4]x[-1,1] of Example 3.46) '
                     'or kind = "polygon" with points and labels')


def _build(name: str, data: dict) -> Scene:
    """The :class:`Scene` of a TOML document; every structural problem is reported at once."""
    problems = _Problems()
    for key in sorted(set(data) - {"name", "description", "boundary", *_SECTIONS}):
        problems.add(key, "unknown section; sections are "
                          + ", ".join(["name", "description", "boundary", *_SECTIONS]))
    for key in ("name", "description"):
        if key in data and not isinstance(data[key], str):
            problems.add(key, f"must be a string, got {_show(data[key])}")
    # a scene states its domain: no table silently becoming the thesis rectangle
    if "geometry" not in data:
        problems.add("geometry", "missing table: " + GEOMETRY_REQUIRED)
    elif isinstance(data["geometry"], dict) and "kind" not in data["geometry"]:
        problems.add("geometry.kind", "missing: " + GEOMETRY_REQUIRED)
    kwargs = {}
    for section, cls in _SECTIONS.items():
        values = data.get(section, {})
        if not isinstance(values, dict):
            problems.add(section, f"must be a table [{section}], got {_show(values)}")
            values = {}
        names = {f.name for f in dataclasses.fields(cls)}
        for key in values:
            if key not in names:
                problems.add(f"{section}.{key}", "unknown key; known keys: "
                             + ", ".join(sorted(names)))
        kwargs[section] = cls(**{k: v for k, v in values.items() if k in names})
    boundary = {}
    if "boundary" not in data:
        problems.add("boundary", "missing table: assign dirichlet/neumann/contact labels")
    elif not isinstance(data["boundary"], dict):
        problems.add("boundary", f"must be a table [boundary], got {_show(data['boundary'])}")
    else:
        for role, labels in data["boundary"].items():
            if role not in _ROLES:
                problems.add(f"boundary.{role}", f"unknown role; use one of {', '.join(_ROLES)}")
                continue
            boundary[role] = [labels] if isinstance(labels, str) else labels
    problems.raise_any()
    scene = Scene(name=str(data.get("name", name)), boundary=boundary, **kwargs)
    # what the document sets, also where it repeats a default (see _settings_without_effect)
    scene.__dict__["_given"] = frozenset(f"{section}.{key}" for section in _SECTIONS
                                         for key in data.get(section, {}))
    return scene


def load_scene(source: str | Path, overrides: list[str] | None = None) -> Scene:
    """Load a scene by file path or shipped name, apply overrides and validate it.

    >>> load_scene("thesis-3.46-frictionless", ["geometry.level=2"]).geometry.level
    2
    """
    name, data = _read_toml(source)
    return scene_from_dict(data, overrides, name)


def scene_from_dict(data: dict, overrides: list[str] | None = None,
                    name: str = "scene") -> Scene:
    """The validated scene of a TOML document already parsed into ``data`` (a dict).

    >>> scene_from_dict({"geometry": {"kind": "thesis-3.46", "level": 1},
    ...                  "boundary": {"dirichlet": ["left", "right", "top", "bottom"]}}).name
    'scene'
    """
    if not isinstance(data, dict):
        raise SceneTypeError("scene", f"must be a table (dict) of sections, got "
                                      f"{type(data).__name__}")
    scene = _build(name, apply_overrides(data, overrides))
    ensure_valid(scene)
    return scene


def _show(value, width: int = 60) -> str:
    """``repr(value)`` for a message, shortened (user input can be arbitrarily long)."""
    try:
        text = repr(value)
    except ValueError:  # an integer beyond Python's digit limit for str()
        text = f"<an integer of {value.bit_length()} bits>"
    return text if len(text) <= width else text[:width - 3] + "..."


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _finite(value) -> bool:
    """A number (not a bool) that is finite in double precision (huge integers are not)."""
    try:
        return _is_number(value) and math.isfinite(value)
    except OverflowError:
        return False


def _positive(value, field_name: str, integer: bool = False) -> None:
    kind = int if integer else (int, float)
    if not isinstance(value, kind) or not _finite(value) or value <= 0:
        raise SceneError(field_name, f"must be a positive {'integer' if integer else 'number'}, "
                                     f"got {_show(value)}")


def _expression(text, field_name: str) -> Expression:
    try:
        return Expression(text)
    except (ExpressionError, TypeError) as err:
        raise SceneError(field_name, str(err)) from None


def _pair(values, field_name: str) -> list[Expression]:
    if not isinstance(values, (list, tuple)) or len(values) != 2:
        raise SceneError(field_name, f"must be a pair [x-component, y-component], got "
                                     f"{_show(values)}")
    problems = _Problems()
    out = []
    for i, v in enumerate(values):
        with problems.check():
            out.append(_expression(v, f"{field_name}[{i}]"))
    problems.raise_any()
    return out


# What each setting must be; the formulas (loads, contact.gap, friction.bound) are checked
# by parsing them, the tables of geometry (points, labels, arcs, side_maxh) entry by entry.
_TYPES = {"str": (str,), "int": (int,), "float": (int, float), "list": (list, tuple),
          "dict": (dict,)}
_TYPE_NAMES = {"str": "a string", "int": "an integer", "float": "a number",
               "list": "a list", "dict": "a table"}
_FORMULAS = {"contact.gap", "friction.bound", "loads.body_force", "loads.traction",
             "loads.displacement"}


def _field_type_problems(section: str, obj) -> list[tuple[str, str]]:
    """``(field, message)`` for every setting of one section whose type is wrong."""
    found = []
    for f in dataclasses.fields(obj):
        key, value = f"{section}.{f.name}", getattr(obj, f.name)
        kinds = [k.strip() for k in str(f.type).split("|")]
        if key in _FORMULAS or (value is None and "None" in kinds):
            continue
        if isinstance(value, bool) or not isinstance(value, _TYPES[kinds[0]]):
            found.append((key, f"must be {_TYPE_NAMES[kinds[0]]}, got {_show(value)}"))
    return found


def _type_problems(scene: Scene) -> list[tuple[str, str]]:
    """``(field, message)`` for every setting of ``scene`` whose type is wrong."""
    found = []
    if not isinstance(scene.name, str):
        found.append(("name", f"must be a string, got {_show(scene.name)}"))
    for section, cls in _SECTIONS.items():
        obj = getattr(scene, section)
        if not isinstance(obj, cls):
            found.append((section, f"must be a {cls.__module__}.{cls.__name__}, got "
                                   f"{type(obj).__name__}"))
            continue
        found += _field_type_problems(section, obj)
    if not isinstance(scene.boundary, dict):
        found.append(("boundary", f"must be a table role -> labels, got {_show(scene.boundary)}"))
        return found
    for role, labels in scene.boundary.items():
        if role not in _ROLES:
            found.append((f"boundary.{role}", f"unknown role; use one of {', '.join(_ROLES)}"))
        elif not isinstance(labels, (list, tuple)) or not all(isinstance(lab, str)
                                                              for lab in labels):
            found.append((f"boundary.{role}", f"must be a list of side labels, got "
                                              f"{_show(labels)}"))
    return found


KINK_ANGLE = 1e-6  # radians: two contact sides meeting at a larger angle form a kink
CUSP_ANGLE = np.pi * (1 - 1e-3)
LABEL = re.compile(r"[A-Za-z0-9_-]+")
SHORT_SIDE = 1e-9  # relative to the diameter: shorter sides are degenerate (netgen crashes)


def _side_table(geo: Geometry, key: str, value: str) -> list[tuple[str, object]]:
    """The entries of ``geometry.<key>``, a table side label -> ``value``, labels checked."""
    table = getattr(geo, key)
    if not isinstance(table, dict):
        raise SceneError(f"geometry.{key}", f"must be a table label = {value}")
    for label in table:
        if label not in geo.labels:
            raise SceneError(f"geometry.{key}.{label}", f"unknown side label {_show(label)}; the "
                                                        f"sides are {', '.join(geo.labels)}")
    return list(table.items())


def _validate_points(geo: Geometry) -> np.ndarray:
    """The polygon's vertices as an array; refuses non-numbers and degenerate polygons."""
    if not isinstance(geo.points, (list, tuple)) or len(geo.points) < 3:
        raise SceneError("geometry.points", f"need at least three [x, y] points, got "
                                            f"{_show(geo.points)}")
    problems = _Problems()
    for i, p in enumerate(geo.points):
        if not (isinstance(p, (list, tuple)) and len(p) == 2 and all(_finite(c) for c in p)):
            problems.add(f"geometry.points[{i}]", f"must be a pair of finite numbers [x, y], "
                                                  f"got {_show(p)}")
    if not isinstance(geo.labels, (list, tuple)) or not all(
            isinstance(lab, str) and LABEL.fullmatch(lab) for lab in geo.labels):
        # labels become netgen boundary names, selected by regular expressions
        problems.add("geometry.labels", f"must be a list of names made of letters, digits, "
                                        f"'_' and '-', got {_show(geo.labels)}")
    elif len(geo.labels) != len(geo.points):
        problems.add("geometry.labels", f"need one label per side ({len(geo.points)}), "
                                        f"got {len(geo.labels)}")
    problems.raise_any()
    pts = np.asarray(geo.points, dtype=float)
    size = float(np.ptp(pts, axis=0).max())
    if size > 1e100 or size < 1e-100:
        raise SceneError("geometry.points", f"the polygon's size {size:.3g} is outside "
                                            "[1e-100, 1e100]; rescale the units")
    # coincident vertices give zero-length sides or touching boundaries, which netgen
    # cannot mesh (a zero-length side crashes it), so they are refused before meshing
    for i in range(len(pts)):
        for j in range(i + 1, len(pts)):
            if np.linalg.norm(pts[i] - pts[j]) <= SHORT_SIDE * size:
                where = f"({pts[i, 0]:.4g}, {pts[i, 1]:.4g})"
                if j == i + 1 or (i == 0 and j == len(pts) - 1):
                    side = i if j == i + 1 else j
                    raise SceneError("geometry.points", f"points[{i}] and points[{j}] "
                                     f"coincide at {where}: side {side} "
                                     f"({_show(geo.labels[side])}) has zero length; remove the "
                                     "repeated point")
                raise SceneError("geometry.points", f"points[{i}] and points[{j}] coincide "
                                                    f"at {where}: the boundary touches itself")
    return pts


def validate_geometry(geo: Geometry) -> None:
    """Raise a :class:`SceneError` for a geometry that cannot be meshed (checked before
    netgen sees it: a zero-length side crashes netgen, a self-intersecting one hangs it)."""
    if not isinstance(geo, Geometry):
        raise SceneTypeError("geometry", f"must be an ngdual.scene.Geometry, got "
                                         f"{type(geo).__name__}")
    wrong = [(f, m) for f, m in _field_type_problems("geometry", geo)]
    if wrong:
        raise SceneError("", "", wrong)
    if geo.kind not in GEOMETRY_KINDS:
        raise SceneError("geometry.kind", f"unknown kind {_show(geo.kind)}; use one of "
                                          + ", ".join(GEOMETRY_KINDS))
    _positive(geo.level, "geometry.level", integer=True)
    if geo.kind != "polygon":
        for key in ("arcs", "side_maxh", "points", "labels"):
            if getattr(geo, key):
                raise SceneError(f"geometry.{key}", f"{key} needs kind = \"polygon\" (the "
                                                    f"{_show(geo.kind)} geometry is fixed)")
        return
    _validate_points(geo)
    for label, centre in _side_table(geo, "arcs", "[x, y] (the arc's centre)"):
        ok = isinstance(centre, (list, tuple)) and len(centre) == 2 and all(
            _finite(c) for c in centre)
        if not ok:
            raise SceneError(f"geometry.arcs.{label}", f"the centre must be [x, y], got "
                                                       f"{_show(centre)}")
    for label, h in _side_table(geo, "side_maxh", "mesh size"):
        _positive(h, f"geometry.side_maxh.{label}")
    curves = geo.curves()
    for curve in curves:
        problem = curve.arc_error()
        if problem:
            raise SceneError(f"geometry.arcs.{curve.label}", problem)
    poly = geometry.outline(curves)
    hit = geometry.self_intersection(poly)
    if hit is not None:
        field_name = "geometry.arcs" if geo.arcs else "geometry.points"
        raise SceneError(field_name, f"the boundary intersects itself at ({hit[0]:.4g}, "
                                     f"{hit[1]:.4g})")
    if geometry.signed_area(poly) <= 0:
        raise SceneError("geometry.points", "the polygon must be listed counter-clockwise "
                                            "and have positive area")
    _positive(geo.maxh, "geometry.maxh")


def _validate_boundary(scene: Scene) -> None:
    sides = scene.geometry.sides()
    known = {label for label, _, _ in sides}
    seen: dict[str, str] = {}
    for role, labels in scene.boundary.items():
        for label in labels:
            if label not in known:
                raise SceneError(f"boundary.{role}", f"unknown boundary label {_show(label)}; the "
                                                     f"geometry has {', '.join(sorted(known))}")
            if label in seen:
                raise SceneError(f"boundary.{role}", f"label {_show(label)} is already "
                                                     f"{seen[label]}")
            seen[label] = role
    missing = sorted(known - set(seen))
    if missing:
        raise SceneError("boundary", f"boundary label {_show(missing[0])} has no condition; "
                                     "list it under dirichlet, neumann or contact")
    if not scene.labels("dirichlet"):
        raise SceneError("boundary.dirichlet", "at least one Dirichlet side is needed "
                                               "(rigid body motions are not excluded otherwise)")


def role_of(scene: Scene, label: str) -> str:
    """dirichlet, neumann or contact: the condition on the sides labelled ``label``."""
    return next(role for role in _ROLES if label in scene.labels(role))


def contact_junctions(scene: Scene) -> list[tuple[np.ndarray, str, float]]:
    """The end points of the contact sides and what meets Gamma_C there.

    Returns ``(point, kind, angle)`` for every corner of the boundary with a contact side
    on at least one side of it: kind ``"dirichlet"`` or ``"neumann"`` where Gamma_C meets
    that part, ``"kink"`` where two contact sides meet at an angle (the multipliers, which
    are normal and tangential components, are discontinuous there), ``"smooth"`` where
    they meet tangentially (one multiplier runs through); ``angle`` is the boundary's
    turning angle there (:func:`ngdual.geometry.turning_angle`).
    """
    curves = scene.geometry.curves()
    out = []
    for i, before in enumerate(curves):
        after = curves[(i + 1) % len(curves)]
        roles = (role_of(scene, before.label), role_of(scene, after.label))
        if "contact" not in roles:
            continue
        angle = geometry.turning_angle(before, after)
        if roles == ("contact", "contact"):
            kind = "kink" if abs(angle) > KINK_ANGLE else "smooth"
        else:
            kind = roles[1] if roles[0] == "contact" else roles[0]
        out.append((before.end, kind, angle))
    return out


def contact_samples(scene: Scene, per_side: int = 401) -> tuple[np.ndarray, np.ndarray]:
    """Points on Gamma_C and the outward normals there (``per_side`` per contact side)."""
    pts, normals = [], []
    for curve in scene.geometry.curves():
        if curve.label in scene.labels("contact"):
            xy, n = curve.sample(per_side)
            pts.append(xy)
            normals.append(n)
    return np.vstack(pts), np.vstack(normals)


def foundation_line(contact: Contact) -> tuple[np.ndarray, np.ndarray]:
    """Point and unit normal (towards the body) of the foundation line."""
    f = contact.foundation
    normal = np.asarray(f["normal"], dtype=float)
    return np.asarray(f["point"], dtype=float), normal / np.linalg.norm(normal)


def gap_at(contact: Contact, xy: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """The gap g at points of Gamma_C with outward normals ``normals`` (see :class:`Contact`)."""
    if contact.foundation is None:
        return Expression(contact.gap_formula).numpy(xy[:, 0], xy[:, 1])
    point, n_f = foundation_line(contact)
    return ((xy - point) @ n_f) / (-(normals @ n_f))


def _validate_foundation(scene: Scene) -> None:
    f = scene.contact.foundation
    if not isinstance(f, dict) or set(f) != {"point", "normal"}:
        raise SceneError("contact.foundation", "must be a table {point = [x, y], normal = "
                                               f"[nx, ny]}}, got {_show(f)}")
    for key in ("point", "normal"):
        v = f[key]
        ok = isinstance(v, (list, tuple)) and len(v) == 2 and all(
            _finite(c) for c in v)
        if not ok:
            raise SceneError(f"contact.foundation.{key}", f"must be a pair of numbers, got "
                                                          f"{_show(v)}")
    if np.linalg.norm(np.asarray(f["normal"], dtype=float)) == 0:
        raise SceneError("contact.foundation.normal", "must not be zero")
    if scene.contact.gap is not None:
        raise SceneError("contact.gap", "give either a gap formula or a foundation line, "
                                        "not both (the foundation determines the gap)")
    point, n_f = foundation_line(scene.contact)
    body = geometry.outline(scene.geometry.curves(), per_arc=401)
    depth = (body - point) @ n_f
    size = float(np.ptp(body, axis=0).max())
    if depth.min() < -1e-9 * size:
        i = int(np.argmin(depth))
        raise SceneError("contact.foundation", f"the foundation cuts the body: the point "
                                               f"({body[i, 0]:.4g}, {body[i, 1]:.4g}) lies "
                                               f"{-depth[i]:.3g} behind the line")
    xy, normals = contact_samples(scene)
    facing = -(normals @ n_f)
    if facing.min() <= np.cos(np.radians(89)):
        i = int(np.argmin(facing))
        raise SceneError("contact.foundation", f"Gamma_C does not face the foundation at "
                                               f"({xy[i, 0]:.4g}, {xy[i, 1]:.4g}) (its normal "
                                               "is at 89 degrees or more from the line's); "
                                               "make that part a Neumann side")


def _validate_contact(scene: Scene, u_d: list[Expression]) -> None:
    """Foundation or gap, ends, kinks: what Gamma_C needs to be posed (see :class:`Contact`)."""
    con = scene.contact
    if con.ends not in CONTACT_ENDS:
        raise SceneError("contact.ends", f"unknown choice {_show(con.ends)}; use one of "
                                         + ", ".join(CONTACT_ENDS))
    if not scene.has_contact:
        if con.foundation is not None:
            raise SceneError("contact.foundation", "a foundation needs a contact boundary "
                                                   "(boundary.contact is empty)")
        return
    if con.foundation is not None:
        _validate_foundation(scene)
    junctions = contact_junctions(scene)
    for point, kind, angle in junctions:
        where = f"({point[0]:.4g}, {point[1]:.4g})"
        if con.ends == "thesis" and kind == "neumann":
            raise SceneError("contact.ends", f"Gamma_N touches Gamma_C at {where}: the "
                                             "thesis' zero ends assume they do not touch; "
                                             "use contact.ends = \"consistent\"")
        if kind == "kink":
            if angle < 0 or angle > CUSP_ANGLE:
                raise SceneError("boundary.contact", f"Gamma_C has a "
                                 f"{'re-entrant' if angle < 0 else 'cusp'} kink at {where} "
                                 "where no normal cone is defined; make one of the two "
                                 "sides a Neumann or Dirichlet side")
    ends = np.array([p for p, kind, _ in junctions if kind == "dirichlet"])
    if not len(ends):
        return
    values = np.column_stack([e.numpy(ends[:, 0], ends[:, 1]) for e in u_d])
    if con.ends == "thesis":
        if np.abs(values).max() > 1e-12:
            raise SceneError("loads.displacement", "the prescribed displacement must vanish "
                                                   "where Gamma_D meets Gamma_C (the thesis' "
                                                   "contact multipliers are zero there)")
        return
    xy, normals = contact_samples(scene)
    for p, u in zip(ends, values):
        k = int(np.argmin(np.linalg.norm(xy - p, axis=1)))
        g = float(gap_at(con, xy[k:k + 1], normals[k:k + 1])[0])
        slide = abs(u @ np.array([normals[k, 1], -normals[k, 0]]))
        if scene.friction.law != "none" and slide > 1e-12:
            # the friction functional q(nu, lambda_t) is posed on the lambda_t dofs only
            raise SceneError("loads.displacement", f"with friction the prescribed "
                                                   f"displacement must not slide along "
                                                   f"Gamma_C where Gamma_D meets it (u_D.t = "
                                                   f"{slide:.3g} at ({p[0]:.4g}, {p[1]:.4g}))")
        if g < u @ normals[k] - 1e-12 * max(1.0, abs(g)):
            raise SceneError("contact.gap", f"where Gamma_D meets Gamma_C at ({p[0]:.4g}, "
                                            f"{p[1]:.4g}) the clamp pushes the body "
                                            f"{u @ normals[k]:.3g} into the foundation but "
                                            f"the gap is {g:.3g}: need g >= u_D.n there")


class SceneTypeError(SceneError, TypeError):
    """An argument of the Python API of the wrong type (a :class:`SceneError` and a TypeError)."""


def check_level(level, field_name: str = "level", optional: bool = False) -> int | None:
    """``level`` if it is a mesh level (an integer >= 1; None too if ``optional``)."""
    if level is None and optional:
        return None
    if isinstance(level, bool) or not isinstance(level, (int, np.integer)):
        raise SceneTypeError(field_name, f"must be an integer >= 1{' or None' * optional}, "
                                         f"got {_show(level)}")
    if level < 1:
        raise SceneError(field_name, f"must be >= 1 (level 1 is the initial mesh), got {level}")
    return int(level)


def ensure_valid(scene: Scene) -> None:
    """:func:`validate` ``scene`` unless it was validated and has not changed since."""
    if not isinstance(scene, Scene):
        raise SceneTypeError("scene", f"must be an ngdual.scene.Scene (see load_scene), got "
                                      f"{type(scene).__name__}")
    key = repr(scene)
    if scene.__dict__.get("_validated_as") != key:
        validate(scene)
        scene.__dict__["_validated_as"] = key


E_RANGE = (1e-30, 1e30)  # beyond, C^-1 ~ 1/E and sigma ~ E reach the ends of double precision


def validate(scene: Scene) -> None:
    """Raise one :class:`SceneError` listing every problem found in ``scene``.

    Independent settings are checked independently, so a scene with several mistakes
    gets them all reported at once, each naming its field; checks that need a sound
    geometry and boundary (sampling the formulas on Gamma_N, Gamma_D, Gamma_C) run only
    when those are sound.
    """
    if not isinstance(scene, Scene):
        raise SceneTypeError("scene", f"must be an ngdual.scene.Scene (see load_scene), got "
                                      f"{type(scene).__name__}")
    problems = _Problems()
    for f, m in _type_problems(scene):
        problems.add(f, m)
    wrong = {f.split(".")[0] for f in (p[0] for p in problems.found)}
    ok = {section: section not in wrong for section in ("geometry", "boundary", *_SECTIONS)}
    if ok["geometry"]:
        ok["geometry"] = problems.run(validate_geometry, scene.geometry)
    if ok["geometry"] and ok["boundary"]:
        ok["boundary"] = problems.run(_validate_boundary, scene)
    if ok["material"]:
        problems.run(_validate_material, scene.material)
    loads = {}
    if ok["loads"]:
        for key in ("body_force", "traction", "displacement"):
            loads[key] = problems.run(_pair, getattr(scene.loads, key), f"loads.{key}",
                                      value=True)
        ok["loads"] = all(v is not None for v in loads.values())
    if ok["contact"]:
        ok["contact"] = problems.run(_validate_contact_settings, scene.contact)
    if ok["friction"]:
        ok["friction"] = problems.run(_validate_friction_settings, scene)
    if ok["solver"]:
        _validate_solver(scene.solver, problems)
    if isinstance(scene.units, Units):  # a bad type of one unit is reported above
        _validate_units(scene.units, problems)
    if ok["solver"] and ok["friction"] and scene.solver.method in SOLVER_METHODS:
        reported = {f for f, _ in problems.found}
        for f, m in _settings_without_effect(scene):
            if f not in reported:  # one problem per field: its bad value comes first
                problems.add(f, m)
    if all(ok[k] for k in ("geometry", "boundary", "loads", "contact", "friction")):
        if problems.run(_validate_formulas_on_sides, scene, loads) \
                and problems.run(_validate_contact, scene, loads["displacement"]):
            problems.run(_validate_gap_and_bound, scene)
    problems.raise_any()
    scene.__dict__["_validated_as"] = repr(scene)  # for ensure_valid


def _validate_material(mat: Material) -> None:
    problems = _Problems()
    with problems.check():
        _positive(mat.E, "material.E")
        if not E_RANGE[0] <= mat.E <= E_RANGE[1]:
            raise SceneError("material.E", f"{mat.E:g} is outside [{E_RANGE[0]:g}, "
                                           f"{E_RANGE[1]:g}], where the compliance 1/E and "
                                           "the stresses stay within double precision; "
                                           "rescale the units")
    if not -1 < mat.nu < 0.5:
        problems.add("material.nu", f"Poisson's ratio must lie in (-1, 0.5), got {_show(mat.nu)}")
    problems.raise_any()


def _validate_contact_settings(con: Contact) -> None:
    problems = _Problems()
    with problems.check():
        _expression(con.gap_formula, "contact.gap")
    if con.ends not in CONTACT_ENDS:
        problems.add("contact.ends", f"unknown choice {_show(con.ends)}; use one of "
                                     + ", ".join(CONTACT_ENDS))
    with problems.check():
        _positive(con.htilde_factor, "contact.htilde_factor", integer=True)
    if con.hhat_factor not in (1, 2):
        problems.add("contact.hhat_factor", f"must be 1 (h^ = h~) or 2 (h^ = 2h~), "
                                            f"got {_show(con.hhat_factor)}")
    problems.raise_any()


def _validate_friction_settings(scene: Scene) -> None:
    fr = scene.friction
    problems = _Problems()
    if fr.law not in FRICTION_LAWS:
        problems.add("friction.law", f"unknown friction law {_show(fr.law)}; use one of "
                                     + ", ".join(FRICTION_LAWS))
    elif fr.law != "none" and not scene.has_contact:
        problems.add("friction.law", f"{_show(fr.law)} friction needs a contact boundary "
                                     "(boundary.contact is empty)")
    if not (_finite(fr.mu) and fr.mu >= 0):
        problems.add("friction.mu", f"friction coefficient must be >= 0, got {_show(fr.mu)}")
    elif fr.law == "coulomb" and fr.mu == 0:
        problems.add("friction.mu", "Coulomb friction needs a coefficient mu > 0 (mu = 0 is "
                                    "frictionless: use friction.law = \"none\")")
    if fr.normal_stress not in NORMAL_STRESSES:
        problems.add("friction.normal_stress", f"unknown choice {_show(fr.normal_stress)}; use "
                                               "one of " + ", ".join(NORMAL_STRESSES))
    with problems.check():
        _expression(fr.bound, "friction.bound")
    problems.raise_any()


def _validate_solver(sol: Solver, problems: _Problems) -> None:
    choices = {"method": SOLVER_METHODS, "metric": METRICS, "loop_order": LOOP_ORDERS,
               "friction_metric": FRICTION_METRICS}
    for key, allowed in choices.items():
        value = getattr(sol, key)
        if value not in allowed:
            problems.add(f"solver.{key}", f"unknown {key.replace('_', ' ')} {_show(value)}; use "
                                          "one of " + ", ".join(allowed))
    for key in ("rho", "eps", "rho1", "rho2", "eps1", "eps2"):
        if problems.run(_positive, getattr(sol, key), f"solver.{key}") and key == "rho2" \
                and not sol.rho2 < 2:
            problems.add("solver.rho2", f"rho2 = {sol.rho2} is outside (0, 2), where the nu "
                                        "iteration converges (it is relative to the stability "
                                        "bound)")
    problems.run(_positive, sol.max_iter, "solver.max_iter", integer=True)


def _validate_units(units: Units, problems: _Problems) -> None:
    for key, allowed in (("length", LENGTH_UNITS), ("stress", STRESS_UNITS)):
        value = getattr(units, key)
        if isinstance(value, str) and value not in allowed:
            problems.add(f"units.{key}", f"unknown {key} unit {_show(value)}; use one of "
                                         + ", ".join(allowed) + " (or leave it out: no unit)")


# The settings each choice reads. "uzawa" reads those of Algorithm 3.38 or of Algorithm 3.41
# (Remark 3.45), whichever the friction law calls for: one set of Uzawa parameters serves
# the scenes of every law (e.g. the tuned steps of ``ngdual bench``).
SOLVER_READS = {"auto": ("method", "metric", "max_iter"),
                "active-set": ("method", "metric", "max_iter"),
                "uzawa": tuple(f.name for f in dataclasses.fields(Solver))}
FRICTION_READS = {"none": ("law",), "tresca": ("law", "bound"),
                  "coulomb": ("law", "mu", "normal_stress")}


def _given(scene: Scene, section: str) -> set[str]:
    """The keys of ``section`` the user set: in the scene's document (TOML, overrides), or,
    for a scene built in Python, those that differ from the default."""
    obj, given = getattr(scene, section), scene.__dict__.get("_given", frozenset())
    return {f.name for f in dataclasses.fields(obj)
            if f"{section}.{f.name}" in given or getattr(obj, f.name) != f.default}


def _settings_without_effect(scene: Scene) -> list[tuple[str, str]]:
    """``(field, message)`` for every setting the chosen method or friction law ignores.

    A setting that does nothing is an error, not a silence: ``solver.rho`` with the
    active-set solver, ``friction.mu`` without Coulomb friction, ...
    """
    found = []
    method = scene.solver.method
    for key in sorted(_given(scene, "solver") - set(SOLVER_READS[method])):
        found.append((f"solver.{key}", f"does nothing with solver.method = {method!r}: the "
                      "active-set solver iterates to round-off and reads only metric and "
                      "max_iter; remove it, or set solver.method = \"uzawa\" for the "
                      "thesis' Algorithms 3.38 / 3.41"))
    law = scene.friction.law if scene.friction.law in FRICTION_LAWS else "none"
    users = {"mu": "coulomb", "normal_stress": "coulomb", "bound": "tresca"}
    for key in sorted(_given(scene, "friction") - set(FRICTION_READS[law])):
        found.append((f"friction.{key}", f"does nothing with friction.law = {law!r}: only "
                      f"{users[key]!r} friction uses it; remove it, or set friction.law = "
                      f"\"{users[key]}\""))
    return found


def _validate_formulas_on_sides(scene: Scene, loads: dict[str, list[Expression]]) -> None:
    """Traction, boundary displacement, gap and Tresca bound where they act.

    Each formula must be finite on its closed sides (their end points are mesh vertices)
    and integrable there (:func:`_pole`). The body force and the quadrature points of the
    actual mesh are checked before assembly (:mod:`ngdual.quadrature_check`).
    """
    problems = _Problems()
    curves = scene.geometry.curves()
    where = {"neumann": "Gamma_N", "dirichlet": "Gamma_D", "contact": "Gamma_C"}
    fields = [(f"loads.traction[{i}]", e, "neumann") for i, e in enumerate(loads["traction"])]
    fields += [(f"loads.displacement[{i}]", e, "dirichlet")
               for i, e in enumerate(loads["displacement"])]
    con, fr = scene.contact, scene.friction
    if scene.has_contact and con.foundation is None:
        fields.append(("contact.gap", Expression(con.gap_formula), "contact"))
    if fr.law == "tresca":
        fields.append(("friction.bound", Expression(fr.bound), "contact"))
    for name, expr, role in fields:
        with problems.check():
            _formula_on_sides(expr, name, [c for c in curves if c.label in scene.labels(role)],
                              where[role])
    problems.raise_any()


def _validate_gap_and_bound(scene: Scene) -> None:
    """The gap must be >= 0 on Gamma_C, a Tresca bound >= 0 and not zero everywhere."""
    if not scene.has_contact:
        return
    problems = _Problems()
    con, fr = scene.contact, scene.friction
    xy, normals = contact_samples(scene)
    x, y = xy[:, 0], xy[:, 1]
    g = gap_at(con, xy, normals)
    if not np.all(np.isfinite(g)):
        i = int(np.argmin(np.isfinite(g)))
        problems.add("contact.gap", f"not finite on Gamma_C at ({x[i]:.4g}, {y[i]:.4g})")
    elif g.min() < 0:
        i = int(np.argmin(g))
        problems.add("contact.gap", f"negative gap {g[i]:.3g} at ({x[i]:.3g}, {y[i]:.3g}); "
                                    "the gap must be >= 0")
    if fr.law == "tresca":
        b = Expression(fr.bound).numpy(x, y)
        if b.min() < 0:
            i = int(np.argmin(b))
            problems.add("friction.bound", f"the Tresca bound F must be >= 0 on Gamma_C, got "
                                           f"{b[i]:.3g} at ({x[i]:.4g}, {y[i]:.4g})")
        elif b.max() == 0:
            problems.add("friction.bound", "Tresca friction needs a bound F > 0 on part of "
                                           "Gamma_C (F = 0 everywhere is frictionless: use "
                                           "friction.law = \"none\")")
    problems.raise_any()


PROBE_POINTS = 8192   # samples per side in which the largest values of a formula are sought
POLE_ORDER = 0.99     # |f| ~ |s - a|^-p near a with p >= 1 is not integrable


def _formula_on_sides(expr: Expression, field_name: str, curves: list, where: str) -> None:
    """Refuse a formula that is not finite, or not integrable, on the closed ``curves``."""
    if expr.constant is not None:  # folded and checked finite at parse time
        return
    for curve in curves:
        s = np.concatenate([[0.0, 1.0], (np.arange(PROBE_POINTS) + 0.5) / PROBE_POINTS])
        xy = curve.at(s)
        values = expr.numpy(xy[:, 0], xy[:, 1])
        bad = ~np.isfinite(values)
        if bad.any():
            i = int(np.argmax(bad))
            raise SceneError(field_name, f"{quote(expr.text)} is not finite on {where} at "
                                         f"({xy[i, 0]:.4g}, {xy[i, 1]:.4g}) "
                                         f"(value {values[i]})")
        pole = _pole(expr, curve, s, np.abs(values))
        if pole is not None:
            point, order, value = pole
            raise SceneError(field_name, f"{quote(expr.text)} is not integrable on {where}: "
                             f"|f| grows like 1/distance^{order:.2g} towards ({point[0]:.6g}, "
                             f"{point[1]:.6g})" + (f" (value {value})" if not
                                                   np.isfinite(value) else ""))


def _pole(expr: Expression, curve, s: np.ndarray, values: np.ndarray):
    """``(point, order, value)`` of a non-integrable singularity of ``expr`` on ``curve``.

    The (up to) three largest sampled values of |f| are zoomed in on together (the
    largest value in a window shrinking 20x per step locates a maximum to round-off),
    and the growth of |f| towards each measured between the distances 1e-7 and 1e-10
    (in the side's parameter): a pole |s - a|^-p gives the order p, a bounded or merely
    steep function about 0, a logarithm about 0.1. None when every order is below 1.
    """
    def f(t):
        q = curve.at(np.clip(t, 0.0, 1.0).ravel())
        return np.abs(expr.numpy(q[:, 0], q[:, 1])).reshape(np.shape(t))

    width = 1.0 / PROBE_POINTS
    starts: list[float] = []
    for i in np.argsort(values)[::-1][:64]:
        if len(starts) < 3 and all(abs(s[i] - t) >= 4 * width for t in starts):
            starts.append(float(s[i]))
    a, w = np.array(starts), width
    offsets = np.linspace(-1.0, 1.0, 41)
    for _ in range(8):
        t = a[:, None] + w * offsets[None, :]
        v = f(t)
        # a non-finite value is the singular point itself
        v = np.where(np.isfinite(v), v, np.inf)
        a, w = t[np.arange(len(a)), np.argmax(v, axis=1)], w / 20
    probes = a[:, None] + np.array([-1e-10, -1e-7, 1e-10, 1e-7])[None, :]
    v = f(probes)
    peaks = f(a)
    inside = (probes >= 0) & (probes <= 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        orders = np.log10(v[:, [0, 2]] / v[:, [1, 3]]) / 3
    orders = np.where(inside[:, [0, 2]] & inside[:, [1, 3]] & (v[:, [1, 3]] > 0),
                      np.nan_to_num(orders, nan=0.0, posinf=np.inf), 0.0).max(axis=1)
    for k in range(len(a)):
        if orders[k] >= POLE_ORDER:
            return curve.at(a[k:k + 1])[0], float(orders[k]), float(peaks[k])
    return None
