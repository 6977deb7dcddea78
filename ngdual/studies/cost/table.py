"""The time-to-accuracy table: per measure, target and method the least wall time to reach it."""

from __future__ import annotations

# the targets of the relative true errors
TARGETS = (0.05, 0.02, 0.01)
# the measures of the table, as the axes of its figures name them
MEASURES = {"pressure": "pressure error on $\\Gamma_C$ (rel. $L^2$) [-]",
            "sigma_energy": "error of $\\sigma$ (rel. compliance norm) [-]"}


def time_to_accuracy(points: list[dict], measure: str, target: float) -> dict | None:
    """The point of least time whose error ``measure`` is at most ``target``.

    >>> time_to_accuracy([{"time_s": 2.0, "e": 0.01}, {"time_s": 1.0, "e": 0.03}], "e", 0.02)
    {'time_s': 2.0, 'e': 0.01}
    """
    hits = [p for p in points if p.get(measure) is not None and p[measure] <= target]
    return min(hits, key=lambda p: p["time_s"]) if hits else None


def accuracy_rows(rows: list[dict], references: dict, measures=tuple(MEASURES)) -> list[dict]:
    """Least time (and its unknowns) to each target per measure and method of one scene's
    solutions ``rows`` (:func:`~.errors.true_errors_of`), with the method's order k and
    multiplier family; ``resolved`` whether the reference of the measure resolves the target
    (``references``: per measure, its ``resolves``); ``failed`` the first failure of the
    method's solves."""
    table = []
    for measure in measures:
        resolves = references[measure]["resolves"]
        for target in TARGETS:
            for method in dict.fromkeys(r["method"] for r in rows):
                solves = [r for r in rows if r["method"] == method]
                hit = time_to_accuracy([r for r in solves if r["status"] == "ok"],
                                       measure, target)
                failed = next((f"{r['status']}: {r.get('message', '')}" for r in solves
                               if r["status"] != "ok"), None)
                table.append({"measure": measure, "target": target, "method": method,
                              "order": solves[0]["order"],
                              "multipliers": solves[0]["multipliers"],
                              "time_s": hit and hit["time_s"], "ndof": hit and hit["ndof"],
                              "level_or_step": hit and hit["level_or_step"],
                              "resolved": target in resolves, "failed": failed})
    return table
