"""The checks of :func:`ngdual.afem.adapt`'s arguments, before anything is meshed."""

from __future__ import annotations

import numpy as np

from ..estimator import ASYMMETRY_NORMS
from ..goal import GOALS
from ..marking import STRATEGIES
from ..scene import SceneError, SceneTypeError, check_level, ensure_valid
from .refinement import check_growth


def check_adapt_arguments(scene, marking, theta, steps, level, asymmetry, reference, on_step,
                          allow_large, goal, tol, window, growth) -> None:
    """A SceneError (SceneTypeError for a wrong type) naming the first bad argument."""
    ensure_valid(scene)
    check_level(level, "level", optional=True)
    if not isinstance(goal, str):
        raise SceneTypeError("goal", f"must be one of {', '.join(GOALS)}, got "
                                     f"{type(goal).__name__}")
    if goal not in GOALS:
        raise SceneError("goal", f"unknown goal {goal!r}; use one of " + ", ".join(GOALS))
    if goal == "pressure" and not scene.labels("contact"):
        raise SceneError("goal", f"scene {scene.name!r} has no contact boundary: no pressure "
                                 "to aim at")
    if window is not None:
        if goal != "pressure":
            raise SceneError("window", "a window selects part of Gamma_C for the pressure "
                                       "goal; use it with goal='pressure'")
        if (not isinstance(window, (tuple, list)) or len(window) != 2
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in window)):
            raise SceneTypeError("window", f"must be two numbers (lo, hi), got {window!r}")
        if not -float("inf") < window[0] < window[1] < float("inf"):
            raise SceneError("window", f"must be finite with lo < hi, got {tuple(window)}")
    if tol is not None:
        if isinstance(tol, bool) or not isinstance(tol, (int, float)):
            raise SceneTypeError("tol", f"must be a number > 0, got {tol!r}")
        if not 0 < tol < float("inf"):
            raise SceneError("tol", f"must be a finite number > 0, got {tol!r}")
    if marking is not None and marking not in STRATEGIES:
        raise SceneError("marking", f"unknown marking {marking!r}; use one of "
                                    + ", ".join(STRATEGIES))
    if theta is not None and (isinstance(theta, bool) or not isinstance(theta, (int, float))):
        raise SceneTypeError("theta", f"must be a number in [0, 1], got {theta!r}")
    if theta is not None and not 0 <= theta <= 1:
        raise SceneError("theta", f"must lie in [0, 1], got {theta!r}")
    if growth is not None:
        check_growth(growth)
    if steps is not None and (isinstance(steps, bool)
                              or not isinstance(steps, (int, np.integer))):
        raise SceneTypeError("steps", f"must be an integer >= 1, got {steps!r}")
    if steps is not None and steps < 1:
        raise SceneError("steps", f"must be >= 1, got {steps}")
    if asymmetry not in ASYMMETRY_NORMS:
        raise SceneError("asymmetry", f"unknown norm {asymmetry!r}; use one of "
                                      + ", ".join(ASYMMETRY_NORMS))
    if reference is not None and not isinstance(reference, dict):
        raise SceneTypeError("reference", f"must be a dict of norms, got "
                                          f"{type(reference).__name__}")
    if on_step is not None and not callable(on_step):
        raise SceneTypeError("on_step", f"must be callable, got {type(on_step).__name__}")
    if not isinstance(allow_large, bool):
        raise SceneTypeError("allow_large", f"must be True or False, got {allow_large!r}")
