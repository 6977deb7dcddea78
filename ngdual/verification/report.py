"""``ngdual verify``: every error against the truth, as tables with observed orders.

Manufactured solutions (:mod:`ngdual.verification.manufactured`) and the analytic contact
benchmarks (:mod:`ngdual.verification.contact_benchmarks`) under uniform refinement; the
full run adds the adaptive runs and the finite-box study. ``--quick`` runs two levels of
each (under a minute), ``--json PATH`` writes every row (atomically).

:func:`run` is the command (``ngdual.cli`` defines its two options).
"""

from __future__ import annotations

import argparse
import math

from ..io import write_json
from .contact_benchmarks import BENCHMARKS, KEYS, adaptive_study, domain_study, format_rows
from .contact_benchmarks import uniform_study as benchmark_study
from .manufactured import CASES
from .manufactured_errors import format_study, manufactured_study

QUICK = {"manufactured": ("frictionless", "coulomb"), "manufactured_levels": (1, 2),
         "benchmark_levels": (1, 2)}
FULL = {"manufactured": tuple(CASES), "manufactured_levels": (1, 2, 3, 4, 5),
        "benchmark_levels": (1, 2, 3, 4)}


def verification_rows(quick: bool = False) -> dict:
    """All rows of the verification: manufactured studies, benchmark studies and, unless
    ``quick``, the adaptive benchmark runs and the finite-box study of the flat punch."""
    plan = QUICK if quick else FULL
    out = {"manufactured": {case: manufactured_study(case, plan["manufactured_levels"])
                            for case in plan["manufactured"]},
           "benchmarks": {name: benchmark_study(name, plan["benchmark_levels"])
                          for name in BENCHMARKS},
           "adaptive": {}, "domain": []}
    if not quick:
        out["adaptive"] = {name: adaptive_study(name) for name in ("hertz", "flat-punch")}
        out["domain"] = domain_study("flat-punch")
    return out


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
    """Compute, print and (with ``--json``) write the verification tables; returns 0."""
    rows = verification_rows(quick=args.quick)
    print(format_report(rows))
    if args.json:
        write_json(_plain(rows), args.json)
    return 0
