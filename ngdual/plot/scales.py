"""Axis labels in the units a scene declares, and colour scales that end at a percentile.

Axis labels carry the units of the scene's ``[units]`` table (:class:`ngdual.scene.Units`,
passed as ``units``); where it declares none a label names the quantity only ("$x_1$",
"von Mises stress"), never a made-up unit. A field with corner singularities takes a
``clip``: its colour scale ends at that percentile and the colour bar says so.
"""

from __future__ import annotations

import numpy as np

CORNER_CLIP = 99.0  # percentile where the colour scale of a field with corner singularities ends


def unit_label(quantity: str, unit: str | None) -> str:
    """``quantity [unit]``, or the quantity alone where no unit is declared.

    >>> unit_label("stress", "MPa"), unit_label("stress", None)
    ('stress [MPa]', 'stress')
    """
    return f"{quantity} [{unit}]" if unit else quantity


def length_unit(units) -> str | None:
    """The length unit of the scene's ``units`` (None: not declared)."""
    return getattr(units, "length", None)


def stress_unit(units) -> str | None:
    """The stress unit of the scene's ``units`` (None: not declared)."""
    return getattr(units, "stress", None)


def clipped_scale(values: np.ndarray, clip: float | None,
                  vmax: float | None = None) -> tuple[float, float, str, str]:
    """``(vmin, vmax, extend, note)`` of a colour scale ending at the ``clip`` percentile.

    A field that changes sign is clipped symmetrically in |value|. ``note`` states the
    clipping and the largest value beyond it (empty without clipping, or when nothing
    lies beyond the percentile). ``vmax`` ends the scale at a given value instead (one
    scale for several pictures), stated the same way where values lie beyond it.

    >>> clipped_scale(np.array([0.0, 1.0, 4.0]), None, vmax=2.0)[1:3]
    (2.0, 'max')
    """
    values = np.asarray(values, float)
    low, high = float(values.min()), float(values.max())
    if vmax is not None:
        if vmax >= high:
            return low, vmax, "neither", ""
        return low, vmax, "max", f"colour scale ends at {vmax:.3g} (max {high:.3g})"
    if clip is None or not 0 < clip < 100:
        return low, high, "neither", ""
    if low < 0 < high:
        top = float(np.percentile(np.abs(values), clip))
        if top >= max(-low, high):
            return low, high, "neither", ""
        return -top, top, "both", (f"colour scale clipped at the {clip:g}th percentile of |value| "
                                   f"(range {low:.3g} to {high:.3g})")
    top = float(np.percentile(values, clip))
    if top >= high:
        return low, high, "neither", ""
    return low, top, "max", f"colour scale clipped at the {clip:g}th percentile (max {high:.3g})"


def coordinates(ax, units) -> None:
    """Equal axes labelled x_1, x_2 in the length unit of ``units``."""
    ax.set_aspect("equal")
    ax.set_xlabel(unit_label(r"$x_1$", length_unit(units)))
    ax.set_ylabel(unit_label(r"$x_2$", length_unit(units)))


def colorbar(fig, art, ax, label: str, extend: str, note: str, wide: bool) -> None:
    """A colour bar labelled ``label`` and the clipping ``note``: below a wide domain (the
    label then has room for both on one line), to the right of a tall one."""
    if wide:
        fig.colorbar(art, ax=ax, label=f"{label}; {note}" if note else label, extend=extend,
                     location="bottom", shrink=0.6, aspect=40)
    else:
        fig.colorbar(art, ax=ax, label=f"{label}\n{note}" if note else label, extend=extend)


def is_wide(points: np.ndarray) -> bool:
    """Whether the domain of ``points`` is wide (its colour bar then goes below it)."""
    return float(np.ptp(points[:, 1])) < 0.6 * float(np.ptp(points[:, 0]))
