"""The methods whose cost of accuracy is measured, and the sweep task each one is.

ngdual's PEERS_k at the orders k = 0 (the thesis' method, its coarse multipliers), 1 and 2
(the facet P_k multipliers on the fine edges) with uniform refinement and with the adaptive
loop aiming at either goal (a tolerance run of :func:`ngdual.adapt`); the primal peer
(:mod:`ngdual.studies.primal_peer`: P1 and P2 displacements, Nitsche contact) with uniform
refinement and adapting by Kelly's indicator. A :class:`Method` names itself as the
work-precision study does (:func:`order_method`, "primal P2, adaptive") and is one sweep
task within a wall-time share (:meth:`Method.task`).
"""

from __future__ import annotations

from dataclasses import dataclass

from ...loop_defaults import STEPS_TOL, THETA_TOL
from ..sweep import Task
from ..variants import setting

GOALS = ("stress", "pressure")
PEER_ORDERS = (1, 2)
# the tolerance of the adaptive runs: far below every target and every reference's own
# error, so that the share of the budget stops a run, not its estimate
ADAPT_TOL = 1e-6
# the adaptive peer's pressure samples: every Gamma_C edge split in this many parts (its
# edges are fine where the pressure varies)
PEER_SUBDIVISIONS = 4


def order_overrides(order: int, family: str = "facet") -> tuple[str, ...]:
    """The settings of PEERS_``order`` with the multipliers ``family`` ("facet" or
    "coarse"; none at order 0: the thesis' method with its coarse multipliers)."""
    if order == 0:
        return ()
    return (setting("discretisation.order", order),
            setting("discretisation.multipliers", family))


def order_method(method: str, order: int, family: str = "facet") -> str:
    """The name of ``method`` ("uniform", "adaptive, pressure goal") at ``order`` with the
    multipliers ``family``.

    >>> order_method("uniform", 2), order_method("uniform", 1, "coarse")
    ('uniform, k = 2', 'uniform, k = 1, coarse')
    """
    if order == 0:
        return method
    return f"{method}, k = {order}" + (", coarse" if family == "coarse" else "")


def method_order(method: str) -> tuple[int, str]:
    """The order k and the multiplier family of a method named by :func:`order_method`;
    a primal peer: the degree of its displacements and its Nitsche contact.

    >>> method_order("uniform"), method_order("uniform, k = 1, coarse")
    ((0, 'coarse'), (1, 'coarse'))
    >>> method_order("primal P2, adaptive")
    (2, 'Nitsche')
    """
    if method.startswith("primal P"):
        return int(method.removeprefix("primal P")[0]), "Nitsche"
    _, _, tail = method.partition(", k = ")
    if not tail:
        return 0, "coarse"
    order, _, family = tail.partition(", ")
    return int(order), family or "facet"


def method_base(method: str) -> str:
    """The method without its order and multipliers ("adaptive, stress goal")."""
    return method.partition(", k = ")[0]


def is_peer(method: str) -> bool:
    """Whether ``method`` is the primal peer's, uniform or adaptive."""
    return method.startswith("primal")


@dataclass(frozen=True)
class Method:
    """One method of a cost study: ``kind`` "uniform" or "adaptive" (ngdual's PEERS_k,
    ``order`` k, the adaptive loop aiming at ``goal``), "peer" or "adaptive peer" (the
    primal peer of degree ``order``)."""

    kind: str
    order: int
    goal: str | None = None

    @property
    def name(self) -> str:
        """The name the work-precision study gives the method.

        >>> Method("adaptive", 1, "pressure").name, Method("adaptive peer", 2).name
        ('adaptive, pressure goal, k = 1', 'primal P2, adaptive')
        """
        if self.kind == "uniform":
            return order_method("uniform", self.order)
        if self.kind == "adaptive":
            return order_method(f"adaptive, {self.goal} goal", self.order)
        return f"primal P{self.order}" + (", adaptive" if self.kind == "adaptive peer" else "")

    def task(self, scene: str, overrides: list[str], share_s: float,
             window: tuple[float, float] | None = None,
             max_elements: int | None = None) -> Task:
        """The sweep task of the method on ``scene`` (a shipped name or a TOML path) with
        ``overrides``, within ``share_s`` seconds of wall time; an adaptive run of ngdual
        measures the pressure goal on ``window`` (lo <= x <= hi) and stops at
        ``max_elements`` triangles."""
        share = round(float(share_s), 1)
        label = f"{self.name} ({share:g} s)"
        if self.kind in ("uniform", "peer"):
            peer = {"peer_order": self.order} if self.kind == "peer" else {}
            own = order_overrides(self.order) if self.kind == "uniform" else ()
            return Task("uniform", {"scene": scene, "share_s": share,
                                    "overrides": [*overrides, *own], **peer}, label, share)
        if self.kind == "adaptive peer":
            return Task("peer_adapt", {"scene": scene, "order": self.order, "share_s": share,
                                       "overrides": list(overrides),
                                       "subdivisions": PEER_SUBDIVISIONS}, label, share)
        windowed = window is not None and self.goal == "pressure"
        return Task("adapt", {"scene": scene, "marking": "dorfler", "theta": THETA_TOL,
                              "steps": STEPS_TOL, "level": None,
                              "overrides": [*overrides, *order_overrides(self.order)],
                              "snapshots": [], "samples": True, "max_elements": max_elements,
                              "goal": self.goal, "tol": ADAPT_TOL,
                              "window": list(window) if windowed else None,
                              "share_s": share}, label, share)


def methods(orders=(0, 1, 2), contact: bool = True) -> list[Method]:
    """The methods of a cost study: at every order of ``orders`` uniform refinement and the
    adaptive loop with each goal (the pressure goal only with ``contact``), then the primal
    peers P1 and P2, uniform and adaptive."""
    goals = GOALS if contact else ("stress",)
    out = []
    for order in orders:
        out += [Method("uniform", order), *(Method("adaptive", order, g) for g in goals)]
    for order in PEER_ORDERS:
        out += [Method("peer", order), Method("adaptive peer", order)]
    return out
