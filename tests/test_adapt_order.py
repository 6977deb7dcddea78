"""The adaptive loop at order k: both goals run with the indicators of order k, and on a
corner-singular problem adaptivity recovers the optimal rate in unknowns.

Example 3.46 without friction and with consistent ends has the stress singularities of the
clamped ends of Gamma_C. Uniform refinement at k = 1 runs into them (the estimate's order
in h_N = N^{-1/2} falls to 0.93 on level 4); the stress goal's loop holds the optimal order
k + 1, the estimate falling like N^{-(k+1)/2} (docs/theory/estimator.md, "The estimator at
order k": 1.95 at k = 1 over ten solves, 3.07 at k = 2). The effectivity of the estimate
is tested in ``test_estimator_order``.
"""

import json
import math

import ngsolve as ngs
import numpy as np
import pytest

from ngdual import budget
from ngdual.afem import AdaptWarning, adapt
from ngdual.cli import main
from ngdual.quantities import fields
from ngdual.scene import SceneError, load_scene

# hertz-cylinder's exact pressure: the overkill's ellipse (docs/theory/estimator.md, "What
# the true error is"; 0.11 % in L2 from the overkill), not Hertz's half-space formula
HERTZ_HALF_WIDTH, HERTZ_PEAK = 0.3407, 3786.0


def order_of(history: list[dict]) -> float:
    """The order of the estimate in h_N = N^{-1/2} from the first record to the last."""
    first, last = history[0], history[-1]
    return (math.log(first["estimator"] / last["estimator"])
            / (0.5 * math.log(last["dofs"]["total"] / first["dofs"]["total"])))


@pytest.mark.parametrize("goal", ["stress", "pressure"])
def test_both_goals_run_at_order_1_with_the_unknowns_and_indicators_of_order_1(goal):
    scene = load_scene("hertz-cylinder", ["discretisation.order=1"])
    history = adapt(scene, steps=2, level=1, goal=goal)
    first = history[0]
    # PEERS_1: the stress rows of RT_1 plus 3 Curl bubbles per triangle, u in P_1
    assert first["dofs"]["M"] == 2 * 3 * first["elements"]
    assert first["dofs"]["X"] > 2 * 3 * first["elements"]
    assert history[1]["elements"] > first["elements"]
    assert all(0 < r["relative_estimate"] < 1 for r in history)
    assert history[1]["estimator"] < first["estimator"]


def test_adapt_takes_the_order_as_an_argument_and_leaves_the_scene_alone():
    scene = load_scene("hertz-cylinder")
    history = adapt(scene, steps=1, level=1, order=1)
    assert history[0]["dofs"]["M"] == 2 * 3 * history[0]["elements"]
    assert scene.discretisation.order == 0
    with pytest.raises(SceneError) as err:
        adapt(scene, steps=1, level=1, order=3)
    assert err.value.field == "order"


def test_ngdual_adapt_takes_the_order_on_the_command_line(tmp_path):
    assert main(["adapt", "thesis-3.46-frictionless", "--set", "discretisation.order=1",
                 "--set", "contact.ends=consistent", "--steps", "2", "--level", "1",
                 "--out", str(tmp_path)]) == 0
    steps = json.loads((tmp_path / "history.json").read_text())["history"]
    assert [s["step"] for s in steps] == [0, 1]
    assert steps[0]["dofs"]["M"] == 2 * 3 * steps[0]["elements"]


def test_a_refinement_that_would_not_fit_the_memory_its_order_needs_ends_the_loop(monkeypatch):
    """Refining all 32 triangles of Example 3.46's level 1 gives about 160: PEERS_0 would
    need 384 MiB, PEERS_2 with the facet multipliers 421 MiB (:mod:`ngdual.budget`); with
    400 MiB available the loop at order 2 stops before that refinement ("memory", with the
    memory needed and the remedy of a run of steps) and says so, at order 0 it refines."""
    scene = load_scene("thesis-3.46-frictionless",
                       ["discretisation.order=2", "contact.ends=consistent"])
    have = 400 * 2**20
    assert budget.solve_memory(160) < have < budget.solve_memory(160, "auto", 2, "facet")
    monkeypatch.setattr(budget, "available_memory", lambda: have)
    with pytest.warns(AdaptWarning, match="the next refinement would have about 160 triangles"):
        history = adapt(scene, marking="max", theta=0.0, steps=2, level=1)
    assert len(history) == 1 and history[0]["stopped_by"] == "memory"
    assert history[0]["marked"] == 0 and history[0]["timings_s"]["refine"] == 0.0
    need = budget.solve_memory(160, "auto", 2, "facet")
    assert f"need about {need / 2**30:.3g} GiB" in history[0]["stop_message"]
    assert "use fewer steps, or allow_large=True" in history[0]["stop_message"]
    order_0 = adapt(scene, marking="max", theta=0.0, steps=2, level=1, order=0,
                    multipliers="coarse")
    assert [r.get("stopped_by") for r in order_0] == [None, "steps"]


@pytest.mark.slow
def test_adaptivity_recovers_the_optimal_order_at_order_1_where_uniform_refinement_does_not():
    scene = load_scene("thesis-3.46-frictionless",
                       ["discretisation.order=1", "contact.ends=consistent"])
    adaptive = adapt(scene, steps=8, level=1)
    uniform = adapt(scene, marking="max", theta=0.0, steps=4, level=1)
    rates = [order_of(adaptive), order_of(uniform[-2:])]
    print(f"\nk = 1: adaptive order {rates[0]:.2f} over {len(adaptive)} solves "
          f"({adaptive[-1]['dofs']['total']} unknowns), uniform's last {rates[1]:.2f}")
    assert rates[0] >= 1.8           # k + 1 = 2
    assert rates[1] <= 1.2           # the corner singularity
    assert adaptive[-1]["estimator"] < uniform[-2]["estimator"]
    assert adaptive[-1]["dofs"]["total"] < uniform[-1]["dofs"]["total"]
    assert np.all(np.diff([r["estimator"] for r in adaptive]) < 0)


def hertz_pressure_error(solution) -> float:
    """||p_h - p||_{L2(Gamma_C)} / ||p||, p_h = -sigma_nn^h (the trace, P_k on every edge)."""
    mesh = solution.problem.fes.mesh
    n = ngs.specialcf.normal(2)
    p_h = -(ngs.BoundaryFromVolumeCF(fields(solution).sigma) * n) * n
    inside = 1 - ngs.x**2 / HERTZ_HALF_WIDTH**2
    p = HERTZ_PEAK * ngs.sqrt(ngs.IfPos(inside, inside, 0))
    ds = ngs.ds(definedon=mesh.Boundaries("bottom"), bonus_intorder=10)
    return math.sqrt(ngs.Integrate((p_h - p)**2 * ds, mesh) / ngs.Integrate(p**2 * ds, mesh))


@pytest.mark.slow
def test_the_pressure_goal_of_order_1_stops_below_one_percent_on_hertz():
    """adapt(hertz, goal="pressure", tol=0.01) at k = 1 stops at a true pressure error below
    1 % (measured: 0.64 % after 5 solves), its estimate within [0.5, 2.5] times the error
    on the way (goal.calibration, the vertex jumps and the far field of order k; measured
    0.72-0.94 at c83fd4a, 0.71-2.26 with Doerfler's own sets; 0.74-1.51 with the far field
    at the edge terms' constant, 0.81-1.57 without the far field of order k, 0.45-3.2
    without the jumps)."""
    scene = load_scene("hertz-cylinder", ["discretisation.order=1"])
    errors = []
    history = adapt(scene, goal="pressure", tol=0.01,
                    on_step=lambda record, solution, *_: errors.append(
                        hertz_pressure_error(solution)))
    effectivity = [r["relative_estimate"] / e for r, e in zip(history, errors)]
    print(f"\nk = 1: errors {np.round(errors, 4).tolist()}, effectivity "
          f"{np.round(effectivity, 2).tolist()}")
    assert history[-1]["stopped_by"] == "tol"
    assert errors[-1] < 0.01
    assert 0.5 <= min(effectivity) and max(effectivity) <= 2.5


@pytest.mark.slow
def test_a_solve_of_hertz_to_one_percent_takes_at_most_five_solves_and_is_within_it():
    """``nd.solve(hertz, tol=0.01)`` (issue 50): the rule's method (k = 2: the pressure is
    singular only at the free ends of the contact zone) stops by its estimate within five
    solves at a true pressure error below 1 % against the finite body's overkill (measured:
    3 solves, 34 638 unknowns, estimate 0.49 %, error 0.58 %). Its time is a benchmark's,
    ``ngdual bench adaptive --orders 2`` (0.8 s on a 2-core machine)."""
    from ngdual.accuracy import solve as solve_to

    solution = solve_to(load_scene("hertz-cylinder"), tol=0.01)
    accuracy = solution.accuracy
    assert accuracy["reached"] and accuracy["order"] == 2 and accuracy["solves"] <= 5
    assert hertz_pressure_error(solution) < 0.01
