"""``ngdual solve``, ``scenes``, ``dofs`` and ``adapt``: the pipeline from the command line."""

from __future__ import annotations

import sys
import warnings

from ..loop_defaults import MAX_GROWTH
from ..scene import SceneError, check_level, load_scene, read_toml, shipped_scenes
from ..solution import PhysicsWarning
from .output import (
    EXIT_NOT_CONVERGED,
    LARGE_MESH,
    PhaseStatus,
    StrictFailure,
    level_flags,
    not_converged,
    number_flag,
    progress_bar,
    result_table,
    strict_failure,
    summary_table,
    warning_lines,
)

# adapt stopped by the memory budget (stopped_by = "memory"): before a refinement that would
# not fit, or at a solve that ran out of memory; history.json keeps the steps before
EXIT_MEMORY = 5


def cmd_solve(args) -> int:
    from .. import budget, post
    from ..io import check_output_dir, write_json
    from ..solution import ConvergenceError
    from ..solvers import solve_scene
    from ..summary import solution_summary
    from ..verification.benchmark import NAMES, benchmark_traces

    level = check_level(args.level, "--level", optional=True)
    if args.tol is not None:
        number_flag(args.tol, "--tol", 1e-6, 0.5)
    scene = load_scene(args.scene, args.set)
    out = check_output_dir(args.out, "--out")
    if args.tol is None or level is not None:
        size = budget.check_scene(scene, level, "--level", args.allow_large)
        large = size.elements > LARGE_MESH
        if large:
            print(f"ngdual: {size.describe()}: meshing and solving take a while",
                  file=sys.stderr)
    else:  # the adaptive loop stops before a step that would not fit (stopped_by memory)
        large = False
    status = PhaseStatus(sys.stderr.isatty() or large)
    iterations = progress_bar("Uzawa" if scene.solver.method == "uzawa" else "Newton")
    try:
        with warnings.catch_warnings():  # printed after the result table instead
            warnings.simplefilter("ignore", PhysicsWarning)
            if args.tol is None:
                solution = solve_scene(scene, level, progress=iterations,
                                       allow_large=args.allow_large, status=status)
            else:
                from ..accuracy import solve_to_tolerance

                status(f"solving to a relative error of {args.tol:g}")
                solution = solve_to_tolerance(scene, args.tol, level=level,
                                              allow_large=args.allow_large)
    except ConvergenceError as err:
        status.done()
        return not_converged(err)
    status("post-processing")
    record = post.result_record(solution)
    bench = benchmark_traces(solution) if solution.problem.spaces.contact is not None else None
    record["summary"] = solution_summary(solution, *(bench.solution, NAMES[scene.benchmark.kind])
                                         if bench else ())
    status.done()
    print(summary_table(record["summary"]))
    print(result_table(record))
    if record["warnings"]:
        print(warning_lines(record["warnings"]))
        if args.strict:
            return strict_failure(StrictFailure(record["warnings"], "the solution",
                                                "nothing written"))
    write_json(record, out / "result.json")
    print(f"wrote {out / 'result.json'}")
    if args.vtk:
        print("wrote " + ", ".join(post.write_vtk(solution, str(out / "solution"))))
    if not args.no_plots:
        where = None if solution.accuracy is None else \
            f"adaptive step {solution.accuracy['solves']}"
        print("wrote " + ", ".join(str(p) for p in solution_figures(solution, out,
                                                                    where=where)))
    return 0 if solution.converged else EXIT_NOT_CONVERGED


def solution_figures(solution, out, prefix: str = "", where: str | None = None) -> list:
    """von_mises.png (colour scale clipped: the corners are singular), deformed.png (the
    body moved by u_h, the magnification in its title) and, with contact,
    contact_traces.png (p_h, q_h against the analytic solution of the scene's
    ``[benchmark]``, if it names one), labelled in the scene's units; the file names start
    with ``prefix``, the titles say ``where`` the mesh comes from (default: its level)."""
    from .. import plot, post
    from ..quantities import fields
    from ..verification.benchmark import benchmark_traces

    scene = solution.problem.scene
    where = where or f"level {solution.problem.level}"
    fig = plot.plot_von_mises(solution.problem.fes.mesh, fields(solution).sigma,
                              scene.material.nu,
                              f"Plane-strain von Mises stress, {scene.name}, {where}",
                              units=scene.units)
    written = plot.save_figure(fig, out / f"{prefix}von_mises.png")
    fig = plot.plot_deformed(solution)
    fig.axes[0].set_title(fig.axes[0].get_title().replace(f"level {solution.problem.level}",
                                                          where))
    written += plot.save_figure(fig, out / f"{prefix}deformed.png")
    if solution.problem.spaces.contact is not None:
        fig = plot.plot_contact_traces(post.contact_traces(solution),
                                       f"Gamma_C traces, {scene.name}, {where}",
                                       units=scene.units, exact=benchmark_traces(solution))
        written += plot.save_figure(fig, out / f"{prefix}contact_traces.png")
    return written


def adapt_figures(run: dict, solution, out) -> list:
    """convergence.png (the goal's relative estimate against unknowns and wall time, the
    --tol line; :func:`ngdual.plot.plot_convergence`) and the pictures of the last step's
    solution, final_*.png: its mesh, von Mises stress, deformed body and contact traces."""
    from .. import plot
    from ..mesh import mesh_arrays

    scene, mesh = solution.problem.scene, solution.problem.fes.mesh
    written = plot.save_figure(plot.plot_convergence(
        run["history"], run["tol"], f"{scene.name}: {run['marking']} marking, goal "
                                    f"{run['goal']}"), out / "convergence.png")
    points, triangles = mesh_arrays(mesh)
    written += plot.save_figure(plot.plot_mesh(
        points, triangles, f"{scene.name}, final mesh (step {run['history'][-1]['step']}): "
                           f"{mesh.ne} triangles", units=scene.units), out / "final_mesh.png")
    return written + solution_figures(solution, out, "final_", f"final mesh ({mesh.ne} "
                                                                "triangles)")


def cmd_scenes(args) -> int:
    """Each shipped scene: name, geometry, friction law, and its description wrapped below."""
    import textwrap

    for name in shipped_scenes():
        scene, description = load_scene(name), read_toml(name)[1].get("description", "")
        print(f"{name:30s} {scene.geometry.kind:12s} friction={scene.friction.law}")
        print(textwrap.fill(description, width=88, initial_indent="    ",
                            subsequent_indent="    "))
    return 0


def cmd_dofs(args) -> int:
    from .. import budget
    from ..forms import Spaces
    from ..mesh import build_mesh

    levels = level_flags(args.levels, "--levels")
    scene = load_scene(args.scene, args.set)
    for level in levels:
        budget.check_scene(scene, level, "--levels", args.allow_large, mesh_only=True)
    print("level " + " ".join(f"{k:>9s}" for k in ("X", "M", "S", "N", "C", "L")))
    for level in levels:
        dofs = Spaces.build(scene, build_mesh(scene.geometry, level)).dofs()
        print(f"{level:5d} " + " ".join(f"{v:9d}" for v in dofs.values()))
    return 0


def cmd_adapt(args) -> int:
    """SOLVE -> ESTIMATE -> MARK -> REFINE; writes DIR/history.json and a mesh per step
    (.vol, and .png with the marked triangles shaded), with --vtk a VTK file per step.
    The failed physics checks of every step are printed below its line and kept in its
    record; with --strict the run stops at the first step that has one, writing nothing
    for that step (history.json then holds the steps before it, if any). A --tol that the
    run does not reach (it stops by its steps, stalls, reaches the smallest triangle it
    refines, or its goal's error is not finite: "singular", also below the tol) is exit
    status 1, with the reason; one reached where the goal's estimate is
    known to be too small (the pressure goal at a kink of Gamma_C) is 0, with that caution
    below the last step. A pressure goal whose window holds no contact stops on the first
    solve ("no_contact", status 1). A run whose next refinement would not fit in memory
    stops before it, and one whose solve runs out of memory stops there ("memory", status
    EXIT_MEMORY = 5, history.json kept)."""
    from ..afem import AdaptWarning

    with warnings.catch_warnings():  # the reference solves' checks are not the run's
        warnings.simplefilter("ignore", PhysicsWarning)
        warnings.simplefilter("ignore", AdaptWarning)   # said below (stop_message)
        return _adapt(args)


def _adapt(args) -> int:

    from .. import budget, plot, post
    from ..afem import adapt, growth_default, loop_defaults, reference_norms
    from ..io import check_output_dir, versions, write_json
    from ..mesh import mesh_arrays
    from ..solution import ConvergenceError

    level = check_level(args.level, "--level", optional=True)
    if args.theta is not None:
        number_flag(args.theta, "--theta", 0, 1)
    if args.steps is not None:
        number_flag(args.steps, "--steps", 1, 10_000, integer=True)
    if args.growth is not None:
        number_flag(args.growth, "--growth", 1, MAX_GROWTH)
    if args.tol is not None and not 0 < args.tol < float("inf"):
        raise SceneError("--tol", f"must be a finite number > 0, got {args.tol}")
    if args.window is not None and args.goal != "pressure":
        raise SceneError("--window", "selects part of Gamma_C for --goal pressure")
    if args.window is not None and not -float("inf") < args.window[0] < args.window[1] \
            < float("inf"):
        raise SceneError("--window", f"must be finite with LO < HI, got {args.window}")
    if args.reference_levels is not None:
        level_flags(args.reference_levels, "--reference-levels")
        if len(args.reference_levels) < 3:
            raise SceneError("--reference-levels", "Aitken extrapolation needs at least three "
                                                   f"levels, got {args.reference_levels}")
    scene = load_scene(args.scene, args.set)
    out = check_output_dir(args.out, "--out")
    theta, steps, level = loop_defaults(args.tol, args.theta, args.steps, level)
    growth = growth_default(args.tol, args.growth)
    budget.check_scene(scene, level, "--level", args.allow_large)
    for reference in args.reference_levels or []:
        budget.check_scene(scene, reference, "--reference-levels", args.allow_large)
    run = {"scene": scene.name, "marking": args.marking, "theta": theta, "growth": growth,
           "steps": steps, "level": level, "asymmetry": args.asymmetry,
           "goal": args.goal, "tol": args.tol, "window": args.window,
           "parameters": scene.to_dict(), "versions": versions(), "history": []}
    if args.reference_levels:
        print(f"reference norms: Aitken extrapolation from levels {args.reference_levels}")
        run["reference_levels"] = args.reference_levels
        try:
            run["reference_norms"] = reference_norms(scene, args.reference_levels)
        except ConvergenceError as err:
            return not_converged(err)

    final = {}
    print(f"estimate (stress, absolute): ||eta_tot|| of (4.50); {args.goal} (relative): the "
          f"goal's estimate over the size of what it measures" + (", compared with --tol"
                                                                 if args.tol else ""))

    def on_step(record, solution, estimated, marked):
        effectivity = record.get("effectivity")
        final["solution"] = solution
        line = (f"step {record['step']:3d}  dofs {record['dofs']['total']:8d}  "
                f"estimate (stress, absolute) {record['estimator']:.4e}"
                + (f"  e_tot {record['e_tot']:.4e}  effectivity {effectivity:.3f}"
                   if effectivity else "")
                + f"  {record['goal']} (relative) {record['relative_estimate']:.3e}"
                + f"  marked {record['marked']}  {record['elapsed_s']:.1f} s"
                + (f"  (stopped by {record['stopped_by']})" if "stopped_by" in record
                   else ""))
        if args.strict and record["warnings"]:
            print(line + "\n" + warning_lines(record["warnings"], "    "))
            step = record["step"]
            raise StrictFailure(record["warnings"], f"step {step}",
                                f"history.json holds the {step} steps before it" if step
                                else "nothing written")
        mesh = solution.problem.fes.mesh
        stem = out / f"mesh_step{record['step']:02d}"
        stem.parent.mkdir(parents=True, exist_ok=True)
        mesh.ngmesh.Save(str(stem) + ".vol")
        points, triangles = mesh_arrays(mesh)
        plot.save_figure(plot.plot_mesh(points, triangles,
                                        f"{scene.name}, {args.marking} marking, step "
                                        f"{record['step']}: {mesh.ne} triangles", marked,
                                        units=scene.units), str(stem) + ".png")
        if args.vtk:
            post.write_vtk(solution, str(out / f"solution_step{record['step']:02d}"))
        run["history"].append(record)
        write_json(run, out / "history.json")
        print(line)
        if "stop_message" in record:
            print(f"    {record['stop_message']}")
        if record["warnings"]:
            print(warning_lines(record["warnings"], "    "))

    try:
        adapt(scene, args.marking, theta, steps, level, args.asymmetry,
              run.get("reference_norms"), on_step, allow_large=args.allow_large,
              goal=args.goal, tol=args.tol,
              window=None if args.window is None else tuple(args.window), growth=growth)
    except ConvergenceError as err:
        return not_converged(err)
    except StrictFailure as err:
        return strict_failure(err)
    except MemoryError:   # on the initial mesh: later solves end the loop ("memory")
        run.update(stopped_by="memory", stop_message=f"the solve on the initial mesh (level "
                                                     f"{level}) ran out of memory")
        write_json(run, out / "history.json")
        print(f"ngdual: stopped by memory: {run['stop_message']} within "
              f"{budget.describe_available()}; choose a coarser --level or maxh",
              file=sys.stderr)
        return EXIT_MEMORY
    write_json(run, out / "history.json")
    print(f"wrote {out / 'history.json'} and {len(run['history'])} meshes (.vol, .png"
          + (", solution_stepNN.vtu)" if args.vtk else ")"))
    if run["history"]:
        print("wrote " + ", ".join(str(p) for p in adapt_figures(run, final["solution"], out)))
    last = run["history"][-1]
    if last["stopped_by"] == "memory":
        print(f"ngdual: stopped by memory: {last['stop_message']}", file=sys.stderr)
        return EXIT_MEMORY
    if last["stopped_by"] == "no_contact":
        print(f"ngdual: not converged: the pressure goal has nothing to measure (stopped by "
              f"no_contact): {last['stop_message']}", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    if args.tol is not None and last["stopped_by"] != "tol":
        measured = (f"the goal's relative estimate {last['relative_estimate']:.3g} is below it "
                    f"but measures no finite error" if last["relative_estimate"] <= args.tol else
                    f"the goal's relative estimate is {last['relative_estimate']:.3g}")
        print(f"ngdual: not converged: --tol {args.tol:g} not reached, {measured} (stopped by "
              f"{last['stopped_by']})", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    return 0 if all(r["converged"] for r in run["history"]) else EXIT_NOT_CONVERGED
