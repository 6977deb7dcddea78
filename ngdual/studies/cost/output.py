"""What a cost study shows: its time-to-accuracy table as text, its work-precision figure and
the styles of its methods' curves (shared with the six-problem study)."""

from __future__ import annotations

from .methods import is_peer, method_base, method_order
from .table import MEASURES, TARGETS

# the curves: a colour per order (the peers: grey P1, black P2), a line style and a marker
# per method
ORDER_COLOURS = {0: "C0", 1: "C1", 2: "C2"}
PEER_COLOURS = {1: "0.55", 2: "k"}
METHOD_STYLES = {"uniform": ("-", "o"), "adaptive, stress goal": ("--", "s"),
                 "adaptive, pressure goal": ("-.", "D"), "primal": (":", "^"),
                 "primal, adaptive": ("-.", "v")}
# the measures in a sentence
WHAT = {"pressure": "contact pressure", "sigma_energy": "stress σ"}


def curve_style(method: str) -> dict:
    """The colour of the method's order (:data:`ORDER_COLOURS`; the peers
    :data:`PEER_COLOURS`), the line style and marker of the method (:data:`METHOD_STYLES`);
    at order k >= 1 the coarse multipliers' markers are hollow.

    >>> curve_style("adaptive, pressure goal, k = 2")
    {'color': 'C2', 'ls': '-.', 'marker': 'D', 'ms': 4}
    >>> curve_style("uniform, k = 1, coarse")["mfc"], curve_style("primal P2, adaptive")["ls"]
    ('none', '-.')
    """
    order, family = method_order(method)
    if is_peer(method):
        ls, marker = METHOD_STYLES["primal, adaptive" if method.endswith("adaptive")
                                   else "primal"]
        return {"color": PEER_COLOURS[order], "ls": ls, "marker": marker, "ms": 4}
    ls, marker = METHOD_STYLES[method_base(method)]
    hollow = {"mfc": "none"} if order and family == "coarse" else {}
    return {"color": ORDER_COLOURS[order], "ls": ls, "marker": marker, "ms": 4, **hollow}


def seconds_and_unknowns(time_s: float, ndof: int) -> str:
    """A cell of a time-to-accuracy table: the time to two digits (one decimal from 10 s on)
    and the unknowns in groups of three.

    >>> seconds_and_unknowns(0.0987, 12721), seconds_and_unknowns(24.93, 592390)
    ('0.099 s (12 721)', '24.9 s (592 390)')
    """
    time = f"{time_s:.1f}" if time_s >= 10 else f"{time_s:.2g}"
    return f"{time} s ({ndof:,})".replace(",", " ")


def percent(value: float | None) -> str:
    """A relative error in per cent, to two digits.

    >>> percent(0.000123), percent(None)
    ('0.012 %', 'unknown')
    """
    return "unknown" if value is None else f"{100 * value:.2g} %"


def reference_line(measure: str, reference: dict, window: tuple[float, float] | None) -> str:
    """One line on the reference of ``measure``: which solution, its own error and how it
    was estimated, the targets it resolves."""
    where = (f" on {window[0]:g} <= x <= {window[1]:g}" if window and measure == "pressure"
             else "")
    resolves = ", ".join(f"{100 * t:g} %" for t in reference["resolves"]) or "no target"
    how = f" ({reference['estimate']})" if reference.get("estimate") else ""
    size = f"{reference['ndof']:,}".replace(",", " ")
    return (f"{WHAT[measure]}{where}: reference {reference['method']}, step "
            f"{reference['step']} ({size} unknowns), own error "
            f"{percent(reference['overkill_error'])}{how}; resolves {resolves}")


def table_text(table: list[dict], measure: str) -> str:
    """The time-to-accuracy table of ``measure`` as text: per method the least wall time to
    each target with its unknowns, "–" where the method does not reach it within its share,
    "unresolved" where the reference cannot tell."""
    rows = [r for r in table if r["measure"] == measure]
    names = list(dict.fromkeys(r["method"] for r in rows))
    width = max(len(n) for n in names) + 2
    head = "method".ljust(width) + "".join(f"{100 * t:g} %".ljust(20) for t in TARGETS)
    lines = [head]
    for name in names:
        cells = []
        for target in TARGETS:
            r = next(r for r in rows if (r["method"], r["target"]) == (name, target))
            if not r["resolved"]:
                cells.append("unresolved")
            elif r["time_s"] is None:
                cells.append("failed" if r["failed"] else "–")
            else:
                cells.append(seconds_and_unknowns(r["time_s"], r["ndof"]))
        lines.append(name.ljust(width) + "".join(c.ljust(20) for c in cells))
    return "\n".join(line.rstrip() for line in lines)


def error_panels(rows: list[dict], references: dict, measure: str) -> list[dict]:
    """Two panels of ``measure``: the true error of every solution against wall time and
    against unknowns, one curve per method (in refinement order), the targets as thin lines
    and the reference's own error."""
    methods = list(dict.fromkeys(r["method"] for r in rows))
    floor = references[measure]["overkill_error"]
    panels = []
    for xkey, xlabel, against in (("time_s", "wall time [s]", "wall time"),
                                  ("ndof", "unknowns [-]", "unknowns")):
        curves = []
        for m in methods:
            pts = sorted((r for r in rows if r["method"] == m and r.get(measure)),
                         key=lambda r: r["ndof"])
            if pts:
                curves.append({"x": [r[xkey] for r in pts], "y": [r[measure] for r in pts],
                               "label": m, **curve_style(m)})
        panels.append({
            "title": f"{WHAT[measure]} against {against}", "xlabel": xlabel,
            "ylabel": MEASURES[measure], "loglog": True, "curves": curves,
            "hlines": [(t, None, {"color": "0.7", "lw": 0.8}) for t in TARGETS]
            + ([(floor, "reference's own error", {"color": "k", "ls": "-.", "lw": 1.0})]
               if floor else [])})
    return panels


def work_precision_figure(rows: list[dict], references: dict, title: str,
                          measures=tuple(MEASURES)):
    """The work-precision figure of one scene: per measure (a row of panels) the true error
    of every solution against wall time and against unknowns."""
    from ...plot import plot_curves

    panels = [p for m in measures for p in error_panels(rows, references, m)]
    return plot_curves(panels, f"What accuracy costs on {title}: true error against wall "
                               "time and unknowns", ncols=2, panel_size=(5.2, 3.6),
                       figure_legend=True, legend_loc="outside right center")
