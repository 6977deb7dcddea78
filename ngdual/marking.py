"""Marking strategies for adaptive refinement: pure functions of the indicators.

Each takes the element indicators eta_T >= 0 (e.g. eta_{tot,T} of (4.50),
``nd.estimate(solution).indicators``) and a parameter theta in [0, 1], and returns a
boolean mask of the elements to refine. Ties are resolved by value, never by
position: two elements with the same indicator are either both marked or both
not, so the result does not depend on the element numbering.

* :func:`mark_max` -- the first algorithm of Section 4.2: eta_T >= theta max_S eta_S.
* :func:`mark_fraction` -- the second algorithm of Section 4.2: the theta share
  of the elements with the largest indicators.
* :func:`mark_dorfler` -- Dörfler's bulk criterion: the smallest set M with
  sum_M eta_T^2 >= theta * sum eta_T^2.

:func:`peak_vertices` says where a marked set's estimate peaks: the vertices a refinement
with a least growth grades towards (:func:`ngdual.afem.refinement.refine_graded`).

>>> mark_max(np.array([1.0, 4.0, 2.0]), 0.5)
array([False,  True,  True])
"""

from __future__ import annotations

import math

import numpy as np

from .scene import SceneError, SceneTypeError

STRATEGIES = ("max", "fraction", "dorfler")
# A vertex is a peak of the marked estimate where the marked triangles at it carry at least
# this share of the largest such sum (the corner of a point singularity, the ends of a
# contact zone; at order 0 the estimate spread over Gamma_C makes many vertices peaks).
# Measured on the work-precision study's tolerance runs (docs/theory/estimator.md, "Steps
# that pay"): 1/4 and 1/2 alike within the noise at k >= 1; 1/4 the faster at k = 0.
PEAK_SHARE = 0.25


def _check(indicators, theta: float) -> np.ndarray:
    """``indicators`` as an array of floats; a SceneError (SceneTypeError for a wrong type)
    naming ``indicators`` or ``theta`` if they are not indicators and a parameter in [0, 1]."""
    wanted = "a 1D array of the element indicators eta_T >= 0 (e.g. nd.estimate(s).indicators)"
    if isinstance(indicators, (str, bytes)) or indicators is None:
        raise SceneTypeError("indicators", f"must be {wanted}, got "
                                           f"{type(indicators).__name__}")
    try:
        values = np.asarray(indicators, dtype=float)
    except (TypeError, ValueError):
        raise SceneTypeError("indicators", f"must be {wanted}, got "
                                           f"{type(indicators).__name__}") from None
    if values.ndim != 1:
        raise SceneError("indicators", f"must be {wanted}, got shape {values.shape}")
    if not np.all(np.isfinite(values)) or np.any(values < 0):
        raise SceneError("indicators", f"must be finite and >= 0 ({wanted})")
    if isinstance(theta, bool) or not isinstance(theta, (int, float, np.integer, np.floating)):
        raise SceneTypeError("theta", f"must be a number in [0, 1], got {type(theta).__name__}")
    if not 0 <= theta <= 1:
        raise SceneError("theta", f"must lie in [0, 1], got {theta!r}")
    return values


def mark_max(indicators, theta: float) -> np.ndarray:
    """Mark T where eta_T >= theta max_S eta_S (Section 4.2, first algorithm).

    theta = 0 marks every element, theta = 1 the elements attaining the maximum.
    """
    indicators = _check(indicators, theta)
    if not len(indicators):
        return np.zeros(0, dtype=bool)
    return indicators >= theta * indicators.max()


def mark_fraction(indicators, theta: float) -> np.ndarray:
    """Mark the ceil(theta * N) elements with the largest indicators (Section 4.2, second).

    Elements tied with the smallest marked indicator are marked too, so the
    mask may hold more than ceil(theta * N) elements. theta = 0 marks none,
    theta = 1 all.
    """
    indicators = _check(indicators, theta)
    count = math.ceil(round(theta * len(indicators), 9))
    if count == 0:
        return np.zeros(len(indicators), dtype=bool)
    threshold = np.sort(indicators)[::-1][count - 1]
    return indicators >= threshold


def mark_dorfler(indicators, theta: float) -> np.ndarray:
    """Dörfler marking: a smallest set M with sum_M eta_T^2 >= theta * sum_T eta_T^2.

    The elements are taken in decreasing order of eta_T until the bulk is
    reached; elements tied with the last one taken are added as well.
    theta = 0 marks none; theta = 1 marks every element with eta_T > 0.
    """
    indicators = _check(indicators, theta)
    if not len(indicators) or theta == 0:
        return np.zeros(len(indicators), dtype=bool)
    ordered = np.sort(indicators)[::-1]
    bulk = np.cumsum(ordered**2)
    if bulk[-1] == 0:
        return np.zeros(len(indicators), dtype=bool)
    # comparing with bulk[-1] (not a separate sum) makes theta = 1 exact in floating point
    count = int(np.searchsorted(bulk, theta * bulk[-1], side="left")) + 1
    return indicators >= ordered[count - 1]


def peak_vertices(triangles: np.ndarray, indicators, marked: np.ndarray,
                  share: float = PEAK_SHARE) -> np.ndarray:
    """The vertices where the estimate of the marked triangles peaks.

    A vertex v weighs w_v = sum of eta_T^2 over the marked triangles T at it; the peaks are
    the vertices with w_v >= ``share`` max_v w_v (none where nothing marked carries an
    estimate).

    Parameters
    ----------
    triangles : array (ne, 3) of int
        The vertex numbers of every triangle (:func:`ngdual.mesh.mesh_arrays`).
    indicators : array_like
        The element indicators eta_T >= 0.
    marked : array of bool
        The marked triangles (:func:`mark`).
    share : float
        The least weight of a peak, as a share in [0, 1] of the largest.

    Returns
    -------
    numpy.ndarray of bool
        One entry per vertex (the largest vertex number of ``triangles`` + 1).

    The two marked triangles meet at vertices 0 and 2, which carry both estimates:

    >>> triangles = np.array([[0, 1, 2], [0, 2, 3], [2, 3, 4]])
    >>> peak_vertices(triangles, [3.0, 1.0, 0.1], np.array([True, True, False]), 0.95)
    array([ True, False,  True, False, False])
    """
    indicators = _check(indicators, 0.0)
    if not 0 <= share <= 1:
        raise ValueError(f"share must lie in [0, 1], got {share!r}")
    triangles = np.asarray(triangles)
    marked = np.asarray(marked, dtype=bool)
    if triangles.shape != (len(indicators), 3) or marked.shape != indicators.shape:
        raise ValueError(f"{len(indicators)} indicators, {marked.shape} marks and "
                         f"{triangles.shape} triangles: one of each per triangle")
    weight = np.zeros(int(triangles.max()) + 1 if triangles.size else 0)
    np.add.at(weight, triangles[marked].ravel(), np.repeat(indicators[marked] ** 2, 3))
    if not weight.size or weight.max() == 0:
        return np.zeros(weight.size, dtype=bool)
    return weight >= share * weight.max()


def mark(indicators, theta: float, strategy: str = "dorfler") -> np.ndarray:
    """Mark with one strategy of Section 4.2 (or Dörfler's).

    Parameters
    ----------
    indicators : array_like
        The element indicators eta_T >= 0, e.g. eta_{tot,T} of (4.50).
    theta : float
        The strategy's parameter in [0, 1].
    strategy : {"max", "fraction", "dorfler"}
        :func:`mark_max`, :func:`mark_fraction` or :func:`mark_dorfler`.

    Returns
    -------
    numpy.ndarray of bool
        The elements to refine.
    """
    functions = {"max": mark_max, "fraction": mark_fraction, "dorfler": mark_dorfler}
    if not isinstance(strategy, str) or strategy not in functions:
        raise SceneError("strategy", f"unknown marking {strategy!r}; use one of "
                                     + ", ".join(STRATEGIES))
    return functions[strategy](indicators, theta)
