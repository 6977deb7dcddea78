"""A warm start: the contact multipliers of a solution on another mesh of the same Gamma_C.

The adaptive loop solves on a refined mesh starting from the previous step's contact set:
:class:`ContactStart` holds that solution's lambda_n, lambda_t on its fine Gamma_C edges and
evaluates them at the new mesh's control points.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..solution import Solution

CANDIDATE_EDGES = 4        # a warm start's edges searched per point, by midpoint distance


@dataclass(frozen=True)
class ContactStart:
    """The contact multipliers of a solution on another (coarser) mesh of the same Gamma_C,
    to start the contact iteration from (the adaptive loop's warm start).

    ``segments`` (n, 2, 2) are the fine Gamma_C edges of that mesh, ``lam_n`` and ``lam_t``
    (n, 2) the multipliers at their ends: P1 on h~, so linear on every fine edge.
    """

    segments: np.ndarray
    lam_n: np.ndarray
    lam_t: np.ndarray

    @classmethod
    def of(cls, solution: Solution) -> ContactStart:
        """The multipliers lambda_n, lambda_t of ``solution`` on its fine Gamma_C edges."""
        pb = solution.problem
        gamma_c = pb.spaces.gamma_c
        fine = pb.to_fine(solution.x)
        segments = np.concatenate([np.stack([chain.path_points[:-1], chain.path_points[1:]], 1)
                                   for chain in gamma_c.coarse.chains])
        values = {}
        for name in ("lam_n", "lam_t"):
            rng = pb.fes.Range(pb.names.index(name))
            values[name] = fine[rng.start:rng.stop][gamma_c.edge_dofs]
        return cls(segments, values["lam_n"], values["lam_t"])

    def at(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """lambda_n, lambda_t at ``points`` of Gamma_C, linear along the nearest edge (a
        refined mesh's vertices on a curved Gamma_C lie off the coarser mesh's chords)."""
        a, b = self.segments[:, 0], self.segments[:, 1]
        # the edge holding a point is among the few whose midpoints are nearest
        _, near = cKDTree(0.5 * (a + b)).query(points, k=min(CANDIDATE_EDGES, len(a)))
        near = near.reshape(len(points), -1)
        d = (b - a)[near]
        t = np.clip(np.einsum("qck,qck->qc", points[:, None, :] - a[near], d)
                    / np.einsum("qck,qck->qc", d, d), 0.0, 1.0)
        foot = a[near] + t[..., None] * d
        best = np.argmin(np.linalg.norm(points[:, None, :] - foot, axis=2), axis=1)
        rows = np.arange(len(points))
        edge, w = near[rows, best], t[rows, best]
        return tuple((1 - w) * v[edge, 0] + w * v[edge, 1] for v in (self.lam_n, self.lam_t))
