"""The own error of an adaptive run's last step, per measure of the true-error studies:
Richardson (:data:`EXTRAPOLATION`) from the distances of the two steps before it
(:func:`run_check`), or from its steps solved again by PEERS_k (:func:`order_reference`);
none where the run stalls or its distances fall faster than any rate of the method."""

from __future__ import annotations

import math

from .numbers import aligned_richardson_check, richardson_check
from .plan import REFERENCE_ORDER

# measures of the true-error studies: key -> (what, how it is made relative), and the
# adaptive run whose last step is the reference of each
TRUE_MEASURES = {"pressure": "relative L2 error of the contact pressure on Gamma_C",
                 "sigma_energy": "relative compliance-norm error of sigma"}
# a run's own error per measure: sigma's errors are near orthogonal in the compliance norm
# (Galerkin), the pressure's need not be (worst case: aligned)
EXTRAPOLATION = {"pressure": aligned_richardson_check, "sigma_energy": richardson_check}
# an adaptive run whose steps grow the unknowns by less than this factor is stalled: its
# estimate is held by a few triangles it cannot improve, and its steps are no sequence to
# extrapolate from
STALLED = 1.3


def fastest_reduction(growth: float, order: int) -> float:
    """The least error ratio e_L / e_(L-1) a step of PEERS_``order`` that multiplies the
    unknowns by ``growth`` can attain: growth^-(k + 1), twice the best rate in the unknowns
    (h^(k+1) ~ N^-(k+1)/2) of sigma and of its normal trace. A Richardson ratio below it is
    no rate but a measure that the last step left unchanged (the stress goal refining the
    corners once the contact zone is resolved: the pressure moved by 3 % and then by
    0.006 %, r = 0.002), and gives no own error.

    >>> round(fastest_reduction(2.0, 0), 3), round(fastest_reduction(1.5, 2), 3)
    (0.5, 0.296)
    """
    return growth ** -(order + 1)


def within_rates(check: dict, unknowns: list[int], order: int) -> dict:
    """A Richardson ``check`` without its own error where its ratio is faster than any rate
    of the method over the last step of ``unknowns`` (:func:`fastest_reduction`)."""
    if check["r"] is not None and check["r"] < fastest_reduction(unknowns[-1] / unknowns[-2],
                                                                 order):
        return {**check, "overkill_error": None}
    return check


def measures(errors: dict) -> dict:
    """The relative errors plotted (:data:`TRUE_MEASURES`) and the absolute total error
    e = (||sigma - sigma_ref||^2 + ||u - u_ref||^2 + ||eta - eta_ref||^2)^(1/2) (L2; div sigma
    has no error when f = 0) that the estimator is compared with."""
    return {"pressure": errors.get("pressure_rel"),
            "pressure_max": errors.get("pressure_max"),
            "pressure_l2": errors.get("pressure_l2"),
            "sigma_energy": errors["sigma_energy"] / errors["sigma_energy_norm"],
            "e_true": math.sqrt(sum(errors.get(k, 0.0) ** 2 for k in ("sigma", "u", "eta")))}


def run_check(run: list[tuple[dict, dict]], lam: float, mu: float, window) -> dict:
    """How accurate an adaptive run's last step is, per measure: Richardson
    (:data:`EXTRAPOLATION`) from the distances of the two steps before it (nested meshes:
    exact integrals), ``None`` where
    the run stalled (a step before the last grew the unknowns by less than
    :data:`STALLED`), the distances do not fall or fall faster than any rate of the
    method (:func:`fastest_reduction`)."""
    from ...verification.overkill import true_errors

    (last_row, last), before = run[-1], run[-3:-1]
    out = {"method": last_row["method"], "step": last_row["level_or_step"],
           "ndof": last_row["ndof"], "elements": last_row["elements"],
           "time_s": last_row["time_s"], "relative_estimate": last_row["relative_estimate"]}
    steps = [r["ndof"] for r, _ in run[-3:]]
    stalled = len(steps) < 3 or min(b / a for a, b in zip(steps, steps[1:])) < STALLED
    d = [measures(true_errors(arrays, last, lam, mu, window)) for _, arrays in before]
    for measure in TRUE_MEASURES:
        check = ({"r": None, "rate": None, "overkill_error": None} if stalled
                 else EXTRAPOLATION[measure](*(e[measure] for e in d)))
        check = within_rates(check, steps, last_row["order"])
        out[measure] = {"d_last-2": d[0][measure] if len(d) == 2 else None,
                        "d_last-1": d[-1][measure] if d else None, **check,
                        "estimate": None if check["overkill_error"] is None else "Richardson"}
    out["stalled"] = stalled
    return out


def distance(candidate: dict, reference: dict, lam: float, mu: float,
             window: float | None = None) -> dict:
    """:func:`ngdual.verification.overkill.true_errors` of ``candidate`` against
    ``reference``, the fields integrated on the finer of the two meshes (a candidate finer
    than the reference is exact on its own triangles, not on the reference's); the norms
    are the reference's."""
    from ...verification.overkill import field_errors, true_errors

    out = true_errors(candidate, reference, lam, mu, window)
    if len(candidate["triangles"]) > len(reference["triangles"]):
        swapped = field_errors(reference, candidate, lam, mu)
        out.update({k: v for k, v in swapped.items() if not k.endswith("_norm")})
    return out


def order_reference(run: list[tuple[dict, dict]], lam: float, mu: float
                    ) -> tuple[dict, dict] | None:
    """The sigma reference of an adaptive run's steps solved again by PEERS_k (k =
    :data:`~ngdual.studies.figures.plan.REFERENCE_ORDER`, arrays ``order_*``): the last such
    step's fields and their own error, Richardson (:data:`EXTRAPOLATION`, orthogonal) from
    the two such steps before it (nested meshes: exact distances); None with fewer than
    three such steps, and no own error where Richardson's ratio is faster than any rate
    (:func:`fastest_reduction`). Returns (its check, with the keys of :func:`run_check`'s
    measures, and its sample arrays)."""
    steps = [(row, {"vertices": a["vertices"], "triangles": a["triangles"],
                    **{n: a[f"order_{n}"] for n in ("sigma", "u", "eta")}}, int(a["order_ndof"]))
             for row, a in run if "order_sigma" in a]
    if len(steps) < 3:
        return None
    (row, last, ndof), before = steps[-1], steps[-3:-1]
    d = [measures(distance(arrays, last, lam, mu))["sigma_energy"] for _, arrays, _ in before]
    check = within_rates(EXTRAPOLATION["sigma_energy"](*d), [before[-1][2], ndof],
                          REFERENCE_ORDER)
    return ({"method": f"{row['method']}, PEERS_{REFERENCE_ORDER}", "step": row["level_or_step"],
             "ndof": ndof, "elements": row["elements"], "d_last-2": d[0], "d_last-1": d[1],
             **check, "estimate": None if check["overkill_error"] is None
             else f"Richardson, PEERS_{REFERENCE_ORDER}"}, last)
