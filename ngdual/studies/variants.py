"""Solver variants, spelled as scene overrides: what ``ngdual bench`` times and the figures run.

An override is ``section.key=value`` with the value a TOML literal (strings quoted), as
``ngdual solve --set`` takes it; :func:`setting` is the one place that spells one. The
figures of the discrete solutions use the default solver (``solver.method = "auto"``, the
same discrete solution as the thesis' algorithms, to round-off); the studies of the
algorithms themselves run the thesis' Uzawa iterations (:data:`UZAWA`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass


def setting(key: str, value) -> str:
    """The override setting ``key`` to ``value`` (a TOML literal: strings quoted).

    >>> setting("solver.method", "uzawa"), setting("solver.rho", 1.1)
    ('solver.method="uzawa"', 'solver.rho=1.1')
    """
    return f"{key}={json.dumps(value)}"


@dataclass(frozen=True)
class Variant:
    """A solver variant: its name, its overrides of the scene and what it is."""

    name: str
    overrides: tuple[str, ...] = ()
    description: str = ""


UZAWA = setting("solver.method", "uzawa")
# The steps with the fewest iterations in a scan of Example 3.46 on levels 3-5 (rho in
# 0.8..1.9, rho1 in 0.8..1.5, rho2 in 1..1.9): rho = 1.1 (h12 metric, Algorithm 3.38:
# 14 steps instead of 16), rho1 = 1.2 and rho2 = 1.8 (nested Uzawa, rho2 relative to the
# computed stability bound of the nu step, which must stay below 2: 54 outer steps instead
# of 102 on level 4, the count still growing with the level).
TUNED = {"rho": 1.1, "rho1": 1.2, "rho2": 1.8}

VARIANTS = {v.name: v for v in (
    Variant("default", (), "solver.method = auto: active set / semismooth Newton on Gamma_C "
                           "after one Cholesky factorisation"),
    Variant("active-set", (setting("solver.method", "active-set"),),
            "the active-set solver (ngdual.solvers.active_set)"),
    Variant("uzawa", (UZAWA,), "Algorithm 3.38 / 3.41 (Remark 3.45), H^1/2 metric, friction "
                               "outside, Jacobi metric for nu; the scene's steps rho = 1"),
    Variant("uzawa-tuned", (UZAWA, *(setting(f"solver.{k}", v) for k, v in TUNED.items())),
            "Uzawa with the steps of TUNED"),
)}
