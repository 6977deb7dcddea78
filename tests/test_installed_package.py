"""ngdual installed from its wheel, without the source checkout, finds its figure scripts and
tutorials: the wheel holds every module of ``ngdual/`` and every script of ``figures/`` and
``tutorials/`` (as ``ngdual/studies/scripts/``), and, unpacked into a folder of its own and run
from another one, ``ngdual figures --only tab_3_1`` and ``ngdual tutorials`` work.
"""

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = "ngdual/studies/scripts"


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out),
                    str(ROOT)], check=True)
    (path,) = out.glob("ngdual-*.whl")
    return path


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory) -> Path:
    """The wheel unpacked into a folder of its own: what ``pip install`` puts into
    site-packages."""
    site = tmp_path_factory.mktemp("site")
    zipfile.ZipFile(wheel).extractall(site)
    return site


def shipped_files() -> dict[str, Path]:
    """Every file the wheel must hold, by its name in the wheel."""
    files = {f"ngdual/{p.relative_to(ROOT / 'ngdual').as_posix()}": p
             for p in (ROOT / "ngdual").rglob("*") if p.suffix in (".py", ".toml")
             and "__pycache__" not in p.parts}
    for kind, patterns in (("figures", ("*.py", "*.md")),
                           ("tutorials", ("*.py", "*.md", "solutions/*.py"))):
        for pattern in patterns:
            files.update({f"{SCRIPTS}/{kind}/{p.relative_to(ROOT / kind).as_posix()}": p
                          for p in (ROOT / kind).glob(pattern)})
    return files


def run_installed(site: Path, cwd: Path, *argv: str) -> subprocess.CompletedProcess:
    """``python -m ngdual ARGV`` importing ngdual from ``site`` only, in ``cwd``."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("NGDUAL_")}
    env["PYTHONPATH"] = str(site)
    return subprocess.run([sys.executable, "-m", "ngdual", *argv], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600)


def test_the_wheel_holds_every_module_scene_figure_script_and_tutorial(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    files = shipped_files()
    assert f"{SCRIPTS}/figures/tab_3_1_dofs.py" in files
    assert f"{SCRIPTS}/tutorials/solutions/01_peers_spaces_solutions.py" in files
    missing = sorted(set(files) - names)
    assert not missing, f"setup.cfg ships no {missing} (a package missing from [options]?)"


def test_the_installed_package_finds_its_scripts_without_the_checkout(installed, tmp_path):
    code = ("import ngdual, ngdual.studies.sources as s; "
            "print(ngdual.__file__); print(s.scripts_folder('figures')); "
            "print(s.scripts_folder('tutorials'))")
    env = {k: v for k, v in os.environ.items() if not k.startswith("NGDUAL_")}
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, check=True, text=True,
                         capture_output=True, env={**env, "PYTHONPATH": str(installed)})
    package, figures, tutorials = map(Path, out.stdout.split())
    assert package == installed / "ngdual" / "__init__.py"
    assert figures == installed / SCRIPTS / "figures"
    assert tutorials == installed / SCRIPTS / "tutorials"


def test_ngdual_tutorials_lists_the_shipped_tutorials(installed, tmp_path):
    done = run_installed(installed, tmp_path, "tutorials")
    assert done.returncode == 0, done.stderr
    # one line per tutorial (number, title, path), then how to run one
    lines = [line for line in done.stdout.splitlines() if line[:2].strip().isdigit()]
    assert len(lines) == len(list((ROOT / "tutorials").glob("[0-9][0-9]_*.py")))
    assert all(str(installed / SCRIPTS / "tutorials") in line for line in lines)
    assert "ngdual tutorials run" in done.stdout


def test_ngdual_figures_runs_table_3_1_from_the_shipped_scripts(installed, tmp_path):
    out = tmp_path / "figures-output"
    done = run_installed(installed, tmp_path, "figures", "--only", "tab_3_1", "--max-level",
                         "2", "--threads", "--out", str(out))
    assert done.returncode == 0, done.stderr
    run = json.loads((out / "run.json").read_text())
    assert run["scripts"] == {"tab_3_1_dofs": {"status": "ok",
                                               "seconds": run["scripts"]["tab_3_1_dofs"]
                                               ["seconds"]}}
    entry = json.loads((out / "entries" / "tab_3_1_dofs.json").read_text())
    assert entry["thesis"] == "Table 3.1" and entry["files"]
    assert "Table 3.1" in (out / "index.md").read_text()
