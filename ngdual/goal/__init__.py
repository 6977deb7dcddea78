"""The goals of the adaptive loop: what its indicators estimate and its tolerance measures.

A goal is an object the loop asks (:class:`Goal`), never a name it tests:

* :class:`StressGoal` (``"stress"``, the thesis'): the error of (3.124) by the indicators
  of (4.50), relative to ||sigma_h||_{H(div)};
* :class:`PressureGoal` (``"pressure"``, with an optional ``window`` of Gamma_C): the
  contact pressure's error ||p - p_h||_{L2(W)} by the indicators of :func:`goal_estimate`
  (:mod:`ngdual.goal.indicators`), relative to ||p_h||_{L2(W)}.

:func:`goal_for` makes one from its name.

>>> goal_for("pressure", (-0.125, 0.125)).size_name
'||p_h||'
"""

from __future__ import annotations

from .base import Goal, Measure
from .indicators import (
    CALIBRATION,
    CALIBRATION_ORDER_K,
    CALIBRATION_WINDOW_ORDER_K,
    END_CONSTANT,
    TERMS,
    PressureEstimate,
    calibration,
    goal_estimate,
    in_window,
)
from .pressure import KINK_EFFECTIVITY, PressureGoal, contact_vertices, singular_free_ends
from .stress import StressGoal

__all__ = ["CALIBRATION", "CALIBRATION_ORDER_K", "CALIBRATION_WINDOW_ORDER_K", "END_CONSTANT",
           "GOALS", "KINK_EFFECTIVITY", "TERMS", "Goal", "Measure", "PressureEstimate",
           "PressureGoal", "StressGoal", "calibration", "contact_vertices", "goal_estimate",
           "goal_for", "in_window", "singular_free_ends"]

# every goal by its name (the CLI's --goal)
GOALS = {"stress": StressGoal, "pressure": PressureGoal}


def goal_for(name: str, window: tuple[float, float] | None = None) -> Goal:
    """The goal called ``name`` (a key of :data:`GOALS`), the pressure goal on ``window``."""
    return GOALS[name](window)
