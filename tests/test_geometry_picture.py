"""The two pictures every tutorial starts from (ngdual.plot.plot_geometry, plot_von_mises).

The geometry picture names every boundary part of the scene (Γ_D, Γ_N, Γ_C with their side
labels) in its legend and draws the mesh; the von Mises picture is an element field whose
colour bar names the quantity and, for a corner singularity, the clipping.
"""

import matplotlib.pyplot as plt
import ngsolve as ngs
from matplotlib.figure import Figure

import ngdual as nd
from ngdual.mesh import build_mesh


def test_the_geometry_picture_names_every_boundary_part_and_draws_the_mesh():
    scene = nd.load_scene("thesis-3.46-coulomb")
    mesh = build_mesh(scene.geometry, 1)
    fig = nd.plot_geometry(scene, level=1)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    legend = [text.get_text() for text in ax.get_legend().get_texts()]
    assert legend == [r"$\Gamma_D$: left, right", r"$\Gamma_N$: top", r"$\Gamma_C$: bottom"]
    assert f"{mesh.ne} triangles" in ax.get_title()
    notes = {text.get_text() for text in ax.texts}
    assert {r"$\Gamma_D$ (left)", r"$\Gamma_C$ (bottom)"} <= notes
    plt.close(fig)


def test_a_scene_without_contact_draws_only_its_parts():
    scene = nd.load_scene("thesis-3.46-frictionless",
                          ["boundary.dirichlet=['left', 'right', 'bottom', 'top']",
                           "boundary.neumann=[]", "boundary.contact=[]"])
    fig = nd.plot_geometry(scene, level=1, title="clamped")
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        r"$\Gamma_D$: left, right, bottom, top"]
    assert ax.get_title() == "clamped"
    plt.close(fig)


def test_the_von_mises_picture_of_a_singular_field_says_it_is_clipped():
    mesh = build_mesh(nd.load_scene("thesis-3.46-coulomb").geometry, 1)
    spike = 1 / ((ngs.x + 4) ** 2 + (ngs.y + 1) ** 2 + 1e-3)          # at the corner (-4, -1)
    singular = ngs.CF((spike, 0, 0, 0), dims=(2, 2))
    fig = nd.plot_von_mises(mesh, singular, 0.3, "spike")
    colorbar = fig.axes[-1]
    label = colorbar.get_xlabel() + colorbar.get_ylabel()
    assert label.startswith("von Mises stress") and "99th percentile" in label, label
    plt.close(fig)
