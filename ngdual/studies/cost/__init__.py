"""``ngdual cost SCENE``: what accuracy costs on any scene, within a budget of wall time.

Every method -- ngdual's PEERS_k at k = 0, 1, 2, uniform and adaptive with either goal, the
primal peers P1 / P2, uniform and adaptive -- runs within its share of the budget, cheap
steps first; every solution is measured against references that measure their own error;
the result is the least wall time to 5, 2 and 1 % true error per method.
:mod:`~.methods` (the methods and their sweep tasks), :mod:`~.budget` (the shares),
:mod:`~.errors` (the true errors and the references, which the six-problem work-precision
study of ``ngdual figures`` measures with too), :mod:`~.table` (time to accuracy),
:mod:`~.output` (the text table and the figure), :mod:`~.run` (:func:`cost`).
"""

from .run import DEFAULT_BUDGET_S, CostResult, NoReference, cost

__all__ = ["DEFAULT_BUDGET_S", "CostResult", "NoReference", "cost"]
