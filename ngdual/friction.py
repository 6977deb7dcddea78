"""Friction terms on Gamma_C: nu on the h^ mesh, q(kappa, mu) = int F kappa mu ds, F of (3.123).

nu is piecewise constant on the h^ edges (L_h^ of (3.61)); F is taken
piecewise constant on the fine edges of T_h along Gamma_C: for Tresca the mean
of the given bound on each fine edge, for Coulomb (Remark 3.45, (3.123))
F|_e^ = mu_f / n^ sum_{e in e^} |sigma_n|_e on every h^ edge, |sigma_n| by default
of the projection of sigma_n onto the h~ hats (see :meth:`FrictionForms.coulomb_bound_of`).
With that,

    (Q_F)_{ji} = q(mu_i, kappa_j) = sum_{e in e^_j} F_e |e| (mu_i(a_e) + mu_i(b_e)) / 2

exactly, mu_i the h~ hats and kappa_j the indicator of the h^ edge j.
The normal and tangential stress per fine edge are linear maps of the unknown
vector, assembled once by NGSolve against piecewise constants on Gamma_C.
"""

from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from . import peers
from .expr import Expression
from .forms import DiscreteProblem, boundary_regex

NEGLIGIBLE = 1e-6  # hat moments of sigma_n below this fraction of the largest are zero
GAUSS = (np.array([0.5 - np.sqrt(15) / 10, 0.5, 0.5 + np.sqrt(15) / 10]),
         np.array([5, 8, 5]) / 18)


@dataclass
class FrictionForms:
    """Everything the friction loop needs on Gamma_C.

    Attributes
    ----------
    T_n, T_t : scipy.sparse.csr_matrix
        sigma_n and sigma_t on every fine Gamma_C edge: ``T_n @ x``.
    lengths : numpy.ndarray
        Fine edge lengths.
    midpoint_hats : scipy.sparse.csr_matrix
        Mean value of every h~ hat on every fine edge.
    edge_of : numpy.ndarray
        Index of the h^ edge containing each fine edge.
    hat_lengths : numpy.ndarray
        Lengths of the h^ edges: the (diagonal) mass matrix of L_h^.
    midpoints : numpy.ndarray
        Fine edge midpoints (for plots).
    normal_stress : str
        The |sigma_n| of the Coulomb bound (3.123): ``"hat-projection"`` or
        ``"fine-edges"`` (see :class:`ngdual.scene.Friction`).
    """

    T_n: sp.csr_matrix
    T_t: sp.csr_matrix
    lengths: np.ndarray
    midpoint_hats: sp.csr_matrix
    edge_of: np.ndarray
    hat_lengths: np.ndarray
    midpoints: np.ndarray
    normal_stress: str = "hat-projection"

    @property
    def n_nu(self) -> int:
        return len(self.hat_lengths)

    def q_matrix(self, F_edges: np.ndarray) -> sp.csr_matrix:
        """Q_F (N_A x N_C) of (3.95) for F given per fine edge."""
        R = sp.csr_matrix((F_edges * self.lengths, (self.edge_of, np.arange(len(self.lengths)))),
                          shape=(self.n_nu, len(self.lengths)))
        return (R @ self.midpoint_hats).tocsr()

    def coulomb_bound(self, x: np.ndarray, mu_f: float) -> np.ndarray:
        """F of (3.123) per fine edge: mu_f times the mean |sigma_n| over its h^ edge."""
        return self.coulomb_bound_of(self.T_n @ x, mu_f)

    def coulomb_bound_of(self, sigma_n: np.ndarray, mu_f: float) -> np.ndarray:
        """F of (3.123) from sigma_n given per fine edge.

        With ``normal_stress = "hat-projection"`` sigma_n is first replaced by
        its lumped L^2 projection onto the h~ hats, sum_i (t_i / m_i) mu_i with
        the moments t_i = int sigma_n mu_i ds = d_Cn(mu_i, sigma) and m_i =
        int mu_i ds (sigma_n is constant on every fine edge, so both are exact
        sums); it is zero wherever the moments are, i.e. where the body separates.
        """
        if self.normal_stress == "hat-projection":
            weights = self.midpoint_hats.T @ self.lengths
            moments = self.midpoint_hats.T @ (self.lengths * sigma_n)
            # an iterative contact solve leaves moments of the size of its tolerance
            # where the body separates: they are zero, and so is F there
            moments[np.abs(moments) <= NEGLIGIBLE * np.abs(moments).max(initial=0.0)] = 0.0
            sigma_n = self.midpoint_hats @ (moments / weights)
        return mu_f * self.per_hat_edge(np.abs(sigma_n))[self.edge_of]

    def per_hat_edge(self, F_edges: np.ndarray) -> np.ndarray:
        """Mean of a fine-edge quantity over each h^ edge."""
        return np.bincount(self.edge_of, F_edges, self.n_nu) / np.bincount(self.edge_of, None,
                                                                             self.n_nu)

    def l2_norm_nu(self, nu: np.ndarray, active: np.ndarray | None = None) -> float:
        """||nu||_{L^2(A_C)}; A_C = the h^ edges where ``active`` is true (all by default)."""
        w = self.hat_lengths if active is None else self.hat_lengths * active
        return float(np.sqrt(np.sum(w * nu**2)))


def _edge_functionals(problem: DiscreteProblem):
    """Matrices of int_e sigma_n ds and int_e sigma_t ds for every fine Gamma_C edge."""
    mesh, fes, names = problem.fes.mesh, problem.fes, problem.names
    labels = problem.scene.labels("contact")
    p0 = ngs.Compress(ngs.SurfaceL2(mesh, order=0,
                                    definedon=mesh.Boundaries(boundary_regex(labels))))
    trial = dict(zip(names, fes.TrialFunction()))
    v0 = p0.TestFunction()
    traction = peers.stress_traction(trial["r1"], trial["r2"])
    n = ngs.specialcf.normal(2)
    t = ngs.CF((n[1], -n[0]))
    ds = ngs.ds(definedon=mesh.Boundaries(boundary_regex(labels)))
    mats = []
    for direction in (n, t):
        form = ngs.BilinearForm(trialspace=fes, testspace=p0)
        form += (direction * traction) * v0 * ds
        form.Assemble()
        rows, cols, vals = form.mat.COO()
        fine = sp.csr_matrix((np.asarray(vals), (np.asarray(rows), np.asarray(cols))),
                             shape=(p0.ndof, fes.ndof))
        mats.append((fine @ problem.P).tocsr())
    dof_of_edge = {}
    for el in mesh.Elements(ngs.BND):
        if el.mat in labels:
            key = frozenset(v.nr for v in el.vertices)
            dof_of_edge[key] = p0.GetDofNrs(el)[0]
    return mats, dof_of_edge


def build_friction_forms(problem: DiscreteProblem) -> FrictionForms:
    """Fine-edge traces, hat means and the h^ edge map for the contact boundary."""
    spaces = problem.spaces
    gamma_c = spaces.gamma_c
    (int_n, int_t), dof_of_edge = _edge_functionals(problem)
    order = np.array([dof_of_edge[frozenset((int(a), int(b)))] for a, b in gamma_c.vertices])
    scale = sp.diags(1.0 / gamma_c.lengths)
    return FrictionForms(T_n=(scale @ int_n[order]).tocsr(), T_t=(scale @ int_t[order]).tocsr(),
                         lengths=gamma_c.lengths,
                         midpoint_hats=gamma_c.hat_means(spaces.prolongations["lam_n"]),
                         edge_of=gamma_c.hhat_edge, hat_lengths=spaces.friction.edge_lengths(),
                         midpoints=gamma_c.midpoints,
                         normal_stress=problem.scene.friction.normal_stress)


def tresca_bound(forms: FrictionForms, problem: DiscreteProblem) -> np.ndarray:
    """The given Tresca bound F, averaged (3-point Gauss) on every fine edge."""
    bound = Expression(problem.scene.friction.bound)
    contact = problem.spaces.contact
    values = np.zeros(len(forms.lengths))
    start = 0
    for chain in contact.chains:
        a, b = chain.path_points[:-1], chain.path_points[1:]
        for s, w in zip(*GAUSS):
            q = a + s * (b - a)
            values[start:start + len(a)] += w * bound.numpy(q[:, 0], q[:, 1])
        start += len(a)
    return values
