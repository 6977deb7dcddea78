"""Hard and bad inputs found by trying to break ngdual: each a clear error or a right answer.

The command line answers bad input with exit status 2, one line naming the field or flag
and nothing written; the Python API with a TypeError or ValueError (``SceneTypeError``,
``SceneError``) that names the argument and says what it should be. A run that would not
fit in the memory this process may use (the machine's, ``ulimit -v``, the cgroup's) stops
before it starts, or, in the adaptive loop, before the refinement that would not fit,
keeping the history of the steps before.
"""

import json
import os
import resource
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ngdual as nd
from ngdual import budget, cli
from ngdual.cli.pipeline import EXIT_MEMORY
from ngdual.mesh import polygon_mesh
from ngdual.scene import Geometry, SceneError, SceneTypeError

GIB = 2**30


def run_cli(argv, capsys):
    """Exit status and the lines on stderr of ``ngdual argv``."""
    status = cli.main(argv)
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err + captured.out
    return status, captured.err.strip().splitlines()


# ---------------------------------------------------------------- scenes netgen cannot mesh

@pytest.mark.parametrize("override, field, words", [
    # a radius of 1e12 puts the arc's points 4e-4 off in double precision: straight
    ("geometry.arcs={ bottom = [0.0, 1e12] }", "geometry.arcs.bottom", "straight side"),
    # the graded strip along the bottom alone needs 1e10 triangles
    ("geometry.side_maxh={ bottom = 1e-6 }", "geometry.side_maxh.bottom", "larger side_maxh"),
    ("geometry.maxh=1e-4", "geometry.maxh", "larger maxh"),
])
def test_a_geometry_beyond_meshing_is_refused_naming_its_field(tmp_path, capsys, override,
                                                               field, words):
    out = tmp_path / "result"
    status, lines = run_cli(["solve", "hertz-cylinder", "--set", override, "--out", str(out),
                             "--no-plots"], capsys)
    assert status == 2
    assert len(lines) == 1 and lines[0].startswith(f"ngdual: error: {field}:"), lines
    assert words in lines[0]
    assert not out.exists()


def test_a_radius_the_scene_resolves_is_still_an_arc():
    """The arc check refuses what double precision cannot resolve, not large radii: a
    radius of 1e5 (1.2e4 times the block) bulges 8e-5 below the chord and is meshed."""
    scene = nd.load_scene("hertz-cylinder", ["geometry.arcs={ bottom = [0.0, 1e5] }"])
    assert nd.validate(scene) is None


def test_a_meshing_failure_names_the_geometry_fields():
    """Should a geometry reach netgen that it cannot mesh, the error names the geometry."""
    geo = nd.load_scene("hertz-cylinder").geometry
    with pytest.raises(SceneError) as err:  # validation refuses this arc: netgen is asked
        polygon_mesh(geo.points, geo.labels, geo.maxh, arcs={"bottom": [0.0, 1e12]},
                     side_maxh=geo.side_maxh)
    assert err.value.field == "geometry"
    assert "geometry.arcs" in str(err.value)


# ---------------------------------------------------------------- ngdual figures

@pytest.mark.parametrize("flags, flag, words", [
    (["--source", "/nonexistent"], "--source", "no figures folder"),
    (["--source", "{empty}"], "--source", "no figure scripts"),
    (["--only", "no_such_figure"], "--only", "'no_such_figure'"),
    (["--only", "fig_3_11", "no_such_figure"], "--only", "'no_such_figure'"),
])
def test_figures_refuses_an_unknown_source_or_name_creating_nothing(tmp_path, capsys, flags,
                                                                    flag, words):
    empty = tmp_path / "empty"
    empty.mkdir()
    out = tmp_path / "figures-out"
    argv = ["figures", *[f.replace("{empty}", str(empty)) for f in flags], "--out", str(out)]
    status, lines = run_cli(argv, capsys)
    assert status == 2
    assert len(lines) == 1 and lines[0].startswith(f"ngdual: error: {flag}:"), lines
    assert words in lines[0]
    assert not out.exists()


# ---------------------------------------------------------------- the Python API

@pytest.fixture(scope="module")
def without_contact():
    """Example 3.46 on level 1 with Gamma_C made a Neumann side: no contact boundary."""
    scene = nd.load_scene("thesis-3.46-frictionless", [
        "geometry.level=1", "boundary.contact=[]", 'boundary.neumann=["top", "bottom"]',
        "contact.gap='0'", "contact.ends='consistent'"])
    return nd.solve(scene)


API = [
    ("estimate-str", lambda s: nd.estimate("x"), SceneTypeError, "solution", "Solution"),
    ("estimate-asymmetry", lambda s: nd.estimate(s, 3), SceneTypeError, "asymmetry", "hdiv"),
    ("norms-none", lambda s: nd.norms(None), SceneTypeError, "solution", "Solution"),
    ("fields-str", lambda s: nd.fields("x"), SceneTypeError, "solution", "Solution"),
    ("mark-str", lambda s: nd.mark("abc", 0.5), SceneTypeError, "indicators", "indicators"),
    ("mark-2d", lambda s: nd.mark(np.ones((2, 2)), 0.5), SceneError, "indicators", "1D array"),
    ("mark-theta-str", lambda s: nd.mark([1.0], "half"), SceneTypeError, "theta", "[0, 1]"),
    ("mark-strategy", lambda s: nd.mark([1.0], 0.5, ["max"]), SceneError, "strategy",
     "dorfler"),
    ("force-balance-none", lambda s: nd.force_balance(None), SceneTypeError, "solution",
     "Solution"),
    ("force-balance-no-contact", lambda s: nd.force_balance(s), SceneError, "solution",
     "no contact boundary"),
    ("contact-traces-none", lambda s: nd.contact_traces(None), SceneTypeError, "solution",
     "Solution"),
    ("plot-contact-traces-none", lambda s: nd.plot_contact_traces(None), SceneTypeError,
     "traces", "contact_traces"),
]


@pytest.mark.parametrize("call, kind, argument, words", [c[1:] for c in API],
                         ids=[c[0] for c in API])
def test_a_wrong_argument_raises_naming_it_and_what_it_should_be(without_contact, call, kind,
                                                                 argument, words):
    with pytest.raises(kind) as err:
        call(without_contact)
    assert isinstance(err.value, (TypeError, ValueError))
    assert err.value.field == argument
    assert str(err.value).startswith(f"{argument}: ")
    assert words in str(err.value)


# ---------------------------------------------------------------- memory limits

def test_the_budget_is_the_smallest_of_the_machine_and_the_cgroup(tmp_path, monkeypatch):
    """A cgroup limit of 1.5 GiB with 1 GiB used by others leaves this process 0.5 GiB plus
    what it holds; without a limit ("max") the machine decides."""
    monkeypatch.setattr(budget, "CGROUP", tmp_path)
    resident, _ = budget._process_memory()
    (tmp_path / "memory.max").write_text(f"{int(1.5 * GIB)}\n")
    (tmp_path / "memory.current").write_text(f"{int(GIB + resident)}\n")
    assert budget.available_memory() == pytest.approx(0.5 * GIB, rel=0.05)
    assert "cgroup" in budget.describe_available()
    # a 1 GiB run is refused, naming the cgroup
    with pytest.raises(SceneError, match="cgroup") as err:
        budget.check(Geometry(), 6, "--level")
    assert err.value.field == "--level"
    (tmp_path / "memory.max").write_text("max\n")
    assert budget.available_memory() > 0.5 * GIB


@pytest.mark.skipif(not Path("/proc/meminfo").is_file(), reason="needs Linux")
def test_without_psutil_the_machine_memory_is_the_kernels_estimate(monkeypatch):
    psutil = pytest.importorskip("psutil")
    expected = psutil.virtual_memory().available
    monkeypatch.setitem(sys.modules, "psutil", None)  # the studies extra not installed
    assert budget._machine_available() == pytest.approx(expected, rel=0.2)


PRLIMIT = shutil.which("prlimit")
needs_prlimit = pytest.mark.skipif(PRLIMIT is None or not sys.platform.startswith("linux"),
                                   reason="needs Linux and prlimit")


@needs_prlimit
def test_the_budget_sees_the_address_space_limit():
    limit = 3 * GIB
    code = "from ngdual import budget; print(budget.available_memory())"
    run = subprocess.run([PRLIMIT, f"--as={limit}", sys.executable, "-c", code],
                         capture_output=True, text=True, check=True)
    assert 0 < float(run.stdout) < limit


@pytest.mark.slow
@needs_prlimit
def test_adapt_under_an_address_space_limit_stops_by_the_budget(tmp_path):
    """``ngdual adapt hertz-cylinder --steps 10000 --theta 0.9`` under ``prlimit --as``:
    each step about triples the mesh, and the loop must stop by the memory budget before the
    refinement that would not fit (``stopped_by = "memory"``, exit status 5), keeping the
    steps before in history.json.
    1.75 GiB leave about 0.6 GiB beside the address space NGSolve reserves: the budget
    stops after step 1 (4.4e4 unknowns, 10 s on a loaded machine); unchecked, the next
    assembly runs out of address space (exit 3, "thrown by allocate matrix"), or larger
    runs crash inside CHOLMOD."""
    if resource.getrlimit(resource.RLIMIT_AS)[0] != resource.RLIM_INFINITY:
        pytest.skip("already under an address-space limit")
    out = tmp_path / "adapt"
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    argv = [PRLIMIT, f"--as={int(1.75 * GIB)}", sys.executable, "-m", "ngdual", "adapt",
            "hertz-cylinder", "--steps", "10000", "--theta", "0.9", "--out", str(out)]
    run = subprocess.run(argv, capture_output=True, text=True, env=env, timeout=600)
    lines = run.stderr.strip().splitlines()
    assert "Traceback" not in run.stderr and "out of memory" not in run.stderr
    assert "GiB" in lines[-1]
    if run.returncode == 2:   # the first mesh alone would not fit: refused as bad input
        assert lines[-1].startswith("ngdual: error: --level:"), lines
        return
    assert run.returncode == EXIT_MEMORY, run.stderr[-2000:]
    assert lines[-1].startswith("ngdual: stopped by memory:"), lines
    history = json.loads((out / "history.json").read_text())["history"]
    assert 1 <= len(history) < 10000
    assert history[-1]["stopped_by"] == "memory"
    assert all(record["converged"] for record in history)
    assert len(list(Path(out).glob("mesh_step*.vol"))) == len(history)
