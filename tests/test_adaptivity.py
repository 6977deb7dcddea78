"""Adaptive refinement: coarse boundary meshes follow it, Dörfler restores the optimal rate,
and both thesis strategies run on Example 3.46 with Coulomb friction.

* Coarse meshes (h~ on Gamma_N, Gamma_C; h^ on Gamma_C) after local netgen refinement:
  every coarse edge is a union of 2-3 fine edges (h~ ~ 2h locally), h^ edges are unions
  of h~ edges, and the meshes of successive steps are nested. Under uniform refinement
  they coincide with the meshes grouped afresh on the finer level.
* L-shaped domain with the re-entrant corner of angle 3 pi / 2, exact mode-I corner
  solution u ~ r^alpha, alpha = 0.5445 (Williams; traction-free on the two sides at the
  corner, u = u_exact on the others). Uniform refinement converges like N^{-alpha/2};
  Dörfler marking (theta = 0.5) on eta_{tot,T} restores the optimal N^{-1/2} of PEERS.
* Example 3.46, Coulomb mu_f = 0.5: max marking theta = 0.5 from level 1 (Table 4.1)
  and fraction marking theta = 0.2 from level 2 (Tables 4.3, 4.4), with the total
  error (3.124) against Aitken-extrapolated norms of uniform levels 1-3.
Run with ``pytest -s`` to see the tables.
"""

import json
import math
from functools import cache

import ngsolve as ngs
import numpy as np
import pytest

from ngdual.afem import adapt, reference_norms, refine
from ngdual.boundary import BoundaryMeshes, CoarseMesh
from ngdual.cli import main
from ngdual.marking import mark_fraction, mark_max
from ngdual.mesh import polygon_mesh, refine_uniformly, thesis_mesh
from ngdual.quantities import norms
from ngdual.rates import fitted_rate
from ngdual.scene import Geometry, Scene, load_scene, validate
from ngdual.solvers import solve_scene
from ngdual.verification.corner import (
    LABELS,
    POINTS,
    corner_exponent,
    exact_error,
    exact_fields,
    l_shape_scene,
)

# --- coarse boundary meshes ----------------------------------------------------------------------


def coarse_node_points(coarse: CoarseMesh) -> set:
    return {tuple(np.round(ch.path_points[n], 12)) for ch, nodes in zip(coarse.chains, coarse.nodes)
            for n in nodes}


def fine_edges_per_coarse_edge(coarse: CoarseMesh) -> np.ndarray:
    return np.concatenate([np.diff(n) for n in coarse.nodes])


def h_ratio(coarse: CoarseMesh) -> np.ndarray:
    """h~_E / h_e for every fine edge e in every coarse edge E."""
    out = []
    for ch, nodes in zip(coarse.chains, coarse.nodes):
        s = ch.arclength
        fine = np.diff(s)
        for a, b in zip(nodes[:-1], nodes[1:]):
            out.extend((s[b] - s[a]) / fine[a:b])
    return np.array(out)


def test_uniform_refinement_reproduces_the_grouped_meshes():
    scene = load_scene("thesis-3.46-coulomb")
    mesh = thesis_mesh(1)
    coarse = BoundaryMeshes.for_scene(scene, mesh)
    for _ in range(2):
        mesh = refine(mesh, np.ones(mesh.ne, dtype=bool))
        coarse = coarse.follow(scene, mesh)
        fresh = BoundaryMeshes.for_scene(scene, mesh)
        for mine, theirs in zip((coarse.neumann, coarse.contact, coarse.friction),
                                (fresh.neumann, fresh.contact, fresh.friction)):
            assert coarse_node_points(mine) == coarse_node_points(theirs)
            assert len(mine.nodes[0]) == len(theirs.nodes[0])


@pytest.mark.parametrize("case", ["thesis", "pentagon"])
def test_coarse_meshes_stay_nested_and_twice_as_coarse_under_local_refinement(case):
    if case == "thesis":
        scene = load_scene("thesis-3.46-coulomb")
        mesh, corner = thesis_mesh(1), np.array([-4.0, -1.0])
    else:
        points = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 2.0), (0.0, 1.0)]
        labels = ["bottom", "right", "roof_right", "roof_left", "left"]
        # maxh 0.25: 8 and 6 fine edges on Gamma_C and Gamma_N, so that the initial
        # grouping already puts two fine (h~) edges into every h~ (h^) edge
        scene = Scene("pentagon", Geometry(kind="polygon", points=points, labels=labels,
                                           maxh=0.25),
                      {"dirichlet": ["right", "roof_left", "left"], "neumann": ["roof_right"],
                       "contact": ["bottom"]}, friction=load_scene("thesis-3.46-coulomb").friction)
        validate(scene)
        mesh = polygon_mesh(points, labels, 0.25)
        corner = np.array([0.5, 0.0])
    coarse = BoundaryMeshes.for_scene(scene, mesh)
    ratios = []
    for step in range(7):
        pts = np.array([v.point for v in mesh.vertices])
        tri = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ngs.VOL)])
        distance = np.linalg.norm(pts[tri].mean(axis=1) - corner, axis=1)
        # a graded mesh: the corner patch every step, a band along the boundary every other
        marked = distance <= np.sort(distance)[2] + 1e-12
        if step % 2:
            marked |= np.abs(pts[tri][:, :, 1].mean(axis=1) - pts[tri][:, :, 1].min()) < 0.3
        new_mesh = refine(mesh, marked)
        new = coarse.follow(scene, new_mesh)
        for old, fine in ((coarse.neumann, new.neumann), (coarse.contact, new.contact),
                          (coarse.friction, new.friction)):
            assert coarse_node_points(old) <= coarse_node_points(fine)  # nested across steps
            for ch, nodes in zip(fine.chains, fine.nodes):
                assert nodes[0] == 0 and nodes[-1] == ch.n_edges and np.all(np.diff(nodes) > 0)
        for tilde in (new.neumann, new.contact):
            assert np.all(fine_edges_per_coarse_edge(tilde) >= 2)
            assert np.all(fine_edges_per_coarse_edge(tilde) <= 3)
            ratios.append(h_ratio(tilde))
        # h^ edges are unions of 2-3 h~ edges
        assert coarse_node_points(new.friction) <= coarse_node_points(new.contact)
        per_hat = [np.diff(np.searchsorted(t, h)) for t, h in zip(new.contact.nodes,
                                                                   new.friction.nodes)]
        assert all(np.all((k >= 2) & (k <= 3)) for k in per_hat)
        mesh, coarse = new_mesh, new
    ratios = np.concatenate(ratios)
    fine_h = np.concatenate([np.diff(ch.arclength) for ch in coarse.contact.chains])
    print(f"\n{case}: contact edges from h = {fine_h.min():.2e} to {fine_h.max():.2e}, "
          f"h~/h in [{ratios.min():.2f}, {ratios.max():.2f}]")
    assert fine_h.max() / fine_h.min() >= 8  # the test did grade the mesh
    assert ratios.min() >= 1.3 and ratios.max() <= 6.0


# --- L-shaped domain -----------------------------------------------------------------------------

def test_corner_solution_is_an_equilibrium_free_at_the_corner_sides():
    """div sigma = 0 in the domain and sigma n = 0 on the two sides at the corner."""
    u, sigma, _ = exact_fields()
    mesh = polygon_mesh(POINTS, LABELS, 0.25)
    div = ngs.CF(tuple(sigma[i, 0].Diff(ngs.x) + sigma[i, 1].Diff(ngs.y) for i in range(2)))
    # away from the corner, where sigma ~ r^(alpha - 1) is smooth
    far = ngs.IfPos(ngs.x * ngs.x + ngs.y * ngs.y - 0.04, 1, 0)
    assert ngs.Integrate(far * div * div, mesh, order=10) < 1e-16
    n = ngs.specialcf.normal(2)
    traction = sigma * n
    sides = ngs.ds(definedon=mesh.Boundaries("corner_v|corner_h"), bonus_intorder=8)
    free = ngs.Integrate(traction * traction * sides, mesh)
    scale = ngs.Integrate(ngs.InnerProduct(sigma, sigma) * far, mesh, order=10)
    assert free < 1e-20 * scale


@cache
def l_shape_runs():
    scene, exact = l_shape_scene(), exact_fields()
    runs = {}
    for name, marking, theta, steps in (("uniform", "max", 0.0, 4),
                                        ("dorfler", "dorfler", 0.5, 9)):
        rows = []

        def on_step(record, solution, estimated, marked, rows=rows):
            rows.append((record["dofs"]["total"], exact_error(solution, exact),
                         record["estimator"]))

        adapt(scene, marking, theta, steps, level=1, asymmetry="l2", on_step=on_step)
        runs[name] = rows
    print("\nL-shape, mode-I corner singularity: error and estimator (as(sigma) in L^2)")
    for name, rows in runs.items():
        for ndof, err, estimate in rows:
            print(f"{name:8s} {ndof:7d}  error {err:.4e}  estimate {estimate:.4e}  "
                  f"effectivity {estimate / err:.2f}")
    return runs


@pytest.mark.slow
def test_dorfler_marking_restores_the_optimal_rate_on_the_l_shape():
    runs = l_shape_runs()
    alpha = corner_exponent()
    rate = {name: fitted_rate(*zip(*[(n, e) for n, e, _ in rows[-3:]]))
            for name, rows in runs.items()}
    print(f"rates of the error (ngdual.rates): uniform {rate['uniform']:.3f} "
          f"(theory alpha = {alpha:.3f}), Dörfler {rate['dorfler']:.3f} (optimal 1)")
    assert rate["uniform"] <= 0.7
    assert rate["dorfler"] >= 0.9
    assert rate["dorfler"] - rate["uniform"] >= 0.3
    # at the same number of DOFs, the adaptive error is much smaller
    n_uniform, e_uniform, _ = runs["uniform"][-1]
    n_adaptive = np.array([n for n, _, _ in runs["dorfler"]])
    e_adaptive = np.array([e for _, e, _ in runs["dorfler"]])
    assert np.interp(np.log(n_uniform), np.log(n_adaptive), e_adaptive) < 0.6 * e_uniform


@pytest.mark.slow
def test_estimator_tracks_the_error_on_the_adaptive_l_shape_meshes():
    effectivity = [estimate / err for _, err, estimate in l_shape_runs()["dorfler"]]
    print(f"effectivity band (Dörfler, L-shape): [{min(effectivity):.2f}, {max(effectivity):.2f}]")
    assert max(effectivity) / min(effectivity) <= 3.0


# --- Example 3.46 with Coulomb friction ---------------------------------------------------------

@cache
def coulomb_reference() -> dict:
    return reference_norms(load_scene("thesis-3.46-coulomb"), [1, 2, 3])


def run_thesis_strategy(marking, theta, level, steps):
    scene = load_scene("thesis-3.46-coulomb")
    captured = []

    def on_step(record, solution, estimated, marked):
        captured.append((estimated.indicators.copy(), None if marked is None else marked.copy(),
                         coarse_node_points(solution.problem.spaces.contact),
                         coarse_node_points(solution.problem.spaces.friction)))

    history = adapt(scene, marking, theta, steps, level=level, reference=coulomb_reference(),
                    on_step=on_step)
    print(f"\nExample 3.46, mu_f = 0.5, {marking} marking theta = {theta}, from level {level}")
    print(f"{'step':>4} {'||s||_X':>10} {'||u||':>9} {'||eta||':>9} {'||phi||':>9} "
          f"{'||lam_t||':>9} {'||lam_n||':>9} {'Dof':>6} {'e_tot':>9} {'effect.':>9} "
          f"{'marked':>6}")
    for r in history:
        nm = r["norms"]
        print(f"{r['step']:4d} {nm['sigma_X']:10.4e} {nm['u']:9.3e} {nm['eta']:9.3e} "
              f"{nm['phi']:9.3e} {nm['lam_t']:9.3e} {nm['lam_n']:9.3e} {r['dofs']['total']:6d} "
              f"{r['e_tot']:9.3e} {r['effectivity']:9.3f} {r['marked']:6d}")
    return history, captured


@pytest.mark.slow
@pytest.mark.parametrize("marking, theta, level", [("max", 0.5, 1), ("fraction", 0.2, 2)])
def test_thesis_strategies_run_on_example_3_46_coulomb(marking, theta, level):
    history, captured = run_thesis_strategy(marking, theta, level, steps=3)
    json.dumps(history, allow_nan=False)
    rule = mark_max if marking == "max" else mark_fraction
    for record, (indicators, marked, tilde, hat) in zip(history, captured):
        assert record["converged"]
        assert record["e_tot"] > 0 and record["effectivity"] == pytest.approx(
            record["estimator"] / record["e_tot"])
        assert record["estimator"] == pytest.approx(math.sqrt(sum(v**2 for v in
                                                            record["estimator_terms"].values())))
        assert set(record["timings_s"]) == {"assemble", "solve", "estimate", "mark", "refine"}
        assert hat <= tilde
        if marked is not None:
            np.testing.assert_array_equal(marked, rule(indicators, theta))
            assert record["marked"] == marked.sum() > 0
    for (prev, now), (c_prev, c_now) in zip(zip(history, history[1:]),
                                            zip(captured, captured[1:])):
        assert now["elements"] > prev["elements"] and now["dofs"]["X"] > prev["dofs"]["X"]
        assert c_prev[2] <= c_now[2] and c_prev[3] <= c_now[3]  # coarse meshes stay nested
    if marking == "fraction":
        assert all(r["marked"] >= math.ceil(theta * r["elements"]) for r in history[:-1])


def test_adapt_command_writes_history_and_meshes(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["adapt", "thesis-3.46-coulomb", "--marking", "max", "--theta", "0.5",
                 "--steps", "2", "--level", "1", "--out", str(out)])
    assert code == 0
    run = json.loads((out / "history.json").read_text())
    assert run["marking"] == "max" and len(run["history"]) == 2
    first, second = run["history"]
    assert second["dofs"]["total"] > first["dofs"]["total"]
    assert first["timings_s"]["refine"] > 0
    for step in (0, 1):
        assert (out / f"mesh_step{step:02d}.png").stat().st_size > 0
        saved = ngs.Mesh(str(out / f"mesh_step{step:02d}.vol"))
        assert saved.ne == run["history"][step]["elements"]
    assert "history.json" in capsys.readouterr().out
    assert main(["adapt", "thesis-3.46-coulomb", "--theta", "1.5", "--out", str(out)]) == 2


def test_uniform_refinement_by_marking_everything_matches_the_levels():
    mesh = refine(thesis_mesh(1), np.ones(32, dtype=bool))
    assert mesh.ne == refine_uniformly(thesis_mesh(1), 1).ne == thesis_mesh(2).ne


@pytest.mark.filterwarnings("ignore::ngdual.solution.PhysicsWarning")
def test_the_first_adaptive_step_solves_what_solve_scene_solves_on_its_level():
    """adapt and solve_scene share one SOLVE step (solvers.solve_on_mesh): on the initial
    level they assemble and solve the same problem, to the last bit."""
    scene = load_scene("thesis-3.46-coulomb")
    first, = adapt(scene, steps=1, level=2)
    assert first["norms"] == norms(solve_scene(scene, 2))
    assert first["marked"] == 0 and first["timings_s"]["refine"] == 0.0


@pytest.mark.parametrize("name", ["hertz-cylinder", "cattaneo-mindlin"])
def test_a_warm_started_contact_iteration_finds_the_cold_started_solution(name):
    """The active set started from the coarser mesh's contact multipliers
    (solvers.start.ContactStart) solves the same discrete problem: the unknowns agree
    to round-off with the solve from z = 0, in fewer semismooth Newton steps (Hertz: one)."""
    from ngdual.afem import refine_with_boundary
    from ngdual.mesh import build_mesh
    from ngdual.solvers import solve_on_mesh
    from ngdual.solvers.start import ContactStart

    scene = load_scene(name)
    mesh = build_mesh(scene.geometry, 1)
    coarse = BoundaryMeshes.for_scene(scene, mesh)
    first = solve_on_mesh(scene, mesh, coarse)
    band = np.array([any(abs(mesh[v].point[0]) < 1.0 and mesh[v].point[1] < 1.0
                         for v in el.vertices) for el in mesh.Elements()])
    mesh, coarse = refine_with_boundary(scene, mesh, coarse, band)
    cold = solve_on_mesh(scene, mesh, coarse)
    warm = solve_on_mesh(scene, mesh, coarse, start=ContactStart.of(first))
    scale = np.max(np.abs(cold.x))
    assert np.max(np.abs(warm.x - cold.x)) <= 1e-10 * scale
    assert warm.iterations["inner"] < cold.iterations["inner"]
    if name == "hertz-cylinder":
        assert warm.iterations["inner"] == 1
