"""How a cost study spends its budget of wall time: shares of the workers' time per method.

A method is one sweep task that stops itself when its next step would end past its share
(:class:`~ngdual.studies.sweep.timing.Share`): the cheap runs (coarse levels, the first
adaptive steps) come first in every method. :data:`EVALUATION_SHARE` of the budget is kept
for the true errors and the outputs; of the workers' time left, the reference runs (the
adaptive runs of the highest order, both goals) take :data:`REFERENCE_SHARE`, the other
methods share the rest evenly; no share exceeds the time left, since a task runs on one
worker. The reference runs stop at :func:`reference_elements` triangles, so that measuring
every solution against their last step fits in the time kept for it.
"""

from __future__ import annotations

from .methods import Method

# the share of the budget kept for the true errors and the outputs
EVALUATION_SHARE = 0.25
# the share of the workers' time the reference runs take
REFERENCE_SHARE = 0.5
# the seconds of a true error per quadrature point of the reference (six per triangle):
# 0.8e-6 to 2.2e-6 s on one core of a 2-core Xeon (references of 27 000 and 53 000
# triangles), the candidate's own triangles included
SECONDS_PER_POINT = 2e-6
# the solutions a method's run yields within its share, about
SOLUTIONS_PER_METHOD = 6
# the smallest budget worth planning: a few coarse solves per method
MIN_BUDGET_S = 10.0


def reference_methods(chosen: list[Method]) -> list[Method]:
    """The runs that give the references: the adaptive runs of the highest order, both
    goals."""
    top = max(m.order for m in chosen if m.kind == "adaptive")
    return [m for m in chosen if m.kind == "adaptive" and m.order == top]


def shares(chosen: list[Method], wall_s: float, workers: int) -> dict[Method, float]:
    """The seconds of wall time each method of ``chosen`` may take, when ``wall_s`` seconds
    of the budget are left and ``workers`` tasks run at once.

    >>> from ngdual.studies.cost.methods import methods
    >>> s = shares(methods((0, 1)), 100.0, 2)
    >>> round(s[Method("adaptive", 1, "pressure")], 1), round(s[Method("uniform", 0)], 1)
    (37.5, 9.4)
    """
    compute = wall_s * (1 - EVALUATION_SHARE)
    total = compute * workers
    references = reference_methods(chosen)
    others = [m for m in chosen if m not in references]
    reference = min(compute, REFERENCE_SHARE * total / len(references))
    rest = (total - reference * len(references)) / max(len(others), 1)
    return {m: reference if m in references else min(compute, rest) for m in chosen}


def reference_elements(chosen: list[Method], wall_s: float) -> int:
    """The triangles of a reference whose true errors against every solution fit in the
    :data:`EVALUATION_SHARE` of ``wall_s`` (most of it: the references' own errors and the
    outputs take the rest)."""
    seconds = 0.6 * EVALUATION_SHARE * wall_s
    solutions = SOLUTIONS_PER_METHOD * len(chosen)
    return max(int(seconds / (solutions * 6 * SECONDS_PER_POINT)), 100)
