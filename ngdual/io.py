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
