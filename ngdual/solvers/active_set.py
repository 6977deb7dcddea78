"""The active-set method: contact and friction at the cost of about one linear solve.

One solver for every order k and multiplier family:

1. Hybridise (:class:`~ngdual.solvers.hybrid.HybridSystem`): (3.62) becomes a symmetric
   positive definite H on the global unknowns, the contact multipliers z = (lambda_n,
   lambda_t) last.
2. Factorise H once with z eliminated last (:class:`~ngdual.solvers.cholesky.SchurCholesky`):
   the trailing block of the factor is the Schur complement G, and the moments of the
   contact rows are t(z) = b - G z without any further solve.
3. Solve the contact problem on z (:mod:`ngdual.solvers.contact_problem`): semismooth
   Newton for no friction or a Tresca bound, the Coulomb fixed point of Remark 3.45 around
   it. The friction law is the one the multiplier spaces carry (:func:`friction_law`): the
   thesis' nu on the h^ mesh (Q_F of (3.95), a bound per fine edge, the Coulomb bound
   (3.123) from sigma_n on the fine edges, which a back substitution gives for any z), or a
   bound on every coefficient (:class:`ngdual.friction.MomentFriction`).
4. One back substitution and the element solves give every unknown.

The result is the discrete solution of (3.62) itself, checked on the assembled system: the
residuals of its rows and of the contact and friction conditions against the scales of
the problem (:mod:`ngdual.solvers.convergence`, the one convergence test of every solver);
if any exceeds ``TOLERANCE`` (the Coulomb bound's: its normal stress's round-off, where
larger; :func:`~ngdual.solvers.convergence.exceeding`) a :class:`ConvergenceError` names each
with its value. G and b
carry the round-off of the Cholesky factors, which a nearly incompressible body amplifies
(Cattaneo-Mindlin, nu = 0.4999, k = 1, level 2: the slip residual 2.0e-9 against 1e-9):
where the residuals on K are not round-off, b takes the difference between the moments on
K and t(z), and the contact problem is solved again (at most ``CONTACT_REFINEMENTS``
times).

``solution.roundoff`` reports (it decides nothing) the round-off level delta
of the computed unknowns: the largest of eps max(kappa_1(G), dim G) (the round-off of the
small problem), eps (lambda + 2 mu) / mu (the condition of the compliance, 3 for nu = 0.25
and 5001 for nu = 0.4999) and a statistical condition estimate (Kenney and Laub's
small-sample method with one sample: the rows of H are perturbed by their unavoidable
rounding eps |H| |x_I| with random signs, and the change this causes in the unknowns is
measured, at the cost of one more forward and back substitution). The behaviour pins
(tests/test_behaviour_unchanged.py) compare two solves to that level.

Where K is singular (a body held by Gamma_C alone floats when nothing touches) H is too,
and :func:`~ngdual.solvers.conforming.conforming_active_set` solves the problem instead.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import scipy.linalg as sla

from ..forms import DiscreteProblem
from ..friction import MomentFriction, build_friction_forms, tresca_bound, tresca_moments
from ..solution import ConvergenceError, Solution
from ..tolerances import COULOMB_FIXED_POINT_TOL
from .cholesky import SchurCholesky
from .conforming import checked_solution, conforming_active_set
from .contact_problem import Condensed, EdgeStress, solve_contact
from .convergence import EdgeFriction, Scales, exceeding, moments, residuals
from .hybrid import HybridSystem
from .linear import blas_threads
from .semismooth import EPS, SAFETY
from .settings import ActiveSetSettings, Model
from .start import ContactStart

CONTACT_REFINEMENTS = 2  # corrections of b by the moments on K
PROBE_SEED = 20110501    # the random signs of the round-off estimate (reproducible)


def friction_law(problem: DiscreteProblem, law: str):
    """(friction, bound): the friction law of the problem's multiplier spaces and, for
    Tresca, its bound. The thesis' nu on the h^ mesh (``spaces.friction``) takes F per fine
    edge (:func:`ngdual.friction.tresca_bound`); without it every coefficient is bounded by
    its own moment of F (:func:`ngdual.friction.tresca_moments`)."""
    if law != "none" and problem.spaces.friction is not None:
        forms = build_friction_forms(problem)
        return forms, tresca_bound(forms, problem) if law == "tresca" else None
    return MomentFriction(), tresca_moments(problem) if law == "tresca" else None


def active_set_solve(problem: DiscreteProblem, settings: ActiveSetSettings,
                     tol: float = COULOMB_FIXED_POINT_TOL, ordering: str = "amd",
                     progress: Callable[[int, float], None] | None = None,
                     start: ContactStart | None = None) -> Solution:
    """Solve (3.62) by condensation onto the contact multipliers and semismooth Newton
    there (module docstring).

    Parameters
    ----------
    problem : DiscreteProblem
        Any assembled problem (every order and multiplier family).
    settings : ActiveSetSettings
        The model (material, boundary parts, friction law, mu_f) and ``max_iter`` (bound on
        the Coulomb fixed-point steps).
    tol : float
        Relative change of F at which the Coulomb fixed point (3.123) stops (or at its
        round-off level, where it stagnates above ``tol``).
    ordering : {"amd", "metis"}
        Fill-reducing ordering of H.
    progress : callable, optional
        ``progress(step, change)`` after every Coulomb fixed-point step.
    start : ContactStart, optional
        The multipliers of a solution on a coarser mesh: the semismooth Newton method starts
        from their values at this mesh's control points. The solution is the same.

    Raises
    ------
    ConvergenceError
        If the contact problem is not solved, the Coulomb fixed point does not converge in
        ``max_iter`` steps, or a residual of (3.62) exceeds ``TOLERANCE``; the message names
        each, ``history`` holds the fixed point's changes.
    """
    model = settings.model
    try:
        # the dense work is small (at most a few thousand unknowns): one BLAS thread is as
        # fast and immune to the spin-waiting of threaded BLAS on busy cores
        with blas_threads():
            return _solve(problem, settings, tol, ordering, progress, start)
    except ConvergenceError as err:
        if problem.spaces.friction is not None and model.has_friction \
                and model.hhat_factor == 1:
            raise ConvergenceError(f"{err}; with h^ = h~ the inf-sup condition (3.74) "
                                   "for nu fails where the contact zone reaches the end of "
                                   "Gamma_C: try contact.hhat_factor = 2",
                                   err.history) from err
        raise


def _solve(problem: DiscreteProblem, settings: ActiveSetSettings, tol: float, ordering: str,
           progress, start: ContactStart | None) -> Solution:
    model = settings.model
    law = model.law
    begin = time.perf_counter()
    hybrid = HybridSystem(problem, friction=law != "none")                     # step 1
    try:
        chol = SchurCholesky(hybrid.H, hybrid.contact_index, ordering)         # step 2
    except np.linalg.LinAlgError:   # SchurCholesky: H is not positive definite
        if problem.spaces.friction is not None:
            raise ConvergenceError("the hybridised system is singular (the body is not held "
                                   "where nothing touches): hold it by Gamma_D or Gamma_N",
                                   []) from None
        return conforming_active_set(problem, settings, start, tol)
    after_factor = time.perf_counter()
    y = chol.forward(hybrid.rhs(problem.rhs))
    substitute = time.perf_counter() - after_factor
    n_c = len(problem.lam_n)
    if n_c == 0:                                     # no contact boundary: a linear solve
        x = hybrid.solve(chol, y, problem.rhs, np.zeros(0))
        seconds = _seconds(problem, hybrid, chol, begin, after_factor, substitute,
                           time.perf_counter())
        return _checked(problem, model, hybrid, chol, y, x, "none", None, None,
                        EPS, "linear", [], {}, seconds)
    friction, bound = friction_law(problem, law)
    G, b = chol.schur, chol.reduced_rhs(y)
    if law == "none":  # lambda_t eliminated, t_t = 0: lambda_t = 0 on a block of G's size
        unit = float(np.mean(np.diag(G))) or 1.0   # (its condition is G's, in any units)
        G, b = sla.block_diag(G, unit * np.eye(n_c)), np.concatenate([b, np.zeros(n_c)])
    G = 0.5 * (G + G.T)
    cond = (Condensed(G, b, np.arange(n_c)) if isinstance(friction, MomentFriction)
            else _edge_stress(problem, hybrid, chol, y, friction, G, b))
    first = start.at(problem.spaces.contact.node_points()) if start is not None else None
    # the Coulomb bound cannot meet its map better than its normal stress's round-off: the
    # fixed point's own floor (convergence.exceeding)
    floors = {"coulomb_bound": SAFETY * cond.stress_roundoff} if law == "coulomb" else {}
    contact_start = time.perf_counter()
    for refinement in range(CONTACT_REFINEMENTS + 1):                           # step 3
        state, F, history, iterations = solve_contact(
            cond, law, model.mu_f, bound, friction, first, settings.max_iter, tol, progress)
        back = time.perf_counter()
        z = state.lam_n if law == "none" else np.concatenate([state.lam_n, state.lam_t])
        x = hybrid.solve(chol, y, problem.rhs, z)                               # step 4
        edges = None if isinstance(friction, MomentFriction) or F is None \
            else EdgeFriction(friction, state.nu)
        found = residuals(problem, x, law, model.mu_f, F, edges)
        if refinement == CONTACT_REFINEMENTS or not exceeding(found, floors):
            break
        # the moments on K are exact for these multipliers, those of the Schur complement
        # carry the round-off of the Cholesky factors: b takes the difference
        on_K = np.concatenate(moments(problem, x))[:len(z)]
        cond.b[:len(z)] += on_K - cond.traction(state)[:len(z)]
        first = (state.lam_n, state.lam_t)
    seconds = _seconds(problem, hybrid, chol, begin, after_factor, substitute, back)
    seconds["contact"] = back - contact_start
    return _checked(problem, model, hybrid, chol, y, x, law, F, edges, cond.roundoff,
                    "active-set", history,
                    {**iterations, "condensed": n_c, "contact_refinements": refinement,
                     "qp_fallback": int(state.fallback)},
                    seconds, found, floors)


def _edge_stress(problem: DiscreteProblem, hybrid: HybridSystem, chol: SchurCholesky,
                 y: np.ndarray, forms, G: np.ndarray, b: np.ndarray) -> EdgeStress:
    """The contact problem whose Coulomb bound (3.123) is made of sigma_n on the fine
    Gamma_C edges: for any z, the back substitution restricted to what those edges'
    triangles read (:meth:`SchurCholesky.solver_on`) and their element solves
    (:meth:`HybridSystem.functional`) give it.

    Its round-off is measured once: the stress of z = 0 (u_n = g, the largest) recovered so
    against the one refined on K (:meth:`HybridSystem.solve`); a nearly incompressible
    body amplifies it (cattaneo-mindlin, nu = 0.4999), and the Coulomb fixed point stops
    stagnating there rather than at the round-off of G."""
    positions, value = hybrid.functional(forms.T_n, problem.rhs)
    solve = chol.solver_on(positions)

    def sigma(z: np.ndarray) -> np.ndarray:
        return value(solve(y, z))

    free = np.zeros(len(hybrid.contact_index))
    plain = sigma(free)
    x = hybrid.solve(chol, y, problem.rhs, free)
    scale = max(float(np.max(np.abs(forms.T_n @ x), initial=0.0)),
                float(np.max(np.abs(forms.T_t @ x), initial=0.0)))
    noise = float(np.max(np.abs(plain - forms.T_n @ x), initial=0.0)) / (scale or 1.0)
    return EdgeStress(G, b, sigma, scale, noise)


def _seconds(problem: DiscreteProblem, hybrid: HybridSystem, chol: SchurCholesky,
             begin: float, after_factor: float, substitute: float, back: float) -> dict:
    """The timings every solve reports: ``factorize`` prepares (hybridisation and Cholesky),
    ``solve`` follows it; ``substitute`` the forward and the final backward substitution
    (with ``cholesky``, the cost of one linear solve: the unit of ngdual bench adaptive)."""
    end = time.perf_counter()
    seconds = {"assemble": problem.assemble_seconds,
               "hybrid_assemble": hybrid.seconds["broken"],
               "hybridize": hybrid.seconds["broken"] + hybrid.seconds["condense"],
               "cholesky": sum(chol.seconds.values()),
               "substitute": substitute + end - back, "solve": end - after_factor,
               "total_solver": end - begin}
    seconds["factorize"] = seconds["hybridize"] + seconds["cholesky"]
    return seconds


def _checked(problem: DiscreteProblem, model: Model, hybrid: HybridSystem,
             chol: SchurCholesky, y: np.ndarray, x: np.ndarray, law: str, F,
             edges: EdgeFriction | None, roundoff: float, method: str, history: list,
             iterations: dict, seconds: dict, found: dict | None = None,
             floors: dict | None = None) -> Solution:
    """The solution x once its residuals on K are round-off
    (:func:`~ngdual.solvers.conforming.checked_solution`; the thesis' nu on the h^ mesh
    reported as it is), with the round-off level ``roundoff`` of its contact problem and
    the compliance's condition reported (module docstring)."""
    found = residuals(problem, x, law, model.mu_f, F, edges) if found is None else found
    level = max(roundoff, EPS * _material_condition(model),
                _roundoff_probe(problem, hybrid, chol, y, x))
    solution = checked_solution(problem, x, law, model.mu_f, F if edges is None else None,
                                method, iterations, history, seconds, found, floors)
    solution.roundoff = level
    if edges is not None:
        forms = edges.forms
        solution.nu, solution.friction_bound, solution.friction_forms = edges.nu, F, forms
        solution.nu_l2 = forms.l2_norm_nu(edges.nu, forms.per_hat_edge(F) > 0)
    return solution


def _material_condition(model: Model) -> float:
    """(lambda + 2 mu) / mu (Lame's): the condition of the compliance (module docstring)."""
    lam, mu = model.lame
    return (lam + 2 * mu) / mu


def _roundoff_probe(problem: DiscreteProblem, hybrid: HybridSystem, chol: SchurCholesky,
                    y: np.ndarray, x: np.ndarray) -> float:
    """The round-off level of the computed x, by a statistical condition estimate: the rows
    of H x_I = r cannot be satisfied better than their rounding, eps (|H| |x_I|)_i; a
    perturbation of that size (random signs, the contact multipliers fixed) is carried
    through the factorisation and the element solves, and the change it causes in the
    unknowns, relative to the problem's scales (S for sigma, D for the others), is
    returned: the accuracy to which two solves of this problem can agree."""
    contact = x[hybrid.contact_unknowns]
    w = chol.solve_with_last(y, contact)
    rng = np.random.default_rng(PROBE_SEED)
    perturbation = EPS * (abs(hybrid.H) @ np.abs(w)) * rng.choice((-1.0, 1.0), size=len(w))
    perturbation[hybrid.contact_index] = 0.0
    dw = chol.solve_with_last(chol.forward(perturbation), np.zeros(len(contact)))
    dx = hybrid.unknowns(dw, np.zeros(problem.n))
    D, S = Scales.sizes(problem, x)
    others = np.ones(problem.n, dtype=bool)
    others[problem.sigma] = False
    return max(float(np.max(np.abs(dx[problem.sigma]), initial=0.0)) / (S or 1.0),
               float(np.max(np.abs(dx[others]), initial=0.0)) / (D or 1.0))
