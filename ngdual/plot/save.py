"""Saving a figure: one file for a path with a suffix, or PNG and PDF with a JSON sidecar of
what the figure says (titles, labels, legends, colour bars) for a stem without one; inside
:func:`~ngdual.plot.slides` at the slide geometry (16:9, 1600 x 900 px)."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from .slides import SLIDE_DPI, fit_slide, in_slides

SIDECAR_FORMATS = (".png", ".pdf")  # what a stem without suffix becomes, with its .json


def figure_texts(fig: Figure) -> dict:
    """Titles, axis labels, legend entries and colour bars of a figure (the JSON sidecar)."""
    axes = []
    for ax in fig.axes:
        colorbar = getattr(ax, "_colorbar", None)
        if colorbar is not None:
            axes.append({"colorbar": True, "label": colorbar.ax.get_ylabel()
                         or colorbar.ax.get_xlabel()})
            continue
        legend = ax.get_legend()
        axes.append({"colorbar": False, "title": ax.get_title(), "xlabel": ax.get_xlabel(),
                     "ylabel": ax.get_ylabel(),
                     "legend": [t.get_text() for t in legend.get_texts()] if legend else [],
                     "labelled_lines": sum(1 for line in ax.get_lines()
                                           if not line.get_label().startswith("_")),
                     "filled": bool(ax.collections or ax.images)})
    suptitle = fig._suptitle.get_text() if fig._suptitle is not None else ""
    legends = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    return {"suptitle": suptitle, "axes": axes, "figure_legend": legends}


def save_figure(fig: Figure, target: str | Path, dpi: int = 130,
                slide: bool | None = None) -> list[Path]:
    """Write ``fig`` atomically and close it; returns the files written.

    ``target`` with a suffix (``out/von_mises.png``) is that one file; a stem without
    suffix (``figures/fig_3_11``) becomes ``stem.png``, ``stem.pdf`` and ``stem.json``
    (:func:`figure_texts`: what the figure says, for tests and indexes).

    ``slide`` (default: inside :func:`~ngdual.plot.slides`): the figure laid out again at
    16:9 and written at exactly 1600 x 900 px (:func:`~ngdual.plot.slides.fit_slide`; ``dpi``
    is then the slide's); otherwise at ``dpi``, cropped to what the figure shows.
    """
    target = Path(target)
    if slide is None:
        slide = in_slides()
    if slide:
        fit_slide(fig)
    target.parent.mkdir(parents=True, exist_ok=True)
    texts = figure_texts(fig) if not target.suffix else None
    written = []
    try:
        for path in [target] if target.suffix else [target.with_suffix(s)
                                                    for s in SIDECAR_FORMATS]:
            tmp = path.with_name(path.stem + ".part" + path.suffix)
            if slide:
                fig.savefig(tmp, dpi=SLIDE_DPI)
            else:
                fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
            tmp.replace(path)
            written.append(path)
    finally:
        plt.close(fig)
    if texts is not None:
        sidecar = target.with_suffix(".json")
        tmp = target.with_name(target.name + ".part.json")
        tmp.write_text(json.dumps(texts, indent=1))
        tmp.replace(sidecar)
    return written
