"""Where the scripts a user reads are: the figure scripts and the lecture tutorials.

They live at the top of the repository (``figures/``, ``tutorials/``), where a reader of
the project finds them first and the documentation links to them. A wheel carries them
inside the package, as ``ngdual/studies/scripts/figures`` and
``ngdual/studies/scripts/tutorials`` (the ``package_dir`` lines of ``setup.cfg``), so that
``ngdual figures`` and ``ngdual tutorials`` work after ``pip install ngdual`` without the
checkout; an editable install (``pip install -e .``) runs the checkout's own folders, so
that an edited script takes effect at once.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..scene import SceneError

KINDS = ("figures", "tutorials")
SHIPPED = Path(__file__).resolve().parent / "scripts"   # inside an installed wheel
CHECKOUT = Path(__file__).resolve().parents[2]          # the source checkout, when editable


def environment_variable(kind: str) -> str:
    """The variable that points at another folder of ``kind``: ``NGDUAL_FIGURES_DIR``,
    ``NGDUAL_TUTORIALS_DIR``."""
    return f"NGDUAL_{kind.upper()}_DIR"


def scripts_folder(kind: str, source: str | Path | None = None) -> Path:
    """The folder of the ``kind`` scripts (``"figures"`` or ``"tutorials"``).

    ``source`` (``--source``) if given, else the folder named by
    :func:`environment_variable`, else the copy shipped inside the installed package,
    else ``kind/`` of the source checkout. A :class:`~ngdual.scene.SceneError` naming
    ``source`` if the folder chosen does not exist.

    >>> scripts_folder("tutorials").name
    'tutorials'
    """
    if kind not in KINDS:
        raise SceneError("kind", f"unknown kind of scripts {kind!r}; use one of "
                                 + ", ".join(KINDS))
    variable = environment_variable(kind)
    chosen = source or os.environ.get(variable)
    if chosen:
        folder = Path(chosen)
    elif (SHIPPED / kind).is_dir():
        folder = SHIPPED / kind
    else:
        folder = CHECKOUT / kind
    if not folder.is_dir():
        raise SceneError("source", f"no {kind} folder at {folder}: point --source or "
                                   f"{variable} at the {kind}/ folder of the ngdual sources")
    return folder
