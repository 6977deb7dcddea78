"""The assembled discrete problem (3.62) (:class:`DiscreteProblem`): its unknowns, ordered

    [sigma | u, eta, phi, lambda_t | lambda_n],

their index sets, the matrix K and its products, and the right-hand side."""

from __future__ import annotations

from dataclasses import dataclass, field

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from .. import peers
from ..geometry import length_scale
from ..scene import Scene
from .peers_block import BrokenPeers
from .spaces import Spaces


@dataclass
class DiscreteProblem:
    """The assembled discrete problem (3.62) without friction terms.

    Attributes
    ----------
    K : scipy.sparse.csr_matrix
        Symmetric matrix of all unknowns (sigma, u, eta, phi, lambda_t, lambda_n): its PEERS
        block summed from ``broken`` plus ``boundary``, formed on first use. The hybridised
        solvers never form it: they read the multipliers' rows from ``boundary``, K x from
        :meth:`apply` and the size of its terms from :meth:`terms`, which makes a solve of
        Example 3.46 with PEERS_1 (50 017 unknowns) 10 % faster than with K formed.
    boundary : scipy.sparse.csr_matrix
        P^T D P: the couplings d_N, d_C of the boundary multipliers with sigma (K less its
        PEERS block; zero without Gamma_N and Gamma_C).
    rhs : numpy.ndarray
        Right-hand side (g, -f, 0, t0, 0, 0).
    lift : numpy.ndarray
        Fine coefficients of the known end values phi = -u_D at the ends of
        Gamma_N (zero for the homogeneous Dirichlet data of the thesis).
    blocks : dict[str, slice]
        Position of every component in the unknown vector.
    broken : BrokenPeers
        The PEERS block element by element, from which K's PEERS block is summed (the
        input of the hybridised solver, :mod:`ngdual.solvers.hybrid`).
    """

    scene: Scene
    spaces: Spaces
    fes: ngs.FESpace
    names: list[str]
    P: sp.csr_matrix
    boundary: sp.csr_matrix
    rhs: np.ndarray
    blocks: dict[str, slice]
    lift: np.ndarray
    broken: BrokenPeers
    assemble_seconds: float
    level: int | None = None
    _K: sp.csr_matrix | None = field(default=None, init=False, repr=False)

    @property
    def K(self) -> sp.csr_matrix:
        """The matrix of (3.62), formed on first use (see the attributes)."""
        if self._K is None:
            # the PEERS unknowns come first and are not prolonged
            K = self.broken.summed(self.n) + self.boundary
            K.eliminate_zeros()
            self._K = K
        return self._K

    @property
    def n(self) -> int:
        """The number of unknowns (rows of K)."""
        return len(self.rhs)

    @property
    def n_peers(self) -> int:
        """The number of PEERS unknowns (sigma, u, eta: they come first; K's PEERS block)."""
        return max(self.blocks[name].stop for name in peers.PEERS if name in self.blocks)

    @property
    def units(self) -> tuple[float, float]:
        """(E*, L): the plane-strain modulus E / (1 - nu^2) and the body's length scale
        (:func:`ngdual.geometry.length_scale`), the units in which a solver judges its
        residuals (:class:`ngdual.solvers.convergence.Scales`)."""
        material = self.scene.material
        return (material.E / (1.0 - material.nu ** 2),
                length_scale(self.scene.geometry.curves()))

    def apply(self, x: np.ndarray) -> np.ndarray:
        """K x, without forming K if it is not formed yet (:meth:`BrokenPeers.apply`)."""
        if self._K is not None:
            return self._K @ x
        return self.broken.apply(x, self.n) + self.boundary @ x

    def terms(self, x: np.ndarray) -> np.ndarray:
        """The size of the terms of K x row by row, from the element matrices and the
        boundary couplings (:meth:`BrokenPeers.apply_magnitudes`, |boundary| |x|), without
        forming K: at least |K| |x| entry by entry, equal where no two element entries of
        K cancel."""
        magnitudes = np.abs(x)
        return self.broken.apply_magnitudes(magnitudes, self.n) + abs(self.boundary) @ magnitudes

    def index(self, *names: str) -> np.ndarray:
        """Indices of the listed components in the unknown vector."""
        present = [n for n in names if n in self.blocks]
        if not present:
            return np.zeros(0, dtype=int)
        return np.concatenate([np.arange(self.blocks[n].start, self.blocks[n].stop)
                               for n in present])

    @property
    def sigma(self) -> np.ndarray:
        return self.index(*peers.STRESS)

    @property
    def mult(self) -> np.ndarray:
        """u, eta, phi, lambda_t: the unknowns of the fixed saddle-point matrix."""
        return self.index("u1", "u2", "eta", "phi1", "phi2", "lam_t")

    @property
    def lam_n(self) -> np.ndarray:
        return self.index("lam_n")

    @property
    def saddle(self) -> np.ndarray:
        """sigma followed by mult: the rows and columns of [[A, B], [B^T, 0]]."""
        return np.concatenate([self.sigma, self.mult])

    def block(self, rows: np.ndarray, cols: np.ndarray) -> sp.csr_matrix:
        """K[rows][:, cols]; from ``boundary`` alone where the rows or the columns are all
        multipliers (the PEERS block has none of their entries)."""
        if self._K is None and (np.min(rows, initial=self.n) >= self.n_peers
                                or np.min(cols, initial=self.n) >= self.n_peers):
            return self.boundary[rows][:, cols].tocsr()
        return self.K[rows][:, cols].tocsr()

    def to_fine(self, x: np.ndarray) -> np.ndarray:
        """Coefficients of the fine product space from a coarse unknown vector."""
        return self.P @ x + self.lift
