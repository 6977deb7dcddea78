"""Limit ratio of every contact solver: contact-solve time / (factorisation + one solve).

The same as ``ngdual bench`` (see :mod:`ngdual.studies.bench`): Example 3.46 without friction and
with Coulomb friction, per level and solver (Uzawa, Uzawa with tuned steps, active set),
one JSON record each with DOFs, times, iterations, peak memory and package versions.

    python benchmarks/limit_ratio.py --levels 1 2 3 4 5 6 --json out/bench.json
    python benchmarks/limit_ratio.py --levels 7 8 --solvers active-set --json out/bench-78.json
"""

from __future__ import annotations

import sys

from ngdual.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
