"""The textbook contact problems (beyond the thesis): one picture per shipped scene.

The shipped scenes whose ``[benchmark]`` table names an analytic solution (``hertz-cylinder``,
``flat-punch``, ``cattaneo-mindlin`` and ``wedge``), on the field level:
left, the von Mises stress around the contact zone, its colour scale clipped at the 99th
percentile of the window shown (stated in the colour bar: the punch edges and the wedge apex
are stress singularities, the clipped elements are drawn in the top colour); right, the
contact pressure p_h -- the projection of -sigma_n^h onto the h~ hats, what the discrete
contact conditions see (:func:`ngdual.verification.analytic.traction_profile`; the
fine-edge values of sigma_n^h, light, oscillate about it) -- against the analytic
half-plane solution the table names, for the computed total force
(:func:`ngdual.verification.benchmark.exact_solution`: Hertz, Sadowsky's flat punch,
Cattaneo-Mindlin, whose tangential traction is shown too, with the computed stick zone
shaded; the blunt wedge, p = (E* s / pi) arccosh(a / |x|)).
"""

import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import numpy as np

from ngdual import plot
from ngdual.scene import load_scene, shipped_scenes
from ngdual.studies.figures import script_main, solve
from ngdual.verification.benchmark import center_coordinate, exact_solution

THESIS = "Beyond the thesis: contact scenes"
STUDIES = ()
SCENES = tuple(name for name in shipped_scenes() if load_scene(name).benchmark.kind != "none")
CLIP = plot.CORNER_CLIP  # percentile of the von Mises stress where the colour scale ends
WINDOW = 3.0       # the window shown: WINDOW contact half-widths around the contact zone


def forces(arrays: dict) -> tuple[float, float]:
    """P = int p_h and Q = int q_h along the foundation (the h~ hat projections)."""
    order = np.argsort(arrays["hat_x"], kind="stable")
    dx = np.diff(arrays["hat_x"][order])

    def integral(values):  # of the P1 function; a kink's two nodes share x (zero width)
        v = values[order]
        return float(0.5 * np.sum(dx * (v[1:] + v[:-1])))

    return integral(arrays["hat_pressure"]), integral(arrays["hat_shear"])


def half_width(exact) -> float:
    """a of the half-plane solution."""
    return exact.hertz.a if hasattr(exact, "hertz") else exact.a


def window(arrays: dict) -> tuple[float, float, float, float]:
    """x- and y-range around the contact zone (WINDOW half-widths beyond it)."""
    x = arrays["edge_x"][arrays["edge_active"] > 0]
    if not len(x):
        x = arrays["edge_x"]
    center, half = 0.5 * (x.min() + x.max()), max(0.5 * (x.max() - x.min()), 1e-3)
    pts = arrays["points"]
    x0, x1 = center - WINDOW * half, center + WINDOW * half
    near = np.abs(pts[:, 0] - center) <= WINDOW * half
    y0 = float(pts[near, 1].min())
    return x0, x1, y0, y0 + (x1 - x0) * 0.5


def run(ctx):
    # COMPUTE: each scene on the field level, with its fields
    level = ctx.plan.field_level
    tasks = [solve(ctx.plan, name, level, fields=True) for name in SCENES]
    ctx.compute(tasks, desc="contact scenes")
    files, numbers, rows = [], {}, []
    for name, task in zip(SCENES, tasks):
        arrays = ctx.arrays(task)
        scene = load_scene(name)
        P, Q = forces(arrays)
        exact = exact_solution(scene, P, Q)
        box = window(arrays)
        x = arrays["edge_x"]
        p_h = -arrays["sigma_n"]
        contact = x[arrays["edge_active"] > 0]
        row = {"scene": name, "level": level, "P": P, "Q": Q,
               "contact_from": float(contact.min()), "contact_to": float(contact.max())}
        if exact is not None:
            row["exact_half_width"] = half_width(exact)
        rows.append(row)
        # PLOT
        fig, (ax_f, ax_c) = plt.subplots(1, 2, figsize=(12.8, 7.2), width_ratios=[1.2, 1],
                                         constrained_layout=True)
        pts, tri = arrays["points"], arrays["triangles"]
        centroids = pts[tri].mean(axis=1)
        inside = ((centroids[:, 0] >= box[0]) & (centroids[:, 0] <= box[1])
                  & (centroids[:, 1] <= box[3]))
        vmax = float(np.percentile(arrays["von_mises"][inside], CLIP))
        art = ax_f.tripcolor(mtri.Triangulation(pts[:, 0], pts[:, 1], tri),
                             facecolors=arrays["von_mises"], cmap="viridis", vmin=0, vmax=vmax,
                             edgecolors="none", rasterized=True)
        fig.colorbar(art, ax=ax_f, extend="max", location="bottom", shrink=0.9, aspect=30,
                     label=plot.unit_label(r"von Mises stress $\sigma_0$", scene.units.stress)
                     + f", clipped at its {CLIP:g}th percentile")
        ax_f.set_xlim(box[0], box[1])
        ax_f.set_ylim(box[2], box[3])
        ax_f.set_aspect("equal")
        ax_f.set_xlabel(plot.unit_label(r"$x_1$", scene.units.length))
        ax_f.set_ylabel(plot.unit_label(r"$x_2$", scene.units.length))
        ax_f.set_title(f"von Mises stress near $\\Gamma_C$ (level {level})")
        order = np.argsort(x)
        hat = np.argsort(arrays["hat_x"])
        ax_c.plot(x[order], p_h[order], drawstyle="steps-mid", lw=0.6, color="0.7",
                  label=r"$-\sigma_n^h$ on fine edges")
        ax_c.plot(arrays["hat_x"][hat], arrays["hat_pressure"][hat], "C0.-", lw=1.4, ms=3,
                  label=r"$p_h$ ($\tilde h$ hat projection)")
        fine = np.linspace(box[0], box[1], 2001)
        x0 = center_coordinate(scene)
        if exact is not None:
            ax_c.plot(fine, exact.pressure(fine - x0), "k--", lw=1, label="half-plane solution")
        if hasattr(exact, "shear"):
            ax_c.plot(arrays["hat_x"][hat], arrays["hat_shear"][hat], "C1.-", lw=1.4, ms=3,
                      label=r"$q_h$ ($\tilde h$ hat projection)")
            ax_c.plot(fine, exact.shear(fine - x0), "k:", lw=1, label="Cattaneo-Mindlin $q$")
            stick = arrays["hat_node_x"][arrays["node_status"] == 1]
            if len(stick):
                ax_c.axvspan(stick.min(), stick.max(), color="0.85", label="computed stick zone")
                row["stick_from"], row["stick_to"] = float(stick.min()), float(stick.max())
            row["exact_c"] = float(exact.c)
        ax_c.set_xlim(box[0], box[1])
        # every p_h, q_h on scale; spikes of the fine-edge stress and the unbounded exact
        # pressure of the flat punch off scale, said in the panel
        inside = (x >= box[0]) & (x <= box[1])
        secondary = [(p_h[inside], "fine-edge values")]
        if exact is not None:
            secondary.append((exact.pressure(fine - x0), "half-plane solution"))
        if hasattr(exact, "shear"):
            secondary.append((exact.shear(fine - x0), "Cattaneo-Mindlin q"))
        low, high, notes = plot.trace_range(
            np.concatenate([arrays["hat_pressure"], arrays["hat_shear"]]), secondary,
            plot.TRACE_CLIP)
        ax_c.set_ylim(low, high)
        plot.corner_note(ax_c, notes)
        ax_c.set_xlabel(plot.unit_label(r"$x_1$ on $\Gamma_C$", scene.units.length))
        ax_c.set_ylabel(plot.unit_label("pressure $p$" + (", shear $q$" if hasattr(exact, "shear")
                                                          else ""), scene.units.stress))
        ax_c.grid(alpha=0.3)
        ax_c.legend(loc="upper right", fontsize="small")
        force = plot.unit_label("", scene.units.force).strip()
        ax_c.set_title(f"tractions on $\\Gamma_C$: P = {P:.4g}"
                       + (f", Q = {Q:.4g}" if abs(Q) > 1e-9 * abs(P) else "")
                       + (f" {force}" if force else ""))
        fig.suptitle(f"{name}: stress near the contact zone and tractions on $\\Gamma_C$")
        files += plot.save_figure(fig, ctx.figure_stem(f"contact_scenes_{name}"))
        numbers[f"{name}: contact zone"] = [row["contact_from"], row["contact_to"]]
        if "exact_half_width" in row:
            numbers[f"{name}: half-plane half-width a"] = row["exact_half_width"]
        if "exact_c" in row:
            numbers[f"{name}: stick zone (computed)"] = [row.get("stick_from"),
                                                        row.get("stick_to")]
            numbers[f"{name}: c (Cattaneo-Mindlin)"] = row["exact_c"]
    # WRITE
    data = ctx.write_json("contact_scenes.json", {"rows": rows},
                          "the shipped contact scenes on the field level: forces, contact and "
                          "stick zones against the half-plane solutions")
    ctx.entry(THESIS, "Hertz, flat punch, Cattaneo-Mindlin and a wedge", [*files, data],
              numbers, notes="half-plane solutions evaluated for the computed total force; "
                             "the accuracy study is `ngdual verify`")


if __name__ == "__main__":
    script_main(__file__)
