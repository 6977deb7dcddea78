"""Coarse boundary meshes: nesting, zero end values, P1 partition of unity."""

import ngsolve as ngs
import numpy as np
import pytest

from ngdual.afem import refine_towards, refine_with_boundary
from ngdual.boundary import BoundaryMeshes, CoarseMesh, boundary_chains, end_rule
from ngdual.forms.spaces import _trace_space
from ngdual.geometry import round_off
from ngdual.mesh import build_mesh, mesh_arrays, polygon_mesh, thesis_mesh
from ngdual.scene import load_scene


def test_contact_chain_is_ordered_along_the_boundary():
    (chain,) = boundary_chains(thesis_mesh(2), ["bottom"])
    assert not chain.closed
    assert np.all(np.diff(chain.points[:, 0]) > 0) or np.all(np.diff(chain.points[:, 0]) < 0)
    assert chain.n_edges == 16


def test_coarse_edges_are_unions_of_fine_edges_and_nested():
    mesh = thesis_mesh(3)
    tilde = CoarseMesh.from_fine(mesh, ["bottom"], 2)
    hat = tilde.coarsened(2)
    assert tilde.n_edges == 16 and hat.n_edges == 8
    assert set(hat.nodes[0]) <= set(tilde.nodes[0])
    np.testing.assert_allclose(tilde.edge_lengths(), 0.5)
    np.testing.assert_allclose(hat.edge_lengths().sum(), 8.0)


def test_odd_number_of_fine_edges_still_covers_the_chain():
    mesh = polygon_mesh([(0, 0), (3, 0), (3, 1), (0, 1)], ["b", "r", "t", "l"], maxh=0.45)
    coarse = CoarseMesh.from_fine(mesh, ["b"], 2)
    (chain,) = coarse.chains
    assert coarse.nodes[0][0] == 0 and coarse.nodes[0][-1] == chain.n_edges
    np.testing.assert_allclose(coarse.edge_lengths().sum(), 3.0)


def test_p1_prolongation_is_a_partition_of_unity_away_from_the_ends():
    mesh = thesis_mesh(3)
    coarse = CoarseMesh.from_fine(mesh, ["bottom"], 2)
    space = _trace_space(mesh, ["bottom"])
    edge_dofs = coarse.fine_edge_dofs(space)
    P = coarse.p1_prolongation(edge_dofs, space.ndof)
    assert P.shape == (space.ndof, coarse.n_p1_dofs)
    row_sums = np.asarray(P.sum(axis=1)).ravel()
    xs = np.array([mesh.vertices[v].point[0] for v in coarse.chains[0].vertices])
    dofs = np.append(edge_dofs[:, 0], edge_dofs[-1, 1])  # along the chain's vertices
    inner = np.abs(xs) < 4 - 0.5 - 1e-9  # beyond the first coarse edge at each end
    np.testing.assert_allclose(row_sums[dofs[inner]], 1.0)
    ends = np.abs(np.abs(xs) - 4) < 1e-12
    np.testing.assert_allclose(row_sums[dofs[ends]], 0.0)


def test_coarse_mass_matches_exact_integrals():
    coarse = CoarseMesh.from_fine(thesis_mesh(2), ["bottom"], 2)
    mass, stiff = coarse.p1_mass_stiffness()
    ones = np.ones(coarse.n_p1_dofs)
    # squared L2 norm of the sum of interior hats (h~ = 1): 1 on [-3, 3], ramps on the end edges
    np.testing.assert_allclose(ones @ mass @ ones, 6 + 2 / 3)
    # the sum of interior hats has slope +-1 on the end edges only
    np.testing.assert_allclose(ones @ stiff @ ones, 2.0)


def test_closed_boundary_has_no_end_constraints():
    mesh = ngs.Mesh(__import__("netgen.geom2d", fromlist=["x"]).unit_square.GenerateMesh(maxh=0.25))
    labels = list(mesh.GetBoundaries())
    coarse = CoarseMesh.from_fine(mesh, sorted(set(labels)), 2)
    (chain,) = coarse.chains
    assert chain.closed
    assert coarse.n_p1_dofs == coarse.n_edges


def test_a_kink_breaks_gamma_c_once_however_close_the_graded_mesh_comes_to_it():
    """The wedge refined 29 times at its apex: vertices 4.6e-10 from the kink, within the
    geometry's round-off (8e-10) of it. Gamma_C still breaks at the apex vertex alone, into
    the two flanks, and the coarse meshes follow the refinement."""
    scene = load_scene("wedge")
    mesh = build_mesh(scene.geometry, 1)
    coarse = BoundaryMeshes.for_scene(scene, mesh)
    tolerance = round_off(scene.geometry.curves())
    for _ in range(29):
        points, triangles = mesh_arrays(mesh)
        apex = int(np.argmin(np.linalg.norm(points, axis=1)))
        mesh, coarse = refine_with_boundary(scene, mesh, coarse, (triangles == apex).any(axis=1))
    points = mesh_arrays(mesh)[0]
    assert np.sum(np.linalg.norm(points, axis=1) <= tolerance) > 1
    rule = end_rule(scene, mesh, "contact")
    assert rule.breaks == {apex}
    chains = boundary_chains(mesh, scene.labels("contact"), rule.breaks)
    assert len(chains) == len(coarse.contact.chains) == 2
    assert all(np.all(ch.points[1:-1, 0] < 0) or np.all(ch.points[1:-1, 0] > 0)
               for ch in chains)


def test_grading_below_the_resolution_is_refused_with_the_field_named():
    scene = load_scene("wedge")
    with pytest.raises(ValueError, match=r"^times: refinement 20 of 30 .* below the smallest"):
        refine_towards(scene, build_mesh(scene.geometry, 1), (0.0, 0.0), 30)
