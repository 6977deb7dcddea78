"""The three-cornered hat: the own error of a run's last step from its distances to two
independent solutions (:func:`three_cornered_hat`), where Richardson gives none; its
corners (:func:`partner`, :func:`nearest_corners`) and the bound that another run's
Richardson estimate sets on it (:func:`hat_bound`)."""

from __future__ import annotations

import functools
import math

from ..cost.methods import method_base, method_order
from .own_errors import TRUE_MEASURES, measures

# a Richardson estimate that bounds a three-cornered hat (hat_bound) counts at this many
# times its value: it assumes the asymptotic ratio, and where a run has both, it lies up
# to 13 % below its hat (the stress goal of order 1: the punch's 0.019 % against 0.022 %,
# Hertz's 1.39 % against 1.53 %) or far above it; a hat is refuted only by a contradiction
# larger than such an error, not by a remote run's (the Hertz stress goal's 1.39 %, 1.8 %
# from the pressure goal of order 1, whose hat is 0.082 %)
RICHARDSON_SAFETY = 2.0


def three_cornered_hat(d_ab: float, d_ac: float, d_bc: float) -> float | None:
    """The error of solution a from the pairwise distances of three solutions a, b, c whose
    errors are orthogonal (d_ab^2 = e_a^2 + e_b^2, ...; the three-cornered hat of clock
    comparisons): e_a = ((d_ab^2 + d_ac^2 - d_bc^2) / 2)^(1/2); None where the distances
    contradict orthogonality (a negative square).

    >>> round(three_cornered_hat(5 ** 0.5, 10 ** 0.5, 13 ** 0.5), 12)  # e = 1, 2, 3
    1.0
    """
    square = (d_ab**2 + d_ac**2 - d_bc**2) / 2
    return math.sqrt(square) if square >= 0 else None


def partner(method: str, methods: list[str]) -> str | None:
    """The run whose last step is the second corner of ``method``'s three-cornered hat:
    the run of the other goal at the same order, else the first of ``methods`` (ordered by
    the unknowns of their last steps, largest first) of another goal; None without one. A
    run of another goal refines elsewhere: its error is the nearest to orthogonal.

    >>> partner("adaptive, pressure goal, k = 2", ["adaptive, stress goal",
    ...         "adaptive, pressure goal", "adaptive, pressure goal, k = 2"])
    'adaptive, stress goal'
    """
    others = [m for m in methods if method_base(m) != method_base(method)]
    same = [m for m in others if method_order(m) == method_order(method)]
    return (same or others or [None])[0]


def pressure_distance(candidate: dict, reference: dict, window: float | None = None
                      ) -> float:
    """The relative L2 distance of two solutions' pressures on Gamma_C (on |x| <=
    ``window``; :func:`ngdual.verification.overkill.pressure_errors`)."""
    from ...verification.overkill import pressure_errors

    return pressure_errors(candidate, reference, window)["pressure_rel"]


def nearest_corners(name: str, names: list[str], distance) -> tuple[str, str] | None:
    """The two of ``names`` nearest to ``name`` by ``distance(a, b)``, nearest first: the
    other corners of its three-cornered hat. The nearest solutions are the most accurate
    ones, so that the hat subtracts squares of small distances (a corner far from the
    truth makes it the difference of two large, nearly equal squares). A solution at
    distance 0 is the same solution (two runs that stopped on the same mesh), no
    independent corner; the two corners must differ from each other too. None without
    two such corners.

    >>> at = {"a": 0.0, "b": 5.0, "c": 1.0, "d": 2.0, "e": 0.0, "f": 1.0}
    >>> nearest_corners("a", list(at), lambda x, y: abs(at[x] - at[y]))
    ('c', 'd')
    """
    others = sorted((distance(name, m), m) for m in names if m != name)
    first = next((m for d, m in others if d > 0), None)
    second = next((m for d, m in others if d > 0 and m != first
                   and distance(first, m) > 0), None)
    return (first, second) if second is not None else None


def hat_checks(checks: list[dict], runs: dict, uniform: tuple[dict, dict] | None,
                lam: float, mu: float, window) -> None:
    """Add to every run's check, per measure, ``hat``: its last step's error by
    :func:`three_cornered_hat` (the distances under ``hat_distances``, the corners under
    ``corners``); where the run's Richardson estimate is missing, the hat's becomes its
    ``overkill_error`` (``estimate`` says which). The corners of sigma: the last step of
    its :func:`partner` run and the finest uniform solution ``uniform``; of the pressure,
    whose distances cost little: the two :func:`nearest_corners` among the other runs'
    last steps and ``uniform``.

    A hat is no own error where another solution's own Richardson estimate refutes it:
    the distances are a norm's, so e_a >= d_ab - e_b (e_b counted twice: Richardson
    estimates err too, :data:`RICHARDSON_SAFETY`), and a hat below that bound
    (``hat_bound``, the largest such bound: from the corners for sigma, from every run
    with a Richardson estimate for the pressure) rests on errors that are not orthogonal
    (:func:`hat_bound`); the run then has no own error (``hat_refuted``)."""
    from ...verification.overkill import true_errors

    if uniform is None:
        return
    by_size = sorted(runs, key=lambda m: -runs[m][-1][0]["ndof"])
    last = {**{m: runs[m][-1][1] for m in runs}, "uniform": uniform[1]}
    # the runs' own errors by Richardson, read before any hat stands in for one
    richardson = {(c["method"], m): c[m]["overkill_error"] for c in checks
                  for m in TRUE_MEASURES if c[m]["estimate"] == "Richardson"}

    # the same pairs come back in later checks (the partner, the finest uniform level)
    @functools.cache
    def sigma(a: str, b: str) -> float:
        x, y = last[a], last[b]
        if len(x["triangles"]) < len(y["triangles"]):
            x, y = y, x
        return measures(true_errors(y, x, lam, mu, window))["sigma_energy"]

    @functools.cache
    def pressure(a: str, b: str) -> float:
        return pressure_distance(last[a], last[b], window)

    for check in checks:
        name = check["method"]
        other = partner(name, by_size)
        corners = {"sigma_energy": other and (other, "uniform"),
                   "pressure": nearest_corners(name, list(last), pressure)}
        for measure, distance in (("sigma_energy", sigma), ("pressure", pressure)):
            if corners[measure] is None:
                continue
            b, c = corners[measure]
            d_ab, d_ac, d_bc = distance(name, b), distance(name, c), distance(b, c)
            hat = three_cornered_hat(d_ab, d_ac, d_bc)
            # sigma's distances cost a field integral each: its corners bound it; the
            # pressure's cost little: every run with a Richardson estimate does
            bounding = {m: distance(name, m) for m in runs if m != name
                        and (m, measure) in richardson} if measure == "pressure" else {}
            bounding.update({b: d_ab, c: d_ac})
            bound = hat_bound(bounding, {m: richardson.get((m, measure)) for m in bounding})
            entry = check[measure]
            entry.update(hat=hat, corners=[b, c], hat_bound=bound,
                         hat_distances={"to_b": d_ab, "to_c": d_ac, "b_to_c": d_bc},
                         hat_refuted=hat is not None and hat < bound)
            if entry["overkill_error"] is None and hat is not None and hat >= bound:
                entry.update(overkill_error=hat, estimate="three-cornered hat")


def hat_bound(distances: dict[str, float], own: dict[str, float | None]) -> float:
    """The least error of a solution a that the triangle inequality allows, e_a >= d_ab -
    e_b, from its ``distances`` to other solutions b and their ``own`` errors (Richardson;
    None: unknown, no bound), each counted at :data:`RICHARDSON_SAFETY` times its value;
    0 where nothing bounds it.

    The three-cornered hat assumes orthogonal errors; the pressure goal's runs of the
    three orders refine alike and their errors share a part. On the flat punch's core the
    order-2 pressure run's hat from the order-1 and order-0 pressure runs is 0.0070 %
    (distances 0.020 and 0.021 %), while the stress goal of order 1, Richardson 0.019 % (its
    own hat 0.022 %), lies 0.060 % from it: the error is at least 0.060 - 2 x 0.019 =
    0.022 %, three times the hat.

    >>> hat_bound({"b": 0.75, "c": 0.5}, {"b": 0.125, "c": None})
    0.5
    >>> hat_bound({"b": 0.3}, {"b": 0.5})
    0.0
    """
    return max([0.0] + [d - RICHARDSON_SAFETY * own[m] for m, d in distances.items()
                        if own.get(m) is not None])
