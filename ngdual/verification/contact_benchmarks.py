"""The shipped contact scenes against their half-plane solutions, per level, with observed orders.

Three benchmarks (:data:`BENCHMARKS`), each a shipped scene with a finer contact side at
level 1 (the shipped scenes resolve the contact zone with two to four h~ edges on level 1,
too few for the asymptotic range on the levels a test can afford):

* ``hertz``: ``hertz-cylinder`` (R = 10, nu = 0.3, box 8 x 4, a = 0.34 = box / 23) with
  its circular bottom cut into three arcs of the same circle (no kink: one chain of
  Gamma_C), the middle one |x| < 1 meshed with h = 1/16 on level 1. Exact: Hertz with the
  computed force P (:func:`ngdual.verification.analytic.hertz`).
* ``flat-punch``: ``flat-punch`` (a = 0.25, box of half-width 16a) with h = 1/128 on the
  punch face on level 1. Exact: the rigid flat punch with the computed P; the force on
  |x| < a/2 against P/3 and the L1 and core errors of the pressure.
* ``cattaneo-mindlin``: ``cattaneo-mindlin`` (nu = 0.4999: Dundurs' beta = 2e-4, the
  normal and tangential problems decouple) on the mesh of ``hertz``. Exact: Cattaneo-Mindlin
  with the computed P and Q, centred at the computed pressure centroid.

The finite box is the other error: :func:`domain_study` solves the same benchmark in boxes
of half-width 8a, 16a, 32a on three levels and extrapolates every error to h -> 0
(Richardson, order 1, the observed order of the force and pressure errors): the limit is
the domain error, the rest the discretisation error. Measured (flat punch, force on
|x| < a/2 against P/3, levels 1-3): limits +0.91 % at 8a, +0.12 % at 16a and -0.06 % at
32a, while the level-3 error at 16a is 0.64 %: on the shipped 16a box the 1 % test measures
the discretisation. For Hertz the extrapolation is not reliable (the core force error
changes sign between levels 1 and 3); at a fixed level 3 the core L2 pressure error is
1.0 % in a box of half-width 6a, 0.18 % at 12a (the shipped box) and 0.17 % at 24a.

Adaptive refinement (:func:`adaptive_study`, Doerfler 0.5) does not pay on these errors:
the estimator of (4.50) marks the bulk (the corners of the clamped top) before Gamma_C, and
after five steps the Hertz pressure error is 9.8 % with 10 500 unknowns against 5.6 % with
12 100 on uniform level 2 (flat punch core force: 1.4 % with 19 900 against 1.2 % with
22 400).

The stick zone and its shift. Where the top is displaced sideways the tangential force Q
acts at the height H of the top: the couple Q H is carried by the clamped top and by an
offset e of the contact pressure (a tilted circle is a translated circle, so the exact
solution is Hertz and Cattaneo-Mindlin centred at x0 = e). ``centroid`` measures e; the
clamp takes nearly all of the couple (e = 0.015a, 0.012a, 0.009a, 0.009a on levels 1-4).
The stick set of the h^ mesh is symmetric about x = 0 on every level (centre 0 to
round-off) and its half-width is c to 0.6, 0.15, 0.26 and 0.0006 h^ cells on levels 1-4:
no shift of the stick zone at the h^ resolution. A shift of 0.1 a would need a coupling
the scene does not have: with nu = 0.3 (beta = 0.29) the normal pressure feeds the
tangential displacement and the stick zone moves (Spence's problem); with nu = 0.4999 that
coupling is 1400 times weaker. Below the h^ resolution the centroid of the slip reserve
mu_f p_h - |q_h| (``stick_centroid_a``) sits at -0.045a and -0.054a on levels 3 and 4;
it is polluted by the shear error in the slip zones (q_max 22-31 %, at the edges of the
contact zone, where the Coulomb bound inherits the spike p_h carries where the edge of the
contact zone lies inside an h~ edge, :func:`ngdual.friction.hat_projection`) and is not
evidence of a shift.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import cache

import numpy as np

from ..afem import adapt
from ..mesh import mesh_size
from ..scene import Scene, load_scene
from ..solution import Solution
from ..solvers import solve_scene
from .analytic import cattaneo_mindlin, flat_punch, hertz
from .traction import pressure_errors, traction_errors, traction_profile


def _cylinder_overrides(half_width: float = 4.0, height: float = 4.0,
                        radius: float = 10.0, fine: float = 1.0 / 16.0) -> list[str]:
    """A cylinder bottom as three arcs of one circle: flanks, and |x| < 1 meshed with ``fine``."""
    def y(x):
        return radius - math.sqrt(radius**2 - x**2)

    w = half_width
    points = [[-w, y(w)], [-1.0, y(1.0)], [1.0, y(1.0)], [w, y(w)], [w, y(w) + height],
              [-w, y(w) + height]]
    return [f"geometry.points={points}",
            'geometry.labels=["flank_left", "bottom", "flank_right", "right", "top", "left"]',
            f"geometry.arcs={{ flank_left = [0.0, {radius}], bottom = [0.0, {radius}], "
            f"flank_right = [0.0, {radius}] }}",
            f"geometry.side_maxh={{ bottom = {fine}, flank_left = {4 * fine}, "
            f"flank_right = {4 * fine} }}",
            'boundary.contact=["flank_left", "bottom", "flank_right"]']


def _punch_overrides(half_width: float = 4.0, a: float = 0.25,
                     fine: float = 1.0 / 128.0) -> list[str]:
    """The flat-punch box of half-width and height ``half_width``, punch face meshed with
    ``fine``."""
    w = half_width
    points = [[-w, 0.0], [-a, 0.0], [a, 0.0], [w, 0.0], [w, w], [-w, w]]
    return [f"geometry.points={points}", f"geometry.side_maxh={{ punch = {fine} }}"]


@dataclass(frozen=True)
class Benchmark:
    """A shipped scene, the overrides that make it the benchmark, and its row function."""

    name: str
    scene: str
    overrides: tuple[str, ...]

    def load(self, extra: tuple[str, ...] = ()) -> Scene:
        return load_scene(self.scene, [*self.overrides, *extra])


BENCHMARKS = {
    "hertz": Benchmark("hertz", "hertz-cylinder", tuple(_cylinder_overrides())),
    "flat-punch": Benchmark("flat-punch", "flat-punch", tuple(_punch_overrides())),
    "cattaneo-mindlin": Benchmark("cattaneo-mindlin", "cattaneo-mindlin",
                                  tuple(_cylinder_overrides())),
}

KEYS = {
    "hertz": ("l2", "l1", "max", "l2_core"),
    "flat-punch": ("l1", "l2_core", "max_core", "force_core"),
    "cattaneo-mindlin": ("l2", "q_l2", "q_l1", "q_max"),
}


def _radius(scene: Scene, label: str = "bottom") -> float:
    """The radius of the arc side ``label``."""
    geo = scene.geometry
    k = list(geo.labels).index(label)
    return float(np.hypot(*(np.asarray(geo.points[k]) - np.asarray(geo.arcs[label]))))


def _common(solution: Solution, errors: dict) -> dict:
    pb = solution.problem
    return {"h": errors["htilde"], "h_mesh": mesh_size(pb.fes.mesh),
            "ndof": sum(pb.spaces.dofs().values()), **errors}


def hertz_row(solution: Solution) -> dict:
    """Hertz errors of one solution (:func:`~ngdual.verification.traction.pressure_errors`,
    exact Hertz with the computed force); ``force_core`` = |int_{|x|<a/2} p_h / (the
    Hertz force there) - 1| (and ``force_core_signed``), ``a_error`` = |a_h - a|."""
    scene = solution.problem.scene
    profile = traction_profile(solution)
    exact = hertz(profile.force, _radius(scene), scene.material.E, scene.material.nu)
    errors = pressure_errors(solution, exact)
    errors["force_core_signed"] = errors["force_core"] / errors["force_core_exact"] - 1.0
    errors["force_core"] = abs(errors["force_core_signed"])
    return _common(solution, {**errors, "a_error": abs(errors["half_width"] - exact.a)})


def flat_punch_row(solution: Solution) -> dict:
    """Flat-punch errors: ``force_core`` = |int_{|x|<a/2} p_h / (P/3) - 1| (and
    ``force_core_signed``), ``width`` =
    |contact width / 2a - 1|, the L1 and core errors of the pressure."""
    profile = traction_profile(solution)
    a = 0.5 * float(np.ptp(profile.x))
    exact = flat_punch(profile.force, a)
    errors = pressure_errors(solution, exact)
    errors["force_core_signed"] = errors["force_core"] / exact.force_within(a / 2) - 1.0
    errors["force_core"] = abs(errors["force_core_signed"])
    errors["width"] = abs(errors["half_width"] / a - 1.0)
    return _common(solution, errors)


def cattaneo_mindlin_row(solution: Solution) -> dict:
    """Cattaneo-Mindlin: pressure errors, shear errors ``q_*``, the computed P, Q, the stick
    half-width ``c_h`` against c = a sqrt(1 - |Q|/(mu_f P)) in units of the h^ cell
    (``c_cells``), the pressure centroid and the stick-zone centre (in units of a)."""
    scene = solution.problem.scene
    profile = traction_profile(solution)
    x0 = profile.centroid
    exact = cattaneo_mindlin(profile.force, profile.tangential_force, _radius(scene),
                             scene.material.E, scene.material.nu, scene.friction.mu)
    errors = pressure_errors(solution, exact, x0=x0)
    shear = traction_errors(solution, exact, x0=x0)
    row = _common(solution, errors)
    row.update({f"q_{k}": shear[k] for k in ("l2", "l1", "max")})
    row.update(Q=shear["tangential_force"], c=exact.c, c_h=shear["stick_half_width"],
               hhat=shear["hhat"], c_cells=abs(shear["stick_half_width"] - exact.c)
               / shear["hhat"], centroid_a=x0 / exact.hertz.a,
               stick_centre_a=shear["stick_centre"] / exact.hertz.a,
               stick_centroid_a=shear["stick_centroid"] / exact.hertz.a)
    return row


ROWS = {"hertz": hertz_row, "flat-punch": flat_punch_row,
        "cattaneo-mindlin": cattaneo_mindlin_row}


@cache
def _uniform_row(name: str, level: int, extra: tuple[str, ...] = ()) -> dict:
    start = time.perf_counter()
    solution = solve_scene(BENCHMARKS[name].load(extra), level)
    seconds = time.perf_counter() - start
    return {"benchmark": name, "level": level, **ROWS[name](solution), "seconds": seconds}


def uniform_study(name: str, levels=(1, 2, 3, 4), extra: tuple[str, ...] = ()) -> list[dict]:
    """One row per level of uniform refinement (rows are cached per process: the solves
    are deterministic). ``extra``: scene overrides on top of the benchmark's."""
    return [dict(_uniform_row(name, level, tuple(extra))) for level in levels]


def adaptive_study(name: str, steps: int = 4, level: int = 1, theta: float = 0.5) -> list[dict]:
    """One row per step of :func:`ngdual.afem.adapt` (Doerfler marking with ``theta``);
    ``level`` is the step and ``h`` = N^(-1/2), N the number of unknowns."""
    rows = []

    def on_step(record, solution, estimated, marked):
        row = ROWS[name](solution)
        # graded meshes: orders against N^(-1/2), the mesh size of a uniform mesh with N dofs
        rows.append({"benchmark": name, "level": record["step"], **row,
                     "h": row["ndof"] ** -0.5, "estimator": record["estimator"],
                     "seconds": float(sum(record["timings_s"].values()))})

    adapt(BENCHMARKS[name].load(), marking="dorfler", theta=theta, steps=steps, level=level,
          on_step=on_step)
    return rows


def domain_study(name: str = "flat-punch", multiples=(8, 16, 32), levels=(1, 2, 3),
                 key: str = "force_core", order: float = 1.0) -> list[dict]:
    """Separate the finite-box error from the discretisation error.

    For every box half-width W = m a (height W for the punch; for the cylinder height 4 and
    a the Hertz half-width of the shipped scene, 0.34), solve on ``levels`` and extrapolate
    ``key`` to h -> 0 from the last two levels with the given ``order``:
    e_0 = e_L - (e_{L-1} - e_L) / (2^order - 1), the domain error; e_L - e_0 is the
    discretisation error on level L. Returns one row per box with the errors per level.
    """
    a = 0.25 if name == "flat-punch" else 0.34
    out = []
    for m in multiples:
        if name == "flat-punch":
            extra = tuple(_punch_overrides(m * a))
        else:
            extra = tuple(_cylinder_overrides(half_width=m * a, height=m * a))
        rows = uniform_study(name, levels, extra)
        # signed errors: the domain error has a sign
        values = [_signed(row, key) for row in rows]
        limit = values[-1] - (values[-2] - values[-1]) / (2**order - 1)
        out.append({"benchmark": name, "multiple": m, "levels": list(levels),
                    "errors": values, "domain": limit, "discretisation": values[-1] - limit,
                    "ndof": rows[-1]["ndof"]})
    return out


def _signed(row: dict, key: str) -> float:
    return row.get(key + "_signed", row[key])


def format_rows(rows: list[dict], keys, h_label: str = "h~") -> str:
    """A text table: level, ndof, h (``h_label``: h~ under uniform refinement), each error
    with its observed order in h, then a, a_h, P."""
    from .manufactured_errors import convergence_orders

    if not rows:
        return ""
    orders = {k: convergence_orders(rows, k) for k in keys}
    head = (f"{'lvl':>3} {'ndof':>7} {h_label:>7} " + " ".join(f"{k:>10} {'ord':>5}" for k in keys)
            + f" {'a':>7} {'a_h':>7} {'P':>10}")
    lines = [f"benchmark {rows[0]['benchmark']}", head]
    for k, row in enumerate(rows):
        cells = [f"{row[q]:10.3e} " + (f"{orders[q][k]:5.2f}" if orders[q][k] is not None
                                        else f"{'':>5}") for q in keys]
        lines.append(f"{row['level']:3d} {row['ndof']:7d} {row['h']:7.4f} " + " ".join(cells)
                     + f" {row['a']:7.4f} {row['half_width']:7.4f} {row['force']:10.2f}")
    return "\n".join(lines)
