"""What every solver returns: the coarse unknown vector and an honest account of the iteration."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .forms import DiscreteProblem
from .friction import FrictionForms


class PhysicsWarning(UserWarning):
    """The category of the Python warnings :func:`ngdual.solvers.solve_scene` issues, one
    per failed physics check (:mod:`ngdual.checks`), e.g. to turn them into errors:
    ``warnings.simplefilter("error", PhysicsWarning)``."""


@dataclass(frozen=True)
class CheckWarning:
    """One failed physics check of a solution (:mod:`ngdual.checks`).

    ``code`` names the check, ``message`` is one line naming the cause, its size and the
    remedy, ``value`` is the measured size and ``tolerance`` the bound it exceeds.
    """

    code: str
    message: str
    value: float
    tolerance: float

    def __str__(self) -> str:
        return self.message


class ConvergenceError(RuntimeError):
    """An iteration that diverged or stagnated; ``history`` holds its residuals."""

    def __init__(self, message: str, history: list[float]):
        super().__init__(message)
        self.history = history


@dataclass
class Solution:
    """A discrete solution of (3.62) with its iteration record.

    ``x`` is ordered like ``problem.K``: (sigma, u, eta, phi, lambda_t, lambda_n).
    With friction, ``nu`` holds the h^ values of nu, ``friction_bound`` the final bound
    F per fine Gamma_C edge and ``friction_forms`` the fine-edge operators on Gamma_C the
    solver built (:class:`ngdual.friction.FrictionForms`: sigma_n, sigma_t per edge, Q_F of
    (3.95)), for post-processing to reuse rather than assemble again. ``settings`` are
    those the solution was computed with (:mod:`ngdual.solvers.settings`). ``warnings``
    lists the physics checks the solution fails (:class:`CheckWarning`,
    :func:`ngdual.checks.physics_checks`; filled by
    :func:`~ngdual.solvers.solve_problem`), empty for a solution to believe. ``trace`` is
    its contact trace once computed (:func:`ngdual.trace.contact_traces`: one per solution).
    ``roundoff`` is the relative round-off level of the computed unknowns where the solver
    measures it (the active-set method, :mod:`ngdual.solvers.active_set`): the accuracy to
    which two solves of the same problem can agree; ``residuals`` hold the convergence
    test's residuals only (:mod:`ngdual.solvers.convergence`). ``accuracy`` describes the
    adaptive run that produced a solution to a tolerance (:func:`ngdual.solve` with ``tol``,
    :func:`ngdual.accuracy.solve_to_tolerance`): its method, estimate, solves and time.
    """

    problem: DiscreteProblem
    x: np.ndarray
    converged: bool
    method: str
    iterations: dict = field(default_factory=lambda: {"outer": 0, "inner": 0})
    residuals: dict = field(default_factory=dict)
    history: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    nu: np.ndarray | None = None
    friction_bound: np.ndarray | None = None
    nu_l2: float | None = None
    friction_forms: FrictionForms | None = None
    settings: object | None = None
    warnings: list[CheckWarning] = field(default_factory=list)
    roundoff: float | None = None
    accuracy: dict | None = None
    trace: object | None = field(default=None, repr=False, compare=False)

    def part(self, *names: str) -> np.ndarray:
        return self.x[self.problem.index(*names)]
