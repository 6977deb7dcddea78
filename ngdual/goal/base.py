"""What the adaptive loop asks of a goal: :class:`Goal` and its :class:`Measure`.

A goal says what the indicators that drive MARK estimate and what a tolerance measures; the
loop (:func:`ngdual.afem.adapt`) and its stop rules (:mod:`ngdual.afem.stops`) ask the goal
object and never test which goal it is.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..checks import thesis_ends_outside_l2
from ..estimator import Estimate
from ..scene import Scene
from ..solution import Solution


@dataclass(frozen=True)
class Measure:
    """One solution measured by a goal: the element ``indicators`` that drive MARK, their
    root-sum-square ``total`` (the estimate of the goal's error), the ``size`` of the
    solution it is relative to, the same size on the whole of what the goal can measure
    (``whole``: the pressure on all of Gamma_C for a window of it) and, where the goal has
    its own indicators, their summed ``terms`` and the wall time they took (``seconds``)."""

    indicators: np.ndarray
    total: float
    size: float
    whole: float
    terms: dict[str, float] = field(default_factory=dict)
    seconds: float | None = None


class Goal:
    """A goal of the adaptive loop. Subclasses set ``name`` and ``size_name`` and measure a
    solution (:meth:`measure`); the other questions have the stress goal's answers here."""

    name: str
    size_name: str           # the size a relative estimate is taken against, for messages
    zero_size_reason: str    # why that size can be 0 on every mesh
    window: tuple[float, float] | None = None

    def measure(self, solution: Solution, estimated: Estimate, norms: dict) -> Measure:
        """The goal's indicators, estimate and size on ``solution``, whose indicators of (4.50)
        are ``estimated`` and whose norms (:func:`ngdual.quantities.norms`) ``norms``."""
        raise NotImplementedError

    def nothing_to_measure(self, solution: Solution, measured: Measure) -> str | None:
        """Why the goal has nothing to measure on ``solution`` (None where it has), whose
        measure is ``measured``."""
        return None

    def infinite_error(self, solution: Solution) -> str | None:
        """Why the goal's error has no finite value on ``solution`` (None where it has one):
        the thesis' ends leave sigma (and p) outside L2 at a clamped end of Gamma_C
        (:func:`ngdual.checks.thesis_ends_outside_l2`)."""
        return thesis_ends_reason(thesis_ends_outside_l2(solution))

    def caution(self, scene: Scene) -> str | None:
        """Why an estimate below tol may still leave the error above it (None: it does not)."""
        return None


def thesis_ends_reason(clamped: np.ndarray, window: bool = False) -> str | None:
    """Why sigma is not in L2 at the ``clamped`` ends of Gamma_C whose lambda the thesis'
    ends set to 0 (None without any); with ``window``, a window away from them is a remedy."""
    if not len(clamped):
        return None
    ends = "end" if len(clamped) == 1 else "ends"
    return (f'contact.ends = "thesis" sets lambda = 0 at the clamped {ends} {points_text(clamped)} '
            f"of Gamma_C against g - u_D.n != 0 there, so sigma is not in L2 there: the "
            f"goal's error is infinite and its estimate measures none; use contact.ends = "
            f'"consistent"' + (f" or a window away from the {ends}" if window else ""))


def points_text(points) -> str:
    """``points`` (x, y) for a message: "(x1, y1), (x2, y2)"."""
    return ", ".join(f"({x:.4g}, {y:.4g})" for x, y in points)
