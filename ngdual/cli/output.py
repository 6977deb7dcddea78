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


def runs_in_process(threads: bool, dask_asked: bool, what: str) -> bool:
    """Whether the ``what`` (tasks, methods) of a study command run one after another in
    this process rather than on dask workers: with ``--threads``, or where dask (the studies
    extra) is not installed, which is said on stderr. Where dask was asked for
    (``dask_asked``: ``--workers``, ``--scheduler``) and is missing, a MissingExtraError
    refuses the command before it writes anything."""
    from ..extras import MissingExtraError, require

    if dask_asked:
        require("dask.distributed", "studies")
        return threads
    if threads:
        return True
    try:
        require("dask.distributed", "studies")
    except MissingExtraError:
        print(f"ngdual: dask (the studies extra) is not installed: the {what} run one after "
              "another in this process (--threads)", file=sys.stderr)
        return True
    return False


def level_flags(levels, flag: str) -> list[int]:
    return [check_level(level, flag) for level in levels]


# rows of the summary: key, what it is, its symbol in the benchmark's formulas, its kind
SUMMARY_ROWS = [("half_width", "contact half-width", "a", "length"),
                ("peak_pressure", "peak pressure", "p0", "stress"),
                ("normal_force", "normal force", "P", "force"),
                ("tangential_force", "tangential force", "Q", "force"),
                ("peak_shear", "peak shear |q_h|", "", "stress"),
                ("stick_half_width", "stick half-width", "c", "length")]
THESIS_HEADING = "norms and residuals of (3.62)"
FRICTION_ONLY = ("stick_nodes", "slip_nodes", "stick_edges", "slip_edges", "max_traction_ratio")


def _g(value: float) -> str:
    """Four significant digits: what a summary of a discretisation can claim."""
    return f"{value:.4g}"


def _unit(summary: dict, kind: str) -> str:
    unit = summary["units"][kind]
    return f" [{unit}]" if unit else ""


def _direction(vector: list[float]) -> str:
    axes = {(1.0, 0.0): "+x_1", (-1.0, 0.0): "-x_1", (0.0, 1.0): "+x_2", (0.0, -1.0): "-x_2"}
    rounded = tuple(round(v, 12) + 0.0 for v in vector)
    return axes.get(rounded, f"({vector[0]:.3g}, {vector[1]:.3g})")


def _zones(runs: list[list[float]]) -> str:
    return ", ".join(f"[{_g(a)}, {_g(b)}]" for a, b in runs) or "none"


def summary_table(summary: dict) -> str:
    """The summary of :func:`ngdual.summary.solution_summary` as a student reads it: the
    method, then one row per quantity with the analytic value of the scene's benchmark
    beside it and the relative difference; stick and slip zones only where friction acts."""
    m = summary["method"]
    where = "an adapted mesh" if m["level"] is None else f"level {m['level']}"
    lines = [f"{m['scene']}, {where}: PEERS order {m['order']}, {m['multipliers']} "
             f"multipliers, {m['solver']}" + ("" if m["converged"] else " (NOT converged)")]
    if not summary["contact"]:
        return "\n".join(lines + ["no contact boundary: no contact quantities"])
    bench = summary.get("benchmark")
    n, t = (_direction(summary["directions"][k]) for k in ("normal", "tangent"))
    width = max(18, len(bench["name"]) + 2) if bench else 0
    lines.append(f"{'':32s}{'computed':>11s}" + (f"{bench['name']:>{width}s}{'difference':>12s}"
                                                   if bench else ""))
    for key, name, symbol, kind in SUMMARY_ROWS:
        if summary.get(key) is None:
            continue
        label = f"{name} {symbol}".strip() + _unit(summary, kind)
        row = f"{label:32s}{_g(summary[key]):>11s}"
        if bench and key in bench["values"]:
            row += f"{_g(bench['values'][key]):>{width}s}"
            if key in bench["difference"]:
                row += f"{bench['difference'][key] * 100:>+10.3g} %"
        lines.append(row + {"half_width": f"   (node spacing {_g(summary['resolution'] or 0)})",
                            "normal_force": f"   (along {n}, on the body)",
                            "tangential_force": f"   (along {t})",
                            "peak_pressure": "" if summary["peak_at"] is None else
                            f"   (at {_g(summary['peak_at'])})"}.get(key, ""))
    lines.append(f"{'contact zone':32s}{_zones(summary['contact_zones'])}")
    if summary.get("friction"):
        lines.append(f"{'stick zone':32s}{_zones(summary['stick'])}")
        lines.append(f"{'slip zones':32s}{_zones(summary['slip'])}")
    if bench:
        forces = "forces P and Q" if "peak_shear" in bench["values"] else "force P"
        lines.append(f"{bench['name']}: the analytic solution for the computed {forces}; "
                     f"positions along {t}")
    else:
        lines.append(f"positions along {t}")
    return "\n".join(lines)


def result_table(record: dict) -> str:
    """The record of ``ngdual solve`` under the heading THESIS_HEADING: DOFs, the norms of
    Tables 3.2/3.3, the contact record (stick and slip counts only with friction), the
    iterations and residuals of (3.62), the timings."""
    lines = [f"-- {THESIS_HEADING} --",
             f"scene {record['scene']}  level {record['level']}  method {record['method']}  "
             f"converged {record['converged']}"]
    lines.append("dofs      " + "  ".join(f"{k}={v}" for k, v in record["dofs"].items()))
    lines.append("norms     " + "  ".join(f"{k}={v:.6e}" for k, v in record["norms"].items()
                                          if v is not None))
    friction = "stick_edges" in record["contact"]
    lines.append("contact   " + "  ".join(f"{k}={_value(v)}" for k, v in record["contact"].items()
                                          if friction or k not in FRICTION_ONLY))
    lines.append("iterations " + "  ".join(f"{k}={v}" for k, v in record["iterations"].items()))
    if record["residuals"]:
        lines.append("residuals " + "  ".join(f"{k}={v:.2e}"
                                              for k, v in record["residuals"].items()))
    lines.append("time [s]  " + "  ".join(f"{k}={v:.3f}"
                                          for k, v in record["timings_s"].items()))
    if "accuracy" in record:
        lines.append(accuracy_line(record["accuracy"]))
    return "\n".join(lines)


def accuracy_line(accuracy: dict) -> str:
    """How a solve to a tolerance went: the method and why, the estimate against the
    tolerance, the solves, the unknowns and the loop's time; and, where the loop stopped
    before the tolerance, by what."""
    line = (f"accuracy  {accuracy['method']} ({accuracy['reason']})  estimate "
            f"{100 * accuracy['relative_estimate']:.3g} % of tol {100 * accuracy['tol']:.3g} %  "
            f"solves={accuracy['solves']}  unknowns={accuracy['unknowns']}  "
            f"loop={accuracy['loop_s']:.2f} s")
    if not accuracy["reached"]:
        line += (f"\n          NOT REACHED: the loop stopped by {accuracy['stopped_by']} at "
                 f"{100 * accuracy['relative_estimate']:.3g} %")
    return line


def _value(value) -> str:
    if isinstance(value, float):
        return _g(value)
    if isinstance(value, list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    return str(value)


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
