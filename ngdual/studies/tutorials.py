"""Support for the lecture tutorials in ``tutorials/``: quick mode, output, notebooks.

The tutorials are jupytext percent-format scripts (``# %%`` cells) named
``NN_topic.py``; their exercise solutions live in ``tutorials/solutions/`` as
``NN_topic_solutions.py``. They run top to bottom as plain scripts
(``python tutorials/01_peers_spaces.py``) and as notebooks written by
``ngdual tutorials --notebooks DIR``. They compute and draw with the public API
(``import ngdual as nd``); a :class:`Lesson` is all they take from here: whether to run
on coarse settings, and where their pictures and numbers go.

Environment variables
---------------------
``NGDUAL_QUICK``
    ``1`` (or ``true``/``yes``) selects coarse meshes and short parameter
    sweeps, so that every tutorial finishes in seconds (the test suite sets it).
``NGDUAL_TUTORIAL_OUT``
    Folder for figures and ``results.json`` (default ``tutorial-output`` in
    the working directory); every tutorial writes into its own subfolder.
``NGDUAL_TUTORIALS_DIR``
    Where the tutorial sources are. By default the ``tutorials/`` folder of the source
    checkout, or its copy inside an installed wheel (:mod:`ngdual.studies.sources`).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from ..extras import require
from ..io import write_json
from .sources import scripts_folder

QUICK_ENV = "NGDUAL_QUICK"
OUT_ENV = "NGDUAL_TUTORIAL_OUT"
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


class Lesson:
    """One running tutorial: its coarse-or-full setting, its output folder, its pictures.

    >>> lesson = Lesson("01_peers_spaces")                        # doctest: +SKIP
    >>> lesson.save(nd.plot_geometry(scene), "geometry")          # doctest: +SKIP

    Attributes
    ----------
    name : str
        The file stem of the tutorial; its output goes to ``NGDUAL_TUTORIAL_OUT/name``.
    quick : bool
        :func:`quick_mode`: coarse meshes and short sweeps.
    out : Path
        The (created) output folder.
    """

    def __init__(self, name: str):
        self.name = name
        self.quick = quick_mode()
        self.out = Path(os.environ.get(OUT_ENV, DEFAULT_OUT)) / name
        self.out.mkdir(parents=True, exist_ok=True)

    def save(self, fig, name: str) -> Path:
        """Save ``fig`` as ``out/name.png`` (:func:`ngdual.plot.save_figure`, which closes
        it); show the file in a notebook, print its path in a script. Headless runs thus
        keep every picture, and a notebook shows it whatever matplotlib backend is active.
        """
        from ..plot import save_figure

        path = save_figure(fig, self.out / f"{name}.png", dpi=120)[0]
        if in_notebook():
            from IPython.display import Image, display

            display(Image(filename=str(path)))
        else:
            print(f"saved {path}")
        return path

    def draw(self, obj, *args, **kwargs) -> None:
        """NGSolve's interactive webgui ``Draw`` inside a notebook; nothing in a script,
        where the saved matplotlib pictures are the ones that always exist."""
        if not in_notebook():
            return
        try:
            from ngsolve.webgui import Draw
        except ImportError:
            return
        Draw(obj, *args, **kwargs)

    def results(self, numbers: dict) -> Path:
        """Write ``numbers`` (and ``quick``) to ``out/results.json``: what the test suite
        checks the mathematics of (``tests/test_tutorials.py``)."""
        path = write_json({"quick": self.quick, **numbers}, self.out / "results.json")
        print(f"wrote {path}")
        return path


@dataclass(frozen=True)
class Tutorial:
    """One tutorial (or solution) file: number, file stem, path and title."""

    number: int
    name: str
    path: Path
    title: str


def tutorials_dir() -> Path:
    """The folder holding the tutorial sources: ``NGDUAL_TUTORIALS_DIR`` if set, else the
    one shipped with ngdual: ``tutorials/`` of the source checkout, or its copy inside an
    installed wheel (:func:`~ngdual.studies.sources.scripts_folder`)."""
    return scripts_folder("tutorials")


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
    jupytext = require("jupytext", "tutorials")
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
