"""Refactoring does not change the numbers: every shipped scene, levels 1-4, gives the
result.json norms stored in ``tests/data/behaviour_norms.json`` (made by
``tests/data/make_behaviour_norms.py``, which records for each scene the commit and the
versions it was computed with) to the accuracy of the solver that computes them.

Two solves of the same discrete problem agree only to what their algorithm guarantees,
and a machine with another CPU, BLAS kernel or thread count takes another rounding path.
So each case's relative tolerance is derived from the settings its scene calls for
(:func:`ngdual.solvers.solver_settings`) and from the round-off level its solver reports:

* Direct solves (no friction, or a given Tresca bound: the active-set method ends exactly
  on its contact and stick sets, then one factorised solve): ``SAFETY delta``, the level
  to which the solver itself accepts its residuals, with ``delta`` its round-off level of
  this problem (``solution.roundoff``, :mod:`ngdual.solvers.active_set`).
  On levels 1-4 of the shipped scenes SAFETY delta is 4e-13 to 1e-11, except on
  cattaneo-mindlin (nu = 0.4999: the compliance's condition (lambda + 2 mu) / mu is 5001),
  1e-10 to 5e-8.
* Iterative solves stop on a relative change: the Coulomb fixed point of the active-set
  method at ``COULOMB_FIXED_POINT_TOL`` or, where it stagnates, at its round-off
  ``SAFETY eps kappa_1(G)`` <= ``SAFETY delta``; Uzawa at ``solver.eps``; nested Uzawa at
  ``solver.eps1`` (the contact loop) and ``solver.eps2`` (the outer increments). A
  contraction with factor q stopped at a change tau is within q/(1-q) tau of its fixed
  point, and a norm moves by at most its Lipschitz constant L times that; two solves may
  stop on different steps, so they differ by up to 2 q/(1-q) L tau. ``STABILITY`` stands
  for 2 q/(1-q) L with a margin.

Measured (levels 1-4 of every shipped scene, OpenBLAS 0.3.33 and 0.3.15, NGSolve 6.2.2608,
2 cores):

* NGSolve's TaskManager with 1 or 2 threads and OpenBLAS with 1 or 2 threads give
  bit-identical norms (assembly is coloured; the solvers run BLAS on one thread).
* Other OpenBLAS kernels (``OPENBLAS_CORETYPE`` = Haswell, Zen, Sandybridge, Prescott
  against the native Cooperlake) and the machine that made the file differ by at most
  12 delta on the direct and the Coulomb cases alike (the fixed point stops at 1e-12 or
  at its round-off), 2.4e-10 = 0.5 delta on cattaneo-mindlin, level 4 (lambda_t, the
  case that failed a fixed 1e-10 on a fresh machine).
* The relative change of a norm per unit of the change at which the iteration stopped
  (stopping it early, at 1e-3 .. 1e-10, against the solve to 1e-12 or to round-off): at
  most 0.76 for the Coulomb fixed point (thesis-3.46-coulomb-gap0, level 4; 2.5e-4 to 0.15
  on the others), 0.68 per unit of eps for Uzawa against the active-set solution
  (thesis-3.46-frictionless, levels 1-3, eps = 1e-6 and 1e-8), 0.012 per unit of
  max(eps1, eps2) for nested Uzawa (thesis-3.46-tresca and -coulomb, levels 1-2,
  eps2 = 1e-6): 2 q/(1-q) L <= 1.6, and ``STABILITY`` = 10 leaves a factor 6.

A norm stored as zero (a structurally vanishing multiplier, no nu without friction) must
be zero again: the active-set method sets it exactly.
"""

import json
import os
from pathlib import Path

import ngsolve as ngs
import pytest
from threadpoolctl import threadpool_info

from ngdual.quantities import norms
from ngdual.scene import load_scene
from ngdual.solvers import (
    ActiveSetSettings,
    NestedUzawaSettings,
    UzawaSettings,
    solve_scene,
    solver_settings,
)
from ngdual.solvers.semismooth import SAFETY
from ngdual.tolerances import COULOMB_FIXED_POINT_TOL

pytestmark = pytest.mark.slow  # every shipped scene up to level 4 with its own solver

STORED = json.loads((Path(__file__).parent / "data" / "behaviour_norms.json").read_text())
CASES = sorted(STORED["norms"])
STABILITY = 10.0  # 2 q/(1-q) L of an iteration stopped on its relative change (above)


def pin_tolerance(settings, solution) -> float:
    """The relative accuracy to which two solves of the same case agree (module docstring)."""
    if isinstance(settings, UzawaSettings):
        return STABILITY * settings.eps
    if isinstance(settings, NestedUzawaSettings):
        return STABILITY * max(settings.eps1, settings.eps2)
    if not isinstance(settings, ActiveSetSettings):
        pytest.fail(f"no pin tolerance is derived for {type(settings).__name__}")
    roundoff = SAFETY * solution.roundoff
    if settings.model.law == "coulomb":
        return STABILITY * max(COULOMB_FIXED_POINT_TOL, roundoff)
    return roundoff


@pytest.mark.parametrize("case", CASES)
def test_every_shipped_scene_gives_the_stored_norms_to_its_solvers_accuracy(case):
    name, level = case.rsplit("@", 1)
    scene = load_scene(name)
    solution = solve_scene(scene, int(level))
    tol = pin_tolerance(solver_settings(scene), solution)
    got = norms(solution)
    want = STORED["norms"][case]
    assert got.keys() == want.keys()
    for key, value in want.items():
        if value is None:
            assert got[key] is None, key
        else:
            assert got[key] == pytest.approx(value, rel=tol, abs=0.0), (case, key, tol)


@pytest.mark.parametrize("variable", ["NGS_NUM_THREADS", "OPENBLAS_NUM_THREADS"])
def test_the_pins_run_on_the_threads_asked_for(variable):
    """CI runs this file with NGSolve's and OpenBLAS's threads set to 1 and to 2: the
    setting must reach the library, or the run on one thread silently runs on all."""
    asked = os.environ.get(variable)
    if asked is None:
        pytest.skip(f"{variable} is not set: the libraries choose their threads")
    if variable == "NGS_NUM_THREADS":
        with ngs.TaskManager():
            used = [ngs.GetNumThreads()]
    else:  # a serial build (cvxopt's, threading layer "disabled") has one thread anyway
        used = [pool["num_threads"] for pool in threadpool_info()
                if pool["internal_api"] == "openblas" and pool["threading_layer"] != "disabled"]
    assert used and all(n == int(asked) for n in used), (variable, asked, used)
