"""The traces on Gamma_C: p_h and q_h per h~ node with the fine-edge stress behind them,
lambda_n - g and lambda_t, and the contact, stick and slip zones (:func:`plot_contact_traces`);
the y-range of a trace panel that leaves isolated spikes off scale and says so
(:func:`trace_range`, :func:`corner_note`)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from .scales import length_unit, stress_unit, unit_label

TRACE_CLIP = 90.0   # percentile of |value| beyond which secondary curves of a trace go off scale
ZONE_COLOURS = {"contact": ("tab:blue", "contact"), "stick": ("tab:green", "stick"),
                "slip": ("tab:orange", "slip")}
NODE_LABELS = {"h~ node": r"$\tilde h$ node"}   # ContactTraces.node_kind as a label
ZOOM = 0.4     # traction panels zoom on the contact zone when it spans less of Gamma_C
QUIET = 0.02   # ... and p_h, q_h outside it stay below this fraction of their largest value


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
        ax.text(0.02, 0.03, "\n".join(lines), transform=ax.transAxes, fontsize="x-small",
                va="bottom", ha="left", bbox={"fc": "white", "alpha": 0.8, "lw": 0})


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


def _shear_label(exact) -> str:
    """The exact solution's legend with its tangential force Q along t, the direction the
    shear is drawn in: the exact shear has the sign of Q everywhere, so the sign of its
    samples along t is the sign of Q along t."""
    name = exact.label.split(", Q =")[0]
    force = getattr(exact.solution, "Q", None)
    if force is None:
        return name
    along_t = np.sign(np.sum(exact.shear)) * abs(force)
    return f"{name}, Q = {along_t:.4g} along $t$"


def plot_contact_traces(traces, title: str = "", units=None, clip: float | None = TRACE_CLIP,
                        exact=None) -> Figure:
    """The contact pressure p_h and shear q_h along Gamma_C, and lambda_n - g, lambda_t.

    Top: p_h and q_h per h~ node (:class:`ngdual.trace.ContactTraces`: what the contact
    conditions of (3.62) control), the main curves, q_h and the exact shear along
    t = (n_2, -n_1) of (3.24), n the outward normal (on a bottom side t points to -x_1), the
    exact tangential force Q in the legend along t too; the values at fixed ends of Gamma_C
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
    from ..scene import SceneTypeError
    from ..trace import ContactTraces

    if not isinstance(traces, ContactTraces):
        raise SceneTypeError("traces", "must be the ContactTraces of nd.contact_traces("
                                       f"solution), got {type(traces).__name__}")
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.8))
    stress, length = stress_unit(units), length_unit(units)
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
    exact_labels = {}
    if exact is not None:
        exact_order = np.argsort(exact.x, kind="stable")
        exact_pressure = (exact.x[exact_order], exact.pressure[exact_order])
        exact_labels = {"pressure": exact.label.split(", Q =")[0], "shear": exact.label}
        if exact.shear is not None:
            exact_shear = (exact.x[exact_order], exact.shear[exact_order])
            exact_labels["shear"] = _shear_label(exact)
    friction = "with friction" if traces.friction else "frictionless: (3.62) makes it zero"
    node = NODE_LABELS.get(traces.node_kind, traces.node_kind)
    panels = [
        (axes[0, 0], pressure, traces.end_pressure, -traces.sigma_n, exact_pressure,
         rf"$p_h$ ({node})", r"$-\sigma_n^h$ (fine edge)",
         unit_label(r"pressure $p_h = -\sigma_n$", stress), "C0",
         "Contact pressure: what (3.62) controls"),
        (axes[0, 1], shear, traces.end_shear, traces.sigma_t, exact_shear,
         rf"$q_h$ ({node})", r"$\sigma_t^h$ (fine edge)",
         unit_label(r"shear $q_h$ along $t = (n_2, -n_1)$", stress), "C1",
         f"Shear traction ({friction}); $n$ the outward normal"),
    ]
    sampled = None if traces.trace_xy is None else \
        (traces.trace_xy[..., 0], -traces.trace_sigma_n, traces.trace_sigma_t)
    for ax, main, end_values, fine, exact_curve, label, fine_label, ylabel, colour, name \
            in panels:
        fine_x = x_edge
        if sampled is None:
            ax.plot(x_edge[edge_order], fine[edge_order], drawstyle="steps-mid", lw=0.6,
                    color="0.6", label=fine_label)
        else:
            # the P_k trace of every fine edge, broken between edges (it is discontinuous)
            values = sampled[1] if ax is axes[0, 0] else sampled[2]
            gap = np.full((len(values), 1), np.nan)
            ax.plot(np.hstack([sampled[0], gap]).ravel(), np.hstack([values, gap]).ravel(),
                    lw=0.6, color="0.6", label=fine_label)
            fine, fine_x = values.ravel(), sampled[0].ravel()
        if exact_curve is not None:
            ax.plot(*exact_curve, "k--", lw=1.0,
                    label=exact_labels["pressure" if ax is axes[0, 0] else "shear"])
        ax.plot(x_nodes[order], main[order], "-", color=colour, lw=1.6)
        ax.plot(x_dof, main[:len(x_dof)], "o", color=colour, ms=3.5, label=label)
        if len(x_end):
            ax.plot(x_end, end_values, "s", mfc="none", mec="tab:red", ms=6,
                    label=r"fixed end of $\Gamma_C$ (no contact condition)")
        inside = (lambda x: np.ones(len(x), bool)) if window is None else \
            (lambda x: (x >= window[0]) & (x <= window[1]))
        secondary = [(fine[inside(fine_x)], "fine-edge values")]
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
        ax.set_title(name, fontsize="medium")
        ax.set_xlabel(unit_label(r"$x_1$ on $\Gamma_C$", length))
    x_node = traces.node_xy[:, 0]
    fine_order = np.argsort(x_node, kind="stable")
    gap = (traces.lam_n - traces.gap)[fine_order]
    axes[1, 0].plot(x_node[fine_order], gap, lw=1.2)
    axes[1, 1].plot(x_node[fine_order], traces.lam_t[fine_order], lw=1.2)
    contact = traces.coarse_xy[traces.coarse_in_contact, 0]
    axes[1, 0].plot(contact, np.interp(contact, x_node[fine_order], gap), "rv", ms=4,
                    label=f"{node} in contact")
    mesh = r"\tilde h" if traces.node_kind == "h~ node" else "h"
    for ax, label, name in ((axes[1, 0], rf"$\lambda_n^{{{mesh}}} - g = -u_n$",
                             "Normal multiplier minus the gap"),
                            (axes[1, 1], rf"$\lambda_t^{{{mesh}}} = -u_t$",
                             "Tangential multiplier")):
        ax.set_ylabel(unit_label(label, length))
        ax.set_title(name, fontsize="medium")
        ax.set_xlabel(unit_label(r"$x_1$ on $\Gamma_C$", length))
    axes[0, 0].legend(loc="best", fontsize="x-small")
    axes[0, 1].legend(loc="best", fontsize="x-small")
    handles = [plt.Rectangle((0, 0), 1, 1, color=ZONE_COLOURS[k][0], alpha=0.25)
               for k in ("contact", "stick", "slip") if k in shown]
    names = [f"{k} zone" for k in ("contact", "stick", "slip") if k in shown]
    line = axes[1, 0].get_legend_handles_labels()
    axes[1, 0].legend([*line[0], *handles], [*line[1], *names], loc="best", fontsize="x-small")
    fig.suptitle(title or r"Traces on the contact boundary $\Gamma_C$")
    fig.tight_layout()
    return fig
