"""``ngdual solve``, ``scenes``, ``dofs`` and ``adapt``: the pipeline from the command line."""

from __future__ import annotations

import sys

from ..scene import SceneError, check_level, load_scene, shipped_scenes
from .output import (
    EXIT_NOT_CONVERGED,
    LARGE_MESH,
    level_flags,
    not_converged,
    number_flag,
    progress_bar,
    result_table,
)


def cmd_solve(args) -> int:
    from .. import budget, plot, post
    from ..io import check_output_dir, write_json
    from ..quantities import fields
    from ..solvers import solve_scene
    from ..solvers.result import ConvergenceError

    level = check_level(args.level, "--level", optional=True)
    scene = load_scene(args.scene, args.set)
    out = check_output_dir(args.out, "--out")
    size = budget.check(scene.geometry, level, "--level", args.allow_large,
                        method=scene.solver.method)
    if size.elements > LARGE_MESH:
        print(f"ngdual: {size.describe()}: meshing and solving take a while", file=sys.stderr)
    try:
        solution = solve_scene(scene, level, progress=progress_bar(), allow_large=args.allow_large)
    except ConvergenceError as err:
        return not_converged(err)
    record = post.result_record(solution)
    print(result_table(record))
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
    from .. import budget
    from ..forms import Spaces
    from ..mesh import build_mesh

    levels = level_flags(args.levels, "--levels")
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

    from .. import budget, plot
    from ..afem import adapt, reference_norms
    from ..io import check_output_dir, versions, write_json
    from ..mesh import mesh_arrays
    from ..solvers.result import ConvergenceError

    level = check_level(args.level, "--level", optional=True)
    number_flag(args.theta, "--theta", 0, 1)
    number_flag(args.steps, "--steps", 1, 10_000, integer=True)
    if args.reference_levels is not None:
        level_flags(args.reference_levels, "--reference-levels")
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
            return not_converged(err)

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
        return not_converged(err)
    write_json(run, out / "history.json")
    print(f"wrote {out / 'history.json'} and {len(run['history'])} meshes (.vol, .png)")
    return 0 if all(r["converged"] for r in run["history"]) else EXIT_NOT_CONVERGED
