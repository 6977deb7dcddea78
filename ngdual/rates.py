"""Convergence rates, and the reference norms the errors of Section 3.4 are measured against.

**The** observed convergence rate of ngdual is the order alpha in the effective mesh size
h_N = N^{-1/2} (N the number of unknowns): between two solutions i and i + 1,

    alpha_i = -2 log(e_i / e_{i+1}) / log(N_i / N_{i+1}),

so that e ~ N^{-alpha/2} (the thesis' alpha of Table 3.4 and Fig. 3.22). Why N and not h:
an adaptive mesh has no single h (h_max hardly moves while N grows), and N is what a
solution costs. Why the factor 2: in 2D uniform refinement gives N ~ h^{-2}, so alpha is
the familiar order in h and compares directly with a priori estimates (alpha = 1 for the
lowest-order PEERS on smooth solutions, the corner exponent on the L-shape) and with the
optimal adaptive rate alpha = 1. :func:`observed_rates` gives alpha between consecutive
solutions, :func:`fitted_rate` the least-squares alpha over several.

Where the exact solution is unknown, its norms are extrapolated from uniform levels
(:func:`extrapolated_norms`, Aitken's Delta^2) and the total error (3.124) compares norms
(:func:`total_error`).
"""

from __future__ import annotations

import math

import numpy as np


def observed_rates(ndofs, errors) -> list[float | None]:
    """alpha between consecutive solutions (see the module docstring); None for the first
    and where an error or a DOF count is missing or not positive.

    >>> [None if a is None else round(a, 12) for a in observed_rates([10, 40], [1.0, 0.5])]
    [None, 1.0]
    """
    out: list[float | None] = [None]
    for n0, e0, n1, e1 in zip(ndofs, errors, ndofs[1:], errors[1:]):
        ok = all(v is not None and v > 0 for v in (n0, e0, n1, e1)) and n0 != n1
        out.append(float(-2 * math.log(e0 / e1) / math.log(n0 / n1)) if ok else None)
    return out


def fitted_rate(ndofs, errors) -> float:
    """The least-squares alpha of e ~ N^{-alpha/2} through all points (at least two).

    >>> round(fitted_rate([10, 40, 160], [1.0, 0.5, 0.25]), 12)
    1.0
    """
    slope = np.polyfit(np.log(np.asarray(ndofs, float)), np.log(np.asarray(errors, float)), 1)[0]
    return float(-2 * slope)


def aitken_extrapolate(values) -> float:
    """Aitken's Delta^2 limit of a sequence from its last three terms (Section 3.4).

    x_inf = x_2 - (x_2 - x_1)^2 / (x_2 - 2 x_1 + x_0). Where the differences
    do not shrink (|x_2 - x_1| >= |x_1 - x_0|: no linear convergence yet) the
    extrapolation is meaningless and the last term is returned.

    >>> round(aitken_extrapolate([1.5, 1.25, 1.125]), 12)
    1.0
    """
    x0, x1, x2 = (float(v) for v in list(values)[-3:])
    d1, d2 = x1 - x0, x2 - x1
    if d1 == 0 or abs(d2) >= abs(d1):
        return x2
    return x2 - d2 * d2 / (d2 - d1)


def extrapolated_norms(sequence: list[dict]) -> dict:
    """The norms of the exact solution: the Aitken limits of the last three of ``sequence``
    (:func:`ngdual.quantities.norms` records of consecutive uniform levels). A quantity missing
    on one of them (None) stays None; with fewer than three levels, the last norms.
    """
    last = [dict(n) for n in sequence[-3:]]
    if len(last) < 3:
        return last[-1] if last else {}
    return {q: (aitken_extrapolate([n[q] for n in last])
                if all(n.get(q) is not None for n in last) else None) for q in last[0]}


def total_error(norms_h: dict, reference: dict) -> tuple[dict, float]:
    """e_i(q) = | ||q_h||^2 - n_q^2 |^{1/2} per quantity and e_tot of (3.124).

    ``norms_h`` is a :func:`ngdual.quantities.norms` record, ``reference`` the (extrapolated)
    norms n_q of the exact solution; quantities missing or ``None`` in either
    (nu without friction) are left out.
    """
    errors = {q: float(np.sqrt(abs(norms_h[q] ** 2 - reference[q] ** 2)))
              for q in norms_h if norms_h[q] is not None and reference.get(q) is not None}
    return errors, float(np.sqrt(sum(e * e for e in errors.values())))
