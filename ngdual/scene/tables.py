"""The tables of a scene and their defaults (the one place defaults live)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from .. import geometry

FRICTION_LAWS = ("none", "tresca", "coulomb")


NORMAL_STRESSES = ("hat-projection", "fine-edges")


METRICS = ("h12", "euclidean")


LOOP_ORDERS = ("friction-outer", "contact-outer")


FRICTION_METRICS = ("jacobi", "mass")


SOLVER_METHODS = ("auto", "uzawa", "active-set")


GEOMETRY_KINDS = ("thesis-3.46", "polygon")


# a stress times a length by its usual name: the unit of a force per unit thickness
FORCE_PER_THICKNESS = {("Pa", "m"): "N/m", ("kPa", "m"): "kN/m", ("MPa", "m"): "MN/m",
                       ("MPa", "mm"): "N/mm", ("N/mm^2", "mm"): "N/mm", ("GPa", "mm"): "kN/mm",
                       ("psi", "in"): "lbf/in", ("ksi", "in"): "kip/in"}
LENGTH_UNITS = ("m", "cm", "mm", "um", "km", "in", "ft")


STRESS_UNITS = ("Pa", "kPa", "MPa", "GPa", "N/mm^2", "psi", "ksi")


ORDERS = (0, 1, 2)


MULTIPLIER_FAMILIES = ("auto", "coarse", "facet")


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
    """Body force f, traction t0 on Gamma_N, prescribed displacement on Gamma_D.

    ``traction`` is one formula pair ``[tx, ty]`` for every side of Gamma_N, or a table
    keyed by Gamma_N label, ``{top = ["0", "-1000"], left = ["0", "0"]}``, whose sides not
    listed are traction-free (:meth:`Scene.tractions`).
    """

    body_force: list = field(default_factory=lambda: ["0", "0"])
    traction: list | dict = field(default_factory=lambda: ["0", "0"])
    displacement: list = field(default_factory=lambda: ["0", "0"])


CONTACT_ENDS = ("consistent", "thesis")
DISCRETE_GAPS = ("nodal", "thesis")


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
    reproduce the thesis tables, tension included). It is a property of the thesis' P1 hats
    of order 0: at order k >= 1, and with the facet multipliers at any order, the scene is
    refused (:func:`ngdual.scene.validate.validate`) and ``"consistent"`` is the choice.

    ``discrete_gap`` says which gap the discrete problem (3.62) sees. ``"nodal"``
    (default): g_h = I_h~ g, the P1 interpolant of g on the h~ mesh of lambda_n, so that
    lambda_n - g_h = -u_n stays in the multiplier space and the contact condition
    lambda_n >= 0 reads u_n <= g at the h~ nodes; with no load the stress is zero,
    whatever the shape of g. ``"thesis"``: g itself in g(tau) = int g tau_n ds of
    (3.32), as in the thesis; the part of g that P1(h~) cannot represent then acts on the
    fine edges like a prescribed displacement (stress without load on a curved gap). Both
    give the same discrete problem where g is affine on every h~ edge (the gaps 0.01, 0
    and |x_1| of Example 3.46).
    """

    gap: str | None = None
    htilde_factor: int = 2
    hhat_factor: int = 2
    ends: str = "consistent"
    foundation: dict | None = None
    discrete_gap: str = "nodal"

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
    with a small friction bound F converge as fast as the others). ``condensed``:
    ``true`` iterates on the Gamma_C response computed once from 2 N_C + 1 solves
    (:mod:`ngdual.solvers.condensed`), ``false`` solves the sparse saddle-point system
    in every step; both give the same iterates to round-off. ``"auto"`` takes the
    response for nested Uzawa, whose thousands of inner steps it makes cheap, and the
    sparse solves for Algorithm 3.38, whose tens of steps cost less than the response
    (:data:`ngdual.solvers.settings.CONDENSED_AUTO`).
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
    condensed: bool | str = "auto"


@dataclass
class Discretisation:
    """The polynomial order k of the PEERS family and the family of the boundary multipliers.

    ``order``: k = 0 (default) is the triple (3.61) of the thesis; k = 1, 2 take the stress
    rows in RT_k plus the Curl of the element bubbles, u in discontinuous P_k and the
    rotation in continuous P_{k+1} (:func:`ngdual.peers.peers_spaces`).

    ``multipliers``: the space of phi on Gamma_N and of lambda_n, lambda_t on Gamma_C.
    ``"coarse"``: continuous P1 on the h~ mesh (C_h~ of (3.61), order 0 only);
    ``"facet"``: discontinuous P_k on the fine edges, the normal traces of RT_k (the
    hybridisation pairing, inf-sup stable by construction, docs/theory/order.md), with the
    sign condition lambda_n >= 0 on the Bernstein coefficients of every fine edge;
    ``"auto"`` (default): ``"coarse"`` at k = 0 (the thesis), ``"facet"`` at k >= 1.
    """

    order: int = 0
    multipliers: str = "auto"

    @property
    def family(self) -> str:
        """The multiplier family ``multipliers`` stands for at this order."""
        if self.multipliers != "auto":
            return self.multipliers
        return "coarse" if self.order == 0 else "facet"


@dataclass
class Units:
    """The units the numbers of the scene are in, for the labels of plots and records.

    The solver never reads them (it computes in whatever consistent units the scene is
    written in: lengths in ``length``, E, tractions and stresses in ``stress``); plots
    label their axes with them. Not given: labels name the quantity without a unit.
    """

    length: str | None = None
    stress: str | None = None

    @property
    def force(self) -> str | None:
        """The unit of a force in 2D, a force per unit thickness (a stress times a length),
        by its usual name where it has one (MPa and mm: N/mm), else ``stress*length``; None
        where either unit is not declared.

        >>> Units("mm", "MPa").force, Units("m", "Pa").force, Units("cm", "MPa").force
        ('N/mm', 'N/m', 'MPa*cm')
        """
        if not (self.length and self.stress):
            return None
        return FORCE_PER_THICKNESS.get((self.stress, self.length),
                                       f"{self.stress}*{self.length}")


BENCHMARK_KINDS = ("none", "hertz", "flat-punch", "cattaneo-mindlin", "wedge")


@dataclass
class Benchmark:
    """The analytic solution a scene is compared with (its pictures draw it against p_h, q_h).

    ``kind`` names a half-plane solution of :mod:`ngdual.verification.analytic`; the loads
    P and Q are the normal and tangential forces the solution carries on Gamma_C, E and nu
    come from ``[material]``, mu_f from ``[friction]``. Each kind reads its own
    parameters, lengths in the scene's units:

    * ``"hertz"``: a cylinder of ``radius`` R on a rigid plane;
    * ``"cattaneo-mindlin"``: the same with Coulomb friction and a tangential load
      below sliding (needs ``friction.law = "coulomb"``);
    * ``"flat-punch"``: a rigid flat punch of ``half_width`` a;
    * ``"wedge"``: a blunt wedge whose flanks have ``slope`` s.

    ``center`` is the point of the foundation line where the solution is centred (the
    foot of the cylinder's axis, the middle of the punch, the apex); the profile runs
    along the foundation (along x_1 without one). ``"none"`` (default): no analytic
    solution.
    """

    kind: str = "none"
    radius: float | None = None
    half_width: float | None = None
    slope: float | None = None
    center: list = field(default_factory=lambda: [0.0, 0.0])


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
    benchmark: Benchmark = field(default_factory=Benchmark)
    discretisation: Discretisation = field(default_factory=Discretisation)

    @property
    def has_contact(self) -> bool:
        return bool(self.boundary.get("contact"))

    @property
    def has_friction(self) -> bool:
        return self.has_contact and self.friction.law != "none"

    def labels(self, role: str) -> list[str]:
        """Boundary labels with the given role (dirichlet, neumann, contact)."""
        return list(self.boundary.get(role, []))

    def tractions(self) -> dict[str, list]:
        """The traction t0 on each side of Gamma_N: ``{label: [tx, ty]}``, one formula pair
        per Gamma_N label (``["0", "0"]`` for a side the ``loads.traction`` table omits).

        >>> from ngdual.scene import load_scene
        >>> scene = load_scene("hertz-cylinder", ['loads.traction={left = ["0", "-1"]}'])
        >>> scene.labels("neumann"), scene.tractions()
        (['left', 'right'], {'left': ['0', '-1'], 'right': ['0', '0']})
        """
        given = self.loads.traction
        if not isinstance(given, dict):
            return {label: list(given) for label in self.labels("neumann")}
        return {label: list(given.get(label, ["0", "0"])) for label in self.labels("neumann")}

    def to_dict(self) -> dict:
        """The scene as plain data (for result records)."""
        return dataclasses.asdict(self)


SECTIONS = {"geometry": Geometry, "material": Material, "loads": Loads,
             "contact": Contact, "friction": Friction, "solver": Solver, "units": Units,
             "benchmark": Benchmark, "discretisation": Discretisation}


ROLES = ("dirichlet", "neumann", "contact")
