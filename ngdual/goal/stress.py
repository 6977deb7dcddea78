"""The stress goal: the thesis' error (3.124), estimated by the indicators of (4.50)."""

from __future__ import annotations

from ..estimator import Estimate
from ..solution import Solution
from .base import Goal, Measure


class StressGoal(Goal):
    """The error of (3.124) by the indicators eta_{tot,T} of (4.50) (Section 4.2), relative to
    ||sigma_h||_{H(div)}, the leading part of the total error that (4.50) bounds.

    >>> StressGoal().name
    'stress'
    """

    name = "stress"
    size_name = "||sigma_h||"
    zero_size_reason = "no load"

    def __init__(self, window: None = None):
        if window is not None:
            raise ValueError("the stress goal measures the whole domain: it takes no window")

    def measure(self, solution: Solution, estimated: Estimate, norms: dict) -> Measure:
        """The indicators of (4.50) (``estimated``) and ||sigma_h||_{H(div)} (``norms``, of
        :func:`ngdual.quantities.norms`)."""
        size = float(norms["sigma_X"])
        return Measure(estimated.indicators, float(estimated.total), size, size)
