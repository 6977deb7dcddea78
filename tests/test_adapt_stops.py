"""The adaptive loop's ends that are not its goal's: the memory and a window without contact.

A tolerance run that would outgrow the machine stops before the refinement that would not
fit (``stopped_by = "memory"``, history.json kept, exit status 5, not the bad-input 2); a
MemoryError of a later solve is recorded the same way; a pressure goal's window without
contact is answered on the first solve (``"no_contact"``), naming where the contact is.
The memory is made small by monkeypatching :func:`ngdual.budget.available_memory`.
"""

import json
import re
import warnings

import pytest

from ngdual import budget
from ngdual.afem import AdaptWarning, ToleranceWarning, adapt, loop
from ngdual.cli import main
from ngdual.cli.pipeline import EXIT_MEMORY
from ngdual.scene import load_scene

# hertz-cylinder's contact half-width (docs/theory/estimator.md: the overkill's ellipse)
HERTZ_HALF_WIDTH = 0.3407


@pytest.fixture(scope="module")
def hertz():
    return load_scene("hertz-cylinder")


@pytest.fixture
def small_memory(monkeypatch):
    """Memory for the solve of about 2000 triangles at order 0: hertz-cylinder's level 1
    fits, its pressure goal's third or fourth refinement does not."""
    have = budget.solve_memory(2000)
    monkeypatch.setattr(budget, "available_memory", lambda: have)
    return have


def test_a_tolerance_run_stops_before_the_refinement_that_would_not_fit(hertz, small_memory):
    with pytest.warns(ToleranceWarning, match=r"above tol = 1e-06: the next refinement would "
                                              r"have about"):
        history = adapt(hertz, goal="pressure", tol=1e-6)
    last = history[-1]
    assert last["stopped_by"] == "memory" and last["marked"] == 0   # nothing refined
    assert all("stopped_by" not in r for r in history[:-1])
    assert 2 <= len(history) < 10
    # every mesh solved fit, and the refinement refused would not have
    assert all(budget.solve_memory(r["elements"]) <= small_memory for r in history)
    message = last["stop_message"]
    need = float(re.search(r"need about ([\d.e+-]+) GiB", message).group(1)) * 2**30
    assert need > small_memory
    assert "times tol = 1e-06" in message and f"{last['relative_estimate']:.3g}" in message
    assert "a looser tol, a higher order" in message and "allow_large=True" in message
    # allow_large refines on
    with pytest.warns(ToleranceWarning, match="steps are spent"):
        more = adapt(hertz, goal="pressure", tol=1e-6, steps=len(history) + 1,
                     allow_large=True)
    assert len(more) == len(history) + 1 and more[-1]["stopped_by"] == "steps"


def test_ngdual_adapt_stopped_by_the_memory_keeps_history_and_exits_with_its_own_status(
        tmp_path, capsys, small_memory):
    status = main(["adapt", "hertz-cylinder", "--goal", "pressure", "--tol", "1e-6",
                   "--out", str(tmp_path)])
    assert status == EXIT_MEMORY and status not in (0, 1, 2, 3, 4)
    out, err = capsys.readouterr()
    assert "(stopped by memory)" in out and "ngdual: stopped by memory: the next refinement" in err
    assert "ToleranceWarning" not in err and "out of memory; choose a coarser" not in err
    run = json.loads((tmp_path / "history.json").read_text())
    assert run["history"][-1]["stopped_by"] == "memory"
    assert len(list(tmp_path.glob("mesh_step*.vol"))) == len(run["history"])


def test_a_memory_error_of_a_later_solve_ends_the_loop_and_is_recorded(hertz, monkeypatch,
                                                                       tmp_path, capsys):
    solve = loop.solve_on_mesh
    calls = []

    def second_solve_fails(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise MemoryError
        return solve(*args, **kwargs)

    monkeypatch.setattr(loop, "solve_on_mesh", second_solve_fails)
    with pytest.warns(AdaptWarning, match="ran out of memory"):
        history = adapt(hertz, goal="pressure", steps=3)
    assert len(history) == 1 and history[0]["stopped_by"] == "memory"
    assert "the solve of step 1" in history[0]["stop_message"]
    calls.clear()
    assert main(["adapt", "hertz-cylinder", "--steps", "3", "--out", str(tmp_path)]) \
        == EXIT_MEMORY
    run = json.loads((tmp_path / "history.json").read_text())
    assert run["history"][-1]["stopped_by"] == "memory"
    assert "ran out of memory (MemoryError)" in capsys.readouterr().err


def test_a_memory_error_of_the_first_solve_is_raised_and_ngdual_adapt_records_it(
        hertz, monkeypatch, tmp_path, capsys):
    def no_memory(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(loop, "solve_on_mesh", no_memory)
    with pytest.raises(MemoryError):
        adapt(hertz, steps=2)
    assert main(["adapt", "hertz-cylinder", "--out", str(tmp_path)]) == EXIT_MEMORY
    run = json.loads((tmp_path / "history.json").read_text())
    assert run["stopped_by"] == "memory" and run["history"] == []
    assert "initial mesh" in capsys.readouterr().err


@pytest.mark.parametrize("order", [0, 1])
def test_a_window_without_contact_is_answered_on_the_first_solve(order):
    """hertz-cylinder's contact zone is |x| < 0.34: a window at 2 <= x <= 3 holds round-off
    pressure only (at order 1 about 1e-13 of p_h on Gamma_C, whose relative estimate
    then read 1e9 and stalled after 9 solves). The first solve stops as "no_contact",
    naming the window and a contact zone that holds the true one."""
    scene = load_scene("hertz-cylinder", [f"discretisation.order={order}"])
    with pytest.warns(ToleranceWarning, match=r"no contact in the window 2 <= x <= 3"):
        history = adapt(scene, goal="pressure", tol=0.01, window=(2.0, 3.0))
    assert len(history) == 1 and history[0]["stopped_by"] == "no_contact"
    lo, hi = map(float, re.search(r"the contact zone lies in (\S+) <= x <= (\S+);",
                                  history[0]["stop_message"]).groups())
    assert lo < -0.5 * HERTZ_HALF_WIDTH and 0.5 * HERTZ_HALF_WIDTH < hi < 2.0
    with pytest.warns(AdaptWarning, match="no contact in the window"):
        assert len(adapt(scene, goal="pressure", window=(2.0, 3.0))) == 1


def test_a_window_inside_the_contact_zone_runs_its_steps_quietly(hertz):
    with warnings.catch_warnings():
        warnings.simplefilter("error", AdaptWarning)
        history = adapt(hertz, goal="pressure", steps=2, window=(-0.1, 0.1))
    assert [r.get("stopped_by") for r in history] == [None, "steps"]


def test_ngdual_adapt_with_a_window_without_contact_exits_1_after_one_solve(tmp_path, capsys):
    assert main(["adapt", "hertz-cylinder", "--goal", "pressure", "--window", "2", "3",
                 "--out", str(tmp_path)]) == 1
    out, err = capsys.readouterr()
    assert "(stopped by no_contact)" in out and "the contact zone lies in" in err
    run = json.loads((tmp_path / "history.json").read_text())
    assert len(run["history"]) == 1 and run["history"][0]["stopped_by"] == "no_contact"
