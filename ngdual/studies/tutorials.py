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
    """Save a matplotlib figure as PNG and close it; in a notebook also show the file.

    The PNG is shown rather than the figure object, so the picture appears whatever
    matplotlib backend is active (:mod:`ngdual.plot` selects Agg).
    """
    import matplotlib.pyplot as plt

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    show_file(path)


def show_file(path: str | Path) -> None:
    """Show a PNG (e.g. one written by :mod:`ngdual.plot`) in a notebook; name it elsewhere."""
    if in_notebook():
        from IPython.display import Image, display

        display(Image(filename=str(path)))
    else:
        print(f"saved {path}")


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
