"""Every size of a ``ngdual figures`` run, derived from one number: the finest uniform level K.

:class:`Plan` derives the levels, grids and step counts from K (``--max-level``); the
tables below name the scenes and cases the studies solve: the two problems of Example
3.46 (:data:`SCENES`), the gap cases of Figs. 3.24-3.28 (:data:`GAP_CASES`), the adaptive
runs of Section 4.2 (:data:`ADAPTIVE_RUNS`) and the problems of the true-error studies
(:data:`TRUTH_PROBLEMS`, :data:`TRUTH_GOALS`, :data:`PEER_ORDERS`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..variants import setting

DEFAULT_MAX_LEVEL = 5
# the wall time of a true-error task: the median of this many runs (Plan.timing_repeats)
TIMING_REPEATS = 3
THESIS_MAX_LEVEL = 8
SCENES = {"frictionless": "thesis-3.46-frictionless", "coulomb": "thesis-3.46-coulomb"}
HHAT1 = setting("contact.hhat_factor", 1)
PROBLEM_TITLES = {"frictionless": r"$\mu_f = 0$", "coulomb": r"$\mu_f = 0.5$"}


@dataclass(frozen=True)
class Plan:
    """Every size of a run, derived from the finest uniform level K.

    K = 8 is the thesis scale. The adaptive runs of Section 4.2 keep the thesis'
    parameters and step counts once K is large enough (28 refinements with max
    marking, snapshots after 1, 3, 5, 7, 9 refinements with fraction marking),
    and shrink with K otherwise so that their last mesh stays about as large as
    level K; the figure titles name the steps actually shown.
    """

    max_level: int = DEFAULT_MAX_LEVEL

    def __post_init__(self):
        if not 2 <= self.max_level <= THESIS_MAX_LEVEL:
            raise ValueError(f"--max-level must lie in 2..{THESIS_MAX_LEVEL}, "
                             f"got {self.max_level}")

    @property
    def levels(self) -> list[int]:
        return list(range(1, self.max_level + 1))

    @property
    def field_level(self) -> int:
        """Level of the field plots of Figs. 3.11-3.21 (at most 6: 65 536 triangles)."""
        return min(self.max_level, 6)

    @property
    def reference_levels(self) -> list[int]:
        """The three levels whose norms give the Aitken-extrapolated reference (3.124)."""
        return self.levels[-3:]

    @property
    def rho_level(self) -> int:
        """Level of the (rho_1, rho_2) grid of Fig. 3.23 (the thesis: the 4th)."""
        return min(self.max_level, 4)

    @property
    def rho_grid(self) -> tuple[float, ...]:
        """rho of Algorithm 3.38 searched on every level (Table 3.5)."""
        return (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75)

    @property
    def rho1_grid(self) -> tuple[float, ...]:
        return (0.5, 0.75, 1.0, 1.25, 1.5, 1.75) if self.max_level >= 4 else (0.5, 1.0, 1.5)

    @property
    def rho2_grid(self) -> tuple[float, ...]:
        """rho_2 is relative to the computed stability bound of the nu step: (0, 2)."""
        return ((0.25, 0.5, 1.0, 1.25, 1.5, 1.9) if self.max_level >= 4
                else (0.5, 1.0, 1.9))

    @property
    def rho_cross(self) -> tuple[tuple[float, float], ...]:
        """(rho_1, rho_2) tried on the levels above :attr:`rho_level` (besides (1, 1))."""
        return ((1.0, 1.9), (1.5, 1.9))

    @property
    def gap_level(self) -> int:
        """Level of the solutions plotted in Figs. 3.24-3.28 (default solver)."""
        return self.field_level

    @property
    def uzawa_gap_level(self) -> int:
        """Level of the nested Uzawa runs of Figs. 3.24-3.28 (the thesis: the 4th)."""
        return max(1, min(self.max_level - 1, 4))

    @property
    def max_marking_refinements(self) -> int:
        return min(28, 7 * (self.max_level - 1))

    @property
    def max_marking_snapshots(self) -> list[int]:
        """Steps shown in Figs. 4.1-4.8 (the thesis: 0, 4, ..., 28)."""
        return [int(v) for v in np.floor(np.linspace(0, self.max_marking_refinements, 8) + 0.5)]

    @property
    def fraction_refinements(self) -> int:
        """fraction marking (theta = 0.2) doubles the mesh about every step."""
        return min(9, 2 * self.max_level - 3) if self.max_level >= 4 else 4

    @property
    def fraction_snapshots(self) -> list[int]:
        """Steps shown in Figs. 4.9-4.13 (the thesis: 1, 3, 5, 7, 9; repeated if fewer)."""
        return [int(v) for v in np.floor(np.linspace(1, self.fraction_refinements, 5) + 0.5)]

    @property
    def dorfler_refinements(self) -> int:
        return 2 * self.max_level

    @property
    def timing_repeats(self) -> int:
        """Timed runs of a true-error task (the median is its wall time,
        :data:`ngdual.studies.sweep.timing.REPEAT_BELOW_S`): :data:`TIMING_REPEATS` from the
        default K on; a smoke run below it times once."""
        return TIMING_REPEATS if self.max_level >= DEFAULT_MAX_LEVEL else 1

    def truth_levels(self, problem: str) -> list[int]:
        """Uniform levels of the true-error studies (:data:`TRUTH_PROBLEMS`): 1 to K minus the
        problem's ``coarser``, the memory and time budget of uniform refinement."""
        return list(range(1, max(2, self.max_level - TRUTH_PROBLEMS[problem].coarser) + 1))

    def order_levels(self, problem: str, order: int) -> list[int]:
        """The uniform levels of PEERS_``order`` in the true-error studies: ``order`` fewer
        than :meth:`truth_levels` (a level of order 2 costs about 6 of order 0), at least
        level 1."""
        return list(range(1, max(1, self.truth_levels(problem)[-1] - order) + 1))

    def order_elements(self, problem: str, order: int) -> int:
        """The budget of the adaptive run of PEERS_``order``: :meth:`reference_elements`
        / 4^order triangles (an unknown of order k costs about one of order 0, and a
        triangle of PEERS_2 holds about six times the unknowns of one of PEERS_0), times the
        problem's ``order_budget``."""
        return TRUTH_PROBLEMS[problem].order_budget * self.reference_elements(problem) // 4 ** order

    def reference_elements(self, problem: str) -> int:
        """The budget of an adaptive run of the true-error studies: it stops after the first
        step with this many triangles (those of one uniform level beyond the finest, at most
        :data:`REFERENCE_ELEMENTS`), unless its tolerance (the problem's ``reference_tol``)
        stops it first."""
        finest = self.truth_levels(problem)[-1]
        return min(TRUTH_PROBLEMS[problem].level1_elements * 4 ** finest, REFERENCE_ELEMENTS)

    def describe(self) -> dict:
        names = ("max_level", "levels", "field_level", "reference_levels", "rho_level",
                 "rho_grid", "rho1_grid", "rho2_grid", "rho_cross", "gap_level", "uzawa_gap_level",
                 "max_marking_refinements", "max_marking_snapshots", "fraction_refinements",
                 "fraction_snapshots", "dorfler_refinements", "timing_repeats")
        return {n: getattr(self, n) for n in names}


# the tolerance of the true-error studies' adaptive runs (TruthProblem.reference_tol)
REFERENCE_TOL = 0.001


@dataclass(frozen=True)
class TruthProblem:
    """A scene of the true-error studies: its overrides and how many levels coarser than K
    its finest uniform level is (a flat punch level has ~6x the triangles of Example 3.46's);
    the tolerance of its adaptive runs (``reference_tol``) and the factor of their budget at
    order k >= 1 (``order_budget``, :meth:`Plan.order_elements`)."""

    scene: str
    overrides: tuple[str, ...] = ()
    coarser: int = 0
    title: str = ""
    level1_elements: int = 32
    reference_tol: float = REFERENCE_TOL
    order_budget: int = 1

    @property
    def pressure_window(self) -> tuple[float, float] | None:
        """The part lo <= x <= hi of Gamma_C whose pressure error the study measures (None:
        all of it): :func:`ngdual.accuracy.pressure_window`, the flat punch's core."""
        return _pressure_window(self.scene, self.overrides)


@functools.cache
def _pressure_window(scene: str, overrides: tuple[str, ...]) -> tuple[float, float] | None:
    from ...accuracy import pressure_window
    from ...scene import load_scene

    return pressure_window(load_scene(scene, list(overrides)))


# Example 3.46 with consistent end values (lambda = g - u_D.n at the clamped ends): the
# thesis' lambda = 0 there contradicts u = 0 on Gamma_D, sigma ~ 1/r at the corners is not in
# L2 and no error norm exists (see figures/effectivity.py); the peer solves this problem too
CONSISTENT = (setting("contact.ends", "consistent"),)
TRUTH_PROBLEMS = {
    "frictionless": TruthProblem("thesis-3.46-frictionless", CONSISTENT, 0,
                                 r"Example 3.46, $\mu_f = 0$"),
    "coulomb": TruthProblem("thesis-3.46-coulomb", CONSISTENT, 0,
                            r"Example 3.46, $\mu_f = 0.5$"),
    # the punch pressure ~ (a - |x|)^(-1/2) is not in L2: its error on the core |x| < a/2
    # (TruthProblem.pressure_window); sigma (~ r^(-1/2)) is in L2 everywhere, but its
    # references converge slowest: at the tolerance 0.001 of the other problems the best,
    # the stress goal of order 1 (307 936 unknowns), is Richardson-accurate to 0.60 %
    # (0.785 per step), which does not resolve 1 %; its steps solved again by PEERS_2
    # converge at 0.89 per step. A third of the tolerance and twice the
    # budget of order k take it about four steps further
    "flat-punch": TruthProblem("flat-punch", (), 2, "flat punch", 206,
                               reference_tol=0.0003, order_budget=2),
    "hertz-cylinder": TruthProblem("hertz-cylinder", (), 2, "Hertz cylinder", 226),
    "cattaneo-mindlin": TruthProblem("cattaneo-mindlin", (), 2, "Cattaneo-Mindlin", 226),
    "wedge": TruthProblem("wedge", (), 2, "wedge", 218),
}
# The adaptive runs of the true-error studies, one per goal of ngdual.afem.adapt (a
# tolerance run: its Doerfler theta and initial level), each to the problem's reference_tol
# (REFERENCE_TOL unless it says otherwise) or the budget Plan.reference_elements; the last
# steps are the candidates for the references.
TRUTH_GOALS = ("stress", "pressure")
# a run grows by 1.1-1.5x per step on its coarsest meshes and by 2-2.7x later: 16 steps
# pass any budget, a run that takes them all is stalled (the wedge's pressure goal needs 13)
ADAPT_STEPS = 16
# a step grows the triangles by about 2.4x: the last step has at most ~200 000 triangles
# (1.5 million unknowns), a few GB and about a minute on one core
REFERENCE_ELEMENTS = 80_000
PEER_ORDERS = (1, 2)
# the stress goal's steps of at most REFERENCE_ORDER_DOFS unknowns are solved again by
# PEERS_k, k = REFERENCE_ORDER, on their meshes: the sigma reference (Hertz: the step of
# 93 114 unknowns gives 588 674 at k = 2 in 28 s, Richardson-accurate to 0.16 %, where the
# last k = 0 step, 661 646 unknowns, is to 1.1 %; Example 3.46, mu_f = 0: the step of
# 215 072 gives 1 358 854 in 36 s, 0.25 %, the last k = 0 step of 1 638 430 0.73 %)
REFERENCE_ORDER = 2
REFERENCE_ORDER_DOFS = 300_000
# the higher orders of the true-error studies: PEERS_k with the facet P_k multipliers on the
# fine edges (k = 0 with the coarse multipliers is the thesis' method), per order both goals'
# tolerance runs and the uniform levels up to Plan.order_levels
ORDERS = (1, 2)
# PEERS_k with the thesis' coarse multipliers of degree k + 1 (uniform levels): they solve
# frictionless contact only, so only on these problems
COARSE_ORDERS = (1, 2)
COARSE_ORDER_PROBLEMS = ("frictionless", "flat-punch", "hertz-cylinder", "wedge")


GAP_CASES = {
    # key: (scene, overrides); solved with the default solver on Plan.gap_level and with the
    # thesis' nested Uzawa on Plan.uzawa_gap_level ("uzawa-" + key)
    "gap0": ("thesis-3.46-coulomb-gap0", []),
    "gap0-hhat1": ("thesis-3.46-coulomb-gap0", [HHAT1]),
    "abs-hhat1": ("thesis-3.46-coulomb-gap-abs", [HHAT1]),
    "abs-hhat2": ("thesis-3.46-coulomb-gap-abs", []),
    "3125-hhat1": ("thesis-3.46-coulomb-gap-3125", [HHAT1]),
    "3125-hhat2": ("thesis-3.46-coulomb-gap-3125", []),
}


ADAPTIVE_RUNS = {
    # key: (marking, theta, initial level)
    "max": ("max", 0.5, 1),
    "fraction": ("fraction", 0.2, 2),
    "dorfler": ("dorfler", 0.5, 1),
}


MANUFACTURED_CASES = ("frictionless", "coulomb-nodes")
