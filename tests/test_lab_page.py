"""The lab page (docs/lab.md) runs as printed and shows what its commands produce.

The page is a sequence of steps, each a ``## Step N: ...`` section. A step's fenced
``bash`` blocks are run in order, as a student would type them, in a fresh folder holding
the page's scene files (``docs/lab/*.toml``). Then every picture the step shows,
``lab/DIR/FILE.png`` in a ``{figure}`` directive, must have been written as ``DIR/FILE.png``,
and every number of its "what you should see" table must hold: a row names the file and
the key, e.g. ```hertz/result.json: summary.peak_pressure``` (``[i]`` indexes a list), and
states the value as ``X ± Y %``, ``X ± Y``, ``A to B`` or ``at most X``. Each step's wall
time is printed (``pytest -s``) beside the time the page states.

The pictures on the page are the ones these commands wrote; to refresh them after a change
of the plots or the solver::

    NGDUAL_LAB_UPDATE=1 python -m pytest -q -m slow tests/test_lab_page.py

which copies each produced picture over ``docs/lab/DIR/FILE.png``, reduced to 256 colours
(a third of the bytes, the same picture to the eye).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pytest
from PIL import Image

import ngdual as nd

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
PAGE = DOCS / "lab.md"
LAB = DOCS / "lab"
STEP_TIMEOUT_S = 300

FENCE = re.compile(r"^```(\S*)[^\n]*\n(.*?)^```\s*$", re.M | re.S)
FIGURE = re.compile(r"^```\{figure\} lab/(\S+\.png)\s*$", re.M)
ROW = re.compile(r"^\|[^|\n]*\|\s*`([\w./-]+\.json): ([^`]+)`\s*\|([^|\n]+)\|", re.M)
TIME = re.compile(r"computer time[^:]*: about (\d+) s", re.I)
NUMBER = r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?"


@dataclass
class Step:
    """One step of the lab: its commands, the pictures it shows, the numbers it states."""

    title: str
    commands: list[str]
    pictures: list[str]
    numbers: list[tuple[str, str, str]]  # (file, key, expected)
    stated_time_s: int | None

    def __str__(self) -> str:
        return self.title


def read_steps(text: str) -> list[Step]:
    """Split the page at its ``## Step`` headings."""
    parts = re.split(r"^## (Step \d+[^\n]*)\n", text, flags=re.M)[1:]
    steps = []
    for title, body in zip(parts[::2], parts[1::2]):
        body = body.split("\n## ", 1)[0]
        commands = [code for lang, code in FENCE.findall(body) if lang == "bash"]
        stated = TIME.search(body)
        steps.append(Step(title.strip(), commands, FIGURE.findall(body),
                          [(f, k.strip(), e.strip()) for f, k, e in ROW.findall(body)],
                          int(stated.group(1)) if stated else None))
    return steps


STEPS = read_steps(PAGE.read_text(encoding="utf-8"))


def lookup(data, key: str):
    """``summary.contact_zones[1][0]`` of a loaded JSON file."""
    for name, index in re.findall(r"(\w+)|\[(-?\d+)\]", key):
        data = data[name] if name else data[int(index)]
    return data


def assert_as_stated(value: float, expected: str, where: str) -> None:
    """The value lies in the range the page states."""
    if m := re.match(rf"({NUMBER}) ± ({NUMBER})( %)?", expected):
        centre, tol = float(m.group(1)), float(m.group(2))
        allowed = tol / 100 * abs(centre) if m.group(3) else tol
        assert abs(value - centre) <= allowed, f"{where} = {value:.6g}, the page says {expected}"
    elif m := re.match(rf"({NUMBER}) to ({NUMBER})", expected):
        assert float(m.group(1)) <= value <= float(m.group(2)), \
            f"{where} = {value:.6g}, the page says {expected}"
    elif m := re.match(rf"at most ({NUMBER})", expected):
        assert value <= float(m.group(1)), f"{where} = {value:.6g}, the page says {expected}"
    else:
        raise AssertionError(f"{where}: the page's value {expected!r} is not in a form the "
                             "test reads (X ± Y %, X ± Y, A to B, at most X)")


def shell_environment() -> dict[str, str]:
    """The interpreter running the tests provides ``ngdual``, without an activated shell."""
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    return env


def run_commands(step: Step, folder: Path) -> float:
    """Run the step's bash blocks in ``folder``; return the wall time in seconds."""
    for scene in LAB.glob("*.toml"):
        shutil.copy(scene, folder)
    env = shell_environment()
    prelude = ("" if shutil.which("ngdual", path=env["PATH"])
               else f'ngdual() {{ "{sys.executable}" -m ngdual "$@"; }}\n')
    start = time.perf_counter()
    for block in step.commands:
        result = subprocess.run(["bash", "-euo", "pipefail", "-c", prelude + block], cwd=folder,
                                env=env, capture_output=True, text=True, timeout=STEP_TIMEOUT_S)
        assert result.returncode == 0, (f"{step}: `{block.strip()}` exited with "
                                        f"{result.returncode}\n{result.stdout[-3000:]}"
                                        f"\n{result.stderr[-3000:]}")
    return time.perf_counter() - start


def test_every_step_has_commands_pictures_numbers_and_a_time():
    assert len(STEPS) >= 5, [str(s) for s in STEPS]
    for step in STEPS:
        assert step.commands, f"{step}: no ```bash block"
        assert step.pictures, f"{step}: no {{figure}} lab/DIR/FILE.png"
        assert step.numbers, f"{step}: no row naming `FILE.json: key`"
        assert step.stated_time_s, f"{step}: no 'computer time ...: about N s'"


def test_every_picture_the_page_shows_is_in_docs_lab():
    shown = [picture for step in STEPS for picture in step.pictures]
    missing = [p for p in shown if not (LAB / p).is_file()]
    assert shown and not missing, f"not in docs/lab: {missing} (NGDUAL_LAB_UPDATE=1, see above)"


def test_every_stated_value_is_in_a_form_the_test_reads():
    for step in STEPS:
        for file, key, expected in step.numbers:
            assert re.match(rf"({NUMBER} ± {NUMBER}|{NUMBER} to {NUMBER}|at most {NUMBER})",
                            expected), f"{step}: {file}: {key}: {expected!r}"


def test_the_students_scene_on_the_page_is_the_file_and_validates():
    text = PAGE.read_text(encoding="utf-8")
    shown = [code for lang, code in FENCE.findall(text) if lang == "toml"]
    scene_file = LAB / "my_block.toml"
    assert shown == [scene_file.read_text(encoding="utf-8")]
    assert nd.load_scene(scene_file).name == "my-block"


def test_the_lab_page_is_in_the_table_of_contents():
    index = (DOCS / "index.md").read_text(encoding="utf-8")
    toctree = index.split("```{toctree}", 1)[1].split("```", 1)[0]
    assert "lab" in toctree.split()


@pytest.mark.slow
@pytest.mark.parametrize("step", STEPS, ids=[s.title.split(":")[0].replace(" ", "") for s in STEPS])
def test_the_steps_commands_produce_its_pictures_and_numbers(step, tmp_path):
    elapsed = run_commands(step, tmp_path)
    print(f"\n{step}: {elapsed:.1f} s on this machine (the page: about {step.stated_time_s} s)")
    missing = [p for p in step.pictures if not (tmp_path / p).is_file()]
    assert not missing, f"{step}: the commands did not write {missing}"
    for file, key, expected in step.numbers:
        value = lookup(json.loads((tmp_path / file).read_text(encoding="utf-8")), key)
        assert_as_stated(float(value), expected, f"{file}: {key}")
    if os.environ.get("NGDUAL_LAB_UPDATE") == "1":
        for picture in step.pictures:
            (LAB / picture).parent.mkdir(parents=True, exist_ok=True)
            with Image.open(tmp_path / picture) as image:
                image.convert("RGB").quantize(256, Image.Quantize.MEDIANCUT).save(
                    LAB / picture, optimize=True)
