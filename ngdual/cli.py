"""The ``ngdual`` command line.

``ngdual solve SCENE [--level N] [--set key=value ...] [--out DIR] [--vtk] [--no-plots]``
solves one scene, prints the result table and writes ``DIR/result.json``
(atomically) plus figures. ``ngdual scenes`` lists the shipped scenes;
``ngdual dofs SCENE --levels 1 2 3`` prints DOF counts without solving;
``ngdual adapt SCENE --marking max|fraction|dorfler --theta T --steps N --out DIR``
runs the adaptive loop and writes ``DIR/history.json`` plus a mesh (.vol, .png) per step.
``ngdual tutorials [--notebooks DIR] [--solutions]`` lists the lecture tutorials or
writes them as Jupyter notebooks.
``ngdual bench [--levels ...] [--json FILE]`` times the contact solvers against one
linear solve of the same matrix (the limit ratio, :mod:`ngdual.bench`).
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
              f"gap={'foundation line' if scene.contact.foundation else scene.contact.gap_formula}")
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


def cmd_adapt(args) -> int:
    """SOLVE -> ESTIMATE -> MARK -> REFINE; writes DIR/history.json and a mesh per step."""
    import ngsolve as ngs
    import numpy as np

    from . import plot
    from .afem import adapt, reference_norms
    from .io import write_json
    from .post import versions
    from .solvers.result import ConvergenceError

    scene = load_scene(args.scene, args.set)
    if not 0 <= args.theta <= 1:
        raise SceneError("--theta", f"must lie in [0, 1], got {args.theta}")
    if args.steps < 1:
        raise SceneError("--steps", f"must be >= 1, got {args.steps}")
    out = Path(args.out)
    run = {"scene": scene.name, "marking": args.marking, "theta": args.theta,
           "steps": args.steps, "level": args.level, "asymmetry": args.asymmetry,
           "parameters": scene.to_dict(), "versions": versions(), "history": []}
    if args.reference_levels:
        print(f"reference norms: Aitken extrapolation from levels {args.reference_levels}")
        run["reference_levels"] = args.reference_levels
        run["reference_norms"] = reference_norms(scene, args.reference_levels)

    def on_step(record, solution, estimate, marked):
        mesh = solution.problem.fes.mesh
        stem = out / f"mesh_step{record['step']:02d}"
        stem.parent.mkdir(parents=True, exist_ok=True)
        mesh.ngmesh.Save(str(stem) + ".vol")
        points = np.array([v.point for v in mesh.vertices])
        triangles = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ngs.VOL)])
        plot.plot_mesh(points, triangles, str(stem) + ".png",
                       f"{scene.name}, {args.marking} marking, step {record['step']}: "
                       f"{mesh.ne} triangles", marked)
        run["history"].append(record)
        write_json(run, out / "history.json")
        effectivity = record.get("effectivity")
        print(f"step {record['step']:3d}  dofs {record['dofs']['total']:8d}  "
              f"eta {record['eta']:.4e}" + (f"  e_tot {record['e_tot']:.4e}  eta/e_tot "
                                           f"{effectivity:.3f}" if effectivity else "")
              + f"  marked {record['marked']}")

    try:
        adapt(scene, args.marking, args.theta, args.steps, args.level, args.asymmetry,
              run.get("reference_norms"), on_step)
    except ConvergenceError as err:
        print(f"ngdual: {err}", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    write_json(run, out / "history.json")
    print(f"wrote {out / 'history.json'} and {len(run['history'])} meshes (.vol, .png)")
    return 0 if all(r["converged"] for r in run["history"]) else EXIT_NOT_CONVERGED


def cmd_figures(args) -> int:
    """Regenerate the figures and tables of Sections 3.4 and 4.2 into DIR (see figures/)."""
    from .figures import run_figures

    try:
        summary = run_figures(args.max_level, args.out, args.scheduler, args.workers,
                              not args.threads, args.only, args.source)
    except (FileNotFoundError, ValueError) as err:
        print(f"ngdual: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    failed = {k: v for k, v in summary["scripts"].items() if v["status"] != "ok"}
    print(f"{len(summary['scripts'])} scripts, {summary['tasks']} tasks "
          f"({summary['computed_tasks']} computed, {len(summary['failed_tasks'])} not ok) "
          f"in {summary['seconds']:.0f} s; wrote {Path(args.out) / 'index.md'}")
    for stem, info in failed.items():
        print(f"ngdual: figure script {stem}: {info['status']}", file=sys.stderr)
    if args.gallery:
        from .figures import write_gallery

        for path in write_gallery(args.out, args.gallery):
            print(f"wrote {path}")
    return 1 if failed else 0


def cmd_bench(args) -> int:
    """Limit ratios of the contact solvers (ngdual.bench): table on stdout, JSON with --json."""
    from .bench import CASES, SOLVERS, bench, summary_rows
    from .io import write_json

    bad = [c for c in args.cases if c not in CASES] + [s for s in args.solvers if s not in SOLVERS]
    if bad:
        print(f"ngdual: error: unknown case or solver {bad[0]!r}; cases: {', '.join(CASES)}; "
              f"solvers: {', '.join(SOLVERS)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    header = (f"{'case':20s} {'lvl':>3} {'solver':12s} {'unknowns':>9} {'assemble':>8} "
              f"{'linear':>8} {'contact':>8} {'ratio':>6} {'r_fast':>6} {'outer':>6} "
              f"{'inner':>6} {'RSS MB':>7}")
    print(header)

    def on_record(run):
        if args.json:
            write_json(run, args.json)
        row = summary_rows({"records": run["records"][-1:]})[0]
        if row["total"] is None:
            print(f"{row['case']:20s} {row['level']:3d} {row['solver']:12s}  {row['error']}")
            return
        print(f"{row['case']:20s} {row['level']:3d} {row['solver']:12s} {row['ndof']:9d} "
              f"{row['assemble']:8.2f} {row['linear']:8.2f} {row['total']:8.2f} "
              f"{row['ratio']:6.2f} {row['ratio_fastest']:6.2f} {row['outer']!s:>6} "
              f"{row['inner']!s:>6} {row['rss']:7.0f}"
              + ("" if row["converged"] else f"  NOT CONVERGED {row['error'] or ''}"),
              flush=True)

    run = bench(args.levels, args.cases, args.solvers, args.isolate, args.timeout, on_record,
                args.blas_threads or None)
    if args.json:
        write_json(run, args.json)
        print(f"wrote {args.json}")
    return 0 if all(r["converged"] for r in run["records"]) else EXIT_NOT_CONVERGED


def cmd_tutorials(args) -> int:
    """List the tutorials; with --notebooks DIR write them (and their solutions) as notebooks."""
    from .tutorials import list_tutorials, write_notebooks

    try:
        items = list_tutorials(args.source)
        if args.notebooks:
            written = write_notebooks(args.notebooks, args.source, solutions=args.solutions)
    except (FileNotFoundError, ImportError) as err:
        print(f"ngdual: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    if not args.notebooks:
        for item in items:
            print(f"{item.number:2d}  {item.title}  ({item.path})")
        return 0
    for path in written:
        print(f"wrote {path}")
    print("execute one with: NGDUAL_QUICK=1 jupyter nbconvert --to notebook --execute "
          f"{written[0] if written else 'NOTEBOOK'}")
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
    ad = sub.add_parser("adapt", help="adaptive refinement (Chapter 4), writes DIR/history.json")
    ad.add_argument("scene")
    ad.add_argument("--marking", choices=["max", "fraction", "dorfler"], default="dorfler")
    ad.add_argument("--theta", type=float, default=0.5, help="marking parameter in [0, 1]")
    ad.add_argument("--steps", type=int, default=5, help="number of solves (default 5)")
    ad.add_argument("--level", type=int, default=None, help="initial mesh level")
    ad.add_argument("--asymmetry", choices=["hdiv", "l2"], default="l2",
                    help="norm of as(sigma_h) in the estimator (default: L2; 'hdiv' as printed "
                         "in eq. 4.15 does not decrease for PEERS)")
    ad.add_argument("--reference-levels", type=int, nargs="+", default=None, metavar="LEVEL",
                    help="uniform levels whose norms give, by Aitken extrapolation, the "
                         "reference for the total error (3.124) and the effectivity index")
    ad.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ad.add_argument("--out", default="out-adapt", help="output folder (default: out-adapt)")
    ad.set_defaults(func=cmd_adapt)
    tu = sub.add_parser("tutorials", help="list the tutorials or write them as notebooks")
    tu.add_argument("--notebooks", metavar="DIR", default=None,
                    help="write the tutorials as .ipynb notebooks into DIR (needs jupytext)")
    tu.add_argument("--solutions", action="store_true",
                    help="with --notebooks: also write the exercise solutions to DIR/solutions")
    tu.add_argument("--source", metavar="DIR", default=None,
                    help="tutorials folder (default: tutorials/ of the source checkout)")
    tu.set_defaults(func=cmd_tutorials)
    fg = sub.add_parser("figures", help="regenerate every figure and table of Sections 3.4 "
                                        "and 4.2 (and the work-precision study)")
    fg.add_argument("--max-level", type=int, default=None, metavar="K",
                    help="finest uniform level; every other size follows from it "
                         "(default 5: 8-11 min on 2 cores; 8 = the thesis scale)")
    fg.add_argument("--out", default="figures-output", help="output folder (default: "
                                                            "figures-output)")
    fg.add_argument("--scheduler", default=None, metavar="ADDRESS",
                    help="address of a running dask scheduler (default: a LocalCluster)")
    fg.add_argument("--workers", type=int, default=None,
                    help="LocalCluster workers (default: one per CPU core)")
    fg.add_argument("--threads", action="store_true",
                    help="one LocalCluster worker thread in this process: quick to start, one "
                         "task at a time")
    fg.add_argument("--only", nargs="+", default=None, metavar="NAME",
                    help="run only the scripts whose name contains one of these")
    fg.add_argument("--source", default=None, metavar="DIR",
                    help="figure scripts folder (default: figures/ of the source checkout)")
    fg.add_argument("--gallery", default=None, metavar="DIR",
                    help="also write small copies of a few figures into DIR (docs/gallery "
                         "for the README)")
    fg.set_defaults(func=cmd_figures)
    be = sub.add_parser("bench", help="contact-solve time / one linear solve, per level and "
                                      "solver (Example 3.46), JSON with --json")
    be.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    be.add_argument("--cases", nargs="+", default=["thesis-3.46", "thesis-3.46-coulomb"])
    be.add_argument("--solvers", nargs="+", default=["uzawa", "uzawa-tuned", "active-set"])
    be.add_argument("--json", default=None, metavar="FILE",
                    help="write all records (with package versions) to FILE, atomically")
    be.add_argument("--isolate", choices=["auto", "always", "never"], default="auto",
                    help="one process per record for its own peak memory (auto: level >= 4)")
    be.add_argument("--timeout", type=float, default=None, metavar="S",
                    help="bound on one isolated record (s)")
    be.add_argument("--blas-threads", type=int, default=1, metavar="N",
                    help="BLAS threads for every solver (default 1; 0: the libraries' own)")
    be.set_defaults(func=cmd_bench)
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
