"""The textbook contact problems can be posed and are solved consistently.

Free sides next to Gamma_C, curved (arcs) and kinked contact sides, a foundation line, and
multipliers that take the data's values where Gamma_C meets Gamma_D (``contact.ends =
"consistent"``): the resultant of sigma n on Gamma_C equals the force the multipliers carry
(exactly where every end is free, up to a discretisation error that shrinks otherwise), the
two independent solvers agree, and the thesis' homogeneous ends stay an explicit choice.
"""

from functools import cache

import numpy as np
import pytest

from ngdual import post, trace
from ngdual.afem import adapt
from ngdual.forms import assemble
from ngdual.mesh import build_mesh
from ngdual.scene import load_scene
from ngdual.solvers import solve_problem, solve_scene

NEW_SCENES = ("hertz-cylinder", "flat-punch", "cattaneo-mindlin", "wedge")
TIGHT_UZAWA = ["solver.method='uzawa'", "solver.eps=1e-11", "solver.eps1=1e-11",
               "solver.eps2=1e-10"]


@cache
def solved(name: str, level: int, extra: tuple = ()):
    return solve_scene(load_scene(name, list(extra)), level)


@pytest.mark.slow
@pytest.mark.parametrize("name", NEW_SCENES)
def test_force_on_gamma_c_equals_the_multiplier_force_on_every_level(name):
    """Every end of Gamma_C is free (free sides, kinks): the h~ hats sum to one on Gamma_C,
    so the resultant and the multiplier force agree to round-off, and no hat moment is
    tensile (every hat has a dof, where (3.62) makes d_Cn(mu_i, sigma) <= 0)."""
    for level in (1, 2, 3):
        balance = post.force_balance(solved(name, level))
        assert balance.mismatch < 1e-9, (level, balance)
        assert balance.multiplier_force[1] > 0  # pressed onto the foundation y = 0
        assert balance.tension < 1e-9, (level, balance)


@pytest.mark.slow
def test_clamped_contact_ends_balance_forces_unless_the_thesis_ends_are_chosen():
    """Example 3.46 with g = 0.01 at the clamped corners: with the thesis' C_h~ (zero at
    the ends) about 1980 of tension sits in the corner cells on every level; with the
    consistent ends the mismatch is a discretisation error that decreases."""
    thesis, consistent = [], []
    for level in (1, 2, 3, 4):
        thesis.append(post.force_balance(solved("thesis-3.46-frictionless", level)))
        consistent.append(post.force_balance(
            solved("thesis-3.46-frictionless", level, ("contact.ends='consistent'",))))
    excess = [np.linalg.norm(b.resultant - b.multiplier_force) / np.linalg.norm(
        b.multiplier_force) for b in thesis[1:]]
    assert min(excess) > 1.0, excess
    assert all(b.resultant[1] < 0 for b in thesis), "net tension on Gamma_C"
    mismatch = [b.mismatch for b in consistent]
    assert mismatch[-1] < 0.025 and mismatch[-1] < mismatch[0], mismatch
    assert max(b.tension for b in consistent[1:]) < 1e-9 < consistent[0].tension


def test_thesis_scenes_keep_the_thesis_ends():
    scene = load_scene("thesis-3.46-coulomb")
    assert scene.contact.ends == "thesis"
    assert load_scene("hertz-cylinder").contact.ends == "consistent"


@pytest.mark.parametrize("name", NEW_SCENES)
@pytest.mark.parametrize("level", [1, *(pytest.param(lv, marks=pytest.mark.slow) for lv in (2, 3)),
                                   *(pytest.param(lv, marks=pytest.mark.long) for lv in (4, 5))])
def test_uzawa_and_active_set_reach_the_same_solution(name, level):
    """Uzawa at tight tolerances and the active-set method: the same sigma and lambda_n.

    Levels 4 and 5 are marked long (not run by CI): Uzawa's outer steps grow with the
    level, and on a 2-core machine one scene takes about 2 min on level 4 (wedge 126 s,
    against 32 s on level 3) and from 2.5 min (hertz-cylinder, 153 s) to half an hour
    (cattaneo-mindlin, nested Uzawa 1826 s) on level 5."""
    fast = solved(name, level)
    uzawa = solved(name, level, tuple(TIGHT_UZAWA))
    assert fast.converged and uzawa.converged
    s = fast.problem.sigma
    assert np.linalg.norm(fast.x[s] - uzawa.x[s]) <= 1e-7 * np.linalg.norm(fast.x[s])
    lam = fast.part("lam_n")
    assert np.max(np.abs(lam - uzawa.part("lam_n"))) <= 1e-7 * max(np.max(np.abs(lam)), 1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("name", NEW_SCENES)
def test_new_scenes_solve_on_levels_four_and_five(name):
    for level in (4, 5) if name == "flat-punch" else (4,):
        sol = solved(name, level)
        assert sol.converged
        assert post.force_balance(sol).mismatch < 1e-9


def test_arc_vertices_lie_on_the_circle_after_refinement():
    scene = load_scene("hertz-cylinder")
    mesh = build_mesh(scene.geometry, 3)
    problem = assemble(scene, mesh)
    pts = np.vstack([c.points for c in problem.spaces.contact.chains])
    radius = np.hypot(pts[:, 0], pts[:, 1] - 10.0)
    assert np.max(np.abs(radius - 10.0)) < 1e-12


def test_kink_splits_the_multipliers():
    """The wedge's two flanks meet at the apex: two chains, both free there."""
    problem = assemble(load_scene("wedge"), build_mesh(load_scene("wedge").geometry, 2))
    contact = problem.spaces.contact
    assert len(contact.chains) == 2
    assert all(free == (True, True) for free in contact.free)
    apex = [tuple(np.round(c.points[k], 12)) for c in contact.chains for k in (0, -1)]
    assert apex.count((0.0, 0.0)) == 2


def test_cattaneo_mindlin_has_stick_inside_slip_nearly_incompressible():
    sol = solved("cattaneo-mindlin", 3)
    diag = trace.friction_diagnostics(sol)
    x = diag.node_xy[:, 0]
    stick = x[diag.node_status == "stick"]
    slip = x[diag.node_status == "slip"]
    assert len(stick) and len(slip)
    assert stick.min() > slip.min() and stick.max() < slip.max()


@pytest.mark.parametrize("name", ["flat-punch",
                                  pytest.param("cattaneo-mindlin", marks=pytest.mark.slow)])
def test_adaptive_refinement_on_a_new_scene_keeps_forces_balanced(name):
    mismatches = []

    def on_step(record, solution, indicators, marked):
        mismatches.append(post.force_balance(solution).mismatch)

    history = adapt(load_scene(name), marking="dorfler", theta=0.5, steps=3, level=1,
                    on_step=on_step)
    assert len(history) == 3 and history[-1]["dofs"]["X"] > history[0]["dofs"]["X"]
    assert max(mismatches) < 1e-9, mismatches


@pytest.mark.slow
def test_graded_mesh_contact_solve_agrees_with_uzawa():
    from ngdual.afem import refine_towards
    scene = load_scene("hertz-cylinder")
    mesh, coarse = refine_towards(scene, build_mesh(scene.geometry, 1), (0.0, 0.0), 6)
    fast = solve_problem(assemble(scene, mesh, coarse))
    uzawa = solve_problem(assemble(load_scene("hertz-cylinder", TIGHT_UZAWA), mesh, coarse))
    s = fast.problem.sigma
    assert np.linalg.norm(fast.x[s] - uzawa.x[s]) <= 1e-7 * np.linalg.norm(fast.x[s])


@pytest.mark.slow
def test_adaptive_runs_of_both_methods_agree():
    """ngdual adapt with Uzawa and with the active-set method: the same estimator on every
    step, hence the same marked elements and the same graded meshes."""
    runs = {}
    for method, extra in (("active-set", ()), ("uzawa", TIGHT_UZAWA)):
        runs[method] = adapt(load_scene("hertz-cylinder", list(extra)), marking="dorfler",
                             theta=0.5, steps=3, level=1)
    fast, uzawa = runs["active-set"], runs["uzawa"]
    assert [r["dofs"] for r in fast] == [r["dofs"] for r in uzawa]
    for a, b in zip(fast, uzawa):
        assert abs(a["estimator"] - b["estimator"]) <= 1e-7 * a["estimator"], (
            a["estimator"], b["estimator"])
