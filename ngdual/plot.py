"""Matplotlib figures (no computation here: inputs are arrays from :mod:`ngdual.post`, or a
scene with its mesh for the two pictures every lecture starts from, :func:`plot_geometry`
and :func:`plot_von_mises`).

Every ``plot_*`` function returns a :class:`matplotlib.figure.Figure`; saving it is the
caller's choice, :func:`save_figure`. Importing this module leaves matplotlib's backend
alone: a notebook keeps its inline backend, a headless run gets Agg by matplotlib's own
fallback.

Axis labels carry the units the scene declares in its ``[units]`` table
(:class:`ngdual.scene.Units`, passed as ``units``); where it declares none a label names
the quantity only ("$x_1$", "von Mises stress"), never a made-up unit. Fields with
corner singularities take ``clip``: the colour scale ends at that percentile and the
colour bar says so.

>>> import numpy as np
>>> fig = plot_mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> type(fig).__name__
'Figure'
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import numpy as np
from matplotlib.figure import Figure

SIDECAR_FORMATS = (".png", ".pdf")  # what a stem without suffix becomes, with its .json
CORNER_CLIP = 99.0  # percentile where the colour scale of a field with corner singularities ends
TRACE_CLIP = 90.0   # the same for the secondary curves of a trace on Gamma_C


def unit_label(quantity: str, unit: str | None) -> str:
    """``quantity [unit]``, or the quantity alone where no unit is declared.

    >>> unit_label("stress", "MPa"), unit_label("stress", None)
    ('stress [MPa]', 'stress')
    """
    return f"{quantity} [{unit}]" if unit else quantity


def _length(units) -> str | None:
    return getattr(units, "length", None)


def _stress(units) -> str | None:
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


def trace_range(main: np.ndarray, secondary: list[tuple[np.ndarray, str]],
                 clip: float | None, note_lines: int = 0) -> tuple[float, float, list[str]]:
    """y-range of a trace panel and the notes on what it leaves off.

    The range holds every value of ``main`` (the quantity to read) and zero. Each
    ``secondary`` series ``(values, label)`` widens it up to ``1.25`` times the ``clip``
    percentile of its non-zero |values| (or the extent of ``main``, if larger): isolated
    spikes beyond that (the corner singularities of the fine-edge stress, an unbounded
    exact solution) stay off scale, and a note names the series, how many values and the
    largest. The range leaves room at the bottom for the notes and ``note_lines`` more lines
    of the caller's (:func:`corner_note`).
    """
    main = np.asarray(main, float)
    main = main[np.isfinite(main)]
    lo, hi = min(0.0, float(main.min(initial=0.0))), max(0.0, float(main.max(initial=0.0)))
    reach = max(-lo, hi)
    for values, _ in secondary:
        values = np.asarray(values, float)
        values = values[np.isfinite(values)]
        if not len(values):
            continue
        bound, size = np.inf, np.abs(values)
        if clip is not None and 0 < clip < 100 and size.any():
            bound = max(1.25 * float(np.percentile(size[size > 0], clip)), reach)
        lo = min(lo, max(float(values.min()), -bound))
        hi = max(hi, min(float(values.max()), bound))
    pad = 0.08 * (hi - lo) or 1.0
    lo, hi = lo - pad, hi + pad

    def off_scale(lo: float) -> list[str]:
        notes = []
        for values, label in secondary:
            values = np.asarray(values, float)
            off = (values < lo) | (values > hi) | np.isinf(values)
            if off.any():
                worst = values[off][np.argmax(np.abs(values[off]))]
                notes.append(f"{label}: {int(off.sum())} value{'s' * (int(off.sum()) > 1)} "
                             f"off scale (up to {worst:.3g})")
        return notes

    lines = len(off_scale(lo)) + note_lines
    if lines:
        share = 0.04 + 0.055 * lines   # of the axes height, taken by the notes
        lo = (lo - share * hi) / (1 - share)
    return lo, hi, off_scale(lo)


def corner_note(ax, lines: list[str]) -> None:
    """``lines`` in a white box in the lower left corner of ``ax`` (what is off scale)."""
    if lines:
        ax.text(0.02, 0.03, "\n".join(lines), transform=ax.transAxes, fontsize=7,
                va="bottom", ha="left", bbox={"fc": "white", "alpha": 0.8, "lw": 0})


def _coordinates(ax, units) -> None:
    ax.set_aspect("equal")
    ax.set_xlabel(unit_label(r"$x_1$", _length(units)))
    ax.set_ylabel(unit_label(r"$x_2$", _length(units)))


def _colorbar(fig, art, ax, label: str, extend: str, note: str, wide: bool) -> None:
    """A colour bar labelled ``label`` and the clipping ``note``: below a wide domain (the
    label then has room for both on one line), to the right of a tall one."""
    if wide:
        fig.colorbar(art, ax=ax, label=f"{label}; {note}" if note else label, extend=extend,
                     location="bottom", shrink=0.6, aspect=40)
    else:
        fig.colorbar(art, ax=ax, label=f"{label}\n{note}" if note else label, extend=extend)


def _is_wide(points: np.ndarray) -> bool:
    return float(np.ptp(points[:, 1])) < 0.6 * float(np.ptp(points[:, 0]))


ZONE_COLOURS = {"contact": ("tab:blue", "contact"), "stick": ("tab:green", "stick"),
                "slip": ("tab:orange", "slip")}
ZOOM = 0.4     # traction panels zoom on the contact zone when it spans less of Gamma_C
QUIET = 0.02   # ... and p_h, q_h outside it stay below this fraction of their largest value


def _zones(x: np.ndarray, status: np.ndarray) -> list[tuple[float, float, str]]:
    """``(x_from, x_to, status)`` of the runs of h~ nodes (sorted by x) with one status other
    than separation; every node covers half of the interval to each neighbour."""
    if not len(x):
        return []
    order = np.argsort(x, kind="stable")
    x, status = x[order], status[order]
    mids = 0.5 * (x[1:] + x[:-1])
    left = np.concatenate([[x[0]], mids])
    right = np.concatenate([mids, [x[-1]]])
    runs = []
    for k, st in enumerate(status):
        if st == "separation":
            continue
        if runs and runs[-1][2] == st and runs[-1][3] == k - 1:
            runs[-1] = (runs[-1][0], right[k], st, k)
        else:
            runs.append((left[k], right[k], st, k))
    return [(a, b, st) for a, b, st, _ in runs]


def _window(traces, x_nodes: np.ndarray, main: list[np.ndarray]) -> tuple[float, float] | None:
    """The x-range of the traction panels when the contact zone is a small part of Gamma_C
    and p_h, q_h vanish (below QUIET of the largest |p_h|, |q_h|) outside it; None: all of
    Gamma_C."""
    touching = traces.coarse_status != "separation"
    if not touching.any():
        return None
    span = float(np.ptp(traces.node_xy[:, 0]))
    x_c = traces.coarse_xy[touching, 0]
    width = max(float(np.ptp(x_c)), 2 * float(np.max(np.diff(np.sort(x_nodes)), initial=0)))
    lo, hi = float(x_c.min()) - width, float(x_c.max()) + width
    if hi - lo >= ZOOM * span:
        return None
    outside = (x_nodes < lo) | (x_nodes > hi)
    # one scale for p_h and q_h: a frictionless q_h is round-off, relative to itself noise
    top = max(float(np.max(np.abs(values), initial=0.0)) for values in main)
    if any(np.any(np.abs(values[outside]) > QUIET * top) for values in main):
        return None
    return lo, hi


def plot_contact_traces(traces, title: str = "", units=None, clip: float | None = TRACE_CLIP,
                        exact=None) -> Figure:
    """The contact pressure p_h and shear q_h along Gamma_C, and lambda_n - g, lambda_t.

    Top: p_h and q_h per h~ node (:class:`ngdual.post.ContactTraces`: what the contact
    conditions of (3.62) control), the main curves; the values at fixed ends of Gamma_C
    (no contact condition there) marked apart; the fine-edge -sigma_n, sigma_t thin and
    light behind them; ``exact`` (e.g. :func:`ngdual.verification.benchmark.benchmark_traces`:
    ``x``, ``pressure``, ``shear`` or None, ``label``) dashed. Bottom: lambda_n - g and
    lambda_t at the fine vertices. Contact, stick and slip zones of the h~ nodes are
    shaded. The y-range holds every value of p_h and q_h; ``clip`` (a percentile of |value|)
    leaves isolated spikes of the fine-edge stress and of the exact solution off scale,
    and the panel says so (None: nothing off scale). Where the contact zone is a small part
    of Gamma_C and p_h, q_h vanish outside it, the top panels show the zone (and say so).
    ``units``: the scene's ``units``.
    """
    from .post import ContactTraces
    from .scene import SceneTypeError

    if not isinstance(traces, ContactTraces):
        raise SceneTypeError("traces", "must be the ContactTraces of nd.contact_traces("
                                       f"solution), got {type(traces).__name__}")
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.8))
    stress, length = _stress(units), _length(units)
    x_dof, x_end = traces.coarse_xy[:, 0], traces.end_xy[:, 0]
    x_nodes = np.concatenate([x_dof, x_end])
    order = np.argsort(x_nodes, kind="stable")
    pressure = np.concatenate([traces.pressure, traces.end_pressure])
    shear = np.concatenate([traces.shear, traces.end_shear])
    window = _window(traces, x_nodes, [pressure, shear])
    x_edge = traces.edge_xy[:, 0]
    edge_order = np.argsort(x_edge, kind="stable")
    zones = _zones(x_dof, traces.coarse_status)
    shown = {}
    for ax in axes.ravel():
        for a, b, st in zones:
            colour, label = ZONE_COLOURS[st]
            patch = ax.axvspan(a, b, color=colour, alpha=0.12, lw=0)
            shown.setdefault(label, patch)
        ax.grid(alpha=0.3)
    exact_pressure = exact_shear = None
    if exact is not None:
        exact_order = np.argsort(exact.x, kind="stable")
        exact_pressure = (exact.x[exact_order], exact.pressure[exact_order])
        if exact.shear is not None:
            exact_shear = (exact.x[exact_order], exact.shear[exact_order])
    friction = "with friction" if traces.friction else "frictionless: (3.62) makes it zero"
    panels = [
        (axes[0, 0], pressure, traces.end_pressure, -traces.sigma_n, exact_pressure,
         r"$p_h$ ($\tilde h$ node)", r"$-\sigma_n^h$ (fine edge)",
         unit_label(r"pressure $p_h = -\sigma_n$", stress), "C0",
         "Contact pressure: what (3.62) controls"),
        (axes[0, 1], shear, traces.end_shear, traces.sigma_t, exact_shear,
         r"$q_h$ ($\tilde h$ node)", r"$\sigma_t^h$ (fine edge)",
         unit_label(r"shear $q_h$ along $t$", stress), "C1", f"Shear traction ({friction})"),
    ]
    for ax, main, end_values, fine, exact_curve, label, fine_label, ylabel, colour, name \
            in panels:
        ax.plot(x_edge[edge_order], fine[edge_order], drawstyle="steps-mid", lw=0.6,
                color="0.6", label=fine_label)
        if exact_curve is not None:
            ax.plot(*exact_curve, "k--", lw=1.0, label=exact.label)
        ax.plot(x_nodes[order], main[order], "-", color=colour, lw=1.6)
        ax.plot(x_dof, main[:len(x_dof)], "o", color=colour, ms=3.5, label=label)
        if len(x_end):
            ax.plot(x_end, end_values, "s", mfc="none", mec="tab:red", ms=6,
                    label=r"fixed end of $\Gamma_C$ (no contact condition)")
        inside = (lambda x: np.ones(len(x), bool)) if window is None else \
            (lambda x: (x >= window[0]) & (x <= window[1]))
        secondary = [(fine[inside(x_edge)], "fine-edge values")]
        if exact_curve is not None:
            secondary.append((exact_curve[1][inside(exact_curve[0])], "exact solution"))
        own = []
        if len(end_values) and end_values.min() < 0 and ax is axes[0, 0]:
            own.append(f"tension at a fixed end of Gamma_C: p = {end_values.min():.3g} "
                       "(no contact condition there)")
        if window is not None:
            ax.set_xlim(*window)
            own.append(f"zoom on the contact zone: outside, |p_h| and |q_h| stay below "
                       f"{QUIET:.0%} of their largest")
        lo, hi, notes = trace_range(main[inside(x_nodes)], secondary, clip, len(own))
        ax.set_ylim(lo, hi)
        corner_note(ax, own + notes)
        ax.set_ylabel(ylabel)
        ax.set_title(name, fontsize=10)
        ax.set_xlabel(unit_label(r"$x_1$ on $\Gamma_C$", length))
    x_node = traces.node_xy[:, 0]
    fine_order = np.argsort(x_node, kind="stable")
    gap = (traces.lam_n - traces.gap)[fine_order]
    axes[1, 0].plot(x_node[fine_order], gap, lw=1.2)
    axes[1, 1].plot(x_node[fine_order], traces.lam_t[fine_order], lw=1.2)
    contact = traces.coarse_xy[traces.coarse_in_contact, 0]
    axes[1, 0].plot(contact, np.interp(contact, x_node[fine_order], gap), "rv", ms=4,
                    label=r"$\tilde h$ node in contact")
    for ax, label, name in ((axes[1, 0], r"$\lambda_n^{\tilde h} - g = -u_n$",
                             "Normal multiplier minus the gap"),
                            (axes[1, 1], r"$\lambda_t^{\tilde h} = -u_t$",
                             "Tangential multiplier")):
        ax.set_ylabel(unit_label(label, length))
        ax.set_title(name, fontsize=10)
        ax.set_xlabel(unit_label(r"$x_1$ on $\Gamma_C$", length))
    axes[0, 0].legend(loc="best", fontsize=7)
    axes[0, 1].legend(loc="best", fontsize=7)
    handles = [plt.Rectangle((0, 0), 1, 1, color=ZONE_COLOURS[k][0], alpha=0.25)
               for k in ("contact", "stick", "slip") if k in shown]
    names = [f"{k} zone" for k in ("contact", "stick", "slip") if k in shown]
    line = axes[1, 0].get_legend_handles_labels()
    axes[1, 0].legend([*line[0], *handles], [*line[1], *names], loc="best", fontsize=7)
    fig.suptitle(title or r"Traces on the contact boundary $\Gamma_C$")
    fig.tight_layout()
    return fig


def plot_element_field(points: np.ndarray, triangles: np.ndarray, values: np.ndarray,
                       title: str, label: str, clip: float | None = None,
                       units=None, vmax: float | None = None) -> Figure:
    """A piecewise constant field on the triangulation, with a colour bar labelled ``label``.

    ``clip``: end the colour scale at this percentile (e.g. 99 for a von Mises stress
    with corner singularities); ``vmax``: end it at this value (to compare pictures);
    the colour bar states the clipping.
    """
    aspect = float(np.ptp(points[:, 1])) / max(float(np.ptp(points[:, 0])), 1e-300)
    fig, ax = plt.subplots(figsize=(11, min(9 * aspect, 12.0) + 2.0), constrained_layout=True)
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    vmin, vmax, extend, note = clipped_scale(values, clip, vmax)
    art = ax.tripcolor(tri, facecolors=values, cmap="viridis", vmin=vmin, vmax=vmax,
                       edgecolors="none")
    _colorbar(fig, art, ax, label, extend, note, _is_wide(points))
    _coordinates(ax, units)
    ax.set_title(title)
    return fig


def plot_mesh(points: np.ndarray, triangles: np.ndarray, title: str = "",
              marked: np.ndarray | None = None, units=None) -> Figure:
    """The triangulation, with the elements marked for refinement shaded (Figs. 4.1-4.13).

    ``marked``: one flag per triangle (the MARK step of the adaptive loop); the legend
    counts them.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    width = max(float(np.ptp(points[:, 0])), 1e-300)
    aspect = float(np.ptp(points[:, 1])) / width
    fig, ax = plt.subplots(figsize=(9.5, min(9.5 * aspect, 12.0) + 1.2))
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    handles = []
    if marked is not None and np.any(marked):
        marked = np.asarray(marked, bool)
        colour = plt.get_cmap("Oranges")(0.6)
        ax.tripcolor(mtri.Triangulation(points[:, 0], points[:, 1], triangles[marked]),
                     facecolors=np.ones(int(marked.sum())), cmap=ListedColormap([colour]),
                     edgecolors="none", rasterized=True)
        handles.append(Patch(color=colour,
                             label=f"{int(marked.sum())} marked for refinement"))
    ax.triplot(tri, color="k", lw=0.25, label=f"{len(triangles)} triangles")
    _coordinates(ax, units)
    ax.set_title(title or f"{len(triangles)} triangles")
    ax.legend(handles=[*ax.get_legend_handles_labels()[0][:1], *handles], loc="upper center",
              bbox_to_anchor=(0.5, -0.25 if aspect < 0.5 else -0.12), ncol=2, fontsize=8)
    return fig


BOUNDARY_ROLES = {"dirichlet": (r"$\Gamma_D$", "tab:blue"), "neumann": (r"$\Gamma_N$", "tab:green"),
                  "contact": (r"$\Gamma_C$", "tab:red")}


def plot_geometry(scene, mesh=None, level: int | None = None, title: str = "") -> Figure:
    """The domain of ``scene`` with its boundary parts Γ_D, Γ_N, Γ_C in colour, every side
    named, and the mesh (``mesh``, or the one of ``level``, default the scene's level).

    >>> import ngdual as nd
    >>> fig = nd.plot_geometry(nd.load_scene("thesis-3.46-coulomb"), level=1)  # doctest: +SKIP
    """
    import ngsolve as ngs
    from matplotlib.collections import LineCollection

    from .mesh import build_mesh, mesh_arrays

    mesh = build_mesh(scene.geometry, level) if mesh is None else mesh
    points, triangles = mesh_arrays(mesh)
    edges: dict = {}
    for element in mesh.Elements(ngs.BND):
        edges.setdefault(element.mat, []).append([v.nr for v in element.vertices])
    width, height = np.ptp(points, axis=0)
    fig, ax = plt.subplots(figsize=(9, max(3.2, 7 * height / width + 1.6)))
    ax.triplot(points[:, 0], points[:, 1], triangles, color="0.6", lw=0.4)
    centre = points.mean(axis=0)
    for role, (symbol, colour) in BOUNDARY_ROLES.items():
        sides = {label: points[np.array(edges[label])] for label in scene.labels(role)
                 if label in edges}
        if not sides:
            continue
        ax.add_collection(LineCollection(np.concatenate(list(sides.values())), colors=colour,
                                         lw=3.5, label=f"{symbol}: {', '.join(sides)}"))
        for label, side in sides.items():
            middle = side.mean(axis=(0, 1))
            inward = 22 * (centre - middle) / (np.linalg.norm(centre - middle) or 1.0)
            ax.annotate(f"{symbol} ({label})", middle, xytext=tuple(inward),
                        textcoords="offset points", color=colour, ha="center", va="center",
                        fontsize=9, bbox={"fc": "white", "ec": "none", "alpha": 0.85, "pad": 1})
    _coordinates(ax, scene.units)
    ax.margins(0.1)
    ax.set_title(title or f"{scene.name}: boundary parts and mesh ({mesh.ne} triangles)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3, fontsize=9,
              frameon=False)
    fig.tight_layout()
    return fig


def plot_von_mises(mesh, sigma, nu: float, title: str, clip: float | None = CORNER_CLIP,
                   vmax: float | None = None, units=None) -> Figure:
    """The plane-strain von Mises stress of ``sigma`` (:func:`ngdual.post.von_mises`) per
    element, on a colour scale ending at the ``clip`` percentile (corner singularities)
    or at ``vmax`` (one scale for several pictures): :func:`plot_element_field`."""
    from .post import element_values, von_mises

    points, triangles, values = element_values(mesh, von_mises(sigma, nu))
    return plot_element_field(points, triangles, values, title,
                              unit_label(r"von Mises stress $\sigma_0$", _stress(units)), clip=clip,
                              units=units, vmax=vmax)


# --- saving, and the JSON sidecar of ngdual figures ----------------------------------------------

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


def save_figure(fig: Figure, target: str | Path, dpi: int = 130) -> list[Path]:
    """Write ``fig`` atomically and close it; returns the files written.

    ``target`` with a suffix (``out/von_mises.png``) is that one file; a stem without
    suffix (``figures/fig_3_11``) becomes ``stem.png``, ``stem.pdf`` and ``stem.json``
    (:func:`figure_texts`: what the figure says, for tests and indexes).
    """
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    texts = figure_texts(fig) if not target.suffix else None
    written = []
    try:
        for path in [target] if target.suffix else [target.with_suffix(s)
                                                    for s in SIDECAR_FORMATS]:
            tmp = path.with_name(path.stem + ".part" + path.suffix)
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


# --- figures of Sections 3.4 and 4.2 (ngdual figures) -------------------------------------------

def plot_field_pair(points: np.ndarray, triangles: np.ndarray, values: list[np.ndarray],
                    titles: list[str], label: str, suptitle: str, clip: float | None = None,
                    units=None) -> Figure:
    """Element fields on one mesh side by side with one colour bar (Figs. 3.11-3.14).

    ``clip``: the colour scale ends at this percentile of all values (the colour bar is
    extended and says so), so that corner singularities do not wash out the rest.
    """
    fig, axes = plt.subplots(1, len(values), figsize=(6.2 * len(values), 3.4),
                             constrained_layout=True)
    axes = np.atleast_1d(axes)
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    vmin, vmax, extend, note = clipped_scale(np.concatenate(values), clip)
    for ax, v, title in zip(axes, values, titles):
        art = ax.tripcolor(tri, facecolors=v, cmap="viridis", vmin=vmin, vmax=vmax,
                           edgecolors="none", rasterized=True)
        _coordinates(ax, units)
        ax.set_title(title)
    _colorbar(fig, art, list(axes), label, extend, note, _is_wide(points))
    fig.suptitle(suptitle)
    return fig


def plot_curves(panels: list[dict], suptitle: str, ncols: int = 2,
                panel_size: tuple[float, float] = (5.6, 3.4),
                figure_legend: bool = False) -> Figure:
    """Line plots, one panel per dict: ``title``, ``xlabel``, ``ylabel``, ``curves`` (dicts of
    ``x``, ``y``, ``label`` and matplotlib style keywords), optional ``loglog``, ``hlines``
    (``(y, label, style)``), ``note`` (text in the corner), ``xlim``, ``ylim``.

    ``figure_legend``: one legend below all panels (the labels of all panels, once each)
    instead of one per panel."""
    n = len(panels)
    ncols = min(ncols, n)
    nrows = int(np.ceil(n / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(panel_size[0] * ncols,
                                                    panel_size[1] * nrows),
                             constrained_layout=True, squeeze=False)
    for ax, panel in zip(axes.ravel(), panels):
        for curve in panel.get("curves", []):
            curve = dict(curve)
            x, y = np.asarray(curve.pop("x"), float), np.asarray(curve.pop("y"), float)
            ax.plot(x, y, **curve)
        for y, label, style in panel.get("hlines", []):
            ax.axhline(y, label=label, **style)
        if panel.get("loglog"):
            ax.set_xscale("log")
            ax.set_yscale("log")
        if panel.get("xlim"):
            ax.set_xlim(*panel["xlim"])
        if panel.get("ylim"):
            ax.set_ylim(*panel["ylim"])
        if panel.get("note"):
            ax.text(0.02, 0.03, panel["note"], transform=ax.transAxes, fontsize=8,
                    va="bottom", ha="left", bbox={"fc": "white", "alpha": 0.8, "lw": 0})
        ax.set_title(panel["title"])
        ax.set_xlabel(panel["xlabel"])
        ax.set_ylabel(panel["ylabel"])
        ax.grid(alpha=0.3, which="both" if panel.get("loglog") else "major")
        labelled = any(not line.get_label().startswith("_") for line in ax.get_lines())
        if labelled and not figure_legend:
            ax.legend(loc=panel.get("legend_loc", "best"), fontsize=8)
    for ax in axes.ravel()[n:]:
        ax.remove()
    if figure_legend:
        handles = {}
        for ax in axes.ravel()[:n]:
            for handle, label in zip(*ax.get_legend_handles_labels()):
                handles.setdefault(label, handle)
        fig.legend(handles.values(), handles.keys(), loc="outside lower center",
                   ncol=min(3, len(handles)), fontsize=8)
    fig.suptitle(suptitle)
    return fig


def plot_heatmaps(x: np.ndarray, y: np.ndarray, grids: list[np.ndarray], titles: list[str],
                  xlabel: str, ylabel: str, cbar_labels: list[str], suptitle: str) -> Figure:
    """Iteration counts over a parameter grid (Fig. 3.23): blue few, red many, numbers in the
    cells, NaN cells (did not converge) hatched and marked with a cross."""
    fig, axes = plt.subplots(1, len(grids), figsize=(5.4 * len(grids), 4.2),
                             constrained_layout=True)
    for ax, grid, title, clabel in zip(np.atleast_1d(axes), grids, titles, cbar_labels):
        data = np.ma.masked_invalid(np.asarray(grid, float))
        art = ax.pcolormesh(np.arange(len(x) + 1), np.arange(len(y) + 1), data.T,
                            cmap="coolwarm", shading="flat")
        ax.set_facecolor("0.85")
        for i in range(len(x)):
            for j in range(len(y)):
                v = grid[i][j]
                ax.text(i + 0.5, j + 0.5, "x" if not np.isfinite(v) else f"{v:.0f}",
                        ha="center", va="center", fontsize=7)
        ax.set_xticks(np.arange(len(x)) + 0.5, [f"{v:g}" for v in x])
        ax.set_yticks(np.arange(len(y)) + 0.5, [f"{v:g}" for v in y])
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        fig.colorbar(art, ax=ax, label=clabel)
    fig.suptitle(suptitle)
    return fig


def plot_domain(points: np.ndarray, triangles: np.ndarray, x: np.ndarray, load: np.ndarray,
                foundations: list, gaps: list, suptitle: str, units=None) -> Figure:
    """Fig. 3.10: Example 3.46 with Gamma_D, Gamma_N (load arrows), Gamma_C and foundations
    (``(x, y, label, style)``) on the left, the gap functions (same form) on the right."""
    fig, (ax, ag) = plt.subplots(1, 2, figsize=(13, 3.8), constrained_layout=True,
                                 gridspec_kw={"width_ratios": [1.6, 1]})
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    ax.triplot(tri, color="0.75", lw=0.5)
    ax.plot([-4, -4], [-1, 1], color="k", lw=4, label=r"$\Gamma_D$ (clamped)")
    ax.plot([4, 4], [-1, 1], color="k", lw=4)
    ax.plot([-4, 4], [1, 1], color="tab:orange", lw=3, label=r"$\Gamma_N$")
    ax.plot([-4, 4], [-1, -1], color="tab:green", lw=3, label=r"$\Gamma_C$")
    scale = 0.6 / max(float(np.max(np.abs(load))), 1e-300)
    for xi, ti in zip(x[::40], load[::40]):
        if abs(ti) > 0:
            ax.annotate("", (xi, 1), (xi, 1 - ti * scale),
                        arrowprops={"arrowstyle": "->", "color": "tab:orange", "lw": 1})
    peak = float(np.max(np.abs(load)))
    ax.plot([], [], color="tab:orange", marker=r"$\downarrow$", ls="none",
            label=rf"$t_0$ (max {peak:.0f}{' ' + _stress(units) if _stress(units) else ''})")
    for fx, fy, label, style in foundations:
        ax.plot(fx, fy, label=label, **style)
    _coordinates(ax, units)
    ax.set_ylim(-3.3, 1.9)
    ax.set_title(r"$\Omega = [-4, 4] \times [-1, 1]$, level-1 mesh")
    ax.legend(loc="upper center", ncol=3, fontsize=8)
    for gx, gy, label, style in gaps:
        ag.plot(gx, gy, label=label, **style)
    ag.set_xlabel(unit_label(r"$x_1$ on $\Gamma_C$", _length(units)))
    ag.set_ylabel(unit_label(r"gap $g(x_1)$", _length(units)))
    ag.set_title("Gap functions of the shipped scenes")
    ag.grid(alpha=0.3)
    ag.legend(fontsize=8)
    fig.suptitle(suptitle)
    return fig
