"""Accuracy on demand: the contact pressure (the stress, without contact) to a tolerance by
the fastest method ngdual has, in one call: ``nd.solve(scene, tol=0.01)``,
``ngdual solve SCENE --tol 0.01``.

The method is chosen by a rule (:func:`fastest_method`, docs/theory/order.md, Accuracy on
demand) derived from the work-precision study of the six problems
(docs/gallery/work_precision_table.csv, the least wall time to 5, 2 and 1 % true error):

* the goal: the pressure goal where the scene has a contact boundary (what a contact
  engineer asks for), the stress goal (4.50) otherwise;
* the multipliers: the facet family (the coarse family of order k never paid: 5 % pressure
  on Example 3.46 in 12 s at k = 1 against 0.18 s with the facet one);
* the order, by where the contact pressure is singular (:func:`fixed_singularities`):
  k = 2 where its only singularities are the free ends of the contact zone (a convex body
  on a foundation: Hertz, Cattaneo-Mindlin), k = 1 where Gamma_C has a fixed singular
  point (a kink, a junction with Gamma_D, an end where the boundary runs straight on or
  turns re-entrant: the wedge's apex, the clamped ends of Example 3.46, the flat punch's
  edges), and k = 1 without contact. Measured on the six problems of the study, the
  tolerance runs of the pressure goal to 5, 1 and 0.3 % (docs/theory/order.md, Accuracy on
  demand): k = 2 is 1.5-1.7 times faster than k = 1 on Hertz and Cattaneo-Mindlin to 1 and
  0.3 %, k = 1 twice as fast as k = 2 on the wedge to 5 and 1 % and 1.2-1.6 times on
  Example 3.46 and the punch to 0.3 %; where both orders reach the tolerance the rule's
  worst choice is 1.5 times the faster order (Example 3.46 with Coulomb friction to 5 %),
  either order alone 1.7 (k = 1) or 2.1 (k = 2) times. At the wedge's apex to 0.3 % k = 1
  stops at the loop's resolution (its estimate at 2.2 %) where k = 2 reaches it: below 1 %
  at a kink ask for ``order=2``;
* the loop: Doerfler marking with the tolerance runs' parameter and least growth of the
  unknowns per step (:data:`ngdual.loop_defaults.THETA_TOL`, ``GROWTH_TOL``), from the
  coarsest level (``LEVEL_TOL``), stopping by the goal's estimate.

A scene that declares its ``[discretisation]`` keeps it, and the thesis' scenes (Example
3.46) keep the thesis' order 0 unless asked (``order=``), so that what they reproduce does
not change with a tolerance.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass

from .afem import adapt
from .forms.spaces import Variant, declared_variant, variant_of
from .goal.pressure import free_straight_ends
from .scene import (
    Scene,
    SceneError,
    check_level,
    contact_junctions,
    contact_samples,
    ensure_valid,
)
from .solution import PhysicsWarning, Solution
from .solvers.dispatch import solve_scene, with_discretisation

FASTEST_ORDER = 1          # the rule's order at fixed singularities, without contact
SMOOTH_ORDER = 2           # ... where the pressure is singular only at free ends
FASTEST_FAMILY = "facet"


@dataclass(frozen=True)
class Method:
    """A method chosen to reach a tolerance: PEERS_``order`` with the ``multipliers``
    family, adapted by ``goal``'s estimate; ``reason`` says why it was chosen."""

    order: int
    multipliers: str
    goal: str
    reason: str
    window: tuple[float, float] | None = None

    def describe(self) -> str:
        """The method in a few words, e.g. ``"adaptive, pressure goal, k = 1, facet"``."""
        where = "" if self.window is None else \
            f" on {self.window[0]:.4g} <= x <= {self.window[1]:.4g}"
        return f"adaptive, {self.goal} goal{where}, k = {self.order}, {self.multipliers}"


def fastest_method(scene: Scene, order: int | None = None,
                   multipliers: str | None = None) -> Method:
    """The method :func:`solve_to_tolerance` runs on ``scene`` (module docstring): the
    order and the family given here, else those the scene declares, else the thesis'
    order 0 for a thesis scene, else the facet family with :data:`SMOOTH_ORDER` where the
    contact pressure has no fixed singular point (:func:`fixed_singularities`) and
    :data:`FASTEST_ORDER` where it has one or the scene has no contact."""
    goal = "pressure" if scene.has_contact else "stress"
    window = pressure_window(scene) if scene.has_contact else None
    declared = declared_variant(scene)
    if order is not None or multipliers is not None:
        chosen, reason = variant_of(with_discretisation(scene, order, multipliers)), "as asked"
    elif declared is not None:
        chosen, reason = declared, "the scene's [discretisation]"
    elif _thesis(scene):
        chosen, reason = variant_of(scene), "a thesis scene keeps the thesis' order 0"
    elif not scene.has_contact:
        chosen = Variant(FASTEST_ORDER, FASTEST_FAMILY)
        reason = "the order of the work-precision study without contact"
    else:
        fixed = fixed_singularities(scene)
        chosen = Variant(FASTEST_ORDER if fixed else SMOOTH_ORDER, FASTEST_FAMILY)
        reason = ("the pressure is singular at fixed points of Gamma_C: " + "; ".join(fixed)
                  if fixed else "the pressure is singular only at the free ends of the "
                                "contact zone, where the higher order pays")
    if window is not None:
        reason += "; the pressure is measured on the middle half of Gamma_C (module docstring)"
    return Method(chosen.order, chosen.family, goal, reason, window)


def fixed_singularities(scene: Scene) -> list[str]:
    """The points of Gamma_C where the contact pressure may be singular whatever the load,
    in words ("a kink at (0, 0)"): its kinks (a wedge's apex), its junctions with Gamma_D
    (a clamped end) and its ends where a free or loaded side runs straight on or turns
    re-entrant (a flat punch's edge, :func:`ngdual.goal.pressure.free_straight_ends`).
    Elsewhere the pressure is singular only where the contact zone ends, a point the
    adaptive loop finds and grades towards, and the higher order pays (module docstring)."""
    what = {"kink": "a kink", "dirichlet": "a junction with Gamma_D"}
    found = [(what[kind], point) for point, kind, _ in contact_junctions(scene) if kind in what]
    found += [("a free side running straight on", point) for point in free_straight_ends(scene)]
    return [f"{name} at ({point[0]:.4g}, {point[1]:.4g})" for name, point in found]


def pressure_window(scene: Scene) -> tuple[float, float] | None:
    """The part of Gamma_C whose pressure error the goal measures: all of it (None), or,
    where the pressure may not be in L2 at an end of Gamma_C, the middle half of Gamma_C's
    abscissae, as the work-precision study measures the punch's core |x| < a/2: at an end
    that meets a free side running straight on or turning re-entrant (a flat punch's edge:
    p ~ d^(-1/2) if the contact zone reaches it, :func:`ngdual.goal.singular_free_ends`),
    and at a clamped end with the thesis' end values (``contact.ends = "thesis"``: lambda = 0
    against g - u_D.n, sigma ~ 1/r there, the thesis' Example 3.46)."""
    clamped = scene.contact.ends == "thesis" and any(
        kind == "dirichlet" for _, kind, _ in contact_junctions(scene))
    if not (clamped or len(free_straight_ends(scene))):
        return None
    x = contact_samples(scene)[0][:, 0]
    lo, hi = float(x.min()), float(x.max())
    quarter = 0.25 * (hi - lo)
    return lo + quarter, hi - quarter


def _thesis(scene: Scene) -> bool:
    """Whether ``scene`` is one of the thesis' (Example 3.46)."""
    return scene.geometry.kind == "thesis-3.46"


def solve(scene: Scene, level: int | None = None,
          progress: Callable[[int, float], None] | None = None, allow_large: bool = False,
          status: Callable[[str], None] | None = None, *, order: int | None = None,
          multipliers: str | None = None, tol: float | None = None) -> Solution:
    """Solve ``scene`` on ``level`` (:func:`ngdual.solvers.solve_scene`, whose arguments
    these are), or, with ``tol``, to that relative error of its contact pressure (of its
    stress, without contact) by the fastest method (:func:`solve_to_tolerance`: adaptive
    from the coarsest level, or from ``level``, stopping by the estimate;
    ``solution.accuracy`` says which method it chose and why, the estimate, the solves,
    the unknowns and the time). Every failed physics check is issued as a
    :class:`~ngdual.solution.PhysicsWarning`.

    >>> import ngdual as nd
    >>> solution = nd.solve(nd.load_scene("hertz-cylinder"), tol=0.05)  # doctest: +SKIP
    >>> solution.accuracy["method"]                                     # doctest: +SKIP
    'adaptive, pressure goal, k = 2, facet'
    """
    if tol is None:
        return solve_scene(scene, level, progress, allow_large, status, order=order,
                           multipliers=multipliers)
    level = check_level(level, "level", optional=True)
    solution = solve_to_tolerance(scene, tol, order=order, multipliers=multipliers,
                                  level=level, allow_large=allow_large)
    for found in solution.warnings:
        warnings.warn(found.message, PhysicsWarning, stacklevel=2)
    return solution


def solve_to_tolerance(scene: Scene, tol: float, *, order: int | None = None,
                       multipliers: str | None = None, level: int | None = None,
                       allow_large: bool = False, on_step=None) -> Solution:
    """The solution whose goal (the contact pressure; the stress without contact) is
    estimated to ``tol`` relative error, by the method of :func:`fastest_method`.

    The adaptive loop (:func:`ngdual.afem.adapt`) runs from the coarsest level (or from
    ``level``) and stops by the goal's estimate. The returned solution is that of the last
    step, and its ``accuracy`` says what was done: the method and why it was chosen, ``tol``, the
    relative estimate reached, the steps (solves), the unknowns, the loop's wall time and
    how the loop stopped (``stopped_by``; only ``"tol"`` means the tolerance was reached,
    otherwise a warning is part of the solution's record). ``on_step`` is passed to the
    loop.

    Raises
    ------
    SceneError
        For a bad ``tol`` (a number in (0, 1)), ``order`` or ``multipliers``.
    """
    ensure_valid(scene)
    if isinstance(tol, bool) or not isinstance(tol, (int, float)) or not 0.0 < tol < 1.0:
        raise SceneError("tol", f"must be a relative error in (0, 1), e.g. 0.01, got {tol!r}")
    method = fastest_method(scene, order, multipliers)
    last: dict = {}

    def keep(record, solution, estimated, marked):
        last["solution"] = solution
        if on_step is not None:
            on_step(record, solution, estimated, marked)

    start = time.perf_counter()
    history = adapt(scene, goal=method.goal, tol=float(tol), order=method.order,
                    multipliers=method.multipliers, level=level, on_step=keep,
                    allow_large=allow_large, window=method.window)
    seconds = time.perf_counter() - start
    final = history[-1]
    solution: Solution = last["solution"]
    solution.timings["total"] = seconds   # the whole loop: what this solution cost
    solution.accuracy = {
        "method": method.describe(), **asdict(method), "tol": float(tol),
        "relative_estimate": final["relative_estimate"],
        "reached": final.get("stopped_by") == "tol",
        "stopped_by": final.get("stopped_by"), "solves": len(history),
        "unknowns": int(final["dofs"]["total"]), "loop_s": seconds,
        "unknowns_per_step": [int(r["dofs"]["total"]) for r in history],
    }
    return solution
