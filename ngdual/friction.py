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
vector, assembled once by NGSolve against the fine trace space of Gamma_C
(:class:`ngdual.contact.ContactBoundary`, the one home of Gamma_C).

With the facet multipliers of order k (:mod:`ngdual.boundary.facet`) lambda_t has the
Bernstein coefficients of lambda_n, and the friction law acts on every coefficient i with
its moment t_t,i = d_Ct(B_i, sigma): |t_t,i| <= F_i, lambda_t,i = 0 where |t_t,i| < F_i and
sign(lambda_t,i) = sign(t_t,i) where lambda_t,i != 0 -- (3.62)_5-7 with nu on the
coefficients and Q_F = diag(F_i) (:class:`MomentFriction`). F_i = int F B_i ds for a given
Tresca bound (:func:`tresca_moments`), F_i = mu_f (-t_n,i) for Coulomb, the weighted
moments of the mortar methods (Hueber and Wohlmuth).
"""

from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from . import peers
from .contact import ContactBoundary, curve_normal
from .expr import Expression
from .forms import TRACE_RULES, DiscreteProblem, boundary_regex
from .geometry import tangent
from .sparse import to_scipy
from .tolerances import friction_vanishes

GAUSS = (np.array([0.5 - np.sqrt(15) / 10, 0.5, 0.5 + np.sqrt(15) / 10]),
         np.array([5, 8, 5]) / 18)


@dataclass
class FrictionForms:
    """Everything the friction loop needs on Gamma_C.

    Gamma_C itself (fine edges, their h^ edges, the h^ mesh) is read from
    :class:`ngdual.contact.ContactBoundary`, its one home.

    Attributes
    ----------
    gamma_c : ngdual.contact.ContactBoundary
        Gamma_C of the mesh: the fine edges in chain order and the h~ / h^ meshes.
    T_n, T_t : scipy.sparse.csr_matrix
        sigma_n and sigma_t on every fine Gamma_C edge: ``T_n @ x``.
    midpoint_hats : scipy.sparse.csr_matrix
        Mean value of every h~ hat on every fine edge.
    normal_stress : str
        The |sigma_n| of the Coulomb bound (3.123): ``"hat-projection"`` or
        ``"fine-edges"`` (see :class:`ngdual.scene.Friction`).
    """

    gamma_c: ContactBoundary
    T_n: sp.csr_matrix
    T_t: sp.csr_matrix
    midpoint_hats: sp.csr_matrix
    normal_stress: str = "hat-projection"

    @property
    def lengths(self) -> np.ndarray:
        """Fine edge lengths."""
        return self.gamma_c.lengths

    @property
    def midpoints(self) -> np.ndarray:
        """Fine edge midpoints (for plots)."""
        return self.gamma_c.midpoints

    @property
    def edge_of(self) -> np.ndarray:
        """Index of the h^ edge containing each fine edge."""
        return self.gamma_c.hhat_edge

    @property
    def hat_lengths(self) -> np.ndarray:
        """Lengths of the h^ edges: the (diagonal) mass matrix of L_h^."""
        return self.gamma_c.friction.edge_lengths()

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

        With ``normal_stress = "hat-projection"`` sigma_n is first replaced by the
        contact pressure p_h of :func:`hat_projection` (zero where the body separates).
        """
        if self.normal_stress == "hat-projection":
            sigma_n = self.midpoint_hats @ hat_projection(self.midpoint_hats, self.lengths,
                                                          sigma_n)
        return mu_f * self.per_hat_edge(np.abs(sigma_n))[self.edge_of]

    def per_hat_edge(self, F_edges: np.ndarray) -> np.ndarray:
        """Mean of a fine-edge quantity over each h^ edge."""
        return np.bincount(self.edge_of, F_edges, self.n_nu) / np.bincount(self.edge_of, None,
                                                                             self.n_nu)

    def l2_norm_nu(self, nu: np.ndarray, active: np.ndarray | None = None) -> float:
        """||nu||_{L^2(A_C)}; A_C = the h^ edges where ``active`` is true (all by default)."""
        w = self.hat_lengths if active is None else self.hat_lengths * active
        return float(np.sqrt(np.sum(w * nu**2)))

    # The friction law as the nested Uzawa algorithm iterates it: nu, |nu_j| <= 1, on the
    # h^ edges (L_h^ of (3.61)), the bound F per fine edge.

    @property
    def nu_mass(self) -> np.ndarray:
        """The (diagonal) mass matrix of the space of nu: the h^ edge lengths (Remark 3.44)."""
        return self.hat_lengths

    def nu_matrix(self, bound: np.ndarray) -> sp.csr_matrix:
        """Q_F of (3.95), nu x lambda_t: q(mu_i, kappa_j) for the bound F per fine edge."""
        return self.q_matrix(bound)

    def given_bound(self, problem: DiscreteProblem) -> np.ndarray:
        """The Tresca bound of ``problem``'s scene per fine edge (:func:`tresca_bound`)."""
        return tresca_bound(self, problem)

    def normal_functionals(self, problem: DiscreteProblem) -> tuple[sp.csr_matrix, np.ndarray]:
        """(N, r): the normal stresses the Coulomb bound is made of, N x - r for the unknowns
        x: sigma_n on every fine edge (``T_n``)."""
        return self.T_n, np.zeros(self.T_n.shape[0])

    def bound_of_normal(self, normal: np.ndarray, mu_f: float) -> np.ndarray:
        """The Coulomb bound F of (3.123) from N x - r of :meth:`normal_functionals`."""
        return self.coulomb_bound_of(normal, mu_f)

    def reported(self, nu: np.ndarray, bound: np.ndarray, t_t: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
        """nu and F as a :class:`~ngdual.solution.Solution` reports them (per h^ edge, per fine
        edge) from those of :meth:`nu_matrix`; ``t_t`` = C_t^T sigma - r_t."""
        return nu, bound


def hat_projection(midpoint_hats: sp.csr_matrix, lengths: np.ndarray,
                   sigma_n: np.ndarray) -> np.ndarray:
    """The contact pressure p_h: nodal values t_i / m_i on the h~ mesh.

    p_h = sum_i (t_i / m_i) mu_i is the lumped L^2 projection of sigma_n onto the h~
    hats mu_i, with the moments t_i = int sigma_n mu_i ds = d_Cn(mu_i, sigma) of (3.62)
    -- the normal forces the contact conditions constrain (t_i <= 0, t_i lambda_i = 0)
    -- and m_i = int mu_i ds (sigma_n is constant on every fine edge, so both are exact
    sums with ``midpoint_hats``, the hat means per fine edge). p_h vanishes where the body
    separates; the fine-edge sigma_n does not: with h~ = 2h it carries modes orthogonal to
    every hat (alternating from fine edge to fine edge), which nothing in (3.62) controls.

    Where the edge of the contact zone lies inside an h~ edge, p_h carries a spike at the
    last node in contact: lambda_n^h is linear on the partly covered h~ edge while the exact
    gap opens smoothly, and the elastic response to that corner of the discrete normal
    displacement is a concentrated compressive force on the node. It is O(theta^2 h~) with
    theta the uncovered part of the edge: at most first order, O(h^{3/2}) in L^2(Gamma_C),
    and not removable from the discrete solution while lambda_n is P1 on h~ (see the
    README, "Contact problems beyond the thesis").

    Moments that vanish by :func:`ngdual.tolerances.friction_vanishes` (1e-6 of the largest)
    are zero: an iterative contact solve leaves moments of the size of its tolerance where
    the body separates.
    """
    weights = midpoint_hats.T @ lengths
    moments = midpoint_hats.T @ (lengths * sigma_n)
    moments[friction_vanishes(moments)] = 0.0
    return moments / weights


def _edge_functionals(problem: DiscreteProblem) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Matrices of int_e sigma_n ds and int_e sigma_t ds on every fine Gamma_C edge e.

    Rows in the order of :class:`ngdual.contact.ContactBoundary`. Assembled against the
    fine trace space of lambda (P1 on every fine edge, discontinuous from edge to edge):
    the two end functions of e sum to its indicator, so int_e sigma_n ds is the sum of
    the rows of the two trace dofs of e (``ContactBoundary.edge_dofs``).
    """
    fes, gamma_c = problem.fes, problem.spaces.gamma_c
    space = problem.spaces.components["lam_n"]
    trial = dict(zip(problem.names, fes.TrialFunction()))
    test = space.TestFunction()
    traction = peers.stress_traction(trial["r1"], trial["r2"])
    # the facet multipliers' d_C acts with the normal of the boundary curve
    # (ngdual.forms): the traces measured against the moments t = C^T sigma need the same
    n = curve_normal(problem.scene, fes.mesh) if problem.spaces.contact.traces \
        else ngs.specialcf.normal(2)
    t = tangent(n)
    ds = ngs.ds(definedon=fes.mesh.Boundaries(boundary_regex(problem.scene.labels("contact"))))
    n_edges = len(gamma_c)
    ends = sp.csr_matrix((np.ones(2 * n_edges), (np.repeat(np.arange(n_edges), 2),
                                                 gamma_c.edge_dofs.ravel())),
                         shape=(n_edges, space.ndof))
    mats = []
    for direction in (n, t):
        form = ngs.BilinearForm(trialspace=fes, testspace=space)
        form += (direction * traction) * test * ds
        form.Assemble()
        mats.append((ends @ to_scipy(form.mat) @ problem.P).tocsr())
    return mats[0], mats[1]


class FacetFrictionForms(FrictionForms):
    """:class:`FrictionForms` of the facet multipliers: every fine edge is its own h^ edge.

    The friction law acts on the Bernstein coefficients (:class:`MomentFriction`); per fine
    edge e it implies |int_e sigma_t ds| <= sum_{i in e} F_i, which is what the fine-edge
    bound ``edge_bound(F)`` = sum_{i in e} F_i / |e| states in the terms of the thesis'
    F per fine edge (the physics checks read it through :meth:`q_matrix`), and
    ``edge_nu`` the nu of every fine edge that goes with it (the stick / slip diagnostics).
    """

    @property
    def edge_of(self) -> np.ndarray:
        return np.arange(len(self.lengths))

    @property
    def hat_lengths(self) -> np.ndarray:
        return self.lengths

    def edge_sums(self, coefficients: np.ndarray) -> np.ndarray:
        """sum_{i in e} c_i on every fine edge e (the means of the B_i on their edge are all
        1 / (k + 1))."""
        per_edge = self.midpoint_hats.shape[1] / self.midpoint_hats.shape[0]
        return per_edge * (self.midpoint_hats @ coefficients)

    def edge_bound(self, coefficients: np.ndarray) -> np.ndarray:
        """sum_{i in e} F_i / |e| on every fine edge e from F_i of the Bernstein coefficients."""
        return self.edge_sums(coefficients) / self.lengths

    def edge_nu(self, t_t: np.ndarray, bound: np.ndarray) -> np.ndarray:
        """nu on every fine edge: sum_{i in e} t_t,i / sum_{i in e} F_i (zero where the edge
        has no bound), in [-1, 1] by the law on the coefficients; +-1 where every coefficient
        of the edge slips the same way."""
        t, F = self.edge_sums(t_t), self.edge_sums(bound)
        return np.divide(t, F, out=np.zeros_like(t), where=F > 0)

    # The friction law on the Bernstein coefficients (MomentFriction) as the nested Uzawa
    # algorithm iterates it: nu_i, |nu_i| <= 1, and F_i on every coefficient.

    @property
    def nu_mass(self) -> np.ndarray:
        """The lumped mass int B_i ds = |e| / (k + 1) of every Bernstein coefficient: the
        (diagonal) metric of nu, one per coefficient."""
        per_edge = self.midpoint_hats.shape[1] // self.midpoint_hats.shape[0]
        return np.repeat(self.lengths / per_edge, per_edge)

    def nu_matrix(self, bound: np.ndarray) -> sp.csr_matrix:
        """Q_F = diag(F_i) (:class:`MomentFriction`)."""
        return MomentFriction().q_matrix(bound)

    def given_bound(self, problem: DiscreteProblem) -> np.ndarray:
        """F_i = int F B_i ds of the scene's Tresca bound (:func:`tresca_moments`)."""
        return tresca_moments(problem)

    def normal_functionals(self, problem: DiscreteProblem) -> tuple[sp.csr_matrix, np.ndarray]:
        """(N, r): the normal moments t_n = C_n^T sigma - r_n, the lambda_n rows of (3.62)."""
        return problem.K[problem.lam_n].tocsr(), problem.rhs[problem.lam_n]

    def bound_of_normal(self, normal: np.ndarray, mu_f: float) -> np.ndarray:
        """F_i = mu_f max(-t_n,i, 0) (:class:`MomentFriction`)."""
        return MomentFriction().coulomb_bound_of(normal, mu_f)

    def reported(self, nu: np.ndarray, bound: np.ndarray, t_t: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
        """nu and F per fine edge (:meth:`edge_nu`, :meth:`edge_bound`), as the active-set
        method reports them."""
        return self.edge_nu(t_t, bound), self.edge_bound(bound)


@dataclass(frozen=True)
class MomentFriction:
    """The friction law on the Bernstein moments of the facet multipliers (module docstring).

    Q_F = diag(F_i) in the conditions of :mod:`ngdual.solvers.semismooth`; for Coulomb
    F_i = mu_f (-t_n,i) with t_n,i = d_Cn(B_i, sigma) <= 0 the normal moment of the same
    coefficient. At k = 0 the B_0 are the indicators of the fine edges, and the law is the
    thesis' on an h^ mesh equal to the fine mesh with F = mu_f |sigma_n| on every edge, the
    normal stress itself rather than its hat projection p_h (which lives on the h~ hats,
    absent here: the fine trace of sigma_n is the multipliers' own).
    """

    def q_matrix(self, bound: np.ndarray) -> sp.csr_matrix:
        """Q_F = diag(F_i)."""
        return sp.diags(np.asarray(bound, dtype=float)).tocsr()

    def coulomb_bound_of(self, t_n: np.ndarray, mu_f: float) -> np.ndarray:
        """F_i = mu_f max(-t_n,i, 0) from the normal moments t_n,i."""
        return mu_f * np.maximum(-np.asarray(t_n, dtype=float), 0.0)


def tresca_moments(problem: DiscreteProblem) -> np.ndarray:
    """F_i = int_{Gamma_C} F B_i ds for the given Tresca bound F, one per Bernstein
    coefficient of the facet multipliers (the rule of the traces, ``forms.TRACE_RULES``)."""
    space = problem.spaces.components["lam_n"]
    labels = problem.scene.labels("contact")
    form = ngs.LinearForm(space)
    form += Expression(problem.scene.friction.bound).coefficient() * space.TestFunction() * ngs.ds(
        definedon=space.mesh.Boundaries(boundary_regex(labels)), intrules=TRACE_RULES)
    form.Assemble()
    return problem.spaces.prolongations["lam_n"].T @ form.vec.FV().NumPy()


def build_friction_forms(problem: DiscreteProblem) -> FrictionForms:
    """Fine-edge traces and hat means on Gamma_C (:class:`ngdual.contact.ContactBoundary`);
    :class:`FacetFrictionForms` with the facet multipliers.

    Parameters
    ----------
    problem : DiscreteProblem
        An assembled problem with friction (:func:`ngdual.forms.assemble`).

    Returns
    -------
    FrictionForms
        sigma_n and sigma_t on the fine edges of Gamma_C, the matrix Q_F of (3.95)
        (``q_matrix``), the Coulomb bound per h^ edge (``coulomb_bound_of``).

    Examples
    --------
    >>> import ngdual as nd
    >>> scene = nd.load_scene("thesis-3.46-tresca")
    >>> forms = nd.friction_forms(nd.assemble(scene, nd.build_mesh(scene.geometry, 1)))
    >>> len(forms.lengths) > forms.n_nu > 0        # fine edges of Gamma_C, h^ edges of nu
    True
    """
    gamma_c = problem.spaces.gamma_c
    int_n, int_t = _edge_functionals(problem)
    scale = sp.diags(1.0 / gamma_c.lengths)
    kind = FacetFrictionForms if problem.spaces.contact.traces else FrictionForms
    return kind(gamma_c, T_n=(scale @ int_n).tocsr(), T_t=(scale @ int_t).tocsr(),
                midpoint_hats=gamma_c.hat_means(problem.spaces.prolongations["lam_n"]),
                normal_stress=problem.scene.friction.normal_stress)


def tresca_bound(forms: FrictionForms, problem: DiscreteProblem) -> np.ndarray:
    """The given Tresca bound F, averaged (3-point Gauss) on every fine edge.

    The points of the (symmetric) rule run along every fine edge from its midpoint in
    the direction of its tangent.
    """
    bound = Expression(problem.scene.friction.bound)
    gamma_c = forms.gamma_c
    values = np.zeros(len(gamma_c))
    for s, w in zip(*GAUSS):
        q = gamma_c.midpoints + ((s - 0.5) * gamma_c.lengths)[:, None] * gamma_c.tangents
        values += w * bound.numpy(q[:, 0], q[:, 1])
    return values
