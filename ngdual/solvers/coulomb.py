"""The Coulomb fixed point of Remark 3.45 on a contact problem condensed onto Gamma_C.

Coulomb friction bounds the tangential traction by mu_f |sigma_n|, which depends on the
solution; Remark 3.45 solves it as a sequence of Tresca problems, F^{m+1} = Phi(F^m) =
mu_f |sigma_n(F^m)| of (3.123). :func:`coulomb_fixed_point` runs that iteration around the
semismooth Newton method of :mod:`ngdual.solvers.semismooth`, on any condensed problem with
t(z) = b - G z (``boundary``: ``G``, ``b``, ``n_c``, ``roundoff``, ``normal_stress(state)`` and
optionally ``stress_roundoff``, the relative round-off of that normal stress)
and any friction law with ``q_matrix(F)`` and ``coulomb_bound_of(sigma_n, mu_f)``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..friction import FrictionForms
from ..solution import ConvergenceError
from ..tolerances import friction_vanishes
from .semismooth import SAFETY, BoundarySolution, semismooth_newton

RELAXATION_MIN = 1.0 / 64  # smallest relaxation of the Coulomb fixed point


def coulomb_fixed_point(boundary, forms: FrictionForms, mu_f: float,
                         tol: float, max_iter: int, progress, noise: float,
                         first: BoundarySolution | None = None,
                         on_sets: Callable[[BoundarySolution], np.ndarray | None] | None = None):
    """Remark 3.45 on Gamma_C: F^0 from the frictionless solution, then Phi(F) = mu_f |sigma_n|
    of (3.123) for the Tresca solution with bound F, warm-started, until F = Phi(F). The
    frictionless solve starts from ``first`` (None: z = 0).

    Stops when the fixed-point residual ||Phi(F) - F|| / ||Phi(F)|| is <= ``tol``, or when it
    has stagnated (no longer halves) below SAFETY times the round-off of F (that of the
    normal stress it is made of, at least eps kappa_1(G));
    the returned F is then Phi(F) with its own Tresca solution.

    Relaxation: the step is F <- F + omega (Phi(F) - F), omega = 1 (the plain fixed point of
    the thesis) until the residual fails to decrease (the iteration oscillates, e.g. for
    large mu_f), then halved each time it does so, down to ``RELAXATION_MIN``. A fixed point
    of the relaxed map is a fixed point of Phi: the solution is the same, and where the plain
    iteration contracts (all shipped scenes), so are the iterates. Where F is zero follows
    :func:`ngdual.tolerances.friction_vanishes` with the round-off ``noise`` of a vanishing
    normal stress.

    ``on_sets(state)``, where given, is the normal stress of the Coulomb problem itself on
    the contact, stick and slip sets of a Tresca solution ``state`` (None if it has none):
    on fixed sets Phi is affine, and its fixed point is one linear solve away. Each new set
    of a Tresca solution is tried once in place of a relaxed step; if the sets are the
    solution's, the next Tresca solve reproduces F to round-off and the iteration stops by
    the same criterion, otherwise it goes on from there (:func:`ngdual.solvers.contact_problem.
    coulomb_on_sets`; the plain iteration takes 12-16 steps on Example 3.46 at order k,
    levels 1-4, this one 2-7).
    """
    G, b, n_c = boundary.G, boundary.b, boundary.n_c
    floor = SAFETY * boundary.roundoff  # = kkt_tolerance(G)
    # F is made of the normal stress: it cannot settle below that stress's round-off
    settled = SAFETY * getattr(boundary, "stress_roundoff", boundary.roundoff)
    state = semismooth_newton(G, b, n_c, start=first, tol=floor)
    inner = state.iterations
    bound = coulomb_bound(forms, boundary.normal_stress(state), mu_f, noise)
    history: list[float] = []
    omega, change = 1.0, np.inf
    # the sets whose Coulomb problem was solved, and whether the last step was such a solve
    tried, jumped = set(), False
    for outer in range(1, max_iter + 1):
        state = semismooth_newton(G, b, n_c, forms.q_matrix(bound).toarray(), start=state,
                                  tol=floor)
        inner += state.iterations
        mapped = coulomb_bound(forms, boundary.normal_stress(state), mu_f, noise)
        change = float(np.linalg.norm(mapped - bound) / (np.linalg.norm(mapped) or 1.0))
        history.append(change)
        if progress:
            progress(outer, change)
        previous = history[-2] if len(history) > 1 else np.inf
        if change <= tol or (change <= settled and change > 0.5 * previous):
            # the last F: its own Tresca solution, so that F, nu and z belong together
            bound = mapped
            state = semismooth_newton(G, b, n_c, forms.q_matrix(bound).toarray(), start=state,
                                      tol=floor)
            inner += state.iterations
            return state, bound, history, {"outer": outer, "inner": int(inner)}
        if change >= previous and not jumped:
            omega = max(0.5 * omega, RELAXATION_MIN)
        jumped = False
        if on_sets is not None:
            key = (state.contact.tobytes(), state.stick.tobytes(), np.sign(state.nu).tobytes())
            if key not in tried:
                tried.add(key)
                stress = on_sets(state)
                jumped = stress is not None
        bound = (coulomb_bound(forms, stress, mu_f, noise) if jumped
                 else bound + omega * (mapped - bound))
    raise ConvergenceError(f"the Coulomb fixed point (3.123) did not converge in "
                           f"solver.max_iter = {max_iter} steps: its relative change of F = "
                           f"{change:.1e} > {tol:.1e} (relaxation omega = {omega:g}); try a "
                           "smaller friction.mu", history)


def coulomb_bound(forms: FrictionForms, sigma_n: np.ndarray, mu_f: float,
                   noise: float) -> np.ndarray:
    """F of (3.123) (``FrictionForms.coulomb_bound_of``), zero where it vanishes.

    On a separated part of Gamma_C the normal stress entering F vanishes up to rounding
    errors of the stress scale; a bound made of rounding errors would turn the friction
    conditions there into conditions on noise, so F is zero where
    :func:`ngdual.tolerances.friction_vanishes` says so, with the round-off level ``noise``.
    """
    bound = forms.coulomb_bound_of(sigma_n, mu_f)
    bound[friction_vanishes(bound, noise)] = 0.0
    return bound
