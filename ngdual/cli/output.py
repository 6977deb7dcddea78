"""What the command line prints: result tables, residual histories, progress, flag checks."""

from __future__ import annotations

import sys

from ..scene import SceneError, check_level

EXIT_NOT_CONVERGED, EXIT_BAD_INPUT, EXIT_INTERNAL, EXIT_WARNINGS = 1, 2, 3, 4
EXIT_BROKEN_PIPE = 141  # what a shell reports for a process ended by SIGPIPE (128 + 13)
HISTORY_ROWS = 8  # residuals shown when an iteration fails
LARGE_MESH = 2e5  # triangles: say so before meshing


def residual_history(err) -> str:
    """The last residuals of a failed iteration, on one line."""
    history = list(getattr(err, "history", None) or [])
    if not history:
        return ""
    start = len(history) - min(len(history), HISTORY_ROWS)
    rows = "  ".join(f"{start + k + 1}: {_residual(v)}" for k, v in enumerate(history[start:]))
    return f"\nngdual: residual history, last {len(history) - start} of {len(history)} " \
           f"steps (step: residual): {rows}"


def _residual(value) -> str:
    try:
        return f"{float(value):.3e}"
    except (TypeError, ValueError):
        return str(value)[:40]


def not_converged(err) -> int:
    print(f"ngdual: not converged: {err}{residual_history(err)}", file=sys.stderr)
    return EXIT_NOT_CONVERGED


def warning_lines(warnings: list[dict], indent: str = "") -> str:
    """The failed physics checks of a record (:mod:`ngdual.checks`), one line each."""
    return "\n".join(f"{indent}warning: {w['message']}" for w in warnings)


class StrictFailure(Exception):
    """A physics check failed under ``--strict``: the record's ``warnings``, ``where``
    (the solution, step k) and what was ``written`` before."""

    def __init__(self, warnings: list[dict], where: str, written: str):
        super().__init__(where)
        self.warnings, self.where, self.written = warnings, where, written


def strict_failure(err: StrictFailure) -> int:
    """Say that ``--strict`` stops here (the warnings are printed already)."""
    n = len(err.warnings)
    print(f"ngdual: error: --strict: {err.where} fails {n} physics check{'s' * (n > 1)} "
          f"({', '.join(w['code'] for w in err.warnings)}: the warnings above); "
          f"{err.written}", file=sys.stderr)
    return EXIT_WARNINGS


def number_flag(value, flag: str, low: float, high: float, integer: bool = False):
    """``value`` if it is a (finite) number in [low, high]; a SceneError naming ``flag``."""
    import math

    kind = "an integer" if integer else "a number"
    if value is None or not math.isfinite(value) or not low <= value <= high:
        raise SceneError(flag, f"must be {kind} in [{low:g}, {high:g}], got {value!r}")
    return value


def level_flags(levels, flag: str) -> list[int]:
    return [check_level(level, flag) for level in levels]


def result_table(record: dict) -> str:
    lines = [f"scene {record['scene']}  level {record['level']}  method {record['method']}  "
             f"converged {record['converged']}"]
    lines.append("dofs      " + "  ".join(f"{k}={v}" for k, v in record["dofs"].items()))
    lines.append("norms     " + "  ".join(f"{k}={v:.6e}" for k, v in record["norms"].items()
                                          if v is not None))
    lines.append("contact   " + "  ".join(f"{k}={v:.6g}" if isinstance(v, float) else f"{k}={v}"
                                          for k, v in record["contact"].items()))
    lines.append("iterations " + "  ".join(f"{k}={v}" for k, v in record["iterations"].items()))
    if record["residuals"]:
        lines.append("residuals " + "  ".join(f"{k}={v:.2e}"
                                              for k, v in record["residuals"].items()))
    lines.append("time [s]  " + "  ".join(f"{k}={v:.3f}"
                                          for k, v in record["timings_s"].items()))
    return "\n".join(lines)


def progress_bar(desc: str = "Uzawa"):
    """progress(iteration, increment) drawing a tqdm bar on stderr when it is a terminal."""
    from tqdm import tqdm

    bar = tqdm(desc=desc, unit="it", leave=False, file=sys.stderr,
               disable=not sys.stderr.isatty())

    def update(iteration: int, increment: float) -> None:
        bar.update(1)
        bar.set_postfix(increment=f"{increment:.1e}")
    return update


class PhaseStatus:
    """status(phase): one stderr line when a phase of a long run begins (meshing,
    assembling, factorising), stamped with the seconds since the run began.

    Silent unless ``enabled`` (the CLI enables it when stderr is a terminal or the mesh
    is large), so that logs of small runs and the tests stay clean.
    """

    def __init__(self, enabled: bool):
        import time

        self.enabled, self._clock = enabled, time.perf_counter
        self._start = self._clock()

    def __call__(self, phase: str) -> None:
        if self.enabled:
            print(f"ngdual: {self._clock() - self._start:7.1f} s  {phase} ...", file=sys.stderr,
                  flush=True)

    def done(self) -> None:
        """Say that the last phase has ended."""
        self("done")
