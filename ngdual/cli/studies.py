"""``ngdual figures``, ``bench``, ``verify``, ``tutorials`` and ``show``: the run machinery of
:mod:`ngdual.studies` and :mod:`ngdual.verification`, and the picture of a scene before it is
solved, from the command line."""

from __future__ import annotations

import re
import sys
from pathlib import Path

from ..scene import SceneError
from .output import (
    EXIT_BAD_INPUT,
    EXIT_NOT_CONVERGED,
    level_flags,
    number_flag,
    runs_in_process,
)


def cmd_figures(args) -> int:
    """Regenerate the figures and tables of Sections 3.4 and 4.2 into DIR (see figures/)."""
    from .. import budget
    from ..io import check_output_dir
    from ..scene import Geometry
    from ..studies.figures import DEFAULT_MAX_LEVEL, THESIS_MAX_LEVEL, run_figures
    from ..studies.figures.run import select_scripts

    in_process = runs_in_process(args.threads,
                                 bool(args.scheduler) or args.workers is not None, "tasks")

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
                              not in_process, args.only, args.source)
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
    """One benchmark of :mod:`ngdual.studies.bench`: its table on stdout, row by row, and
    with --json its records (package versions, machine) in FILE, rewritten after each row."""
    from importlib import import_module

    from ..io import check_output_file, write_json

    module = import_module(f"..studies.bench.{args.benchmark.replace('-', '_')}", __package__)
    settings = BENCH_SETTINGS[args.benchmark](args)
    if args.json:
        check_output_file(args.json, "--json")
    columns = (module.COLUMNS[settings["case"]] if isinstance(module.COLUMNS, dict)
               else module.COLUMNS)
    print(" ".join(_cell(title, spec) for title, _, spec in columns))

    def on_record(study: dict) -> None:
        if args.json:
            write_json(study, args.json)
        print(_row(columns, study["records"][-1]), flush=True)

    study = module.run(**settings, on_record=on_record)
    if args.json:
        write_json(study, args.json)
        print(f"wrote {args.json}")
    converged = all(r.get("converged", True) for r in study["records"])
    return 0 if converged else EXIT_NOT_CONVERGED


def _cell(value, spec: str) -> str:
    """``value`` in the column format ``spec``; a title or a missing value (``-``) in a
    numeric column is aligned right."""
    if value is None or isinstance(value, str) and not spec.endswith("s"):
        width = re.match(r"\d*", spec).group() or "0"
        return format("-" if value is None else value, f">{width}")
    return format(value, spec)


def _row(columns, record: dict) -> str:
    """One record as a table row; a failed record says so after the row."""
    cells = []
    for _, key, spec in columns:
        value = record
        for part in key.split("."):
            value = value.get(part) if isinstance(value, dict) else None
        cells.append(_cell(value, spec))
    line = " ".join(cells)
    if record.get("converged") is False:
        line += "  NOT CONVERGED" + (f": {record['error']}" if record.get("error") else "")
    return line


def _known(flag: str, values, known) -> None:
    for value in values:
        if value not in known:
            raise SceneError(flag, f"unknown {flag[2:].rstrip('s')} {value!r}; use one of "
                                   + ", ".join(known))


def _sized_levels(args, scene_names, methods=("auto",)) -> list[int]:
    """``--levels`` checked as levels and against the memory the machine has, for every
    scene of ``scene_names`` and solver method of ``methods``."""
    from .. import budget
    from ..scene import load_scene

    levels = level_flags(args.levels, "--levels")
    for name in scene_names:
        geometry = load_scene(name, getattr(args, "overrides", [])).geometry
        for level in levels:
            for method in methods:
                budget.check(geometry, level, "--levels", args.allow_large, method=method)
    return levels


def _limit_ratio_settings(args) -> dict:
    from ..studies.bench.limit_ratio import CASES, SOLVERS

    _known("--cases", args.cases, CASES)
    _known("--solvers", args.solvers, SOLVERS)
    if args.timeout is not None:
        number_flag(args.timeout, "--timeout", 1e-3, 1e7)
    number_flag(args.blas_threads, "--blas-threads", 0, 1024, integer=True)
    methods = sorted({"active-set" if s == "active-set" else "uzawa" for s in args.solvers})
    return {"levels": _sized_levels(args, [CASES[c] for c in args.cases], methods),
            "cases": args.cases, "solvers": args.solvers, "isolate": args.isolate,
            "timeout": args.timeout, "blas_threads": args.blas_threads or None}


def _levels_settings(args) -> dict:
    return {"scene": args.scene, "levels": _sized_levels(args, [args.scene]),
            "overrides": args.overrides}


def _estimator_cost_settings(args) -> dict:
    number_flag(args.repeat, "--repeat", 1, 1000, integer=True)
    return {"scene": args.scene, "levels": _sized_levels(args, [args.scene]),
            "repeat": args.repeat}


def _infsup_settings(args) -> dict:
    return {"scenes": args.scenes, "levels": _sized_levels(args, args.scenes),
            "overrides": args.overrides}


def _primal_peer_settings(args) -> dict:
    from ..studies.bench.primal_peer import CASES

    _known("--case", [args.case], CASES)
    if args.law is not None and args.case != "cattaneo-mindlin":
        raise SceneError("--law", "the friction law is a setting of --case cattaneo-mindlin")
    number_flag(args.hc, "--hc", 1e-6, 1.0)
    for gamma0 in args.gammas:
        number_flag(gamma0, "--gammas", 1e-12, 1e12)
    physics = {k: v for k, v in (("nu", args.nu), ("law", args.law)) if v is not None}
    if "nu" in physics:
        number_flag(args.nu, "--nu", 0.0, 0.5 - 1e-12)
    return {"case": args.case, "orders": args.orders, "levels": level_flags(args.levels,
                                                                            "--levels"),
            "hc": args.hc, "thetas": args.thetas, "gammas": args.gammas, **physics}


def _adaptive_settings(args) -> dict:
    from .. import budget
    from ..afem import loop_defaults
    from ..loop_defaults import MAX_GROWTH
    from ..scene import ORDERS, check_level, load_scene

    level = check_level(args.level, "--level", optional=True)
    wrong = sorted(set(args.orders) - set(ORDERS))
    if wrong:
        raise SceneError("--orders", f"the order k of PEERS_k is one of "
                                     f"{', '.join(map(str, ORDERS))}, got "
                                     f"{', '.join(map(str, wrong))}")
    number_flag(args.tol, "--tol", 0, 1e3)
    tol = args.tol or None
    if args.steps is not None:
        number_flag(args.steps, "--steps", 1, 100, integer=True)
    if args.theta is not None:
        number_flag(args.theta, "--theta", 0, 1)
    if args.growth is not None:
        number_flag(args.growth, "--growth", 1, MAX_GROWTH)
    scene = load_scene(args.scene, args.overrides)
    if args.goal == "pressure" and not scene.labels("contact"):
        raise SceneError("--goal", f"scene {scene.name!r} has no contact boundary: no "
                                   "pressure to aim at; use --goal stress")
    budget.check_scene(scene, loop_defaults(tol, None, None, level)[2], "--level",
                       args.allow_large)
    return {"scene": args.scene, "overrides": args.overrides, "orders": args.orders,
            "goal": args.goal, "tol": tol, "level": level, "steps": args.steps,
            "theta": args.theta, "growth": args.growth, "allow_large": args.allow_large}


BENCH_SETTINGS = {"limit-ratio": _limit_ratio_settings, "levels": _levels_settings,
                  "estimator-cost": _estimator_cost_settings, "infsup": _infsup_settings,
                  "primal-peer": _primal_peer_settings, "adaptive": _adaptive_settings}


def cmd_verify(args) -> int:
    """Print the verification tables (:mod:`ngdual.verification.report`); ``--orders K ...``
    only those of the orders K of PEERS_k. Exit status 1 when a study fails its check
    (:func:`ngdual.verification.report.order_rows`)."""
    from ..io import check_output_file
    from ..scene import ORDERS
    from ..verification.report import run

    wrong = sorted(set(args.orders or ()) - set(ORDERS))
    if wrong:
        raise SceneError("--orders", f"the order k of PEERS_k is one of "
                                     f"{', '.join(map(str, ORDERS))}, got "
                                     f"{', '.join(map(str, wrong))}")
    if args.json:
        check_output_file(args.json, "--json")
    return run(args)


def cmd_tutorials(args) -> int:
    """List the tutorials; with --notebooks DIR write them (and their solutions) as notebooks;
    ``run NAME`` runs one as a script, headless, and lists the files it wrote."""
    from ..io import check_output_dir
    from ..studies.tutorials import find_tutorial, list_tutorials, run_tutorial, write_notebooks

    if args.action == "run":
        try:
            item = find_tutorial(args.name, args.source)
        except LookupError as err:
            raise SceneError("NAME", str(err)) from None
        except FileNotFoundError as err:
            raise SceneError("--source", str(err)) from None
        out = check_output_dir(args.out, "--out")
        status, written = run_tutorial(item, out, quick=True if args.quick else None)
        print(f"\n{item.name} wrote {len(written)} files:")
        for path in written:
            print(f"  {path}")
        if status:
            print(f"ngdual: tutorial {item.name} failed with exit status {status}",
                  file=sys.stderr)
            return 1
        return 0
    if args.notebooks:
        check_output_dir(args.notebooks, "--notebooks")
    try:
        items = list_tutorials(args.source)
        if args.notebooks:
            written = write_notebooks(args.notebooks, args.source, solutions=args.solutions)
    except FileNotFoundError as err:
        print(f"ngdual: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    if not args.notebooks:
        for item in items:
            print(f"{item.number:2d}  {item.title}  ({item.path})")
        print("run one with: ngdual tutorials run NAME (e.g. ngdual tutorials run "
              f"{items[0].name if items else '01'})")
        return 0
    for path in written:
        print(f"wrote {path}")
    print("open them with: jupyter lab " + str(args.notebooks) + "  (or execute one: "
          "jupyter nbconvert --to notebook --execute "
          f"{written[0] if written else 'NOTEBOOK'}; pip install \"ngdual[tutorials]\")")
    return 0


def cmd_show(args) -> int:
    """Draw SCENE's domain, its boundary parts with their labels and the mesh of --level
    (default 1, the initial mesh; :func:`ngdual.plot.plot_geometry`) into DIR/geometry.png,
    without solving."""
    from .. import budget
    from ..io import check_output_dir
    from ..mesh import build_mesh
    from ..plot import plot_geometry, save_figure
    from ..scene import check_level, load_scene

    level = check_level(args.level, "--level")
    scene = load_scene(args.scene, args.set)
    out = check_output_dir(args.out, "--out")
    budget.check_scene(scene, level, "--level", args.allow_large, mesh_only=True)
    mesh = build_mesh(scene.geometry, level)
    fig = plot_geometry(scene, mesh, title=f"{scene.name}: boundary parts and the mesh of "
                                           f"level {level} ({mesh.ne} triangles)")
    print(f"wrote {save_figure(fig, out / 'geometry.png')[0]}")
    return 0
