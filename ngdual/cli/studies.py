"""``ngdual figures``, ``bench``, ``verify`` and ``tutorials``: the run machinery of
:mod:`ngdual.studies` and :mod:`ngdual.verification` from the command line."""

from __future__ import annotations

import sys
from pathlib import Path

from ..scene import SceneError
from .output import EXIT_BAD_INPUT, EXIT_NOT_CONVERGED, level_flags, number_flag


def cmd_figures(args) -> int:
    """Regenerate the figures and tables of Sections 3.4 and 4.2 into DIR (see figures/)."""
    from .. import budget
    from ..io import check_output_dir
    from ..scene import Geometry
    from ..studies.figures import DEFAULT_MAX_LEVEL, THESIS_MAX_LEVEL, run_figures
    from ..studies.figures.run import select_scripts

    max_level = DEFAULT_MAX_LEVEL if args.max_level is None else args.max_level
    number_flag(max_level, "--max-level", 2, THESIS_MAX_LEVEL, integer=True)
    if args.workers is not None:
        number_flag(args.workers, "--workers", 1, 256, integer=True)
    try:
        select_scripts(args.only, args.source)
    except SceneError as err:  # named by the Python argument; the user typed the flag
        raise SceneError(f"--{err.field}", err.problems[0][1]) from None
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
        from ..studies.figures import write_gallery

        for path in write_gallery(args.out, args.gallery):
            print(f"wrote {path}")
    return 1 if failed else 0


def cmd_bench(args) -> int:
    """Limit ratios of the contact solvers (ngdual.studies.bench): table on stdout, JSON
    with --json."""
    from .. import budget
    from ..io import check_output_file, write_json
    from ..scene import Geometry
    from ..studies.bench import CASES, SOLVERS, bench, summary_rows

    for flag, values, known in (("--cases", args.cases, CASES), ("--solvers", args.solvers,
                                                                  SOLVERS)):
        for value in values:
            if value not in known:
                raise SceneError(flag, f"unknown {flag[2:-1]} {value!r}; use one of "
                                       + ", ".join(known))
    levels = level_flags(args.levels, "--levels")
    if args.timeout is not None:
        number_flag(args.timeout, "--timeout", 1e-3, 1e7)
    number_flag(args.blas_threads, "--blas-threads", 0, 1024, integer=True)
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
    from ..io import check_output_file
    from ..verification.report import run

    if args.json:
        check_output_file(args.json, "--json")
    return run(args)


def cmd_tutorials(args) -> int:
    """List the tutorials; with --notebooks DIR write them (and their solutions) as notebooks."""
    from ..io import check_output_dir
    from ..studies.tutorials import list_tutorials, write_notebooks

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
