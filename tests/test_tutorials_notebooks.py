"""The tutorials as notebooks and as scripts with the core install alone.

``ngdual tutorials --notebooks DIR`` writes valid nbformat-4 notebooks without jupytext (the
percent-format scripts are read by :func:`ngdual.studies.tutorials.percent_cells`, whose cells
are checked against jupytext's own reading where it is installed); ``ngdual tutorials run
NAME`` runs one headless and lists the files it wrote; ``Lesson.draw`` leaves a PNG in a
script; every tutorial states its run time at its top.
"""

import json
import re
import subprocess
import sys

import ngsolve as ngs
import pytest
from netgen.geom2d import unit_square
from test_core_dependencies import UNINSTALL

from ngdual.cli import main
from ngdual.studies.tutorials import Lesson, list_tutorials, percent_cells

TUTORIALS = list_tutorials()
EVERY_FILE = TUTORIALS + list_tutorials(solutions=True)
RUN_TIME = re.compile(r"\*\*Run time\*\* on a 2-core laptop: about \d+ (s|min)")

WRITE_WITHOUT_EXTRAS = UNINSTALL + r"""
from ngdual.cli import main
sys.exit(main(["tutorials", "--notebooks", sys.argv[2], "--solutions"]))
"""


def test_notebooks_are_written_with_the_core_install_and_are_valid_nbformat(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    from test_core_dependencies import blocked_modules  # the extras' packages, uninstalled

    blocked = blocked_modules()
    assert {"jupytext", "nbformat"} <= set(blocked)
    run = subprocess.run([sys.executable, "-c", WRITE_WITHOUT_EXTRAS, json.dumps(blocked),
                          str(tmp_path)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    written = sorted(tmp_path.glob("*.ipynb")) + sorted(tmp_path.glob("solutions/*.ipynb"))
    assert [p.stem for p in written] == [t.name for t in EVERY_FILE]
    for path in written:
        notebook = nbformat.read(path, as_version=4)
        nbformat.validate(notebook)
        assert notebook.metadata.kernelspec.name == "python3"
        assert notebook.cells[0].cell_type == "markdown"
        assert notebook.cells[0].source.startswith("# ")                 # the title
        assert all(cell.execution_count is None for cell in notebook.cells
                   if cell.cell_type == "code")


@pytest.mark.parametrize("item", EVERY_FILE, ids=lambda t: t.name)
def test_cells_are_those_jupytext_reads(item):
    jupytext = pytest.importorskip("jupytext")
    theirs = [(c.cell_type, c.source.strip("\n"))
              for c in jupytext.read(item.path, fmt="py:percent").cells if c.source.strip()]
    assert percent_cells(item.path.read_text("utf-8")) == theirs


@pytest.mark.parametrize("item", TUTORIALS, ids=lambda t: t.name)
def test_every_tutorial_states_its_run_time_at_its_top(item):
    title = percent_cells(item.path.read_text("utf-8"))[0][1]
    assert RUN_TIME.search(title), title[:400]


def test_tutorials_run_runs_one_headless_and_lists_the_files_it_wrote(tmp_path, capfd):
    out = tmp_path / "out"
    assert main(["tutorials", "run", "01", "--quick", "--out", str(out)]) == 0
    printed = capfd.readouterr().out                     # the tutorial's output, then the list
    listed = printed.split("01_peers_spaces wrote ")[-1].splitlines()[1:]
    listed = [line.strip() for line in listed]
    results = out / "01_peers_spaces" / "results.json"
    assert str(results) in listed and any(p.endswith(".png") for p in listed)
    assert sorted(listed) == sorted(str(p) for p in out.rglob("*") if p.is_file())
    dofs = {row["level"]: (row["X"], row["M"], row["S"])
            for row in json.loads(results.read_text())["dofs"]}
    assert dofs[1] == (180, 64, 27)                                      # Table 3.1


def test_tutorials_run_reports_a_failing_tutorial_and_an_unknown_name(tmp_path, capfd):
    (tmp_path / "01_broken.py").write_text("# %% [markdown]\n# # Broken\n\n# %%\n"
                                           "raise SystemExit(7)\n")
    assert main(["tutorials", "run", "broken", "--source", str(tmp_path), "--out",
                 str(tmp_path / "out")]) == 1
    assert "tutorial 01_broken failed with exit status 7" in capfd.readouterr().err
    assert main(["tutorials", "run", "no_such", "--source", str(tmp_path)]) == 2
    err = capfd.readouterr().err
    assert err.startswith("ngdual: error: NAME: unknown tutorial 'no_such'") and "01_broken" in err


def test_draw_leaves_a_png_in_a_script(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("NGDUAL_TUTORIAL_OUT", str(tmp_path))
    lesson = Lesson("draw")
    mesh = ngs.Mesh(unit_square.GenerateMesh(maxh=0.5))
    path = lesson.draw(ngs.x * ngs.y, mesh, "field")
    assert path == tmp_path / "draw" / "field.png" and path.read_bytes()[:4] == b"\x89PNG"
    assert "a notebook shows it with NGSolve's interactive Draw" in capsys.readouterr().out
    import matplotlib.pyplot as plt

    saved = lesson.save(plt.figure(), "vector")
    stamp = saved.stat().st_mtime_ns
    assert lesson.draw(ngs.CF((ngs.x, ngs.y)), mesh, "vector") == saved  # its own picture
    assert saved.stat().st_mtime_ns == stamp
