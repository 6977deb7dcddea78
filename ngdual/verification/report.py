"""``ngdual verify``: every error against the truth, as tables with observed orders.

Manufactured solutions (:mod:`ngdual.verification.manufactured`) and the analytic contact
benchmarks (:mod:`ngdual.verification.contact_benchmarks`) under uniform refinement; the
full run adds the adaptive runs and the finite-box study. Per order k = 0, 1, 2 of PEERS_k
(:mod:`ngdual.verification.order`), with the observed orders of sigma, u, the rotation and
the contact pressure, three studies and what each can check:

* elasticity on the unit square: sigma's orders within 0.15 of k + 1 on the last two levels;
* frictionless contact with the quadratic u_n, whose gap the multipliers represent on the
  contact zone (the check case): sigma's orders within 0.15 of k + 1, the contact set exact;
* frictionless contact with the quartic u_n (the general case): sigma's orders against the
  prediction of :func:`ngdual.verification.order.expected_order` (k + 1, but k + 1/2
  asymptotically at even k >= 2, where the gap's P_k interpolant costs half an order),
  failing only more than 0.15 below it; the contact set exact.

``--quick`` runs two levels of each (three for the orders; under a minute),
``--orders K [K ...]`` only the tables of those orders, ``--json PATH`` writes every row
(atomically).

:func:`run` is the command (``ngdual.cli`` defines its options); its exit status is 1 when
a study of an order fails its check.
"""

from __future__ import annotations

import argparse
import math

from ..io import write_json
from ..scene import ORDERS
from .contact_benchmarks import BENCHMARKS, KEYS, adaptive_study, domain_study, format_rows
from .contact_benchmarks import uniform_study as benchmark_study
from .manufactured import CASES
from .manufactured_errors import format_study, manufactured_study
from .order import (
    ORDER_SLACK,
    contact_study,
    convergence_study,
    expected_order,
    order_check,
    set_check,
)

QUICK = {"manufactured": ("frictionless", "coulomb"), "manufactured_levels": (1, 2),
         "benchmark_levels": (1, 2), "elasticity_levels": (1, 2, 3),
         "contact_levels": (1, 2, 3)}
FULL = {"manufactured": tuple(CASES), "manufactured_levels": (1, 2, 3, 4, 5),
        "benchmark_levels": (1, 2, 3, 4), "elasticity_levels": (1, 2, 3, 4),
        "contact_levels": (1, 2, 3, 4)}
ORDER_COLUMNS = ("sigma", "u", "eta", "pressure")   # errors with orders in the order tables


def verification_rows(quick: bool = False, orders=ORDERS, only_orders: bool = False) -> dict:
    """All rows of the verification: manufactured studies, benchmark studies, the studies
    of every order in ``orders`` (:func:`order_rows`) and, unless ``quick``, the adaptive
    benchmark runs and the finite-box study of the flat punch; ``only_orders``: the
    studies of the orders alone."""
    plan = QUICK if quick else FULL
    out = {"manufactured": {}, "benchmarks": {}, "adaptive": {}, "domain": [],
           "orders": order_rows(orders, plan)}
    if only_orders:
        return out
    out["manufactured"] = {case: manufactured_study(case, plan["manufactured_levels"])
                           for case in plan["manufactured"]}
    out["benchmarks"] = {name: benchmark_study(name, plan["benchmark_levels"])
                         for name in BENCHMARKS}
    if not quick:
        out["adaptive"] = {name: adaptive_study(name) for name in ("hertz", "flat-punch")}
        out["domain"] = domain_study("flat-punch")
    return out


def order_rows(orders, plan: dict) -> list[dict]:
    """Per order k the studies of :mod:`ngdual.verification.order` on the plan's levels,
    each with what it can check: "elasticity" (sigma within 0.15 of k + 1), "contact" with
    the quadratic gap (sigma within 0.15 of k + 1, the contact set exact) and "contact"
    with the quartic gap (sigma at least :func:`ngdual.verification.order.expected_order`
    minus 0.15, the contact set exact).

    Returns
    -------
    list of dict
        ``problem``, ``gap`` (None for elasticity), ``order``, ``rows``, ``check``
        (:func:`ngdual.verification.order.order_check`), ``set_check``
        (:func:`ngdual.verification.order.set_check`; None for elasticity) and ``passed``.
    """
    out = []
    for k in orders:
        rows = convergence_study("peers", k, plan["elasticity_levels"])
        out.append(_study("elasticity", None, k, rows, order_check(rows), None))
        for gap, expected in (("quadratic", None), ("quartic", expected_order(k, "quartic"))):
            rows = contact_study(k, plan["contact_levels"], gap=gap)
            out.append(_study("contact", gap, k, rows, order_check(rows, expected=expected),
                              set_check(rows)))
    return out


def _study(problem: str, gap: str | None, order: int, rows: list[dict], check: dict,
           sets: dict | None) -> dict:
    return {"problem": problem, "gap": gap, "order": order, "rows": rows, "check": check,
            "set_check": sets,
            "passed": check["passed"] and (sets is None or sets["passed"])}


def format_orders(studies: list[dict]) -> str:
    """The studies of :func:`order_rows` as one text table: errors and observed orders per
    level and, on each study's last row, sigma's expected order (the target of its check)
    and the verdict ("pass" or "FAIL")."""
    if not studies:
        return ""
    lines = ["order k of PEERS_k: observed orders in N^-1/2; pressure: sigma_n^h on Gamma_C "
             "in L2; set: the contact set's error (a length), exact on the last two levels",
             f"  elasticity, contact with gap quad (u_n quadratic, which the P_k gap "
             f"represents on the contact zone): sigma within {ORDER_SLACK:g} of k + 1 on "
             "the last two levels",
             f"  contact with gap quart (u_n quartic, the general case): sigma at least the "
             f"expected order minus {ORDER_SLACK:g}; expected k + 1, but k + 1/2 as h -> 0 "
             "at even k >= 2 (the gap's P_k interpolant: docs/theory/order.md, \"What "
             "limits k = 2\")",
             f"{'problem':>10} {'gap':>5} {'k':>2} {'lvl':>3} {'ndof':>7} {'sec':>6} "
             + " ".join(f"{q:>9} {'ord':>5}" for q in ORDER_COLUMNS)
             + f" {'set':>7} {'expected':>8} {'check':>5}"]
    for study in studies:
        rows = study["rows"]
        gap = {None: "", "quadratic": "quad", "quartic": "quart"}[study["gap"]]
        for i, row in enumerate(rows):
            cells = [f"{'':>15}" if q not in row else f"{row[q]:9.3e} "
                     + (f"{row[q + '_order']:5.2f}" if row[q + "_order"] is not None
                        else f"{'':>5}") for q in ORDER_COLUMNS]
            cset = f"{row['contact_set']:7.4f}" if "contact_set" in row else f"{'':>7}"
            expected = check = ""
            if i == len(rows) - 1:
                c = study["check"]
                expected = f"{c['target']:g}"
                check = "pass" if study["passed"] else "FAIL"
            lines.append(f"{study['problem']:>10} {gap:>5} {row['order']:2d} {row['level']:3d} "
                         f"{row['ndof']:7d} {row['seconds']:6.2f} " + " ".join(cells)
                         + f" {cset} {expected:>8} {check:>5}")
    return "\n".join(lines)


def format_domain(rows: list[dict]) -> str:
    """The finite-box study as a text table."""
    if not rows:
        return ""
    levels = rows[0]["levels"]
    lines = [f"finite box ({rows[0]['benchmark']}): error per level, its h -> 0 limit (the "
             "domain error) and the discretisation error on the last level",
             f"{'W/a':>5} " + " ".join(f"{'L' + str(lv):>9}" for lv in levels)
             + f" {'domain':>9} {'discr.':>9}"]
    for row in rows:
        lines.append(f"{row['multiple']:5g} " + " ".join(f"{e:+9.2e}" for e in row["errors"])
                     + f" {row['domain']:+9.2e} {row['discretisation']:+9.2e}")
    return "\n".join(lines)


def format_report(rows: dict) -> str:
    """Every table of :func:`verification_rows`."""
    parts = [format_study(study) for study in rows["manufactured"].values()]
    parts += [format_rows(study, KEYS[name]) for name, study in rows["benchmarks"].items()]
    cm = rows["benchmarks"].get("cattaneo-mindlin", [])
    if cm:
        lines = ["cattaneo-mindlin stick zone: c = a sqrt(1 - |Q|/(mu_f P)) against the h^ "
                 "stick set",
                 f"{'lvl':>3} {'Q':>9} {'c':>7} {'c_h':>7} {'h^':>7} {'|dc|/h^':>8} "
                 f"{'x_p/a':>7} {'x_s/a':>7}"]
        for r in cm:
            lines.append(f"{r['level']:3d} {r['Q']:9.2f} {r['c']:7.4f} {r['c_h']:7.4f} "
                         f"{r['hhat']:7.4f} {r['c_cells']:8.3f} {r['centroid_a']:+7.3f} "
                         f"{r['stick_centroid_a']:+7.3f}")
        parts.append("\n".join(lines))
    for name, study in rows["adaptive"].items():
        parts.append(f"adaptive {name} (Doerfler 0.5; lvl = step, orders in N^-1/2)\n"
                     + format_rows(study, KEYS[name], "N^-1/2").split("\n", 1)[1])
    parts.append(format_domain(rows["domain"]))
    parts.append(format_orders(rows["orders"]))
    return "\n\n".join(p for p in parts if p)


def _plain(value):
    """JSON-ready: numpy scalars to floats (NaN to None), containers recursively."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if value is None or isinstance(value, (bool, int, str)):
        return value
    value = float(value)
    return value if math.isfinite(value) else None


def run(args: argparse.Namespace) -> int:
    """Compute, print and (with ``--json``) write the verification tables; returns 0, or 1
    when a study of an order fails its check (:func:`order_rows`; ``--orders``: only those
    orders)."""
    only = args.orders is not None
    rows = verification_rows(quick=args.quick, orders=sorted(set(args.orders)) if only else ORDERS,
                             only_orders=only)
    print(format_report(rows))
    if args.json:
        write_json(_plain(rows), args.json)
    return 0 if all(study["passed"] for study in rows["orders"]) else 1
