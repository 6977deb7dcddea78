"""Scene description: geometry, material, loads, contact, friction, solver settings.

A scene is a TOML file (or the equivalent :class:`Scene` object). Every user
error is detected here, by :func:`validate`, and reported as one
:class:`SceneError` whose message names the offending field, e.g.
``material.nu: Poisson's ratio must lie in (-1, 0.5), got 0.5``.

The schema (all tables optional except ``geometry`` and ``boundary``)::

    name = "thesis-3.46-frictionless"
    [geometry]   kind = "thesis-3.46" | "polygon", level, points, labels, maxh
    [boundary]   dirichlet = [labels], neumann = [labels], contact = [labels]
    [material]   E, nu                                   (plane strain)
    [loads]      body_force = [fx, fy], traction = [tx, ty], displacement = [ux, uy]
    [contact]    gap, htilde_factor (h~/h), hhat_factor (h^/h~: 1 or 2)
    [friction]   law = "none" | "tresca" | "coulomb", mu, bound (Tresca F),
                 normal_stress = "hat-projection" | "fine-edges" (the |sigma_n| of F)
    [solver]     method, metric, rho, eps, max_iter, rho1, rho2, eps1, eps2, loop_order,
                 friction_metric

Loads, gap and bound are formulas in ``x`` and ``y`` (see :mod:`ngdual.expr`).
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from .expr import Expression, ExpressionError

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


class SceneError(ValueError):
    """A scene that cannot be solved; ``field`` names the offending entry."""

    def __init__(self, field_name: str, message: str):
        super().__init__(f"{field_name}: {message}")
        self.field = field_name


@dataclass
class Geometry:
    """A polygonal domain whose sides carry boundary labels.

    ``kind = "thesis-3.46"`` is the rectangle [-4,4]x[-1,1] of Example 3.46
    with the structured mesh of Table 3.1 (sides ``bottom``, ``right``,
    ``top``, ``left``); ``kind = "polygon"`` is meshed by netgen with ``maxh``.
    Side ``i`` runs from ``points[i]`` to ``points[i+1]`` (cyclically).
    ``level`` k means k-1 uniform refinements of the initial mesh.
    """

    kind: str = "thesis-3.46"
    level: int = 4
    points: list = field(default_factory=list)
    labels: list = field(default_factory=list)
    maxh: float = 0.5

    def sides(self) -> list[tuple[str, np.ndarray, np.ndarray]]:
        """``(label, start, end)`` of every side, counter-clockwise."""
        if self.kind == "thesis-3.46":
            pts = [(-4.0, -1.0), (4.0, -1.0), (4.0, 1.0), (-4.0, 1.0)]
            labels = ["bottom", "right", "top", "left"]
        else:
            pts, labels = self.points, self.labels
        arr = np.asarray(pts, dtype=float)
        return [(labels[i], arr[i], arr[(i + 1) % len(arr)]) for i in range(len(arr))]


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


@dataclass
class Contact:
    """Rigid foundation at gap g >= 0; coarse multiplier meshes h~ and h^."""

    gap: str = "0"
    htilde_factor: int = 2
    hhat_factor: int = 2


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
    there by semismooth Newton (:mod:`ngdual.solvers.fast`: the same discrete solution
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
             "contact": Contact, "friction": Friction, "solver": Solver}
_ROLES = ("dirichlet", "neumann", "contact")


def shipped_scenes() -> list[str]:
    """Names of the scenes shipped in :mod:`ngdual.scenes`."""
    folder = resources.files("ngdual.scenes")
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def _read_toml(source: str | Path) -> tuple[str, dict]:
    path = Path(source)
    if path.suffix == ".toml" or path.exists():
        if not path.is_file():
            raise SceneError("scene", f"no such scene file {str(path)!r}")
        text, default_name = path.read_text(), path.stem
    else:
        name = str(source)
        if name not in shipped_scenes():
            raise SceneError("scene", f"unknown scene {name!r}; shipped scenes: "
                                      + ", ".join(shipped_scenes()))
        text = resources.files("ngdual.scenes").joinpath(name + ".toml").read_text()
        default_name = name
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError("scene", f"invalid TOML in {str(source)!r}: {err}") from None
    return default_name, data


def _parse_value(text: str):
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_overrides(data: dict, overrides: list[str] | None) -> dict:
    """Apply ``--set section.key=value`` overrides (values parsed as TOML, else strings)."""
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
        data.setdefault(parts[0], {})[parts[1]] = _parse_value(value)
    return data


def _build(name: str, data: dict) -> Scene:
    unknown = set(data) - {"name", "description", "boundary", *_SECTIONS}
    if unknown:
        raise SceneError(sorted(unknown)[0], "unknown section")
    kwargs = {}
    for section, cls in _SECTIONS.items():
        values = dict(data.get(section, {}))
        names = {f.name for f in dataclasses.fields(cls)}
        for key in values:
            if key not in names:
                raise SceneError(f"{section}.{key}", "unknown key; known keys: "
                                 + ", ".join(sorted(names)))
        kwargs[section] = cls(**values)
    if "boundary" not in data:
        raise SceneError("boundary", "missing table: assign dirichlet/neumann/contact labels")
    boundary = {}
    for role, labels in data["boundary"].items():
        if role not in _ROLES:
            raise SceneError(f"boundary.{role}", f"unknown role; use one of {', '.join(_ROLES)}")
        labels = [labels] if isinstance(labels, str) else list(labels)
        boundary[role] = labels
    return Scene(name=str(data.get("name", name)), boundary=boundary, **kwargs)


def load_scene(source: str | Path, overrides: list[str] | None = None) -> Scene:
    """Load a scene by file path or shipped name, apply overrides and validate it.

    >>> load_scene("thesis-3.46-frictionless", ["geometry.level=2"]).geometry.level
    2
    """
    name, data = _read_toml(source)
    scene = _build(name, apply_overrides(data, overrides))
    validate(scene)
    return scene


def _positive(value, field_name: str, integer: bool = False) -> None:
    kind = int if integer else (int, float)
    if isinstance(value, bool) or not isinstance(value, kind) or not np.isfinite(value) \
            or value <= 0:
        raise SceneError(field_name, f"must be a positive {'integer' if integer else 'number'}, "
                                     f"got {value!r}")


def _expression(text, field_name: str) -> Expression:
    try:
        return Expression(text)
    except (ExpressionError, TypeError) as err:
        raise SceneError(field_name, str(err)) from None


def _pair(values, field_name: str) -> list[Expression]:
    if not isinstance(values, (list, tuple)) or len(values) != 2:
        raise SceneError(field_name, f"must be a pair [x-component, y-component], got {values!r}")
    return [_expression(v, f"{field_name}[{i}]") for i, v in enumerate(values)]


def _validate_geometry(geo: Geometry) -> None:
    if geo.kind not in GEOMETRY_KINDS:
        raise SceneError("geometry.kind", f"unknown kind {geo.kind!r}; use one of "
                                          + ", ".join(GEOMETRY_KINDS))
    _positive(geo.level, "geometry.level", integer=True)
    if geo.kind == "polygon":
        pts = np.asarray(geo.points, dtype=float) if len(geo.points) else np.zeros((0, 2))
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
            raise SceneError("geometry.points", "need at least three [x, y] points")
        if len(geo.labels) != len(pts):
            raise SceneError("geometry.labels", f"need one label per side ({len(pts)}), "
                                                f"got {len(geo.labels)}")
        area = 0.5 * np.sum(pts[:, 0] * np.roll(pts[:, 1], -1) - np.roll(pts[:, 0], -1) * pts[:, 1])
        if area <= 0:
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
                raise SceneError(f"boundary.{role}", f"unknown boundary label {label!r}; the "
                                                     f"geometry has {', '.join(sorted(known))}")
            if label in seen:
                raise SceneError(f"boundary.{role}", f"label {label!r} is already "
                                                     f"{seen[label]}")
            seen[label] = role
    missing = sorted(known - set(seen))
    if missing:
        raise SceneError("boundary", f"boundary label {missing[0]!r} has no condition; list it "
                                     "under dirichlet, neumann or contact")
    if not scene.labels("dirichlet"):
        raise SceneError("boundary.dirichlet", "at least one Dirichlet side is needed "
                                               "(rigid body motions are not excluded otherwise)")
    ends = {role: {tuple(p) for label, a, b in sides if seen[label] == role for p in (a, b)}
            for role in _ROLES}
    touch = ends["neumann"] & ends["contact"]
    if touch:
        point = tuple(float(c) for c in sorted(touch)[0])
        raise SceneError("boundary", f"Gamma_N touches Gamma_C at {point}; separate them by a "
                                     "Dirichlet side (the formulation assumes they do not touch)")


def _contact_points(scene: Scene, per_side: int = 401) -> tuple[np.ndarray, np.ndarray]:
    pts = [a + np.linspace(0, 1, per_side)[:, None] * (b - a)
           for label, a, b in scene.geometry.sides() if label in scene.labels("contact")]
    xy = np.vstack(pts)
    return xy[:, 0], xy[:, 1]


def _validate_contact_ends(scene: Scene, u_d: list[Expression]) -> None:
    """lambda_t, lambda_n vanish at the ends of Gamma_C (C_h~ of (3.61)), so must u_D there."""
    ends = np.array([p for label, a, b in scene.geometry.sides()
                     if label in scene.labels("contact") for p in (a, b)])
    if not len(ends):
        return
    values = np.abs(np.concatenate([e.numpy(ends[:, 0], ends[:, 1]) for e in u_d]))
    if values.max() > 1e-12:
        raise SceneError("loads.displacement", "the prescribed displacement must vanish where "
                                               "Gamma_D meets Gamma_C (the contact multipliers "
                                               "are zero at the ends of Gamma_C)")


def validate(scene: Scene) -> None:
    """Raise :class:`SceneError` for the first problem found in ``scene``."""
    _validate_geometry(scene.geometry)
    _validate_boundary(scene)
    mat = scene.material
    _positive(mat.E, "material.E")
    if isinstance(mat.nu, bool) or not isinstance(mat.nu, (int, float)) or not -1 < mat.nu < 0.5:
        raise SceneError("material.nu", f"Poisson's ratio must lie in (-1, 0.5), got {mat.nu!r}")
    _pair(scene.loads.body_force, "loads.body_force")
    _pair(scene.loads.traction, "loads.traction")
    u_d = _pair(scene.loads.displacement, "loads.displacement")
    _validate_contact_ends(scene, u_d)

    con, fr, sol = scene.contact, scene.friction, scene.solver
    gap = _expression(con.gap, "contact.gap")
    _positive(con.htilde_factor, "contact.htilde_factor", integer=True)
    if con.hhat_factor not in (1, 2) or isinstance(con.hhat_factor, bool):
        raise SceneError("contact.hhat_factor", f"must be 1 (h^ = h~) or 2 (h^ = 2h~), "
                                                f"got {con.hhat_factor!r}")
    if fr.law not in FRICTION_LAWS:
        raise SceneError("friction.law", f"unknown friction law {fr.law!r}; use one of "
                                         + ", ".join(FRICTION_LAWS))
    if isinstance(fr.mu, bool) or not isinstance(fr.mu, (int, float)) or not fr.mu >= 0:
        raise SceneError("friction.mu", f"friction coefficient must be >= 0, got {fr.mu!r}")
    if fr.normal_stress not in NORMAL_STRESSES:
        raise SceneError("friction.normal_stress", f"unknown choice {fr.normal_stress!r}; use "
                                                   "one of " + ", ".join(NORMAL_STRESSES))
    bound = _expression(fr.bound, "friction.bound")
    if scene.has_contact:
        x, y = _contact_points(scene)
        with np.errstate(invalid="ignore", divide="ignore"):
            g = gap.numpy(x, y)
            b = bound.numpy(x, y)
        if not np.all(np.isfinite(g)):
            raise SceneError("contact.gap", f"{con.gap!r} is not finite on Gamma_C")
        if g.min() < 0:
            i = int(np.argmin(g))
            raise SceneError("contact.gap", f"negative gap {g[i]:.3g} at ({x[i]:.3g}, {y[i]:.3g}); "
                                            "the gap must be >= 0")
        if fr.law == "tresca" and (not np.all(np.isfinite(b)) or b.min() < 0):
            raise SceneError("friction.bound", "the Tresca bound F must be finite and >= 0 "
                                               "on Gamma_C")
    elif fr.law != "none":
        raise SceneError("friction.law", f"{fr.law!r} friction needs a contact boundary "
                                         "(boundary.contact is empty)")
    if sol.method not in SOLVER_METHODS:
        raise SceneError("solver.method", f"unknown solver method {sol.method!r}; use one of "
                                          + ", ".join(SOLVER_METHODS))
    if sol.metric not in METRICS:
        raise SceneError("solver.metric", f"unknown metric {sol.metric!r}; use one of "
                                          + ", ".join(METRICS))
    if sol.loop_order not in LOOP_ORDERS:
        raise SceneError("solver.loop_order", f"unknown loop order {sol.loop_order!r}; use one "
                                              "of " + ", ".join(LOOP_ORDERS))
    if sol.friction_metric not in FRICTION_METRICS:
        raise SceneError("solver.friction_metric", f"unknown metric {sol.friction_metric!r}; "
                                                   "use one of " + ", ".join(FRICTION_METRICS))
    if not 0 < sol.rho2 < 2:
        raise SceneError("solver.rho2", f"rho2 = {sol.rho2} is outside (0, 2), where the nu "
                                        "iteration converges (it is relative to the stability "
                                        "bound)")
    for key in ("rho", "eps", "rho1", "rho2", "eps1", "eps2"):
        _positive(getattr(sol, key), f"solver.{key}")
    _positive(sol.max_iter, "solver.max_iter", integer=True)
