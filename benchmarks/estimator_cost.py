"""Cost of the a posteriori estimator (4.50) against one linear solve on the same mesh.

For every level of a scene: solve it, then time (median of ``--repeat`` runs)
``estimate(solution)`` and one linear solve of the saddle-point system of that
mesh (sparse LU factorisation plus one forward/back substitution), the cost
unit of every solver in :mod:`ngdual.solvers`. Prints a table, writes JSON.

    python benchmarks/estimator_cost.py --levels 1 2 3 4 5 --json out/bench-estimator.json
"""

from __future__ import annotations

import argparse
import json
import statistics
import time


def one_level(scene_name: str, level: int, repeat: int) -> dict:
    from ngdual.estimator import estimate
    from ngdual.scene import load_scene
    from ngdual.solvers import solve_scene
    from ngdual.solvers.linear import Factorization

    solution = solve_scene(load_scene(scene_name), level)
    problem = solution.problem

    def linear_solve() -> None:
        saddle = problem.saddle
        Factorization(problem.block(saddle, saddle)).solve(problem.rhs[saddle])

    def timed(fn) -> float:
        runs = []
        for _ in range(repeat):
            start = time.perf_counter()
            fn()
            runs.append(time.perf_counter() - start)
        return statistics.median(runs)

    t_est, t_lin = timed(lambda: estimate(solution)), timed(linear_solve)
    return {"scene": scene_name, "level": level, "elements": problem.fes.mesh.ne,
            "ndof": int(problem.K.shape[0]), "estimate_s": t_est, "linear_solve_s": t_lin,
            "ratio": t_est / t_lin}


def main() -> None:
    from ngdual.io import versions

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="thesis-3.46-frictionless")
    p.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--json", default=None, help="write the records to this JSON file")
    args = p.parse_args()
    rows = []
    print(f"{'level':>5} {'elements':>8} {'ndof':>8} {'estimate [s]':>12} "
          f"{'linear solve [s]':>16} {'ratio':>6}")
    for level in args.levels:
        row = one_level(args.scene, level, args.repeat)
        rows.append(row)
        print(f"{level:5d} {row['elements']:8d} {row['ndof']:8d} {row['estimate_s']:12.4f} "
              f"{row['linear_solve_s']:16.4f} {row['ratio']:6.2f}", flush=True)
    if args.json:
        from pathlib import Path

        from ngdual.io import write_json

        write_json({"rows": rows, "versions": versions()}, Path(args.json))
        print(f"wrote {args.json}")
    else:
        print(json.dumps(rows))


if __name__ == "__main__":
    main()
