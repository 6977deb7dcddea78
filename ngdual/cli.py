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
linear solve of the same matrix (the limit ratio, :mod:`ngdual.studies.bench`).
``ngdual verify [--quick] [--json FILE]`` prints the errors against exact solutions with
observed orders (:mod:`ngdual.verification.report`).
Exit status: 0 solved and converged, 1 not converged, 2 bad input (one message naming
every field or flag at fault; nothing is written), 3 an internal error (a bug: the message
says so; ``ngdual --debug ...`` shows the traceback). Runs whose estimated size exceeds the
memory available are refused before meshing; ``--allow-large`` runs them anyway.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .scene import SceneError, check_level, load_scene, shipped_scenes

EXIT_NOT_CONVERGED, EXIT_BAD_INPUT, EXIT_INTERNAL = 1, 2, 3
HISTORY_ROWS = 8  # residuals shown when an iteration fails
LARGE_MESH = 2e5  # triangles: say so before meshing


def _history(err) -> str:
    """The last residuals of a failed iteration, on one line."""
    history = list(getattr(err, "history", None) or [])
    if not history:
        return ""
    start = len(history) - min(len(history), HISTORY_ROWS)
    rows = "  ".join(f"{start + k + 1}: {_residual(v)}" for k, v in enumerate(history[start:]))
    return f"\nngdual: residual history, last {len(history) - start} of {len(history)} " \
           f"steps (step: residual): {rows}"


def _residual(value) -> str:
    try:
        return f"{float(value):.3e}"
    except (TypeError, ValueError):
        return str(value)[:40]


def _not_converged(err) -> int:
    print(f"ngdual: not converged: {err}{_history(err)}", file=sys.stderr)
    return EXIT_NOT_CONVERGED


def _number(value, flag: str, low: float, high: float, integer: bool = False):
    """``value`` if it is a (finite) number in [low, high]; a SceneError naming ``flag``."""
    import math

    kind = "an integer" if integer else "a number"
    if value is None or not math.isfinite(value) or not low <= value <= high:
        raise SceneError(flag, f"must be {kind} in [{low:g}, {high:g}], got {value!r}")
    return value


def _levels(levels, flag: str) -> list[int]:
    return [check_level(level, flag) for level in levels]


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
    from . import budget, plot, post
    from .io import check_output_dir, write_json
    from .quantities import fields
    from .solvers import solve_scene
    from .solvers.result import ConvergenceError

    level = check_level(args.level, "--level", optional=True)
    scene = load_scene(args.scene, args.set)
    out = check_output_dir(args.out, "--out")
    size = budget.check(scene.geometry, level, "--level", args.allow_large,
                        method=scene.solver.method)
    if size.elements > LARGE_MESH:
        print(f"ngdual: {size.describe()}: meshing and solving take a while", file=sys.stderr)
    try:
        solution = solve_scene(scene, level, progress=_progress(), allow_large=args.allow_large)
    except ConvergenceError as err:
        return _not_converged(err)
    record = post.result_record(solution)
    print(_table(record))
    write_json(record, out / "result.json")
    print(f"wrote {out / 'result.json'}")
    if args.vtk:
        print(f"wrote {post.write_vtk(solution, str(out / 'solution'))}")
    if not args.no_plots:
        f = fields(solution)
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
    from . import budget
    from .forms import Spaces
    from .mesh import build_mesh

    levels = _levels(args.levels, "--levels")
    scene = load_scene(args.scene, args.set)
    for level in levels:
        budget.check(scene.geometry, level, "--levels", args.allow_large, mesh_only=True)
    print("level " + " ".join(f"{k:>9s}" for k in ("X", "M", "S", "N", "C", "L")))
    for level in levels:
        dofs = Spaces.build(scene, build_mesh(scene.geometry, level)).dofs()
        print(f"{level:5d} " + " ".join(f"{v:9d}" for v in dofs.values()))
    return 0


def cmd_adapt(args) -> int:
    """SOLVE -> ESTIMATE -> MARK -> REFINE; writes DIR/history.json and a mesh per step."""

    from . import budget, plot
    from .afem import adapt, reference_norms
    from .io import check_output_dir, versions, write_json
    from .mesh import mesh_arrays
    from .solvers.result import ConvergenceError

    level = check_level(args.level, "--level", optional=True)
    _number(args.theta, "--theta", 0, 1)
    _number(args.steps, "--steps", 1, 10_000, integer=True)
    if args.reference_levels is not None:
        _levels(args.reference_levels, "--reference-levels")
        if len(args.reference_levels) < 3:
            raise SceneError("--reference-levels", "Aitken extrapolation needs at least three "
                                                   f"levels, got {args.reference_levels}")
    scene = load_scene(args.scene, args.set)
    out = check_output_dir(args.out, "--out")
    budget.check(scene.geometry, level, "--level", args.allow_large, method=scene.solver.method)
    for reference in args.reference_levels or []:
        budget.check(scene.geometry, reference, "--reference-levels", args.allow_large,
                     method=scene.solver.method)
    run = {"scene": scene.name, "marking": args.marking, "theta": args.theta,
           "steps": args.steps, "level": level, "asymmetry": args.asymmetry,
           "parameters": scene.to_dict(), "versions": versions(), "history": []}
    if args.reference_levels:
        print(f"reference norms: Aitken extrapolation from levels {args.reference_levels}")
        run["reference_levels"] = args.reference_levels
        try:
            run["reference_norms"] = reference_norms(scene, args.reference_levels)
        except ConvergenceError as err:
            return _not_converged(err)

    def on_step(record, solution, estimate, marked):
        mesh = solution.problem.fes.mesh
        stem = out / f"mesh_step{record['step']:02d}"
        stem.parent.mkdir(parents=True, exist_ok=True)
        mesh.ngmesh.Save(str(stem) + ".vol")
        points, triangles = mesh_arrays(mesh)
        plot.plot_mesh(points, triangles, str(stem) + ".png",
                       f"{scene.name}, {args.marking} marking, step {record['step']}: "
                       f"{mesh.ne} triangles", marked)
        run["history"].append(record)
        write_json(run, out / "history.json")
        effectivity = record.get("effectivity")
        print(f"step {record['step']:3d}  dofs {record['dofs']['total']:8d}  "
              f"estimator {record['estimator']:.4e}" + (f"  e_tot {record['e_tot']:.4e}  eta/e_tot "
                                           f"{effectivity:.3f}" if effectivity else "")
              + f"  marked {record['marked']}")

    try:
        adapt(scene, args.marking, args.theta, args.steps, level, args.asymmetry,
              run.get("reference_norms"), on_step, allow_large=args.allow_large)
    except ConvergenceError as err:
        return _not_converged(err)
    write_json(run, out / "history.json")
    print(f"wrote {out / 'history.json'} and {len(run['history'])} meshes (.vol, .png)")
    return 0 if all(r["converged"] for r in run["history"]) else EXIT_NOT_CONVERGED


def cmd_figures(args) -> int:
    """Regenerate the figures and tables of Sections 3.4 and 4.2 into DIR (see figures/)."""
    from . import budget
    from .io import check_output_dir
    from .scene import Geometry
    from .studies.figures import DEFAULT_MAX_LEVEL, THESIS_MAX_LEVEL, run_figures

    max_level = DEFAULT_MAX_LEVEL if args.max_level is None else args.max_level
    _number(max_level, "--max-level", 2, THESIS_MAX_LEVEL, integer=True)
    if args.workers is not None:
        _number(args.workers, "--workers", 1, 256, integer=True)
    check_output_dir(args.out, "--out")
    if args.gallery:
        check_output_dir(args.gallery, "--gallery")
    budget.check(Geometry(), max_level, "--max-level", args.allow_large)
    try:
        summary = run_figures(max_level, args.out, args.scheduler, args.workers,
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
        from .studies.figures import write_gallery

        for path in write_gallery(args.out, args.gallery):
            print(f"wrote {path}")
    return 1 if failed else 0


def cmd_bench(args) -> int:
    """Limit ratios of the contact solvers (ngdual.studies.bench): table on stdout, JSON
    with --json."""
    from . import budget
    from .io import check_output_file, write_json
    from .scene import Geometry
    from .studies.bench import CASES, SOLVERS, bench, summary_rows

    for flag, values, known in (("--cases", args.cases, CASES), ("--solvers", args.solvers,
                                                                  SOLVERS)):
        for value in values:
            if value not in known:
                raise SceneError(flag, f"unknown {flag[2:-1]} {value!r}; use one of "
                                       + ", ".join(known))
    levels = _levels(args.levels, "--levels")
    if args.timeout is not None:
        _number(args.timeout, "--timeout", 1e-3, 1e7)
    _number(args.blas_threads, "--blas-threads", 0, 1024, integer=True)
    if args.json:
        check_output_file(args.json, "--json")
    methods = {"active-set" if s == "active-set" else "uzawa" for s in args.solvers}
    for level in levels:
        for method in methods:
            budget.check(Geometry(), level, "--levels", args.allow_large, method=method)
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

    run = bench(levels, args.cases, args.solvers, args.isolate, args.timeout, on_record,
                args.blas_threads or None)
    if args.json:
        write_json(run, args.json)
        print(f"wrote {args.json}")
    return 0 if all(r["converged"] for r in run["records"]) else EXIT_NOT_CONVERGED


def cmd_verify(args) -> int:
    from .io import check_output_file
    from .verification.report import run

    if args.json:
        check_output_file(args.json, "--json")
    return run(args)


def cmd_tutorials(args) -> int:
    """List the tutorials; with --notebooks DIR write them (and their solutions) as notebooks."""
    from .io import check_output_dir
    from .studies.tutorials import list_tutorials, write_notebooks

    if args.notebooks:
        check_output_dir(args.notebooks, "--notebooks")
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
    from . import __version__

    p = argparse.ArgumentParser(prog="ngdual", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"ngdual {__version__}",
                   help="print the version of ngdual and exit")
    p.add_argument("--debug", action="store_true",
                   help="show the Python traceback of any error (for developers)")
    # --debug after the subcommand too; SUPPRESS keeps a value given before it
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                        help=argparse.SUPPRESS)
    sized = argparse.ArgumentParser(add_help=False, parents=[common])
    sized.add_argument("--allow-large", action="store_true",
                       help="run even when the estimated memory exceeds what the machine has "
                            "available (the estimate is refused otherwise)")
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("solve", help="solve one scene and write DIR/result.json",
                       parents=[sized])
    s.add_argument("scene", help="path to a TOML scene or the name of a shipped scene")
    s.add_argument("--level", type=int, default=None, help="mesh level (default: the scene's)")
    s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene entry, e.g. --set friction.mu=0.5")
    s.add_argument("--out", default="out", help="output folder (default: out)")
    s.add_argument("--vtk", action="store_true", help="also write a VTK file for ParaView")
    s.add_argument("--no-plots", action="store_true", help="do not write PNG figures")
    s.set_defaults(func=cmd_solve)
    sc = sub.add_parser("scenes", help="list the shipped scenes", parents=[common])
    sc.set_defaults(func=cmd_scenes)
    d = sub.add_parser("dofs", help="degrees of freedom per level (Table 3.1), without solving",
                       parents=[sized])
    d.add_argument("scene")
    d.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4])
    d.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    d.set_defaults(func=cmd_dofs)
    ad = sub.add_parser("adapt", help="adaptive refinement (Chapter 4), writes DIR/history.json",
                        parents=[sized])
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
    tu = sub.add_parser("tutorials", help="list the tutorials or write them as notebooks",
                        parents=[common])
    tu.add_argument("--notebooks", metavar="DIR", default=None,
                    help="write the tutorials as .ipynb notebooks into DIR (needs jupytext)")
    tu.add_argument("--solutions", action="store_true",
                    help="with --notebooks: also write the exercise solutions to DIR/solutions")
    tu.add_argument("--source", metavar="DIR", default=None,
                    help="tutorials folder (default: tutorials/ of the source checkout)")
    tu.set_defaults(func=cmd_tutorials)
    fg = sub.add_parser("figures", help="regenerate every figure and table of Sections 3.4 "
                                        "and 4.2 (and the work-precision study)",
                        parents=[sized])
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
                                      "solver (Example 3.46), JSON with --json",
                        parents=[sized])
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
    ve = sub.add_parser("verify", help="errors against exact solutions: manufactured contact "
                                       "problems and the Hertz, flat-punch and "
                                       "Cattaneo-Mindlin benchmarks, with observed orders")
    ve.add_argument("--quick", action="store_true",
                    help="two levels of two manufactured cases and of every benchmark (~20 s)")
    ve.add_argument("--json", default=None, metavar="FILE",
                    help="also write every row (with package versions) to FILE, atomically")
    ve.set_defaults(func=cmd_verify)
    return p


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (see the module docstring).

    Users never see a traceback: bad input is one message naming the field or flag
    (status 2), anything unexpected one line saying it is a bug (status 3);
    ``--debug`` lets every exception through with its traceback.
    """
    try:
        args = parser().parse_args(argv)
    except SystemExit as err:  # argparse printed the usage error (or the help)
        return err.code if isinstance(err.code, int) else EXIT_BAD_INPUT
    if args.debug:
        return args.func(args)
    try:
        return args.func(args)
    except SceneError as err:
        print(f"ngdual: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except MemoryError:
        print("ngdual: error: out of memory; choose a coarser level or maxh", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("ngdual: interrupted", file=sys.stderr)
        return 130
    except Exception as err:  # a bug: one line, the traceback with --debug
        print(f"ngdual: internal error: {type(err).__name__}: {str(err)[:500]} (a bug in "
              "ngdual: run again with --debug for the traceback and report it)",
              file=sys.stderr)
        return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
