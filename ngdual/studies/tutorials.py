"""Support for the lecture tutorials in ``tutorials/``: quick mode, output, plots, notebooks.

The tutorials are jupytext percent-format scripts (``# %%`` cells) named
``NN_topic.py``; their exercise solutions live in ``tutorials/solutions/`` as
``NN_topic_solutions.py``. They run top to bottom as plain scripts
(``python tutorials/01_peers_mixed_elasticity.py``) and as notebooks written by
``ngdual tutorials --notebooks DIR``.

Environment variables
---------------------
``NGDUAL_QUICK``
    ``1`` (or ``true``/``yes``) selects coarse meshes and short parameter
    sweeps, so that every tutorial finishes in seconds (the test suite sets it).
``NGDUAL_TUTORIAL_OUT``
    Folder for figures and ``results.json`` (default ``tutorial-output`` in
    the working directory); every tutorial writes into its own subfolder.
``NGDUAL_TUTORIALS_DIR``
    Where the tutorial sources are. By default they are found next to the
    package, i.e. in the source checkout that ``pip install -e .`` links to.

Pictures
--------
:func:`plot_geometry` draws the domain of a scene with its boundary parts Γ_D, Γ_N,
Γ_C and the mesh (the first picture of every tutorial); :func:`plot_von_mises` the von
Mises stress per element on a percentile-clipped colour scale (stated on the colour
bar), because corner singularities would otherwise take the whole scale (through
:func:`ngdual.plot.plot_element_field`; the traces on Γ_C are ``nd.plot_contact_traces``).
They return matplotlib figures; :func:`save_figure` saves a figure and shows it in a
notebook.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from ..io import write_json

QUICK_ENV = "NGDUAL_QUICK"
OUT_ENV = "NGDUAL_TUTORIAL_OUT"
SOURCE_ENV = "NGDUAL_TUTORIALS_DIR"
DEFAULT_OUT = "tutorial-output"
TRUE_WORDS = ("1", "true", "yes", "on")
_NAME = re.compile(r"^(\d\d)_[a-z0-9_]+\.py$")
KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}


def quick_mode() -> bool:
    """True when ``NGDUAL_QUICK`` asks for the coarse settings (tests, quick looks)."""
    return os.environ.get(QUICK_ENV, "").strip().lower() in TRUE_WORDS


def in_notebook() -> bool:
    """True inside a Jupyter kernel (where NGSolve's webgui can draw), False in a script."""
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    return shell is not None and type(shell).__name__ == "ZMQInteractiveShell"


def draw(obj, *args, **kwargs) -> None:
    """Show ``obj`` with NGSolve's webgui ``Draw`` inside a notebook; do nothing elsewhere.

    Scripts run headless, so the matplotlib figures saved by the tutorials are
    the pictures that always exist; the webgui view is an extra for notebooks
    (interactive where ``anywidget`` is installed).
    """
    if not in_notebook():
        return
    try:
        from ngsolve.webgui import Draw
    except ImportError:
        return
    Draw(obj, *args, **kwargs)


def output_dir(tutorial: str) -> Path:
    """The (created) folder where ``tutorial`` writes its figures and ``results.json``."""
    path = Path(os.environ.get(OUT_ENV, DEFAULT_OUT)) / tutorial
    path.mkdir(parents=True, exist_ok=True)
    return path


def save_figure(fig, path: str | Path) -> None:
    """Save a matplotlib figure as PNG (:func:`ngdual.plot.save_figure`: atomically, then
    closed); in a notebook also show the file.

    The PNG is shown rather than the figure object, so the picture appears whatever
    matplotlib backend is active (a headless run uses Agg).
    """
    from ..plot import save_figure as write

    write(fig, path, dpi=120)
    show_file(path)


def show_file(path: str | Path) -> None:
    """Show a PNG in a notebook; print its path elsewhere."""
    if in_notebook():
        from IPython.display import Image, display

        display(Image(filename=str(path)))
    else:
        print(f"saved {path}")


# --- pictures -------------------------------------------------------------------------------

ROLES = {"dirichlet": (r"$\Gamma_D$", "tab:blue"), "neumann": (r"$\Gamma_N$", "tab:green"),
         "contact": (r"$\Gamma_C$", "tab:red")}


def boundary_segments(mesh) -> dict:
    """The boundary edges of an NGSolve mesh by label: label -> array (k, 2, 2) of segments."""
    import ngsolve as ngs
    import numpy as np

    from ..mesh import mesh_arrays

    points, _ = mesh_arrays(mesh)
    found: dict = {}
    for element in mesh.Elements(ngs.BND):
        found.setdefault(element.mat, []).append([v.nr for v in element.vertices])
    return {label: points[np.array(edges)] for label, edges in found.items()}


def plot_geometry(scene, mesh=None, level: int | None = None, title: str | None = None):
    """The domain of ``scene`` with Γ_D, Γ_N, Γ_C in colour, each side named, and the mesh.

    ``mesh``: an NGSolve mesh of the scene; by default the mesh of ``level`` (default:
    the scene's level) is built. Returns the matplotlib figure.
    """
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.collections import LineCollection

    from ..mesh import build_mesh, mesh_arrays

    if mesh is None:
        mesh = build_mesh(scene.geometry, level)
    points, triangles = mesh_arrays(mesh)
    segments = boundary_segments(mesh)
    width, height = np.ptp(points, axis=0)
    fig, ax = plt.subplots(figsize=(9, max(3.2, 7 * height / width + 1.6)))
    ax.triplot(points[:, 0], points[:, 1], triangles, color="0.6", lw=0.4)
    centre = points.mean(axis=0)
    for role, (symbol, colour) in ROLES.items():
        labels = [label for label in scene.labels(role) if label in segments]
        if not labels:
            continue
        lines = np.concatenate([segments[label] for label in labels])
        ax.add_collection(LineCollection(lines, colors=colour, lw=3.5,
                                         label=f"{symbol}: {', '.join(labels)}"))
        for label in labels:
            middle = segments[label].mean(axis=(0, 1))
            inward = centre - middle
            inward = 22 * inward / (np.linalg.norm(inward) or 1.0)
            ax.annotate(f"{symbol} ({label})", middle, xytext=tuple(inward),
                        textcoords="offset points", color=colour, ha="center", va="center",
                        fontsize=9, bbox={"fc": "white", "ec": "none", "alpha": 0.85, "pad": 1})
    ax.set_aspect("equal")
    ax.margins(0.1)
    ax.set_xlabel("$x_1$")
    ax.set_ylabel("$x_2$")
    ax.set_title(title or f"{scene.name}: boundary parts and mesh ({mesh.ne} triangles)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3, fontsize=9,
              frameon=False)
    fig.tight_layout()
    return fig


def plot_von_mises(mesh, sigma, nu: float, title: str, clip: float | None = 97.0,
                   label: str = "von Mises stress", vmax: float | None = None):
    """The plane-strain von Mises stress of ``sigma`` per element (value at the centroid):
    :func:`ngdual.plot.plot_element_field` of :func:`ngdual.post.von_mises`.

    ``clip``: the colour scale ends at this percentile of the element values (corner
    singularities would otherwise take the whole scale); the colour bar says so and
    gives the true maximum. ``None`` shows the full range. ``vmax`` ends the scale at a
    given value instead (to compare pictures). Returns the figure.
    """
    from ..plot import plot_element_field
    from ..post import element_values, von_mises

    points, triangles, values = element_values(mesh, von_mises(sigma, nu))
    return plot_element_field(points, triangles, values, title, label, clip=clip, vmax=vmax)


def save_results(tutorial: str, results: dict) -> Path:
    """Write the numbers a tutorial computed to ``output_dir(tutorial)/results.json``.

    The test suite reads this file and checks the mathematics behind the numbers.
    """
    return write_json(results, output_dir(tutorial) / "results.json")


@dataclass(frozen=True)
class Tutorial:
    """One tutorial (or solution) file: number, file stem, path and title."""

    number: int
    name: str
    path: Path
    title: str


def tutorials_dir() -> Path:
    """The folder holding the tutorial sources.

    ``NGDUAL_TUTORIALS_DIR`` if set, else ``tutorials/`` beside the ``ngdual``
    package folder: the source checkout of an editable install.
    """
    env = os.environ.get(SOURCE_ENV)
    folder = Path(env) if env else Path(__file__).resolve().parents[2] / "tutorials"
    if not folder.is_dir():
        raise FileNotFoundError(
            f"no tutorials folder at {folder}: the tutorials ship with the source checkout "
            f"(pip install -e .); point {SOURCE_ENV} or --source at its tutorials/ folder")
    return folder


def _title(path: Path) -> str:
    """The first markdown heading of a percent-format script (``# # Title``)."""
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("# # "):
            return line[4:].strip()
    return path.stem


def list_tutorials(folder: str | Path | None = None, solutions: bool = False) -> list[Tutorial]:
    """The tutorials (or, with ``solutions=True``, their solutions) sorted by number."""
    folder = Path(folder) if folder is not None else tutorials_dir()
    if solutions:
        folder = folder / "solutions"
    if not folder.is_dir():
        raise FileNotFoundError(f"no tutorials folder at {folder}")
    found = []
    for path in sorted(folder.glob("*.py")):
        match = _NAME.match(path.name)
        if match:
            found.append(Tutorial(int(match.group(1)), path.stem, path, _title(path)))
    return found


def write_notebooks(dest: str | Path, folder: str | Path | None = None,
                    solutions: bool = False) -> list[Path]:
    """Convert the tutorials to ``.ipynb`` files in ``dest`` with jupytext.

    With ``solutions=True`` the solutions go to ``dest/solutions`` as well.
    Returns the paths written. Needs the ``tutorials`` extra (jupytext).
    """
    try:
        import jupytext
    except ImportError:
        raise ImportError("writing notebooks needs jupytext: pip install -e '.[tutorials]'") \
            from None
    dest = Path(dest)
    groups = [(dest, list_tutorials(folder))]
    if solutions:
        groups.append((dest / "solutions", list_tutorials(folder, solutions=True)))
    written = []
    for target, items in groups:
        target.mkdir(parents=True, exist_ok=True)
        for item in items:
            notebook = jupytext.read(item.path, fmt="py:percent")
            notebook.metadata["kernelspec"] = dict(KERNELSPEC)
            path = target / (item.name + ".ipynb")
            jupytext.write(notebook, path, fmt="ipynb")
            written.append(path)
    return written
