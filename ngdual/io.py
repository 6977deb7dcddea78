"""How results are written: atomically, as plain JSON, with the package versions.

Every file ngdual writes (``result.json``, sweep records and arrays, figure data, bench
runs) goes through :func:`atomic`: a temporary file in the target folder renamed into
place, so a killed run never leaves a half-written file. JSON has no NaN or infinity and
no numpy types: :func:`plain` turns them into None and Python numbers, once, for every
writer. :func:`versions` is the provenance every record carries.
"""

from __future__ import annotations

import json
import math
import os
import platform
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

# the packages a result depends on: the numerics, the linear algebra, the sweeps
PACKAGES = ("ngsolve", "netgen-mesher", "numpy", "scipy", "cvxpy", "clarabel", "cvxopt",
            "pymetis", "matplotlib", "dask", "distributed")


def versions() -> dict:
    """Versions of ngdual, Python, the platform and :data:`PACKAGES` (None: not installed)."""
    from . import __version__

    out = {"ngdual": __version__, "python": platform.python_version(),
           "platform": platform.platform()}
    for pkg in PACKAGES:
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def plain(value):
    """``value`` as plain JSON data: numpy scalars and arrays as Python numbers and lists,
    dict keys as strings, NaN and infinities as None (JSON has neither).

    >>> plain({1: [float("nan"), 2.0]})
    {'1': [None, 2.0]}
    """
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return plain(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


@contextmanager
def atomic(path: str | Path, mode: str = "w", **kwargs) -> Iterator:
    """Open a temporary file next to ``path`` and rename it to ``path`` when the block ends
    without an exception (removed otherwise): ``path`` is the old file or the whole new one.

    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "a.txt"
    >>> with atomic(target) as fh:
    ...     _ = fh.write("done")
    >>> target.read_text()
    'done'
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_json(data: dict, path: str | Path) -> Path:
    """Write ``plain(data)`` as JSON to ``path`` atomically (never a partial file)."""
    with atomic(path) as fh:
        json.dump(plain(data), fh, indent=2, allow_nan=False)
        fh.write("\n")
    return Path(path)


def write_npz(arrays: dict, path: str | Path) -> Path:
    """Write numpy ``arrays`` compressed to ``path`` atomically."""
    import numpy as np

    with atomic(path, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    return Path(path)


def check_output_dir(path: str | Path, field_name: str = "--out") -> Path:
    """``path`` if it is, or can be created as, a writable folder; a SceneError naming
    ``field_name`` otherwise. Checked before any work, and nothing is left behind."""
    return _check_output(Path(path), field_name, folder=True)


def check_output_file(path: str | Path, field_name: str) -> Path:
    """``path`` if a file can be written there (atomically: its folder must be writable)."""
    return _check_output(Path(path), field_name, folder=False)


def _check_output(path: Path, field_name: str, folder: bool) -> Path:
    from .scene import SceneError

    if path.exists():
        if folder and not path.is_dir():
            raise SceneError(field_name, f"{str(path)!r} is an existing file, not a folder")
        if not folder and path.is_dir():
            raise SceneError(field_name, f"{str(path)!r} is a folder, not a file")
    existing = path.absolute() if folder else path.absolute().parent
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise SceneError(field_name, f"cannot create {str(path)!r}: {str(existing)!r} is a "
                                     "file")
    try:  # access() says yes to root on read-only file systems: try a file and remove it
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as err:
        raise SceneError(field_name, f"cannot create files in {str(existing)!r} "
                                     f"({err.strerror or err})") from None
    return path
