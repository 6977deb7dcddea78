"""``ngdual cost SCENE``: what accuracy costs on a scene, within a budget of wall time
(:mod:`ngdual.studies.cost`)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..scene import ORDERS, SceneError
from .output import EXIT_NOT_CONVERGED, number_flag, runs_in_process


def add_cost(sub, common: argparse.ArgumentParser) -> None:
    """The ``cost`` subcommand of the parser whose subparsers are ``sub``."""
    from ..studies.cost.budget import MIN_BUDGET_S
    from ..studies.cost.run import DEFAULT_BUDGET_S

    co = sub.add_parser("cost", help="what accuracy costs on a scene: the least wall time to "
                                     "5, 2, 1 % true error of every method, within a budget",
                        parents=[common])
    co.add_argument("scene", help="path to a TOML scene or the name of a shipped scene")
    co.add_argument("--budget", type=float, default=DEFAULT_BUDGET_S, metavar="SECONDS",
                    help=f"wall time of the whole study, at least {MIN_BUDGET_S:g} s (default "
                         f"{DEFAULT_BUDGET_S:g}): every method stops before a step that would "
                         "end past its share, the references take the largest shares")
    co.add_argument("--out", default="cost-output",
                    help="output folder: cost.json, work_precision.png and the records "
                         "(default: cost-output)")
    co.add_argument("--orders", type=int, nargs="+", default=list(ORDERS), metavar="K",
                    help="the orders k of PEERS_k (default: 0 1 2); the primal peers P1 and "
                         "P2 always run")
    co.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a scene entry, e.g. --set friction.mu=0.5")
    co.add_argument("--window", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                    help="the pressure's error on the part of Gamma_C with LO <= x <= HI only "
                         "(default: all of it, or its middle half where an end of Gamma_C "
                         "meets a free side running straight on: a flat punch's core, whose "
                         "pressure is not in L2 at the punch edges)")
    co.add_argument("--workers", type=int, default=None,
                    help="dask workers (the studies extra; default: one per CPU core)")
    co.add_argument("--threads", action="store_true",
                    help="the methods one after another in this process (no dask)")
    co.set_defaults(func=cmd_cost)


def cmd_cost(args) -> int:
    """Run :func:`ngdual.studies.cost.cost`; print the references' own errors and the
    time-to-accuracy tables; write DIR/cost.json and DIR/work_precision.png. Exit status 1
    when no reference run finished a step."""
    from .. import plot
    from ..io import check_output_dir, write_json
    from ..scene import load_scene
    from ..studies.cost import NoReference, cost
    from ..studies.cost.budget import MIN_BUDGET_S
    from ..studies.cost.output import reference_line, table_text, work_precision_figure
    from ..studies.cost.run import check_measurable

    start = time.perf_counter()
    number_flag(args.budget, "--budget", MIN_BUDGET_S, 1e6)
    wrong = sorted(set(args.orders) - set(ORDERS))
    if wrong:
        raise SceneError("--orders", f"the order k of PEERS_k is one of "
                                     f"{', '.join(map(str, ORDERS))}, got "
                                     f"{', '.join(map(str, wrong))}")
    if args.workers is not None:
        number_flag(args.workers, "--workers", 1, 256, integer=True)
        if args.threads:
            raise SceneError("--workers", "with --threads the methods run one after another "
                                          "in this process: give one of the two")
    if args.window is not None and not args.window[0] < args.window[1]:
        raise SceneError("--window", f"must be LO < HI, got {args.window}")
    check_measurable(load_scene(args.scene, args.set))
    out = check_output_dir(args.out, "--out")
    in_process = runs_in_process(args.threads, args.workers is not None, "methods")
    try:
        result = cost(args.scene, args.budget, out, sorted(set(args.orders)), args.set,
                      args.window, args.workers, not in_process)
    except NoReference as err:
        print(f"ngdual: not converged: {err}", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    for measure in result.measures:
        print(reference_line(measure, result.references[measure], result.window))
        print(table_text(result.table, measure))
        print()
    analytic = result.references["pressure"].get("analytic")
    if analytic:
        print(f"the pressure reference differs from the half-plane formula of the scene's "
              f"[benchmark] ({analytic['kind']}) by {100 * analytic['relative_l2']:.2g} % "
              "(a finite body: a cross-check, not its error)")
    written = plot.save_figure(work_precision_figure(result.rows, result.references,
                                                     result.scene), out / "work_precision.png")
    seconds = time.perf_counter() - start
    written.insert(0, write_json({**result.record(), "command_s": seconds}, out / "cost.json"))
    load = result.machine["load_average"][0]
    print(f"{seconds:.0f} s of a budget of {result.budget_s:g} s, {result.workers} worker"
          f"{'s' * (result.workers > 1)}, load average {load:.1f}: single runs, whose times "
          "vary by 10-25 % with the machine's load")
    print("wrote " + ", ".join(str(Path(p)) for p in written))
    if seconds > result.budget_s:
        print(f"ngdual: cost took {seconds:.0f} s, over its budget of {result.budget_s:g} s "
              "(a step took longer than predicted)", file=sys.stderr)
    return 0
