"""The docs' gallery is slide-ready (issue 49): every PNG in ``docs/gallery`` is at least
1600 px wide at 16:9 (within 1 %), read from the PNG header; and a figure saved inside
:func:`ngdual.plot.slides` is exactly 1600 x 900 px."""

import struct
from pathlib import Path

import matplotlib.pyplot as plt
import pytest

from ngdual import plot

GALLERY = Path(__file__).parents[1] / "docs" / "gallery"
PNGS = sorted(GALLERY.glob("*.png"))


def png_size(path: Path) -> tuple[int, int]:
    """Width and height from the IHDR chunk (the PNG signature, then its length and type)."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR", path.name
    return struct.unpack(">II", head[16:24])


def test_the_gallery_has_pictures():
    assert len(PNGS) >= 9


@pytest.mark.parametrize("path", PNGS, ids=[p.name for p in PNGS])
def test_every_gallery_png_is_a_16_to_9_slide_at_least_1600_px_wide(path):
    width, height = png_size(path)
    assert width >= 1600, (path.name, width, height)
    assert abs(width / height / (16 / 9) - 1) <= 0.01, (path.name, width, height)


def test_the_png_header_reads_what_matplotlib_reads():
    path = PNGS[0]
    height, width = plt.imread(path).shape[:2]
    assert png_size(path) == (width, height)


def test_a_figure_saved_for_slides_is_1600_by_900(tmp_path):
    with plot.slides():
        fig, ax = plt.subplots(figsize=(9, 2))   # any size: saved at the slide's
        ax.plot([0, 1], [0, 1], label="a line")
        ax.set(title="t", xlabel="x [mm]", ylabel="y [mm]")
        ax.legend()
        [png] = plot.save_figure(fig, tmp_path / "slide.png")
    assert png_size(png) == plot.SLIDE_PIXELS == (1600, 900)
    fig, ax = plt.subplots(figsize=(9, 2))       # outside: its own size, cropped
    ax.plot([0, 1], [0, 1])
    [png] = plot.save_figure(fig, tmp_path / "own.png")
    assert png_size(png)[0] < 1600
