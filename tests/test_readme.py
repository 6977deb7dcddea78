"""The README is a quick start: what ngdual is first, the two commands, where to go next.

It opens with one sentence on what ngdual is, then exactly two commands (the main job and
the full test suite as CI runs it), the fast tier right below them, and stays within 150
lines; every file it links exists in the checkout.
"""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
COMMANDS = ['pip install -e . && ngdual solve hertz-cylinder --out out/hertz',
            'pip install -e ".[test,docs]" && python -m pytest -q -m "not long"']


def test_the_readme_is_a_quick_start_of_at_most_150_lines():
    assert len(README.splitlines()) <= 150


def test_the_readme_says_what_ngdual_is_before_its_two_commands():
    before, block = README.split("```bash\n", 1)
    assert "contact" in before and "elasticity" in before and "NGSolve" in before
    assert block.split("```", 1)[0].strip().splitlines() == COMMANDS
    assert "`python -m pytest -q`" in block.split("```", 2)[1]    # the fast tier, below


def test_every_file_the_readme_links_exists():
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", README)
    local = [link for link in links if "://" not in link]
    assert len(local) > 10
    missing = [link for link in local if not (ROOT / link).exists()]
    assert not missing, missing
