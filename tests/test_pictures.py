"""Pictures that tell the truth at a glance (ngdual.plot).

* Every plot function returns a matplotlib Figure and writes nothing; saving is
  ``save_figure``'s job (one file for a path with a suffix, PNG + PDF + JSON sidecar for a
  stem). Importing ngdual.plot leaves matplotlib's backend alone.
* Axis labels carry the units the scene's ``[units]`` table declares, and without it name
  the quantity only (never "[stress units]").
* A field with a corner singularity gets a clipped colour scale and the colour bar says
  so; a trace on Gamma_C never clips p_h, only spikes of the fine-edge stress, and says
  so; meshes of adaptive runs shade the marked triangles and count them in the legend.
"""

import json
import os
import subprocess
import sys

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.figure import Figure

from ngdual import plot
from ngdual.scene import Units
from ngdual.trace import ContactTraces

# a 4 x 2 grid of the rectangle [0, 4] x [0, 1], 16 triangles
X, Y = np.meshgrid(np.linspace(0, 4, 5), np.linspace(0, 1, 3))
POINTS = np.column_stack([X.ravel(), Y.ravel()])
TRIANGLES = np.array([t for i in range(4) for j in range(2)
                      for t in ([j * 5 + i, j * 5 + i + 1, (j + 1) * 5 + i + 1],
                                [j * 5 + i, (j + 1) * 5 + i + 1, (j + 1) * 5 + i])])
MM_MPA = Units(length="mm", stress="MPa")


def traces() -> ContactTraces:
    """Traces on the bottom side y = 0: in contact on [1, 3], a corner spike at x = 0, fixed
    ends at x = 0 and x = 4."""
    nodes = np.linspace(0, 4, 33)
    mids = 0.5 * (nodes[1:] + nodes[:-1])
    sigma_n = np.where(np.abs(mids - 2) < 1, -1.0, 0.0)
    sigma_n[0] = 500.0
    lam_n = np.where(np.abs(nodes - 2) <= 1, 0.0, 0.01 * np.abs(nodes - 2))
    coarse = nodes[2:-1:2]
    in_contact = lam_n[2:-1:2] == 0
    return ContactTraces(np.column_stack([mids, 0 * mids]), np.full(32, 0.125), sigma_n,
                         0.1 * sigma_n, sigma_n < 0, np.column_stack([nodes, 0 * nodes]),
                         lam_n, 0.001 * nodes, 0 * nodes, np.column_stack([coarse, 0 * coarse]),
                         lam_n[2:-1:2], 0 * coarse, in_contact, in_contact * 1.0,
                         0 * coarse, np.array([[0.0, 0.0], [4.0, 0.0]]), np.zeros(2),
                         np.zeros(2), np.where(in_contact, "contact", "separation"), False)


def every_figure(units=None) -> dict[str, Figure]:
    values = np.linspace(0, 1, len(TRIANGLES))
    return {
        "contact_traces": plot.plot_contact_traces(traces(), "traces", units=units),
        "element_field": plot.plot_element_field(POINTS, TRIANGLES, values, "field",
                                                 plot.unit_label("stress", units and units.stress),
                                                 units=units),
        "mesh": plot.plot_mesh(POINTS, TRIANGLES, "mesh", values > 0.5, units=units),
        "field_pair": plot.plot_field_pair(POINTS, TRIANGLES, [values, values], ["a", "b"],
                                           "value", "pair", units=units),
        "curves": plot.plot_curves([{"title": "t", "xlabel": "x", "ylabel": "y",
                                     "curves": [{"x": [1, 2], "y": [3, 4], "label": "c"}]}],
                                   "curves"),
        "heatmaps": plot.plot_heatmaps(np.array([1.0, 2.0]), np.array([1.0]),
                                       [np.array([[1.0], [np.nan]])], ["h"], "x", "y", ["n"],
                                       "heat"),
        "domain": plot.plot_domain(POINTS, TRIANGLES, np.linspace(-4, 4, 81),
                                   -np.ones(81), [], [(np.zeros(2), np.zeros(2), "g", {})],
                                   "domain", units=units),
    }


def labels(fig: Figure) -> list[str]:
    texts = plot.figure_texts(fig)
    return [text for ax in texts["axes"] for key in ("xlabel", "ylabel", "label")
            if (text := ax.get(key))]


def test_plot_functions_return_figures_and_write_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    figures = every_figure()
    assert all(isinstance(fig, Figure) for fig in figures.values()), figures
    assert not list(tmp_path.iterdir())
    for fig in figures.values():
        plt.close(fig)


def test_save_figure_writes_one_file_or_a_stem_with_its_sidecar_and_closes_the_figure(
        tmp_path):
    fig = plot.plot_mesh(POINTS, TRIANGLES, "one file")
    assert plot.save_figure(fig, tmp_path / "out" / "mesh.png") == [tmp_path / "out" / "mesh.png"]
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["mesh.png"]
    assert not plt.fignum_exists(fig.number)
    fig = plot.plot_mesh(POINTS, TRIANGLES, "a stem")
    written = plot.save_figure(fig, tmp_path / "stem" / "fig_4_01")
    assert [p.name for p in written] == ["fig_4_01.png", "fig_4_01.pdf"]
    sidecar = json.loads((tmp_path / "stem" / "fig_4_01.json").read_text())
    assert sidecar["axes"][0]["title"] == "a stem"
    assert all(p.stat().st_size > 0 for p in written)
    assert not list(tmp_path.rglob("*.part*"))


def test_every_picture_drawn_for_slides_is_16_to_9_at_1600_px_with_legible_fonts(tmp_path):
    """Inside ``plot.slides()`` each picture is laid out again at 16:9 and written at
    1600 x 900 px (``ngdual figures`` and the gallery), no text under 9 pt (15 px)."""
    with plot.slides():
        figures = every_figure()
        for name, fig in figures.items():
            fig.canvas.draw()
            sizes = {t.get_fontsize() for t in fig.findobj(matplotlib.text.Text)
                     if t.get_text().strip()}
            assert min(sizes) >= 9, (name, sorted(sizes))
            [png] = plot.save_figure(fig, tmp_path / f"{name}.png")
            assert plt.imread(png).shape[:2] == (900, 1600), name


def test_importing_ngdual_plot_leaves_the_matplotlib_backend_alone():
    code = ("import matplotlib; matplotlib.use('svg'); import ngdual.plot; "
            "print(matplotlib.get_backend())")
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=env).stdout
    assert out.strip() == "svg"


def test_labels_carry_the_declared_units():
    for name, fig in every_figure(MM_MPA).items():
        if name in ("curves", "heatmaps"):   # their labels are the caller's
            continue
        texts = labels(fig)
        assert any("[mm]" in t for t in texts), (name, texts)
        if name in ("contact_traces", "element_field"):
            assert any("[MPa]" in t for t in texts), (name, texts)
        plt.close(fig)


def test_without_declared_units_labels_name_the_quantity_and_no_made_up_unit():
    for name, fig in every_figure().items():
        for text in labels(fig):
            assert "units" not in text and "[length]" not in text, (name, text)
            assert "[mm]" not in text and "[MPa]" not in text, (name, text)
        plt.close(fig)
    fig = plot.plot_contact_traces(traces())
    assert r"pressure $p_h = -\sigma_n$" in labels(fig)
    plt.close(fig)


def test_a_corner_singularity_is_clipped_and_the_colour_bar_says_so():
    values = np.full(len(TRIANGLES), 1.0)
    values[: len(values) // 2] = np.linspace(0.5, 1.5, len(values) // 2)
    values[0] = 1e4                                     # the corner
    fig = plot.plot_element_field(POINTS, TRIANGLES, values, "von Mises", "stress", clip=90)
    art = fig.axes[0].collections[0]
    assert art.get_clim()[1] < 2 < values.max()
    bar = [a for a in plot.figure_texts(fig)["axes"] if a["colorbar"]][0]["label"]
    assert "90th percentile" in bar and "1e+04" in bar
    plt.close(fig)
    fig = plot.plot_element_field(POINTS, TRIANGLES, np.ones_like(values), "flat", "stress",
                                  clip=90)
    bar = [a for a in plot.figure_texts(fig)["axes"] if a["colorbar"]][0]["label"]
    assert bar == "stress"                              # nothing clipped, nothing said
    plt.close(fig)


def test_a_signed_field_is_clipped_symmetrically():
    values = np.concatenate([np.linspace(-1, 1, 15), [-50.0]])
    vmin, vmax, extend, note = plot.clipped_scale(values, 90)
    assert vmin == -vmax and vmax < 2 and extend == "both" and "-50" in note


def test_the_pressure_panel_holds_p_h_and_leaves_only_a_fine_edge_spike_off_scale():
    fig = plot.plot_contact_traces(traces())
    ax = fig.axes[0]
    low, high = ax.get_ylim()
    assert low <= 0 and high >= 1                        # every p_h (0 and 1) on scale
    assert low > -500                                    # the corner spike of -sigma_n is not
    notes = " ".join(t.get_text() for t in ax.texts)
    assert "fine-edge values: 1 value off scale (up to -500)" in notes
    plt.close(fig)


def test_an_adaptive_mesh_shades_and_counts_the_marked_triangles():
    marked = np.zeros(len(TRIANGLES), bool)
    marked[[0, 3, 5]] = True
    fig = plot.plot_mesh(POINTS, TRIANGLES, "step 1", marked)
    ax = fig.axes[0]
    shaded = ax.collections[0].get_paths()               # only the marked triangles
    centroids = np.array([path.vertices[:3].mean(axis=0) for path in shaded])
    assert np.allclose(np.sort(centroids, axis=0),
                       np.sort(POINTS[TRIANGLES[marked]].mean(axis=1), axis=0))
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "3 marked for refinement" in legend and "16 triangles" in legend
    plt.close(fig)


@pytest.mark.parametrize("bad", [0, 100, None])
def test_no_clipping_outside_the_open_percentile_range(bad):
    assert plot.clipped_scale(np.array([0.0, 1.0, 100.0]), bad) == (0.0, 100.0, "neither", "")
