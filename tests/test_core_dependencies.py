"""``import ngdual``, ``nd.solve``, ``nd.adapt`` and ``ngdual solve`` need only the core.

The packages of the extras (``setup.cfg``), with every package they pull in that the core
does not, are blocked in a subprocess by an import hook, as if they were not installed.
There ngdual and every module of its pipeline import (fast tier) and, in the slow tier, a
scene with contact and Coulomb friction is solved on level 1, adapted one step and solved
by the README's first command; ``ngdual figures`` runs a figure in this process (saying so),
while ``ngdual figures --workers 2`` names the extra it needs (:func:`ngdual.extras.require`).
"""

import configparser
import json
import os
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

from ngdual.cli.output import EXIT_BAD_INPUT
from ngdual.extras import MissingExtraError, require

SETUP_CFG = Path(__file__).resolve().parents[1] / "setup.cfg"


def requirements() -> tuple[list[str], dict[str, list[str]]]:
    """install_requires and extras_require of setup.cfg, an extra's ``ngdual[...]`` expanded."""
    cfg = configparser.ConfigParser()
    cfg.read(SETUP_CFG)
    lines = lambda text: [s.strip() for s in text.splitlines() if s.strip()]  # noqa: E731
    declared = {name: lines(text) for name, text in cfg["options.extras_require"].items()}

    def expand(reqs: list[str]) -> list[str]:
        out = []
        for text in reqs:
            req = Requirement(text)
            out += expand([r for e in sorted(req.extras) for r in declared[e]]) \
                if req.name == "ngdual" else [text]
        return out

    return lines(cfg["options"]["install_requires"]), {e: expand(r) for e, r in declared.items()}


def closure(reqs: list[str]) -> set[str]:
    """The installed distributions ``reqs`` need, with their dependencies (markers evaluated)."""
    found, seen, todo = set(), set(), [Requirement(r) for r in reqs]
    while todo:
        req = todo.pop()
        name = canonicalize_name(req.name)
        if (req.marker and not req.marker.evaluate({"extra": ""})) \
                or (name, frozenset(req.extras)) in seen:
            continue
        seen.add((name, frozenset(req.extras)))
        try:
            needs = metadata.requires(name) or []
        except metadata.PackageNotFoundError:
            continue
        found.add(name)
        for text in needs:
            sub = Requirement(text)
            if sub.marker is None or any(sub.marker.evaluate({"extra": e})
                                         for e in ("", *req.extras)):
                sub.marker = None
                todo.append(sub)
    return found


def blocked_modules() -> list[str]:
    """Top-level import names installed only by the extras."""
    core, extras = requirements()
    needed = closure(core) | {"ngdual", "pip", "setuptools", "wheel"}
    optional = closure([r for reqs in extras.values() for r in reqs]) - needed
    names = set()
    for module, dists in metadata.packages_distributions().items():
        dists = {canonicalize_name(d) for d in dists}
        if dists & optional and not dists & needed and module.isidentifier():
            names.add(module)
    return sorted(names)


# a subprocess in which the packages named in argv[1] cannot be imported
UNINSTALL = r"""
import importlib.abc, json, sys

BLOCKED = set(json.loads(sys.argv[1]))

class Uninstalled(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"No module named {name!r} (blocked)", name=name)

sys.meta_path.insert(0, Uninstalled())
"""

IMPORTS = UNINSTALL + r"""
import ngdual as nd
import ngdual.afem, ngdual.cli, ngdual.plot, ngdual.post, ngdual.solvers, ngdual.studies
print(json.dumps(sorted({m.partition(".")[0] for m in sys.modules} & BLOCKED)))
"""

RUNS = UNINSTALL + r"""
import warnings
import ngdual as nd
from ngdual.cli import main

scene = nd.load_scene("thesis-3.46-coulomb", ["geometry.level=1"])
with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # the thesis ends warn; the solve is what is tested
    solution = nd.solve(scene)
    history = nd.adapt(scene, steps=2, level=1)
status = main(["solve", "thesis-3.46-coulomb", "--level", "1", "--out", sys.argv[2]])
figures = main(["figures", "--only", "tab_3_1", "--max-level", "2", "--workers", "2",
                "--out", sys.argv[2] + "-f"])
in_process = main(["figures", "--only", "tab_3_1", "--max-level", "2", "--out", sys.argv[2] + "-t"])
loaded = sorted({m.partition(".")[0] for m in sys.modules} & BLOCKED)
print(json.dumps({"converged": bool(solution.converged), "steps": len(history),
                  "elements": [r["elements"] for r in history], "cli": status,
                  "figures": figures, "in_process": in_process, "loaded": loaded}))
"""


def run_without(blocked: list[str], script: str, cwd: Path) -> subprocess.CompletedProcess:
    """``script`` in a fresh interpreter with the ``blocked`` packages uninstalled."""
    return subprocess.run([sys.executable, "-c", script, json.dumps(blocked), str(cwd / "out")],
                          capture_output=True, text=True, cwd=cwd, timeout=600,
                          env={**os.environ, "MPLBACKEND": "Agg"})


@pytest.fixture(scope="module")
def blocked():
    names = blocked_modules()
    assert {"dask", "distributed", "pymetis", "jupytext", "sphinx", "selenium",
            "hypothesis"} <= set(names), names
    return names


def test_the_extras_packages_are_not_in_install_requires(blocked):
    core, _ = requirements()
    core_names = {canonicalize_name(Requirement(r).name) for r in core}
    assert not core_names & {"dask", "distributed", "pymetis", "clarabel", "jupytext"}
    assert "clarabel" in closure(core)       # the QP solver the solvers name comes with cvxpy
    assert {"ngsolve", "netgen-mesher", "numpy", "scipy", "cvxpy", "cvxopt",
            "matplotlib"} <= core_names


def test_ngdual_and_its_pipeline_import_with_the_extras_uninstalled(blocked, tmp_path):
    run = run_without(blocked, IMPORTS, tmp_path)
    assert run.returncode == 0, run.stderr[-3000:]
    assert json.loads(run.stdout.strip().splitlines()[-1]) == []


@pytest.mark.slow
def test_solve_adapt_and_the_cli_solve_run_with_the_extras_uninstalled(blocked, tmp_path):
    run = run_without(blocked, RUNS, tmp_path)
    assert run.returncode == 0, run.stderr[-3000:]
    result = json.loads(run.stdout.strip().splitlines()[-1])
    assert result["converged"] and result["steps"] == 2 and result["cli"] == 0, result
    assert result["elements"][1] > result["elements"][0]          # the mesh was refined
    assert result["loaded"] == []
    assert (tmp_path / "out" / "result.json").is_file()
    # a study names the extra it needs, as bad input rather than as a bug
    assert result["figures"] == EXIT_BAD_INPUT
    assert 'pip install "ngdual[studies]"' in run.stderr
    assert result["in_process"] == 0 and (tmp_path / "out-t" / "index.md").is_file()
    assert "run one after another in this process" in run.stderr
    assert not (tmp_path / "out-f").exists()


def test_a_missing_extra_is_named_with_its_install_command():
    with pytest.raises(MissingExtraError, match=r'pip install "ngdual\[studies\]"'):
        require("ngdual_no_such_package", "studies")
