"""The index of a run (``DIR/index.md``), its markdown tables and the docs' gallery."""

from __future__ import annotations

import json
import re
from pathlib import Path

from ...io import atomic

_NUMBER = re.compile(r"(Fig|Table)s?\.\s*(\d+)\.(\d+)")


def thesis_order(label: str) -> tuple:
    """Sort key of a thesis reference: chapter, number, figures before tables."""
    match = _NUMBER.search(label)
    if not match:
        return (99, 99, 0)
    return (int(match.group(2)), int(match.group(3)), 0 if match.group(1) == "Fig" else 1)


def _format(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (list, tuple)) and any(isinstance(v, (list, tuple)) for v in value):
        return ", ".join("(" + _format(v) + ")" if isinstance(v, (list, tuple)) else _format(v)
                         for v in value)
    if isinstance(value, (list, tuple)):
        return ", ".join(_format(v) for v in value)
    return str(value)


def write_index(out: Path, summary: dict, template: Path) -> Path:
    """``DIR/index.md`` from ``template`` (``figures/index_template.md``) and the entries of
    the scripts."""
    template = template.read_text()
    entries = []
    for path in sorted((out / "entries").glob("*.json")):
        entries.append(json.loads(path.read_text()))
    entries.sort(key=lambda e: thesis_order(e["thesis"]))
    blocks = []
    for e in entries:
        status = summary["scripts"].get(e["script"], {}).get("status", "from an earlier run")
        lines = [f"### {e['thesis']}: {e['title']}", "",
                 f"Script `figures/{e['script']}.py` ({status}).", ""]
        images = [f for f in e["files"] if f.endswith(".png")]
        lines += [f"![{e['thesis']}]({f})" for f in images[:1]]
        lines += ["", "Files: " + ", ".join(f"[{Path(f).name}]({f})" for f in e["files"]), ""]
        if e["numbers"]:
            lines += ["| quantity | ours |", "|---|---|"]
            lines += [f"| {k} | {_format(v)} |" for k, v in e["numbers"].items()]
            lines.append("")
        if e.get("table"):
            lines += [e["table"], ""]
        if e["thesis_says"]:
            lines += [f"Thesis: {e['thesis_says']}", ""]
        if e["notes"]:
            lines += [f"Notes: {e['notes']}", ""]
        blocks.append("\n".join(lines))
    failed = summary.get("failed_tasks", {})
    failures = "\n".join(f"* `{k}` ({v['label']}): **{v['status']}** {v['message']}"
                         for k, v in failed.items()) or "none"
    text = (template.replace("{{max_level}}", str(summary["max_level"]))
            .replace("{{started}}", summary["started"])
            .replace("{{seconds}}", f"{summary.get('seconds', 0):.0f}")
            .replace("{{tasks}}", f"{summary.get('tasks', 0)} tasks, "
                                  f"{summary.get('computed_tasks', 0)} computed in this run")
            .replace("{{versions}}", ", ".join(f"{k} {v}" for k, v in summary["versions"].items()
                                               if v and k != "platform"))
            .replace("{{plan}}", "\n".join(f"* `{k}`: {_format(v)}"
                                           for k, v in summary["plan"].items()))
            .replace("{{entries}}", "\n".join(blocks))
            .replace("{{failures}}", failures))
    path = out / "index.md"
    with atomic(path) as fh:
        fh.write(text)
    return path


GALLERY = ("fig_3_11_von_mises", "fig_3_19_tangential_displacement", "fig_3_23_rho_grid",
           "fig_4_13_", "work_precision_pressure", "work_precision_sigma",
           *(f"contact_scenes_{name}" for name in ("hertz-cylinder", "flat-punch",
                                                    "cattaneo-mindlin", "wedge")))
GALLERY_SIZE = (1600, 900)  # the slide geometry of ngdual.plot.slides: 16:9


def write_gallery(out: str | Path, dest: str | Path, size: tuple[int, int] = GALLERY_SIZE,
                  names: tuple[str, ...] = GALLERY) -> list[Path]:
    """Copies of the PNGs of ``out/figures`` starting with ``names`` (8-bit palette) for the
    docs' gallery, each ``size`` pixels (16:9, for slides): a slide-sized figure as it is,
    any other scaled to fit and centred on white."""
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    written = []
    for name in names:
        for path in sorted((Path(out) / "figures").glob(f"{name}*.png"))[:1]:
            target = dest / re.sub(r"_step\d+", "", path.name)  # stable for the docs
            written.append(gallery_copy(path, target, size))
    return written


def gallery_copy(source: str | Path, target: str | Path,
                 size: tuple[int, int] = GALLERY_SIZE) -> Path:
    """``source`` as an 8-bit PNG of ``size`` pixels at ``target``: scaled to fit (never
    above its own resolution unless it is smaller than ``size``) and centred on white."""
    from PIL import Image

    with Image.open(source) as img:
        img = img.convert("RGB")
        if img.size != tuple(size):
            scale = min(size[0] / img.width, size[1] / img.height)
            img = img.resize((round(img.width * scale), round(img.height * scale)),
                             Image.LANCZOS)
            canvas = Image.new("RGB", tuple(size), "white")
            canvas.paste(img, ((size[0] - img.width) // 2, (size[1] - img.height) // 2))
            img = canvas
        img.quantize(colors=256, method=Image.FASTOCTREE).save(target, optimize=True)
    return Path(target)


def markdown_table(rows: list[dict], columns: dict[str, str], missing: str = "-") -> str:
    """A markdown table of ``rows``; ``columns`` maps keys to headers (a missing value:
    ``missing``).

    >>> print(markdown_table([{"a": 1, "b": 0.5}], {"a": "A", "b": "B"}))
    | A | B |
    |---|---|
    | 1 | 0.5 |
    """
    head = "| " + " | ".join(columns.values()) + " |"
    rule = "|" + "---|" * len(columns)
    body = ["| " + " | ".join(missing if r.get(k) is None else _format(r[k]) for k in columns)
            + " |" for r in rows]
    return "\n".join([head, rule, *body])
