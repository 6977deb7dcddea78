"""The ``ngdual`` command line.

``ngdual solve SCENE [--level N] [--set key=value ...] [--out DIR] [--vtk] [--no-plots]
[--strict]``
solves one scene, prints the result table and writes ``DIR/result.json``
(atomically) plus figures. ``ngdual scenes`` lists the shipped scenes;
``ngdual dofs SCENE --levels 1 2 3`` prints DOF counts without solving;
``ngdual adapt SCENE --marking max|fraction|dorfler --theta T --steps N --goal stress|pressure
--tol TOL [--window LO HI] --out DIR [--vtk] [--strict]``
runs the adaptive loop and writes ``DIR/history.json`` plus a mesh (.vol, .png with the
marked triangles shaded) and, with ``--vtk``, a VTK file per step.
``ngdual tutorials [--notebooks DIR] [--solutions]`` lists the lecture tutorials or
writes them as Jupyter notebooks; ``ngdual tutorials run NAME [--quick] [--out DIR]`` runs
one as a script and lists the files it wrote. ``ngdual show SCENE [--level N] [--out DIR]``
draws the geometry, its boundary labels and the initial mesh without solving.
``ngdual bench BENCHMARK [--json FILE]`` runs one benchmark of :mod:`ngdual.studies.bench`:
``limit-ratio`` (the contact solvers against one linear solve of the same matrix),
``levels``, ``estimator-cost``, ``infsup``, ``primal-peer``.
``ngdual verify [--quick] [--orders K ...] [--json FILE]`` prints the errors against exact
solutions with observed orders, per order k of PEERS_k too (:mod:`ngdual.verification.report`;
exit status 1 when a study misses what it can show: k + 1, k + 1/2 for the general contact
case at even k >= 2, the exact contact set).
After the result table ``solve`` prints one ``warning:`` line per failed physics check
(tension or a force imbalance on Gamma_C, penetration, the friction bound, contact at a
clamped end, thesis end values that contradict the data; :mod:`ngdual.checks`), also
stored in ``result.json`` under ``warnings``; ``adapt`` prints them below each step.
Exit status: 0 solved and converged, 1 not converged, 2 bad input (one message naming
every field or flag at fault; nothing is written), 3 an internal error (a bug: the message
says so; ``ngdual --debug ...`` shows the traceback), 4 a physics check failed under
``--strict`` (``solve`` writes nothing; ``adapt`` stops at that step), 5 ``adapt`` stopped
by the memory (its next refinement would not fit in the memory available, or a solve ran
out of it; ``history.json`` keeps the steps before, the last with ``stopped_by =
"memory"``). Runs whose estimated size exceeds the memory available are refused before
meshing (status 2); ``--allow-large`` runs them, and lets ``adapt`` refine, anyway.
"""

from __future__ import annotations

import argparse
import os
import sys

from ..extras import MissingExtraError
from ..loop_defaults import (
    GROWTH_TOL,
    LEVEL_TOL,
    MARKING,
    MAX_GROWTH,
    STEPS,
    STEPS_TOL,
    THETA,
    THETA_TOL,
)
from ..marking import STRATEGIES
from ..scene import SceneError
from .cost import add_cost
from .output import (
    EXIT_BAD_INPUT,
    EXIT_BROKEN_PIPE,
    EXIT_INTERNAL,
    EXIT_NOT_CONVERGED,
    EXIT_WARNINGS,
)
from .pipeline import EXIT_MEMORY, cmd_adapt, cmd_dofs, cmd_scenes, cmd_solve
from .studies import cmd_bench, cmd_figures, cmd_show, cmd_tutorials, cmd_verify


def parser() -> argparse.ArgumentParser:
    from .. import __version__

    p = argparse.ArgumentParser(
        prog="ngdual", description=__doc__.splitlines()[0],
        epilog=f"exit status: 0 solved and converged, {EXIT_NOT_CONVERGED} not converged, "
               f"{EXIT_BAD_INPUT} bad input (nothing written), {EXIT_INTERNAL} internal error, "
               f"{EXIT_WARNINGS} a physics check failed under --strict, {EXIT_MEMORY} adapt "
               f"stopped by the memory (history.json kept)")
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
    s.add_argument("--vtk", action="store_true",
                   help="also write DIR/solution.vtu (u as a vector: ParaView's Warp By Vector "
                        "applies it) and, with contact, DIR/solution_contact.vtu (lambda as "
                        "a vector on Gamma_C)")
    s.add_argument("--no-plots", action="store_true", help="do not write PNG figures")
    s.add_argument("--strict", action="store_true",
                   help=f"fail with exit status {EXIT_WARNINGS}, writing nothing, when a "
                        "physics check fails (the warning lines after the result table)")
    s.add_argument("--tol", type=float, default=None, metavar="TOL",
                   help="solve to this relative error of the contact pressure (of the stress "
                        "without contact), e.g. 0.01, by the fastest method: adaptive from "
                        "the coarsest level (or --level), stopping by the estimate; the "
                        "result says which method was chosen and why")
    s.set_defaults(func=cmd_solve)
    sc = sub.add_parser("scenes", help="list the shipped scenes", parents=[common])
    sc.set_defaults(func=cmd_scenes)
    d = sub.add_parser("dofs", help="degrees of freedom per level (Table 3.1), without solving",
                       parents=[sized])
    d.add_argument("scene", help="path to a TOML scene or the name of a shipped scene")
    d.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4], metavar="LEVEL",
                   help="mesh levels (default: 1 2 3 4)")
    d.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene entry, e.g. --set contact.htilde_factor=1")
    d.set_defaults(func=cmd_dofs)
    ad = sub.add_parser("adapt", help="adaptive refinement (Chapter 4), writes DIR/history.json",
                        parents=[sized])
    ad.add_argument("scene", help="path to a TOML scene or the name of a shipped scene")
    ad.add_argument("--marking", choices=STRATEGIES, default=MARKING,
                    help="marking strategy (Section 4.2): max (eta_T >= theta max eta_T), "
                         "fraction (the theta share of the triangles with the largest "
                         "eta_T) or dorfler (the fewest triangles carrying theta of the "
                         "squared estimate, Doerfler; default)")
    ad.add_argument("--theta", type=float, default=None,
                    help=f"marking parameter in [0, 1] (default {THETA:g}, the thesis'; with "
                         f"--tol {THETA_TOL:g}, which grows the unknowns faster)")
    ad.add_argument("--growth", type=float, default=None,
                    help=f"the least factor in [1, {MAX_GROWTH:g}] by which a step multiplies "
                         "the triangles: the marked ones refined, then those at the peaks of "
                         "their estimate, again until the mesh has grown by G (default 1, "
                         f"the marked triangles alone, as in the thesis; with --tol "
                         f"{GROWTH_TOL:g})")
    ad.add_argument("--steps", type=int, default=None,
                    help=f"number of solves (default {STEPS}); with --tol the largest number "
                         f"(default {STEPS_TOL})")
    ad.add_argument("--goal", choices=["stress", "pressure"], default="stress",
                    help="what the indicators estimate: stress, the error of (3.124) by "
                         "(4.50) (default), or pressure, ||p - p_h|| in L2 on Gamma_C")
    ad.add_argument("--tol", type=float, default=None,
                    help="stop at the first step whose goal estimate relative to the "
                         "solution's size (||sigma_h|| in H(div), ||p_h|| on Gamma_C) is at "
                         "most TOL; a run that stops short of it (by --steps, a stalled "
                         "estimate or the smallest triangle the loop refines) exits with "
                         f"status 1, one whose next refinement would not fit in memory "
                         f"with status {EXIT_MEMORY}")
    ad.add_argument("--window", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                    help="with --goal pressure: the error of the pressure on the part of "
                         "Gamma_C with LO <= x <= HI only (default: all of Gamma_C), e.g. "
                         "--window -0.125 0.125 for the flat punch's core, whose pressure "
                         "is not in L2 at the punch edges; a window without contact stops "
                         "on the first solve, with status 1")
    ad.add_argument("--level", type=int, default=None,
                    help=f"initial mesh level (default: the scene's; with --tol {LEVEL_TOL})")
    ad.add_argument("--asymmetry", choices=["hdiv", "l2"], default="l2",
                    help="norm of as(sigma_h) in the estimator (default: L2; 'hdiv' as printed "
                         "in eq. 4.15 does not decrease for PEERS)")
    ad.add_argument("--reference-levels", type=int, nargs="+", default=None, metavar="LEVEL",
                    help="uniform levels whose norms give, by Aitken extrapolation, the "
                         "reference for the total error (3.124) and the effectivity index")
    ad.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a scene entry, e.g. --set friction.mu=0.5")
    ad.add_argument("--out", default="out-adapt", help="output folder (default: out-adapt)")
    ad.add_argument("--vtk", action="store_true",
                    help="also write DIR/solution_stepNN.vtu (and _contact.vtu) per step for "
                         "ParaView")
    ad.add_argument("--strict", action="store_true",
                    help=f"stop with exit status {EXIT_WARNINGS} at the first step whose "
                         "solution fails a physics check, writing nothing for it "
                         "(history.json keeps the steps before)")
    ad.set_defaults(func=cmd_adapt)
    tu = sub.add_parser("tutorials", help="list the tutorials, write them as notebooks or run "
                                          "one", parents=[common])
    tu.add_argument("--notebooks", metavar="DIR", default=None,
                    help="write the tutorials as .ipynb notebooks into DIR (with the core "
                         "install; Jupyter itself comes with the tutorials extra)")
    tu.add_argument("--solutions", action="store_true",
                    help="with --notebooks: also write the exercise solutions to DIR/solutions")
    tu.add_argument("--source", metavar="DIR", default=None,
                    help="tutorials folder (default: tutorials/ of the source checkout)")
    tu.set_defaults(func=cmd_tutorials, action=None)
    tutorial = tu.add_subparsers(dest="action", metavar="run NAME",
                                 help="run one tutorial as a script (ngdual tutorials run "
                                      "--help)")
    run = tutorial.add_parser("run", help="run one tutorial as a script, headless "
                                          "(matplotlib's Agg backend), and list the files it "
                                          "wrote", parents=[common])
    run.add_argument("name", metavar="NAME",
                     help="the tutorial: its file name, number or topic, e.g. 07_adaptivity, "
                          "7 or adaptivity (a solution: 07_adaptivity_solutions)")
    run.add_argument("--out", default="tutorial-output",
                     help="output folder; the tutorial writes into DIR/NAME (default: "
                          "tutorial-output)")
    run.add_argument("--quick", action="store_true",
                     help="coarse meshes and short sweeps (NGDUAL_QUICK=1): seconds instead "
                          "of minutes")
    run.add_argument("--source", metavar="DIR", default=argparse.SUPPRESS,
                     help="tutorials folder (default: tutorials/ of the source checkout)")
    sh = sub.add_parser("show", help="draw a scene's geometry, boundary labels and initial "
                                     "mesh into DIR/geometry.png, without solving",
                        parents=[sized])
    sh.add_argument("scene", help="path to a TOML scene or the name of a shipped scene")
    sh.add_argument("--level", type=int, default=1,
                    help="mesh level (default 1, the initial mesh; the scene's level is the "
                         "one ngdual solve uses)")
    sh.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a scene entry, e.g. --set geometry.maxh=0.5")
    sh.add_argument("--out", default="out", help="output folder (default: out)")
    sh.set_defaults(func=cmd_show)
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
                    help="the tasks one after another in this process: quick to start, and "
                         "without dask (the studies extra)")
    fg.add_argument("--only", nargs="+", default=None, metavar="NAME",
                    help="run only the scripts whose name contains one of these")
    fg.add_argument("--source", default=None, metavar="DIR",
                    help="figure scripts folder (default: figures/ of the source checkout)")
    fg.add_argument("--gallery", default=None, metavar="DIR",
                    help="also write 16:9 slide copies (1600 x 900 px) of a few figures "
                         "into DIR (docs/gallery, for the docs site and the README)")
    fg.set_defaults(func=cmd_figures)
    be = sub.add_parser("bench", help="benchmarks: the solvers' and the estimator's cost, the "
                                      "inf-sup constants, the primal peer (a table; JSON with "
                                      "--json)", parents=[common])
    bench = be.add_subparsers(dest="benchmark", required=True, metavar="BENCHMARK",
                              help="which benchmark (each has its own --help)")
    json_out = argparse.ArgumentParser(add_help=False)
    json_out.add_argument("--json", default=None, metavar="FILE",
                          help="write all records (with package versions and the machine) "
                               "to FILE, atomically after each one")
    one_scene = argparse.ArgumentParser(add_help=False)
    one_scene.add_argument("--scene", default="thesis-3.46-frictionless",
                           help="a TOML scene or a shipped scene (default: "
                                "thesis-3.46-frictionless)")

    def levels_flag(p: argparse.ArgumentParser, last: int = 5) -> None:
        p.add_argument("--levels", type=int, nargs="+", default=list(range(1, last + 1)),
                       metavar="LEVEL", help=f"mesh levels (default: 1 ... {last})")

    lr = bench.add_parser("limit-ratio", help="contact-solve time / one linear solve, per "
                                              "level and solver (Example 3.46)",
                          parents=[sized, json_out])
    levels_flag(lr)
    lr.add_argument("--cases", nargs="+", default=["thesis-3.46", "thesis-3.46-coulomb"],
                    metavar="CASE", help="benchmark cases (default: thesis-3.46 "
                                         "thesis-3.46-coulomb)")
    lr.add_argument("--solvers", nargs="+", default=["uzawa", "uzawa-tuned", "active-set"],
                    metavar="SOLVER", help="solvers to time (default: uzawa uzawa-tuned "
                                           "active-set)")
    lr.add_argument("--isolate", choices=["auto", "always", "never"], default="auto",
                    help="one process per record for its own peak memory (auto: level >= 4)")
    lr.add_argument("--timeout", type=float, default=None, metavar="S",
                    help="bound on one isolated record (s)")
    lr.add_argument("--blas-threads", type=int, default=1, metavar="N",
                    help="BLAS threads for every solver (default 1; 0: the libraries' own)")
    lv = bench.add_parser("levels", help="one scene per level, each in its own process: "
                                         "unknowns, iterations, times, peak memory, norms",
                          parents=[sized, json_out, one_scene])
    levels_flag(lv, 6)
    lv.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    dest="overrides", help="override a scene entry, e.g. "
                                           "--set solver.metric=euclidean")
    ec = bench.add_parser("estimator-cost", help="the estimator (4.50) against one linear "
                                                 "solve, per level",
                          parents=[sized, json_out, one_scene])
    levels_flag(ec)
    ec.add_argument("--repeat", type=int, default=3, metavar="N",
                    help="timed runs per level, the median is kept (default 3)")
    inf = bench.add_parser("infsup", help="discrete inf-sup constants of the boundary "
                                          "multipliers phi, lambda_t, lambda_n",
                           parents=[sized, json_out])
    inf.add_argument("--scenes", nargs="+", metavar="SCENE",
                     default=["thesis-3.46-frictionless", "hertz-cylinder", "flat-punch",
                              "wedge"], help="scenes (default: thesis-3.46-frictionless "
                                             "hertz-cylinder flat-punch wedge)")
    levels_flag(inf)
    inf.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                     dest="overrides", help="override an entry of every scene, e.g. "
                                            "--set contact.ends=consistent")
    pp = bench.add_parser("primal-peer", help="the primal Nitsche peer against Hertz or "
                                              "Cattaneo-Mindlin", parents=[common, json_out])
    pp.add_argument("--case", default="hertz", choices=["hertz", "cattaneo-mindlin"],
                    help="Hertz (frictionless) or Cattaneo-Mindlin (default: hertz)")
    pp.add_argument("--orders", type=int, nargs="+", default=[1, 2], choices=[1, 2],
                    help="polynomial orders (default: 1 2)")
    levels_flag(pp)
    pp.add_argument("--hc", type=float, default=0.05,
                    help="contact edge length on level 1 (default 0.05)")
    pp.add_argument("--thetas", type=float, nargs="+", default=[-1.0], metavar="THETA",
                    help="Nitsche variants: -1 skew-symmetric, 0 incomplete, 1 symmetric "
                         "(default: -1)")
    pp.add_argument("--gammas", type=float, nargs="+", default=[1.0], metavar="GAMMA0",
                    help="Nitsche penalties gamma0 (default: 1; the gamma study: "
                         "--thetas -1 0 1 --gammas 0.3 1 3 10 100)")
    pp.add_argument("--nu", type=float, default=None,
                    help="Poisson ratio (default: 0.3 for hertz, 0.49 for cattaneo-mindlin)")
    pp.add_argument("--law", choices=["coulomb", "tresca"], default=None,
                    help="friction law of cattaneo-mindlin (default: coulomb)")
    adp = bench.add_parser("adaptive", help="every step of adaptive runs at orders 0, 1, 2: "
                                            "unknowns, growth, the solve and the fixed cost "
                                            "of the step",
                           parents=[sized, json_out])
    adp.add_argument("--scene", default="hertz-cylinder",
                     help="a TOML scene or a shipped scene (default: hertz-cylinder)")
    adp.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                     dest="overrides", help="override a scene entry, e.g. "
                                            "--set contact.ends=consistent")
    adp.add_argument("--orders", type=int, nargs="+", default=[0, 1, 2], metavar="K",
                     help="the orders k of PEERS_k, one run each (default: 0 1 2)")
    adp.add_argument("--goal", choices=["stress", "pressure"], default="pressure",
                     help="what the indicators estimate (default: pressure)")
    adp.add_argument("--tol", type=float, default=0.01,
                     help="the goal's relative tolerance (default 0.01); 0 for a run of "
                          "--steps steps without one")
    adp.add_argument("--level", type=int, default=None,
                     help=f"level of the initial mesh (default: {LEVEL_TOL} with a tol, else "
                          "the scene's)")
    adp.add_argument("--steps", type=int, default=None,
                     help=f"adaptive steps (default {STEPS}; with a tol the largest number, "
                          f"{STEPS_TOL})")
    adp.add_argument("--theta", type=float, default=None,
                     help=f"Doerfler's bulk parameter (default {THETA:g}; with a tol "
                          f"{THETA_TOL:g})")
    adp.add_argument("--growth", type=float, default=None,
                     help=f"the least growth of the unknowns per step, in [1, {MAX_GROWTH:g}] "
                          f"(default 1; with a tol {GROWTH_TOL:g})")
    be.set_defaults(func=cmd_bench)
    ve = sub.add_parser("verify", help="errors against exact solutions: manufactured contact "
                                       "problems and the Hertz, flat-punch and "
                                       "Cattaneo-Mindlin benchmarks, with observed orders")
    ve.add_argument("--quick", action="store_true",
                    help="two levels of two manufactured cases and of every benchmark, "
                         "three of each order k (~50 s)")
    ve.add_argument("--json", default=None, metavar="FILE",
                    help="also write every row (with package versions) to FILE, atomically")
    ve.add_argument("--orders", nargs="+", type=int, default=None, metavar="K",
                    help="only the convergence of PEERS_k for these orders k (0, 1, 2) on "
                         "elasticity and frictionless contact; exit status 1 when sigma's "
                         "observed order misses k + 1 (the general contact case: its "
                         "prediction, k + 1/2 at even k >= 2) or the contact set is wrong")
    ve.set_defaults(func=cmd_verify)
    add_cost(sub, common)
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
        status = args.func(args)
        sys.stdout.flush()  # a reader that stopped early shows here, not at interpreter exit
        return status
    except (SceneError, MissingExtraError) as err:  # the message names the field or the extra
        print(f"ngdual: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except MemoryError:
        print("ngdual: error: out of memory; choose a coarser level or maxh", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("ngdual: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of stdout stopped (ngdual tutorials | head): not a bug
        # Python would report the broken pipe again when it flushes stdout at exit
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except Exception as err:  # a bug: one line, the traceback with --debug
        print(f"ngdual: internal error: {type(err).__name__}: {str(err)[:500]} (a bug in "
              "ngdual: run again with --debug for the traceback and report it)",
              file=sys.stderr)
        return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
