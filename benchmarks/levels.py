"""One scene on levels 1..K: DOFs, iterations (outer/inner), times, peak memory, norms.

Each level runs in its own process so that the peak resident memory is per level.

    python benchmarks/levels.py --levels 1 2 3 4 5 6 --json out/bench-frictionless.json
    python benchmarks/levels.py --scene thesis-3.46-coulomb --levels 1 2 3 4 5
"""

from __future__ import annotations

import argparse
import json
import platform
import resource
import subprocess
import sys


def one_level(scene_name: str, level: int, overrides: list[str]) -> dict:
    from ngdual.io import versions
    from ngdual.quantities import norms
    from ngdual.scene import load_scene
    from ngdual.solvers import solve_scene

    scene = load_scene(scene_name, overrides)
    sol = solve_scene(scene, level)
    dofs = sol.problem.spaces.dofs()
    return {"scene": scene_name, "level": level, "overrides": overrides,
            "ndof": int(sol.problem.K.shape[0]), "dofs": dofs,
            "converged": sol.converged, "iterations": sol.iterations,
            "timings_s": sol.timings, "norms": norms(sol),
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "versions": versions()}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4, 5, 6])
    p.add_argument("--scene", default="thesis-3.46-frictionless")
    p.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="scene override, e.g. --set solver.metric=\"euclidean\"")
    p.add_argument("--json", default=None, help="write all records to this JSON file")
    p.add_argument("--one", type=int, default=None, help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.one is not None:
        print(json.dumps(one_level(args.scene, args.one, args.set)))
        return
    rows = []
    machine = platform.processor() or platform.machine()
    print(f"{args.scene} {' '.join(args.set)}; machine: {machine}, "
          f"python {platform.python_version()}")
    print(f"{'lvl':>3} {'unknowns':>9} {'outer':>6} {'inner':>6} {'assemble':>9} "
          f"{'factor':>8} {'condense':>8} {'iterate':>8} {'total':>8} {'RSS MB':>7} "
          f"{'sigma_X':>12} {'u':>11} {'eta':>11} {'phi':>11} "
          f"{'lam_t':>11} {'lam_n':>11}")
    for level in args.levels:
        sets = [f"--set={s}" for s in args.set]
        out = subprocess.run([sys.executable, __file__, "--one", str(level), "--scene",
                              args.scene, *sets], check=True, capture_output=True,
                             text=True).stdout
        r = json.loads(out.strip().splitlines()[-1])
        rows.append(r)
        t, n = r["timings_s"], r["norms"]
        its = r["iterations"]
        print(f"{level:3d} {r['ndof']:9d} {its['outer']:6d} {its['inner']:6d} {t['assemble']:9.2f} "
              f"{t['factorize']:8.2f} {t.get('condense', 0.0):8.2f} {t['solve']:8.2f} "
              f"{t['total']:8.2f} "
              f"{r['peak_rss_mb']:7.0f} {n['sigma_X']:12.6e} {n['u']:11.5e} {n['eta']:11.5e} "
              f"{n['phi']:11.5e} {n['lam_t']:11.5e} {n['lam_n']:11.5e}", flush=True)
    if args.json:
        from ngdual.io import write_json

        write_json({"case": args.scene, "overrides": args.set, "records": rows}, args.json)


if __name__ == "__main__":
    main()
