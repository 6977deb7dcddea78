"""The numerical constants of the solvers, each in one place, and the rule for "F is zero here".

Every other tolerance of the solvers is derived from the problem at hand (the round-off level
of :mod:`ngdual.solvers.active_set`, the KKT tolerance of :mod:`ngdual.solvers.semismooth`)
or is a scene setting (``solver.eps`` and friends, defaults in :mod:`ngdual.scene`).

When is the friction bound zero?
--------------------------------
The bound F of (3.95) (given for Tresca, F = mu_f |sigma_n| of (3.123) for Coulomb) decides
where friction acts at all: an h^ edge with F = 0 has no friction condition, its nu is
arbitrary (Lemma 3.29). Computed values are never exactly zero where the body separates,
so one rule says when F, and the normal stress it is made of, count as zero:

    F is zero where |F| <= max(F_ZERO * max_{Gamma_C} |F|, noise),

relative to the largest value of the same quantity along Gamma_C (so it is independent of
units, load and mesh), F_ZERO = 1e-6. Why 1e-6 (measured on the Coulomb scenes shipped,
levels 1-4): on separated edges the hat moments of sigma_n that an iterative contact solve
leaves (Algorithms 3.38/3.41 at their default tolerances) are up to 3e-8 of the largest, a
direct solve leaves up to 7e-11 (nu = 0.4999); in contact they are above 1e-3 of the
largest and the bounds of the h^ edges above 3e-4 (cattaneo-mindlin, level 4, the last
edges of the contact zone). 1e-6 lies between, more than a decade and a half from each.
``noise`` is the round-off level of a vanishing value where a solver knows it (the
active-set solver: SAFETY delta_0 mu_f times its stress scale): it decides when even the
largest value is round-off, on a Gamma_C that is separated everywhere. The same rule
applies to quantities proportional to F (rows of Q_F) and, through their square root, to
those proportional to F^2 (the diagonal of the nu operator).
"""

from __future__ import annotations

import numpy as np

# The sparse factorisations (UMFPACK through NGSolve, CHOLMOD through cvxopt) bind to the
# first OpenBLAS in the process, NGSolve's, which is threaded. Measured on 2 shared cores:
# UMFPACK on Example 3.46, level 6 (247k unknowns), 64 s of CPU with threaded BLAS against
# 4.4 s with one thread; CHOLMOD, level 7, 8.7 s with two threads against 1.5 s with one
# (small dense updates dominated by spin-waiting threads when other processes compete).
# The dense work on Gamma_C (at most a few thousand unknowns) is as fast with one thread.
BLAS_THREADS = 1

# An iteration whose increment grows by this factor over its first one diverges (a step
# rho beyond the stability bound grows geometrically; a converging one never does).
DIVERGENCE_FACTOR = 1e6

# Clarabel (interior point, through cvxpy) to the accuracy of double precision: the QPs
# either are the independent solver the iterative ones are checked against to 1e-8 and
# below, or start a polish on the active set they find.
CLARABEL_TOLERANCES = {"tol_gap_abs": 1e-12, "tol_gap_rel": 1e-12, "tol_feas": 1e-12}
# the QP of the whole discrete problem (ngdual.solvers.qp): also the KKT ratio and a step bound
CLARABEL_WHOLE_PROBLEM = {**CLARABEL_TOLERANCES, "tol_ktratio": 1e-10, "max_iter": 500}

# Relative change of F at which the Coulomb fixed point of the active-set solver stops
# (it also stops where the change stagnates at its round-off level).
COULOMB_FIXED_POINT_TOL = 1e-12

F_ZERO = 1e-6  # F is zero where it is at most this fraction of its largest value (above)


def friction_vanishes(values: np.ndarray, noise: float = 0.0) -> np.ndarray:
    """Where a friction bound (or a quantity proportional to it) is zero (module docstring).

    >>> friction_vanishes(np.array([1.0, 1e-7, 1e-3, 0.0])).tolist()
    [False, True, False, True]
    >>> friction_vanishes(np.array([1e-17, 2e-17]), noise=1e-15).tolist()
    [True, True]
    """
    size = np.abs(values)
    return size <= max(F_ZERO * np.max(size, initial=0.0), noise)
