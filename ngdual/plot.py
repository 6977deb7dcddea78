"""Matplotlib figures (no computation here: inputs are arrays from :mod:`ngdual.post`)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402
import numpy as np  # noqa: E402


def _save(fig, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.stem + ".part" + path.suffix)
    fig.savefig(tmp, dpi=150, bbox_inches="tight")
    plt.close(fig)
    tmp.replace(path)
    return path


def plot_contact_traces(traces, path: Path, title: str = "") -> Path:
    """sigma_n, sigma_t (per fine edge), lambda_n - g and lambda_t (nodal) along Gamma_C."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex=True)
    x_edge, x_node = traces.edge_xy[:, 0], traces.node_xy[:, 0]
    order = np.argsort(x_node)
    panels = [
        (axes[0, 0], x_edge, traces.sigma_n, r"$\sigma_n^h$ [stress units]", "steps-mid"),
        (axes[0, 1], x_edge, traces.sigma_t, r"$\sigma_t^h$ [stress units]", "steps-mid"),
        (axes[1, 0], x_node[order], (traces.lam_n - traces.gap)[order],
         r"$\lambda_n^{\tilde h} - g$ [length]", "default"),
        (axes[1, 1], x_node[order], traces.lam_t[order], r"$\lambda_t^{\tilde h}$ [length]",
         "default"),
    ]
    for ax, xs, ys, label, style in panels:
        idx = np.argsort(xs)
        ax.plot(xs[idx], ys[idx], drawstyle=style, lw=1.2)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    contact = traces.coarse_xy[traces.coarse_in_contact, 0]
    level = np.interp(contact, x_node[order], (traces.lam_n - traces.gap)[order])
    axes[1, 0].plot(contact, level, "rv", ms=4, label=r"$\tilde h$-node in contact")
    axes[1, 0].legend(loc="best")
    for ax in axes[1]:
        ax.set_xlabel(r"$x_1$ on $\Gamma_C$ [length]")
    fig.suptitle(title or r"Traces on the contact boundary $\Gamma_C$")
    fig.tight_layout()
    return _save(fig, path)


def plot_element_field(points: np.ndarray, triangles: np.ndarray, values: np.ndarray,
                       path: Path, title: str, label: str) -> Path:
    """A piecewise constant field on the triangulation, with a colour bar."""
    fig, ax = plt.subplots(figsize=(11, 3.6))
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    art = ax.tripcolor(tri, facecolors=values, cmap="viridis", edgecolors="none")
    fig.colorbar(art, ax=ax, label=label)
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x_1$ [length]")
    ax.set_ylabel(r"$x_2$ [length]")
    ax.set_title(title)
    return _save(fig, path)


def plot_mesh(points: np.ndarray, triangles: np.ndarray, path: Path, title: str = "",
              marked: np.ndarray | None = None) -> Path:
    """The triangulation, with the elements marked for refinement shaded (Figs. 4.1-4.13)."""
    fig, ax = plt.subplots(figsize=(8, 8 * np.ptp(points[:, 1]) / max(np.ptp(points[:, 0]), 1e-300)
                                    + 0.8))
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    if marked is not None and np.any(marked):
        ax.tripcolor(tri, facecolors=np.asarray(marked, dtype=float), cmap="Oranges",
                     vmin=0, vmax=2.5, edgecolors="none")
    ax.triplot(tri, color="k", lw=0.3)
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x_1$ [length]")
    ax.set_ylabel(r"$x_2$ [length]")
    ax.set_title(title or f"{len(triangles)} triangles")
    return _save(fig, path)
