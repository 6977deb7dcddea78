"""Numbers derived from sweep records (pure functions): checks, errors, the best run.

The rates and the reference norms live in :mod:`ngdual.rates`.
"""

from __future__ import annotations

import math

from ...rates import total_error


def require(record: dict | None, what: str) -> dict:
    """``record`` if its task finished with status ok, else a clear error naming it."""
    if record is None:
        raise RuntimeError(f"{what}: no record (the task did not finish; see run.json)")
    if record.get("status") != "ok":
        raise RuntimeError(f"{what}: {record.get('status')}: {record.get('message', '')}")
    return record


def outcome(record: dict | None) -> str:
    """One line on how a solve ended: iterations, or the failure and its message."""
    if record is None:
        return "missing"
    if record["status"] != "ok":
        return f"{record['status']}: {record.get('message', '')[:200]}"
    return (f"ok, outer {record['iterations']['outer']}, inner {record['iterations']['inner']}, "
            f"{record['timings_s']['total']:.1f} s")


def errors(records: list[dict], reference: dict) -> list[dict]:
    """e_i(q) per quantity and e_tot of (3.124) for each record (None if it has no norms)."""
    out = []
    for r in records:
        if not r or "norms" not in r:
            out.append(None)
            continue
        per, tot = total_error(r["norms"], reference)
        out.append({"errors": per, "e_tot": tot})
    return out


def iterations_key(record: dict) -> tuple:
    """The fewest iterations win: total inner then outer (nested), outer (Uzawa), then time."""
    it = record["iterations"]
    return (it.get("inner", 0) or it.get("outer", 0), it.get("outer", 0),
            record["timings_s"]["solve"])


def best(records: dict) -> tuple | None:
    """The key of the converged record with the fewest iterations (see :func:`iterations_key`)."""
    ok = {k: r for k, r in records.items() if r and r.get("status") == "ok"}
    return min(ok, key=lambda k: iterations_key(ok[k])) if ok else None


def richardson_check(d_coarse: float, d_fine: float) -> dict:
    """The overkill's own error from the distances d of the two levels below it (L-2, L-1)
    to it, for errors e_k = C r^k orthogonal between levels (Galerkin orthogonality:
    d_k^2 = e_k^2 - e_L^2): (d_{L-2} / d_{L-1})^2 = (1 + r^2) / r^2, so
    r^2 = 1 / (ratio^2 - 1) and e_L = d_{L-1} r / (1 - r^2)^(1/2). ``rate`` = -log2 r (the
    order in h); None where the distances do not decrease (ratio <= 1).

    >>> round(richardson_check(5 ** 0.5, 1.0)["overkill_error"], 12)  # r = 1/2
    0.57735026919
    """
    if not (d_coarse and d_fine) or d_coarse <= d_fine:
        return {"r": None, "rate": None, "overkill_error": None}
    r = 1 / math.sqrt((d_coarse / d_fine) ** 2 - 1)
    if r >= 1:
        return {"r": r, "rate": -math.log2(r), "overkill_error": None}
    return {"r": r, "rate": -math.log2(r), "overkill_error": d_fine * r / math.sqrt(1 - r * r)}


def aligned_richardson_check(d_coarse: float, d_fine: float) -> dict:
    """The overkill's own error as :func:`richardson_check` does, for errors e_k = C q^k
    that are not orthogonal but, worst case, aligned (d_k = e_k - e_L; a pressure on
    Gamma_C): d_{L-2} / d_{L-1} = 1 + 1 / q, e_L = d_{L-1} q / (1 - q). Same keys; None
    where the distances fall by less than 2x (q >= 1: no geometric sequence).

    >>> round(aligned_richardson_check(3.0, 1.0)["overkill_error"], 12)  # q = 1/2
    1.0
    """
    if not (d_coarse and d_fine) or d_coarse <= 2 * d_fine:
        return {"r": None, "rate": None, "overkill_error": None}
    q = 1 / (d_coarse / d_fine - 1)
    return {"r": q, "rate": -math.log2(q), "overkill_error": d_fine * q / (1 - q)}

