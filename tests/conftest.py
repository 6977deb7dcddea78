"""Test-suite set-up: pictures without a display, and the two tiers named in the summary.

``python -m pytest -q`` runs the fast tier: setup.cfg's ``addopts`` deselect the tests
marked ``slow`` (the full tier, what CI runs with ``-m "not long"``) and ``long`` (never in
CI). When that default selection leaves tests out, the summary says how to run them.
"""

import matplotlib

matplotlib.use("Agg")

FULL_TIER = 'python -m pytest -q -m "not long"'


def default_markexpr(config) -> str | None:
    """The ``-m`` expression of setup.cfg's addopts: the fast tier's selection."""
    args = config.getini("addopts")  # already split as a shell would
    return next((b for a, b in zip(args, args[1:]) if a == "-m"), None)


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    deselected = len(terminalreporter.stats.get("deselected", []))
    if deselected and config.getoption("markexpr") == default_markexpr(config):
        terminalreporter.write_line(
            f"fast tier: {deselected} tests marked slow or long were not run; the full suite "
            f"as CI runs it: {FULL_TIER}")
