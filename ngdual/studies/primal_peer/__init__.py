"""A primal peer for contact: P1/P2 displacements, Nitsche contact, semismooth Newton.

"The method a user would pick instead" of ngdual's dual-dual mixed method, the independent
solver of the work-precision study (``ngdual figures``) and of ``ngdual bench primal-peer``:
:mod:`~.nitsche` (the discretisation and the Newton solver, :func:`solve_primal`),
:mod:`~.result` (what it returns), :mod:`~.scenes` (an ngdual scene solved by it, on the
scene's mesh or any other: :func:`primal_solution`, public as ``nd.solve_primal``),
:mod:`~.cases` (Hertz and Cattaneo-Mindlin against their half-plane solutions).
"""

from .cases import cattaneo_mindlin_case, hertz_case, hertz_mesh, hertz_pressure
from .nitsche import NewtonError, solve_primal
from .result import PrimalResult
from .scenes import primal_arguments, primal_samples, primal_solution, solve_scene_primal

__all__ = ["NewtonError", "PrimalResult", "cattaneo_mindlin_case", "hertz_case", "hertz_mesh",
           "hertz_pressure", "primal_arguments", "primal_samples", "primal_solution",
           "solve_primal", "solve_scene_primal"]
