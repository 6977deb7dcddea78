"""The ``ngdual`` command line.

``ngdual solve SCENE [--level N] [--set key=value ...] [--out DIR] [--vtk] [--no-plots]``
solves one scene, prints the result table and writes ``DIR/result.json``
(atomically) plus figures. ``ngdual scenes`` lists the shipped scenes;
``ngdual dofs SCENE --levels 1 2 3`` prints DOF counts without solving.
Exit status: 0 solved and converged, 1 not converged, 2 bad input.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .scene import SceneError, load_scene, shipped_scenes

EXIT_NOT_CONVERGED, EXIT_BAD_INPUT = 1, 2


def _table(record: dict) -> str:
    lines = [f"scene {record['scene']}  level {record['level']}  method {record['method']}  "
             f"converged {record['converged']}"]
    lines.append("dofs      " + "  ".join(f"{k}={v}" for k, v in record["dofs"].items()))
    lines.append("norms     " + "  ".join(f"{k}={v:.6e}" for k, v in record["norms"].items()
                                          if v is not None))
    lines.append("contact   " + "  ".join(f"{k}={v:.6g}" if isinstance(v, float) else f"{k}={v}"
                                          for k, v in record["contact"].items()))
    lines.append("iterations " + "  ".join(f"{k}={v}" for k, v in record["iterations"].items()))
    if record["residuals"]:
        lines.append("residuals " + "  ".join(f"{k}={v:.2e}"
                                              for k, v in record["residuals"].items()))
    lines.append("time [s]  " + "  ".join(f"{k}={v:.3f}"
                                          for k, v in record["timings_s"].items()))
    return "\n".join(lines)


def _progress():
    from tqdm import tqdm

    bar = tqdm(desc="Uzawa", unit="it", leave=False, file=sys.stderr,
               disable=not sys.stderr.isatty())

    def update(iteration: int, increment: float) -> None:
        bar.update(1)
        bar.set_postfix(increment=f"{increment:.1e}")
    return update


def cmd_solve(args) -> int:
    from . import plot, post
    from .io import write_json
    from .solve import solve_scene
    from .solvers.result import ConvergenceError

    scene = load_scene(args.scene, args.set)
    out = Path(args.out)
    try:
        solution = solve_scene(scene, args.level, progress=_progress())
    except ConvergenceError as err:
        print(f"ngdual: {err}", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    record = post.result_record(solution)
    print(_table(record))
    write_json(record, out / "result.json")
    print(f"wrote {out / 'result.json'}")
    if args.vtk:
        print(f"wrote {post.write_vtk(solution, str(out / 'solution'))}")
    if not args.no_plots:
        f = post.fields(solution)
        pts, tris, vm = post.element_values(solution.problem.fes.mesh,
                                            post.von_mises(f.sigma, scene.material.nu))
        written = [plot.plot_element_field(pts, tris, vm, out / "von_mises.png",
                                           f"Plane-strain von Mises stress, {scene.name}, "
                                           f"level {record['level']}", "stress units")]
        if solution.problem.spaces.contact is not None:
            written.append(plot.plot_contact_traces(post.contact_traces(solution),
                                                    out / "contact_traces.png",
                                                    f"Gamma_C traces, {scene.name}, "
                                                    f"level {record['level']}"))
        print("wrote " + ", ".join(str(p) for p in written))
    return 0 if solution.converged else EXIT_NOT_CONVERGED


def cmd_scenes(args) -> int:
    for name in shipped_scenes():
        scene = load_scene(name)
        print(f"{name:34s} {scene.geometry.kind:12s} friction={scene.friction.law:8s} "
              f"gap={scene.contact.gap}")
    return 0


def cmd_dofs(args) -> int:
    from .forms import Spaces
    from .mesh import build_mesh

    scene = load_scene(args.scene, args.set)
    print("level " + " ".join(f"{k:>9s}" for k in ("X", "M", "S", "N", "C", "L")))
    for level in args.levels:
        dofs = Spaces.build(scene, build_mesh(scene.geometry, level)).dofs()
        print(f"{level:5d} " + " ".join(f"{v:9d}" for v in dofs.values()))
    return 0


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="ngdual", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("solve", help="solve one scene and write DIR/result.json")
    s.add_argument("scene", help="path to a TOML scene or the name of a shipped scene")
    s.add_argument("--level", type=int, default=None, help="mesh level (default: the scene's)")
    s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene entry, e.g. --set friction.mu=0.5")
    s.add_argument("--out", default="out", help="output folder (default: out)")
    s.add_argument("--vtk", action="store_true", help="also write a VTK file for ParaView")
    s.add_argument("--no-plots", action="store_true", help="do not write PNG figures")
    s.set_defaults(func=cmd_solve)
    sc = sub.add_parser("scenes", help="list the shipped scenes")
    sc.set_defaults(func=cmd_scenes)
    d = sub.add_parser("dofs", help="degrees of freedom per level (Table 3.1), without solving")
    d.add_argument("scene")
    d.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4])
    d.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    d.set_defaults(func=cmd_dofs)
    return p


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    try:
        return args.func(args)
    except SceneError as err:
        print(f"ngdual: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
