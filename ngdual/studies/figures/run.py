"""``ngdual figures``: every figure and table of Sections 3.4 and 4.2, and what accuracy costs.

The scripts in ``figures/`` (one per thesis figure or table) each compute, write
their data (CSV / JSON, with the package versions) and plot (PNG and PDF). They
share their solves through *studies*: named lists of sweep tasks that
:func:`~ngdual.studies.figures.tasks.studies` derives from one number, the finest uniform
level K (``--max-level``; :class:`~ngdual.studies.figures.plan.Plan` derives every size
from it). A run first computes all studies the selected scripts declare (``STUDIES``), as
one dask sweep (:class:`~ngdual.studies.sweep.Runner`) whose records go to
``DIR/records`` -- re-running skips them -- then runs the scripts, which only read records
through a :class:`~ngdual.studies.figures.output.Context`, and writes ``DIR/index.md``:
every output next to its thesis counterpart, with our numbers. The scripts run inside
:func:`ngdual.plot.slides`: every picture is a 16:9 slide of 1600 x 900 px.
"""

from __future__ import annotations

import importlib.util
import json
import sys
import time
from datetime import datetime
from pathlib import Path

from ...io import versions, write_json
from ...plot.slides import slides
from ...scene import SceneError
from ..sources import scripts_folder
from ..sweep import Runner, Task
from .index import write_index
from .output import Context
from .plan import DEFAULT_MAX_LEVEL, Plan


def figures_dir(source: str | Path | None = None) -> Path:
    """The figure scripts' folder: ``source`` (``--source``), else ``NGDUAL_FIGURES_DIR``,
    else the one shipped with ngdual (:func:`~ngdual.studies.sources.scripts_folder`)."""
    return scripts_folder("figures", source)


def figure_scripts(source: str | Path | None = None) -> list[Path]:
    """The figure scripts (``figures/*.py`` not starting with ``_``), sorted by name."""
    return sorted(p for p in figures_dir(source).glob("*.py") if not p.name.startswith("_"))


def select_scripts(only: list[str] | None = None, source: str | Path | None = None
                   ) -> list[Path]:
    """The figure scripts to run: every one, or those whose name contains one of ``only``
    (``--only``); a SceneError naming ``only`` for a name that matches no script, or
    ``source`` for a folder without scripts. Nothing is created before this check."""
    scripts = figure_scripts(source)
    if not scripts:
        raise SceneError("source", f"no figure scripts (*.py) in {figures_dir(source)}")
    if only is None:
        return scripts
    if isinstance(only, str) or not all(isinstance(name, str) for name in only):
        raise SceneError("only", f"must be a list of script names, got {only!r}")
    stems = [p.stem for p in scripts]
    unknown = [name for name in only if not any(name in stem for stem in stems)]
    if unknown:
        raise SceneError("only", f"no figure script matches {', '.join(map(repr, unknown))}; "
                                 f"the scripts are {', '.join(stems)}")
    return [p for p in scripts if any(name in p.stem for name in only)]


def load_script(path: Path):
    """Import a figure script; it must define ``THESIS``, ``STUDIES`` and ``run(ctx)``."""
    spec = importlib.util.spec_from_file_location(f"ngdual_figure_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for name in ("THESIS", "STUDIES", "run"):
        if not hasattr(module, name):
            raise AttributeError(f"figure script {path} defines no {name}")
    return module


def run_figures(max_level: int | None = None, out: str | Path = "figures-output",
                scheduler: str | None = None, workers: int | None = None,
                processes: bool = True, only: list[str] | None = None,
                source: str | Path | None = None, progress: bool | None = None) -> dict:
    """Compute the studies, run the selected scripts, write the index. Returns the run summary."""
    from tqdm import tqdm

    start = time.perf_counter()
    max_level = max_level or DEFAULT_MAX_LEVEL
    plan = Plan(max_level)
    scripts = select_scripts(only, source)
    modules = {p.stem: load_script(p) for p in scripts}
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary = {"max_level": max_level, "plan": plan.describe(), "out": str(out),
               "scheduler": scheduler or "LocalCluster", "workers": workers,
               "processes": processes,
               "started": datetime.now().astimezone().isoformat(timespec="seconds"),
               "versions": versions(), "scripts": {}, "failed_tasks": {}}
    with Runner(scheduler, workers, processes, progress) as runner:
        ctx = Context(out, plan, runner)
        # COMPUTE: every study the selected scripts need, as one sweep (both workers busy)
        all_studies = ctx.studies()
        needed = list(dict.fromkeys(s for m in modules.values() for s in m.STUDIES))
        tasks = [t for name in needed for t in all_studies[name]]
        t0 = time.perf_counter()
        runner.run(tasks, ctx.records_dir, desc="sweeps")
        summary["sweep_s"] = time.perf_counter() - t0
        summary["tasks"] = len({t.id for t in tasks})
        summary["computed_tasks"] = runner.computed
        # WRITE + PLOT: the scripts read the records
        for stem, module in tqdm(modules.items(), desc="figures", unit="script",
                                 disable=None if progress is None else not progress):
            ctx.script = stem
            t0 = time.perf_counter()
            try:
                with slides():  # every picture a 16:9 slide, 1600 x 900 px
                    module.run(ctx)
                status = "ok"
            except Exception as err:  # noqa: BLE001 - one broken figure must not stop the rest
                import traceback

                status = f"error: {type(err).__name__}: {err}"
                print(f"ngdual figures: {stem} failed:\n{traceback.format_exc()}", file=sys.stderr)
            summary["scripts"][stem] = {"status": status, "seconds": time.perf_counter() - t0}
        summary["failed_tasks"] = _failed_tasks(ctx, tasks)
    summary["seconds"] = time.perf_counter() - start
    write_json(summary, out / "run.json")
    write_index(out, summary, figures_dir(source) / "index_template.md")
    return summary


def _failed_tasks(ctx: Context, tasks: list[Task]) -> dict:
    out = {}
    for t in {t.id: t for t in tasks}.values():
        try:
            record = json.loads((ctx.records_dir / f"{t.id}.json").read_text())
        except (OSError, ValueError):
            out[t.id] = {"label": t.label, "status": "missing", "message": ""}
            continue
        if record.get("status") != "ok":
            out[t.id] = {"label": t.label, "status": record.get("status"),
                         "message": record.get("message", "")[:500]}
    return out


def script_main(path: str) -> None:
    """``python figures/<script>.py [--max-level K] [--out DIR]``: run one script (and its
    studies), as ``ngdual figures --only <script>`` does."""
    import argparse

    p = argparse.ArgumentParser(description=f"regenerate {Path(path).stem}")
    p.add_argument("--max-level", type=int, default=DEFAULT_MAX_LEVEL)
    p.add_argument("--out", default="figures-output")
    p.add_argument("--threads", action="store_true",
                   help="the tasks one after another in this process (no dask)")
    args = p.parse_args()
    summary = run_figures(args.max_level, args.out, processes=not args.threads,
                          only=[Path(path).stem], source=Path(path).parent)
    print(f"wrote {Path(args.out) / 'index.md'} ({summary['seconds']:.0f} s)")
