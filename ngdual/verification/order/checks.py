"""Whether a study of order k reaches its targets: the observed orders of a quantity on its
last two levels (:func:`order_check`) and an exact contact set (:func:`set_check`)."""

from __future__ import annotations

ORDER_SLACK = 0.15    # the observed order of sigma lies within this of k + 1
SET_TOLERANCE = 1e-12    # the contact set's error (a length) counted as exact


def order_check(rows: list[dict], quantity: str = "sigma",
                expected: float | None = None) -> dict:
    """Whether the observed orders of ``quantity`` on the last two levels of a study of one
    order k (rows of :func:`~ngdual.verification.order.convergence_study` or
    :func:`~ngdual.verification.order.contact_study`) reach their target.

    Without ``expected`` the target is k + 1 and the orders must lie within
    :data:`ORDER_SLACK` of it (rule "within"); with it, an asymptotic prediction
    (:func:`~ngdual.verification.order.expected_order`) that the orders on coarse levels may
    still exceed, and they must not fall more than :data:`ORDER_SLACK` below it (rule "at least").

    >>> rows = [{"order": 1, "sigma_order": None}, {"order": 1, "sigma_order": 2.05},
    ...         {"order": 1, "sigma_order": 1.98}]
    >>> order_check(rows)["passed"]
    True
    >>> rows = [{"order": 2, "sigma_order": r} for r in (None, 2.92, 2.79)]
    >>> order_check(rows)["passed"], order_check(rows, expected=2.5)["passed"]
    (False, True)
    """
    target = rows[0]["order"] + 1 if expected is None else expected
    observed = [r[quantity + "_order"] for r in rows[-2:] if r[quantity + "_order"] is not None]
    if expected is None:
        met = all(abs(a - target) <= ORDER_SLACK for a in observed)
    else:
        met = all(a >= target - ORDER_SLACK for a in observed)
    return {"quantity": quantity, "target": target,
            "rule": "within" if expected is None else "at least", "observed": observed,
            "passed": bool(observed) and met}


def set_check(rows: list[dict]) -> dict:
    """Whether the contact set is exact (its error below :data:`SET_TOLERANCE`) on the last
    two levels of a :func:`~ngdual.verification.order.contact_study`, once h is below the
    set's feature size.

    >>> set_check([{"contact_set": 4.0}, {"contact_set": 0.0}, {"contact_set": 0.0}])
    {'errors': [0.0, 0.0], 'passed': True}
    """
    errors = [r["contact_set"] for r in rows[-2:]]
    return {"errors": errors, "passed": all(e <= SET_TOLERANCE for e in errors)}
