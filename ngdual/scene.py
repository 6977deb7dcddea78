"""Scene description: geometry, material, loads, contact, friction, solver settings.

A scene is a TOML file (or the equivalent :class:`Scene` object). Every user
error is detected here, by :func:`validate`, and reported as one
:class:`SceneError` whose message names the offending field, e.g.
``material.nu: Poisson's ratio must lie in (-1, 0.5), got 0.5``.

The schema (all tables optional except ``geometry`` and ``boundary``)::

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

Loads, gap and bound are formulas in ``x`` and ``y`` (see :mod:`ngdual.expr`).
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from . import geometry
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


KINK_ANGLE = 1e-6  # radians: two contact sides meeting at a larger angle form a kink
CUSP_ANGLE = np.pi * (1 - 1e-3)


def _side_table(geo: Geometry, key: str, value: str) -> list[tuple[str, object]]:
    """The entries of ``geometry.<key>``, a table side label -> ``value``, labels checked."""
    table = getattr(geo, key)
    if not isinstance(table, dict):
        raise SceneError(f"geometry.{key}", f"must be a table label = {value}")
    for label in table:
        if label not in geo.labels:
            raise SceneError(f"geometry.{key}.{label}", f"unknown side label {label!r}; the "
                                                        f"sides are {', '.join(geo.labels)}")
    return list(table.items())


def _validate_geometry(geo: Geometry) -> None:
    if geo.kind not in GEOMETRY_KINDS:
        raise SceneError("geometry.kind", f"unknown kind {geo.kind!r}; use one of "
                                          + ", ".join(GEOMETRY_KINDS))
    _positive(geo.level, "geometry.level", integer=True)
    if geo.kind != "polygon":
        for key in ("arcs", "side_maxh"):
            if getattr(geo, key):
                raise SceneError(f"geometry.{key}", f"{key} needs kind = \"polygon\" (the "
                                                    f"{geo.kind!r} geometry is fixed)")
        return
    pts = np.asarray(geo.points, dtype=float) if len(geo.points) else np.zeros((0, 2))
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
        raise SceneError("geometry.points", "need at least three [x, y] points")
    if len(geo.labels) != len(pts):
        raise SceneError("geometry.labels", f"need one label per side ({len(pts)}), "
                                            f"got {len(geo.labels)}")
    for label, centre in _side_table(geo, "arcs", "[x, y] (the arc's centre)"):
        c = np.asarray(centre, dtype=float) if isinstance(centre, (list, tuple)) else None
        if c is None or c.shape != (2,) or not np.all(np.isfinite(c)):
            raise SceneError(f"geometry.arcs.{label}", f"the centre must be [x, y], got "
                                                       f"{centre!r}")
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
                                               f"[nx, ny]}}, got {f!r}")
    for key in ("point", "normal"):
        v = f[key]
        ok = isinstance(v, (list, tuple)) and len(v) == 2 and all(
            isinstance(c, (int, float)) and not isinstance(c, bool) and np.isfinite(c) for c in v)
        if not ok:
            raise SceneError(f"contact.foundation.{key}", f"must be a pair of numbers, got {v!r}")
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
        raise SceneError("contact.ends", f"unknown choice {con.ends!r}; use one of "
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
    con, fr, sol = scene.contact, scene.friction, scene.solver
    _expression(con.gap_formula, "contact.gap")
    _validate_contact(scene, u_d)
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
        xy, normals = contact_samples(scene)
        x, y = xy[:, 0], xy[:, 1]
        with np.errstate(invalid="ignore", divide="ignore"):
            g = gap_at(con, xy, normals)
            b = bound.numpy(x, y)
        if not np.all(np.isfinite(g)):
            raise SceneError("contact.gap", f"{con.gap_formula!r} is not finite on Gamma_C")
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
