"""What a figure script works with: :class:`Context`, the plan, the records and the outputs.

Output folder of a run::

    DIR/index.md            the index (from figures/index_template.md)
    DIR/run.json            settings, plan, versions, script times, failed tasks
    DIR/records/            one JSON (+ NPZ) record per task
    DIR/data/               CSV / JSON data of every figure and table
    DIR/figures/            PNG and PDF (+ a JSON sidecar naming titles, labels, legends)
    DIR/entries/            one JSON per script: its thesis counterpart, files and numbers
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...io import atomic, plain, versions, write_json
from ...rates import extrapolated_norms
from ..sweep import Runner, Task, load_arrays, load_record
from .numbers import require
from .plan import PROBLEM_TITLES, SCENES, Plan
from .tasks import solve, studies


@dataclass
class Context:
    """What a figure script works with: the plan, the records, the output folders."""

    out: Path
    plan: Plan
    runner: Runner | None = None
    script: str = ""
    written: list = field(default_factory=list)

    @property
    def records_dir(self) -> Path:
        return self.out / "records"

    def studies(self) -> dict[str, list[Task]]:
        return studies(self.plan)

    def compute(self, tasks: list[Task], desc: str = "sweep") -> list[dict | None]:
        """Records of ``tasks``; missing ones are computed (needs a runner)."""
        records = [load_record(self.records_dir, t) for t in tasks]
        missing = [t for t, r in zip(tasks, records) if r is None]
        if missing and self.runner is not None:
            self.runner.run(missing, self.records_dir, desc)
            records = [load_record(self.records_dir, t) for t in tasks]
        return records

    def record(self, task: Task) -> dict | None:
        return self.compute([task])[0]

    def arrays(self, task: Task) -> dict[str, np.ndarray]:
        return load_arrays(self.records_dir, task) if self.record(task) else {}

    # shared studies
    def uniform(self, problem: str) -> list[dict | None]:
        return self.compute([solve(self.plan, problem, lv) for lv in self.plan.levels])

    def reference(self, problem: str) -> dict:
        """The Aitken-extrapolated norms of the uniform levels (:mod:`ngdual.rates`)."""
        return extrapolated_norms([r["norms"] for r in self.uniform(problem) if r])

    def fields(self, problem: str) -> tuple[dict | None, dict]:
        task = solve(self.plan, problem, self.plan.field_level)
        return self.record(task), self.arrays(task)

    def both_fields(self) -> dict[str, tuple[dict, dict]]:
        """Record and field arrays of both problems on :attr:`Plan.field_level`."""
        out = {}
        for problem in SCENES:
            record, arrays = self.fields(problem)
            out[problem] = (require(record, f"{SCENES[problem]} level "
                                            f"{self.plan.field_level}"), arrays)
        return out

    def titles(self, what: str = "") -> list[str]:
        """Panel titles: the two problems, the level and the DOFs."""
        return [f"{what}{PROBLEM_TITLES[p]}, level {self.plan.field_level}" for p in SCENES]

    # output
    def data_path(self, name: str) -> Path:
        path = self.out / "data" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        return path

    def figure_stem(self, name: str) -> Path:
        path = self.out / "figures" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        return path

    def header(self, description: str) -> dict:
        return {"description": description, "script": self.script, "plan": self.plan.describe(),
                "versions": versions()}

    def _header_lines(self, description: str) -> list[str]:
        """``key: value`` lines of :meth:`header` for a text file (non-strings as JSON)."""
        return [f"{key}: {json.dumps(value) if not isinstance(value, str) else value}"
                for key, value in self.header(description).items()]

    def write_json(self, name: str, data: dict, description: str) -> Path:
        path = write_json({**self.header(description), **data}, self.data_path(name))
        self.written.append(path)
        return path

    def write_csv(self, name: str, rows: list[dict], description: str) -> Path:
        """Rows as CSV; ``#`` lines first: description, plan and package versions."""
        path = self.data_path(name)
        columns = list(dict.fromkeys(k for row in rows for k in row))
        with atomic(path, newline="") as fh:
            for line in self._header_lines(description):
                fh.write(f"# {line}\n")
            writer = csv.DictWriter(fh, columns)
            writer.writeheader()
            for row in rows:
                writer.writerow({k: _csv_value(row.get(k)) for k in columns})
        self.written.append(path)
        return path

    def write_markdown(self, name: str, text: str, description: str) -> Path:
        """Markdown ``text`` after an HTML comment with the description, plan and package
        versions (a table to paste into a page)."""
        path = self.data_path(name)
        header = "\n".join(self._header_lines(description))
        with atomic(path) as fh:
            fh.write(f"<!--\n{header}\n-->\n\n{text}")
        self.written.append(path)
        return path

    def entry(self, thesis: str, title: str, files: list, numbers: dict | None = None,
              thesis_says: str = "", notes: str = "", table: str = "") -> Path:
        """Register this script's outputs for the index (``DIR/entries/<script>.json``).

        ``numbers``: our headline numbers; ``thesis_says``: what the thesis states
        about them; ``table``: a markdown table shown in the index.
        """
        files = [Path(f) for f in files]
        data = {"script": self.script, "thesis": thesis, "title": title,
                "files": [str(f.relative_to(self.out)) for f in files],
                "numbers": numbers or {}, "thesis_says": thesis_says, "notes": notes,
                "table": table}
        return write_json(data, self.out / "entries" / f"{self.script}.json")


def _csv_value(value):
    """A CSV cell: floats in full precision, NaN and None empty."""
    value = plain(value)
    return "" if value is None else repr(value) if isinstance(value, float) else value
