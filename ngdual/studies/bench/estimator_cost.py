"""What the a posteriori estimator (4.50) costs against one linear solve on the same mesh
(``ngdual bench estimator-cost``).

For every level of a scene: solve it, then time (median of ``repeat`` runs)
``estimate(solution)`` and one linear solve of the saddle-point system of that mesh
(sparse LU factorisation plus one forward/back substitution), the cost unit of every
solver in :mod:`ngdual.solvers`.
"""

from __future__ import annotations

from .measure import header, median_seconds, solve_quietly, warning_messages

# the table ngdual bench estimator-cost prints: (title, key of a record, format)
COLUMNS = (("level", "level", "5d"), ("elements", "elements", "8d"), ("ndof", "ndof", "8d"),
           ("estimate [s]", "estimate_s", "12.4f"),
           ("linear solve [s]", "linear_solve_s", "16.4f"), ("ratio", "ratio", "6.2f"))


def one_level(scene: str, level: int, repeat: int) -> dict:
    """The estimator's and one linear solve's median times for ``scene`` on ``level``."""
    from ...estimator import estimate
    from ...scene import load_scene
    from ...solvers.linear import Factorization

    solution = solve_quietly(load_scene(scene), level)
    problem = solution.problem

    def linear_solve() -> None:
        saddle = problem.saddle
        Factorization(problem.block(saddle, saddle)).solve(problem.rhs[saddle])

    t_est = median_seconds(lambda: estimate(solution), repeat)
    t_lin = median_seconds(linear_solve, repeat)
    return {"scene": scene, "level": level, "elements": problem.fes.mesh.ne,
            "ndof": problem.n, "estimate_s": t_est, "linear_solve_s": t_lin,
            "ratio": t_est / t_lin, "warnings": warning_messages(solution)}


def run(scene: str, levels, repeat: int = 3, on_record=None) -> dict:
    """The records of ``scene`` on every level of ``levels``; ``on_record(study)`` after
    each."""
    study = header("estimator-cost", scene=scene, repeat=repeat)
    for level in levels:
        study["records"].append(one_level(scene, level, repeat))
        if on_record:
            on_record(study)
    return study
