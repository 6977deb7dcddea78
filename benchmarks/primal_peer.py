"""The primal peer (:mod:`ngdual.studies.primal_peer`) against Hertz and Cattaneo-Mindlin.

    python -m benchmarks.primal_peer                 # Hertz, P1 and P2, levels 1..5
    python -m benchmarks.primal_peer --cattaneo --orders 2 --hc 0.025 --levels 1 2 3 4
                                                     # Cattaneo-Mindlin (Coulomb), P2
    python -m benchmarks.primal_peer --gamma-study --levels 1 3   # errors per theta, gamma0
"""

import argparse

from ngdual.studies.primal_peer import NewtonError, cattaneo_mindlin_case, hertz_case


def _hertz_table(orders, levels, hc: float = 0.025, **kw) -> None:
    print(f"Hertz (frictionless), theta = {kw.get('theta', -1.0)}, "
          f"gamma0 = {kw.get('gamma0', 1.0)}, level-1 contact edges hc = {hc}")
    print(f"{'P':>2} {'lvl':>3} {'h_C':>8} {'ndof':>7} {'it':>3} {'time/s':>7} {'asm/s':>6} "
          f"{'sol/s':>6} {'L2 rel':>9} {'max rel':>9} {'a_Hertz':>8} {'a_h':>8} {'P':>9} "
          f"{'reaction':>9} {'uy/McEwen':>9}")
    for order in orders:
        for level in levels:
            r = hertz_case(order, level, mesh_kw={"hc": hc}, **kw)
            print(f"{order:>2} {level:>3} {r.hc:>8.5f} {r.ndof:>7} {r.newton_iterations:>3} "
                  f"{r.time_total:>7.2f} {r.time_assemble:>6.2f} {r.time_solve:>6.2f} "
                  f"{r.l2_error:>9.2e} {r.max_error:>9.2e} {r.a_hertz:>8.5f} "
                  f"{r.a_measured:>8.5f} {r.force:>9.6f} {r.reaction:>9.6f} "
                  f"{r.approach_ratio:>9.4f}", flush=True)


def _cattaneo_table(orders, levels, hc: float = 0.025, **kw) -> None:
    print(f"Cattaneo-Mindlin ({kw.get('law', 'coulomb')}), nu = {kw.get('nu', 0.49)}, "
          f"theta = {kw.get('theta', -1.0)}, gamma0 = {kw.get('gamma0', 1.0)}")
    print(f"{'P':>2} {'lvl':>3} {'h_C':>8} {'ndof':>7} {'it':>3} {'time/s':>7} {'P':>9} "
          f"{'Q':>10} {'a':>8} {'c formula':>9} {'c_h':>8} {'|dc|/h_C':>8} {'q L2 rel':>9}")
    for order in orders:
        for level in levels:
            r = cattaneo_mindlin_case(order, level, mesh_kw={"hc": hc}, **kw)
            print(f"{order:>2} {level:>3} {r.hc:>8.5f} {r.ndof:>7} {r.newton_iterations:>3} "
                  f"{r.time_total:>7.2f} {r.P:>9.5f} {r.Q:>10.6f} {r.a_hertz:>8.5f} "
                  f"{r.c_formula:>9.5f} {r.c_measured:>8.5f} "
                  f"{abs(r.c_measured - r.c_formula) / r.hc:>8.2f} "
                  f"{r.traction_l2_error:>9.2e}", flush=True)


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    p.add_argument("--orders", type=int, nargs="+", default=[1, 2])
    p.add_argument("--theta", type=float, default=-1.0)
    p.add_argument("--gamma0", type=float, default=1.0)
    p.add_argument("--cattaneo", action="store_true", help="the Cattaneo-Mindlin study")
    p.add_argument("--law", default="coulomb", choices=["coulomb", "tresca"])
    p.add_argument("--nu", type=float, default=None)
    p.add_argument("--hc", type=float, default=0.05, help="contact edge length on level 1")
    p.add_argument("--gamma-study", action="store_true",
                   help="Hertz errors for every --thetas x --gammas")
    p.add_argument("--thetas", type=float, nargs="+", default=[-1.0, 0.0, 1.0])
    p.add_argument("--gammas", type=float, nargs="+", default=[0.3, 1.0, 3.0, 10.0, 100.0])
    args = p.parse_args(argv)
    if args.gamma_study:
        for theta in args.thetas:
            for gamma0 in args.gammas:
                try:
                    _hertz_table(args.orders, args.levels, hc=args.hc, theta=theta,
                                 gamma0=gamma0)
                except NewtonError as err:
                    print("  ", err)
        return
    if args.cattaneo:
        kw = {"theta": args.theta, "gamma0": args.gamma0, "law": args.law}
        if args.nu is not None:
            kw["nu"] = args.nu
        _cattaneo_table(args.orders, args.levels, hc=args.hc, **kw)
        return
    kw = {"theta": args.theta, "gamma0": args.gamma0}
    if args.nu is not None:
        kw["nu"] = args.nu
    _hertz_table(args.orders, args.levels, hc=args.hc, **kw)


if __name__ == "__main__":
    main()

