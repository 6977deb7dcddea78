"""The analytic solution a scene names in its ``[benchmark]`` table, evaluated along Gamma_C.

:class:`ngdual.scene.Benchmark` names a half-plane solution of
:mod:`ngdual.verification.analytic` and its geometric parameters; the loads are those the
discrete solution carries: P = int p_h and Q = int q_h along the foundation
(:func:`ngdual.verification.traction.traction_profile`, the h~ hat projections the contact
conditions of (3.62) see). :func:`benchmark_traces` samples the exact pressure and shear
along the fine edges of Gamma_C in the conventions of :class:`ngdual.trace.ContactTraces`
(pressure positive in compression, shear along t = (n_2, -n_1) of (3.24)), for
:func:`ngdual.plot.plot_contact_traces`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene import Scene, foundation_line
from ..solution import Solution
from .analytic import cattaneo_mindlin, flat_punch, hertz, wedge
from .traction import plane_direction, traction_profile

SAMPLES = 16  # points per fine edge of Gamma_C where the exact traction is evaluated

NAMES = {"hertz": "Hertz", "flat-punch": "flat punch (Sadowsky)",
         "cattaneo-mindlin": "Cattaneo-Mindlin", "wedge": "blunt wedge"}


def exact_solution(scene: Scene, P: float, Q: float = 0.0):
    """The solution ``scene.benchmark`` names for the normal force P and tangential force Q
    (per unit thickness), or None for ``kind = "none"``.

    >>> from ngdual.scene import load_scene
    >>> hertz = exact_solution(load_scene("hertz-cylinder"), P=100.0)
    >>> type(hertz).__name__, hertz.R, round(hertz.a, 6)       # a = sqrt(4 P R / (pi E*))
    ('HertzContact', 10.0, 0.076113)
    """
    bench, mat = scene.benchmark, scene.material
    if bench.kind == "hertz":
        return hertz(P, bench.radius, mat.E, mat.nu)
    if bench.kind == "cattaneo-mindlin":
        return cattaneo_mindlin(P, Q, bench.radius, mat.E, mat.nu, scene.friction.mu)
    if bench.kind == "flat-punch":
        return flat_punch(P, bench.half_width)
    if bench.kind == "wedge":
        return wedge(P, bench.slope, mat.E, mat.nu)
    return None


def center_coordinate(scene: Scene) -> float:
    """``benchmark.center`` as a coordinate along the foundation, measured from the
    foundation's point (from x_1 = 0 without one), as the x of
    :class:`~ngdual.verification.traction.TractionProfile`."""
    origin = np.zeros(2) if scene.contact.foundation is None else \
        foundation_line(scene.contact)[0]
    return float((np.asarray(scene.benchmark.center, float) - origin) @ plane_direction(scene))


@dataclass(frozen=True)
class BenchmarkTraces:
    """The exact traction at points along Gamma_C (``xy``), for a picture of the traces.

    ``pressure``: -sigma_n (positive in compression); ``shear``: sigma . n . t with t of
    (3.24), None where the solution has no shear; ``label``: the solution and its P
    (and Q), for a legend; ``solution``: the object of :mod:`ngdual.verification.analytic`.
    """

    xy: np.ndarray
    pressure: np.ndarray
    shear: np.ndarray | None
    label: str
    solution: object

    @property
    def x(self) -> np.ndarray:
        """x_1 of the points (the axis of :func:`ngdual.plot.plot_contact_traces`)."""
        return self.xy[:, 0]


def benchmark_traces(solution: Solution) -> BenchmarkTraces | None:
    """The analytic solution of the scene's ``[benchmark]`` for the forces of ``solution``,
    sampled along the fine edges of Gamma_C (None without one)."""
    scene = solution.problem.scene
    if scene.benchmark.kind == "none":
        return None
    profile = traction_profile(solution)
    P, Q = profile.force, profile.tangential_force
    exact = exact_solution(scene, P, Q)
    gamma_c = solution.problem.spaces.gamma_c
    s = (np.arange(SAMPLES) + 0.5) / SAMPLES - 0.5
    xy = (gamma_c.midpoints[:, None, :]
          + (s[None, :, None] * gamma_c.lengths[:, None, None]) * gamma_c.tangents[:, None, :])
    direction = plane_direction(scene)
    along = ((xy - np.asarray(scene.benchmark.center, float)) @ direction).ravel()
    shear = None
    if hasattr(exact, "shear"):
        # q(x) points along the foundation; sigma_t along t of (3.24) of each fine edge
        sign = np.repeat(gamma_c.tangents @ direction, SAMPLES)
        shear = sign * exact.shear(along)
    label = f"{NAMES[scene.benchmark.kind]}, P = {P:.4g}" + (f", Q = {Q:.4g}"
                                                             if shear is not None else "")
    return BenchmarkTraces(xy.reshape(-1, 2), exact.pressure(along), shear, label, exact)
