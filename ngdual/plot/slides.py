"""One figure geometry for slides: 16:9, 1600 x 900 pixels, fonts sized to be read there.

Inside :func:`slides` (``ngdual figures`` runs every figure script in it) a figure is drawn
with the slide fonts (:data:`SLIDE_RC`: 13 pt text, 125 dpi: labels about 23 px high) and
:func:`~ngdual.plot.save_figure` writes it at :data:`SLIDE_SIZE` inches and
:data:`SLIDE_DPI`, exactly :data:`SLIDE_PIXELS`, with the panels laid out again to fill the
frame (:func:`fit_slide`). Outside it, figures keep their own size and the saved picture is
cropped to what it shows, as before (the pictures of ``ngdual solve``, a notebook).

>>> with slides():
...     in_slides()
True
>>> in_slides(), SLIDE_PIXELS
(False, (1600, 900))
"""

from __future__ import annotations

from contextlib import contextmanager

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

SLIDE_SIZE = (12.8, 7.2)  # inches: 16:9
SLIDE_DPI = 125
SLIDE_PIXELS = (round(SLIDE_SIZE[0] * SLIDE_DPI), round(SLIDE_SIZE[1] * SLIDE_DPI))
# fonts for a 1600 px frame shown full screen: nothing below 10 pt (17 px at 125 dpi);
# the modules' "small" / "x-small" are relative to font.size
SLIDE_RC = {"font.size": 14, "axes.titlesize": 14, "axes.labelsize": 14,
            "xtick.labelsize": 12, "ytick.labelsize": 12, "legend.fontsize": 12,
            "figure.titlesize": 16, "lines.linewidth": 1.8, "lines.markersize": 6,
            "figure.figsize": SLIDE_SIZE, "figure.dpi": SLIDE_DPI}

_depth = [0]  # how many slides() contexts are open


@contextmanager
def slides():
    """Draw and save figures for slides (:data:`SLIDE_RC` fonts, :data:`SLIDE_PIXELS`)."""
    with plt.rc_context(SLIDE_RC):
        _depth[0] += 1
        try:
            yield
        finally:
            _depth[0] -= 1


def in_slides() -> bool:
    """Whether a :func:`slides` context is open (:func:`~ngdual.plot.save_figure` then writes
    slide-sized pictures)."""
    return _depth[0] > 0


def fit_slide(fig: Figure) -> Figure:
    """Resize ``fig`` to :data:`SLIDE_SIZE` and lay its panels out again to fill it
    (constrained layout; a figure whose colour bars were laid out by another engine keeps
    that engine, which lays it out again at the new size)."""
    fig.set_size_inches(*SLIDE_SIZE)
    fig.set_dpi(SLIDE_DPI)
    try:
        fig.set_layout_engine("constrained")
    except RuntimeError:
        pass
    return fig
