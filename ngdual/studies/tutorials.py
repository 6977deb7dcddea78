"""Support for the lecture tutorials in ``tutorials/``: quick mode, output, notebooks.

The tutorials are jupytext percent-format scripts (``# %%`` cells) named
``NN_topic.py``; their exercise solutions live in ``tutorials/solutions/`` as
``NN_topic_solutions.py``. They run top to bottom as plain scripts
(``python tutorials/01_peers_spaces.py``) and as notebooks written by
``ngdual tutorials --notebooks DIR`` (:func:`write_notebooks`, with the core install: the
percent format is read here, the notebooks are plain nbformat-4 JSON), and one runs as a
script with ``ngdual tutorials run NAME`` (:func:`run_tutorial`). They compute and draw with
the public API (``import ngdual as nd``); a :class:`Lesson` is all they take from here:
whether to run on coarse settings, and where their pictures and numbers go.

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

import json
import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from ..io import write_json
from .sources import scripts_folder

QUICK_ENV = "NGDUAL_QUICK"
OUT_ENV = "NGDUAL_TUTORIAL_OUT"
DEFAULT_OUT = "tutorial-output"
TRUE_WORDS = ("1", "true", "yes", "on")
_NAME = re.compile(r"^(\d\d)_[a-z0-9_]+\.py$")
KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
_CELL = re.compile(r"^# %%(?:\s+\[(\w+)\])?")   # a percent-format cell marker and its type


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
        self.saved: set[Path] = set()

    def _write(self, fig, name: str) -> Path:
        from ..plot import save_figure

        path = save_figure(fig, self.out / f"{name}.png", dpi=120)[0]
        self.saved.add(path)
        return path

    def save(self, fig, name: str) -> Path:
        """Save ``fig`` as ``out/name.png`` (:func:`ngdual.plot.save_figure`, which closes
        it); show the file in a notebook, print its path in a script. Headless runs thus
        keep every picture, and a notebook shows it whatever matplotlib backend is active.
        """
        path = self._write(fig, name)
        if in_notebook():
            from IPython.display import Image, display

            display(Image(filename=str(path)))
        else:
            print(f"saved {path}")
        return path

    def draw(self, cf, mesh, name: str, **kwargs) -> Path:
        """A field to turn and zoom: NGSolve's interactive webgui ``Draw(cf, mesh, name)``
        in a notebook, the picture ``out/name.png`` in a script.

        The picture is the one this lesson saved as ``name`` (:meth:`save`), else the
        element means of ``cf`` (its norm if it is a vector) drawn here; a notebook
        without the webgui (the ``tutorials`` extra) shows that picture instead.
        """
        path = self.out / f"{name}.png"
        if path not in self.saved:
            import ngsolve as ngs

            from ..plot import plot_element_field
            from ..post import element_values

            scalar = ngs.Norm(cf) if cf.dim > 1 else cf
            fig = plot_element_field(*element_values(mesh, scalar), f"{self.name}: {name}",
                                     name)
            path = self._write(fig, name)
        if not in_notebook():
            print(f"saved {path} (a notebook shows it with NGSolve's interactive Draw)")
            return path
        try:
            from ngsolve.webgui import Draw
        except ImportError:
            from IPython.display import Image, display

            display(Image(filename=str(path)))
            return path
        Draw(cf, mesh, name, **kwargs)
        return path

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


def find_tutorial(name: str, folder: str | Path | None = None) -> Tutorial:
    """The tutorial (or solution) called ``name``: its file stem (``07_adaptivity``), its
    file name, its number (``7``, ``07``) or its topic (``adaptivity``).

    >>> find_tutorial("7").name
    '07_adaptivity'
    """
    items = list_tutorials(folder)
    if (Path(folder) if folder is not None else tutorials_dir()).joinpath("solutions").is_dir():
        items += list_tutorials(folder, solutions=True)
    key = Path(str(name)).name.removesuffix(".py")
    for item in items:
        if key in (item.name, item.name[3:]) or key.isdigit() and int(key) == item.number:
            return item
    raise LookupError(f"unknown tutorial {key!r}; the tutorials are "
                      + ", ".join(item.name for item in items if item.path.parent == items[0]
                                  .path.parent) + " (and their NN_topic_solutions)")


def run_tutorial(item: Tutorial, out: str | Path = DEFAULT_OUT,
                 quick: bool | None = None) -> tuple[int, list[Path]]:
    """Run one tutorial as a script in a fresh Python, headless (matplotlib's Agg backend),
    its output below ``out``; its printout goes to this process' terminal.

    ``quick``: coarse settings (None: as ``NGDUAL_QUICK`` says). Returns the script's exit
    status and the files it wrote (new or rewritten below ``out``), sorted.
    """
    out = Path(out)
    before = _stamps(out)
    env = dict(os.environ, MPLBACKEND="Agg", **{OUT_ENV: str(out)})
    if quick is not None:
        env[QUICK_ENV] = "1" if quick else "0"
    status = subprocess.run([sys.executable, str(item.path)], env=env).returncode
    after = _stamps(out)
    return status, sorted(path for path, stamp in after.items() if before.get(path) != stamp)


def _stamps(folder: Path) -> dict[Path, tuple[int, int]]:
    """Modification time and size of every file below ``folder``."""
    return {path: (path.stat().st_mtime_ns, path.stat().st_size)
            for path in folder.rglob("*") if path.is_file()} if folder.is_dir() else {}


def percent_cells(text: str) -> list[tuple[str, str]]:
    """``(cell_type, source)`` of each cell of a jupytext percent-format script.

    A ``# %% [markdown]`` cell is its comment lines without their ``# ``; a ``# %%`` cell
    is code as written. Blank lines around a cell belong to no cell.

    >>> percent_cells("# %% [markdown]\\n# # Title\\n#\\n# Text.\\n\\n# %%\\nx = 1\\n")
    [('markdown', '# Title\\n\\nText.'), ('code', 'x = 1')]
    """
    cells: list[tuple[str, list[str]]] = []
    for line in text.splitlines():
        marker = _CELL.match(line)
        if marker:
            cells.append(("markdown" if marker.group(1) in ("markdown", "md") else "code", []))
        elif cells:
            cells[-1][1].append(line)
        elif line.strip():  # lines before the first marker: one code cell
            cells.append(("code", [line]))
    out = []
    for kind, lines in cells:
        if kind == "markdown":
            lines = [line[2:] if line.startswith("# ") else line.lstrip("#") for line in lines]
        source = "\n".join(lines).strip("\n")
        if source.strip():
            out.append((kind, source))
    return out


def notebook(path: str | Path) -> dict:
    """The nbformat-4 notebook of one percent-format script, not executed (plain JSON:
    ``json.dump`` writes it, Jupyter opens and runs it)."""
    cells = []
    for number, (kind, source) in enumerate(percent_cells(Path(path).read_text("utf-8"))):
        cell = {"cell_type": kind, "id": f"cell-{number}", "metadata": {},
                "source": source.splitlines(keepends=True)}
        if kind == "code":
            cell.update(execution_count=None, outputs=[])
        cells.append(cell)
    return {"cells": cells, "nbformat": 4, "nbformat_minor": 5,
            "metadata": {"kernelspec": dict(KERNELSPEC),
                         "language_info": {"name": "python"}}}


def write_notebooks(dest: str | Path, folder: str | Path | None = None,
                    solutions: bool = False) -> list[Path]:
    """Write the tutorials as ``.ipynb`` notebooks (:func:`notebook`) into ``dest``.

    With ``solutions=True`` the solutions go to ``dest/solutions`` as well.
    Returns the paths written. Needs only the core install.
    """
    dest = Path(dest)
    groups = [(dest, list_tutorials(folder))]
    if solutions:
        groups.append((dest / "solutions", list_tutorials(folder, solutions=True)))
    written = []
    for target, items in groups:
        target.mkdir(parents=True, exist_ok=True)
        for item in items:
            path = target / (item.name + ".ipynb")
            path.write_text(json.dumps(notebook(item.path), indent=1, ensure_ascii=False)
                            + "\n", encoding="utf-8")
            written.append(path)
    return written
