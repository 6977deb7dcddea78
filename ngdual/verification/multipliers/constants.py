"""The discrete inf-sup and continuity constants of the boundary multipliers of order k
against the stresses of PEERS_k or AFW_k (:func:`constants`), and their table.

The inf-sup constant is

    beta_h = inf_mu sup_{tau in X_h} d(mu, tau) / (|mu|_{1/2,h} ||tau||_{H(div)}),

and the continuity constant gamma_h the same with sup sup, in the norm |.|_{1/2,h} of
:mod:`ngdual.verification.multipliers.pairing`. beta_h and gamma_h both bounded say that
this discrete dual norm is uniformly equivalent to |.|_{1/2,h}: the pairing is stable in the
norms of the analysis (Lemma 3.28: H(div) on the stresses), not in a weaker mesh-dependent
one. docs/theory/order.md derives it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ... import peers
from ...mesh import build_mesh
from ..infsup import dense_singular_values, gram_matrix
from ..order import unit_square
from .bases import Part, model_parts, multiplier_basis, scene_parts
from .pairing import pair


@dataclass
class Stresses:
    """The stress family of order k on a mesh as a product space (for
    :func:`ngdual.verification.infsup.gram_matrix`)."""

    fes: ngs.FESpace
    names: list[str]

    @classmethod
    def of(cls, mesh: ngs.Mesh, family: str, order: int) -> Stresses:
        spaces = peers.family_spaces(mesh, family, order)
        names = list(spaces)
        return cls(ngs.FESpace([spaces[n] for n in names]), names)

    @property
    def sigma(self) -> np.ndarray:
        ranges = [self.fes.Range(self.names.index(c)) for c in peers.STRESS if c in self.names]
        return np.concatenate([np.arange(r.start, r.stop) for r in ranges])


def constants(mesh: ngs.Mesh, parts: list[Part], multipliers: str = "coarse", order: int = 0,
              ratio: int = 2, family: str = "peers") -> dict:
    """beta_h and gamma_h of ``multipliers`` of order k on ``parts`` against the stresses
    of ``family`` (PEERS_k or AFW_k), H(div) on the stresses and |.|_{1/2,h} on the
    multipliers (:func:`ngdual.verification.infsup.dense_singular_values`).

    Returns
    -------
    dict
        ``multipliers``, ``ratio``, ``family``, ``order``, ``multiplier_dofs``,
        ``stresses``, ``beta``, ``gamma`` and ``seconds``.
    """
    start = time.perf_counter()
    stresses = Stresses.of(mesh, family, order)
    pairings = [pair(multiplier_basis(mesh, part, multipliers, order, ratio), part,
                     stresses.fes, stresses.names, order) for part in parts]
    s = stresses.sigma
    B = sp.hstack([p.B for p in pairings], format="csr")[s].toarray()
    X = gram_matrix(stresses)[s][:, s]
    beta, gamma = dense_singular_values(X, B, sla.block_diag(*[p.norm for p in pairings]),
                                        indices=(0, -1))
    return {"multipliers": multipliers, "ratio": ratio, "family": family, "order": order,
            "multiplier_dofs": int(B.shape[1]), "stresses": int(X.shape[0]),
            "beta": beta, "gamma": gamma, "seconds": time.perf_counter() - start}


def scene_constants(scene, level: int, multipliers: str = "coarse", order: int = 0,
                    ratio: int = 2, family: str = "peers") -> dict:
    """:func:`constants` on Gamma_N and Gamma_C of ``scene`` at mesh ``level``."""
    mesh = build_mesh(scene.geometry, level)
    return {"scene": scene.name, "level": level,
            **constants(mesh, scene_parts(scene, mesh), multipliers, order, ratio, family)}


CHOICES = (("coarse", 2), ("coarse", 1), ("facet", 1))


def table(orders=(0, 1, 2), levels=(1, 2, 3, 4), choices=CHOICES, family: str = "peers"
          ) -> list[dict]:
    """beta_h and gamma_h of every (multipliers, ratio) of ``choices``, order and level on the
    model problem (:func:`unit_square`, :func:`model_parts`), with ``h``."""
    rows = []
    for multipliers, ratio in choices:
        for order in orders:
            for level in levels:
                rows.append({"level": level, "h": 2.0 ** -(level + 1),
                             **constants(unit_square(level), model_parts(), multipliers,
                                         order, ratio, family)})
    return rows


def format_table(rows: list[dict]) -> str:
    """The table as Markdown: one line per stress family, multipliers, h~/h and k; beta_h
    (gamma_h) per level."""
    levels = sorted({r["level"] for r in rows})
    keys = list(dict.fromkeys((r["family"], r["multipliers"], r["ratio"], r["order"])
                              for r in rows))
    cell = {(r["family"], r["multipliers"], r["ratio"], r["order"], r["level"]): r
            for r in rows}
    lines = ["| stresses | multipliers | h~/h | k | "
             + " | ".join(f"level {lv}" for lv in levels) + " |",
             "|---|---|---|---|" + "---|" * len(levels)]
    for key in keys:
        cells = [f"{cell[key + (lv,)]['beta']:.4f} ({cell[key + (lv,)]['gamma']:.2f})"
                 if key + (lv,) in cell else "" for lv in levels]
        lines.append(f"| {key[0].upper()} | {key[1]} | {key[2]} | {key[3]} | "
                     + " | ".join(cells) + " |")
    return "\n".join(lines)
