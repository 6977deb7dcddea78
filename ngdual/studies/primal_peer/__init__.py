"""A primal peer for contact: P1/P2 displacements, Nitsche contact, semismooth Newton.

"The method a user would pick instead" of ngdual's dual-dual mixed method, the independent
solver of the work-precision study (``ngdual figures``) and of ``ngdual bench primal-peer``:
:mod:`~.nitsche` (the discretisation and the Newton solver, :func:`solve_primal`),
:mod:`~.result` (what it returns), :mod:`~.adaptive` (the peer adapting by Kelly's indicator,
:func:`adapt_primal`), :mod:`~.scenes` (an ngdual scene solved by it, on the
scene's mesh or any other: :func:`primal_solution`, public as ``nd.solve_primal``),
:mod:`~.cases` (Hertz and Cattaneo-Mindlin against their half-plane solutions).
"""

from .adaptive import adapt_primal, kelly_indicators
from .cases import cattaneo_mindlin_case, hertz_case, hertz_mesh, hertz_pressure
from .nitsche import NewtonError, solve_primal
from .result import PrimalResult
from .scenes import (
    primal_arguments,
    primal_samples,
    primal_solution,
    solve_scene_primal,
    taylor_hood,
)

__all__ = ["NewtonError", "PrimalResult", "adapt_primal", "cattaneo_mindlin_case", "hertz_case",
           "hertz_mesh", "hertz_pressure", "kelly_indicators", "primal_arguments",
           "primal_samples", "primal_solution", "solve_primal", "solve_scene_primal",
           "taylor_hood"]
