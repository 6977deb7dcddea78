"""Atomic file output: results are written to a temporary file and renamed."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path


def write_json(data: dict, path: str | Path) -> Path:
    """Write ``data`` as JSON to ``path`` atomically (never a partial file)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w") as fh:
            json.dump(data, fh, indent=2, allow_nan=False)
            fh.write("\n")
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


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
