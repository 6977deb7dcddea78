"""Write ``behaviour_norms.json``: the result.json norms of every shipped scene, levels 1-4.

``tests/test_behaviour_unchanged.py`` compares every later version of the code against these
numbers. Re-make a scene only when a change of its numerics is intended, and say so in the
commit; the other scenes keep their numbers and the record of how they were made.

    python tests/data/make_behaviour_norms.py                      # every shipped scene
    python tests/data/make_behaviour_norms.py --scenes hertz-cylinder wedge

For each scene the file records under ``made`` the commit it was computed at, the files of
``ngdual/`` that differed from that commit (``modified``: if any, the commit alone does not
reproduce the numbers; null: not recorded) and the versions of Python, the platform and
the packages. It prints, per re-made scene, the largest relative change of each norm over
the levels, the number a commit that changes the numerics states.
"""

import argparse
import json
import subprocess
from pathlib import Path

from ngdual.io import versions
from ngdual.quantities import norms
from ngdual.scene import load_scene, shipped_scenes
from ngdual.solvers import solve_scene

LEVELS = (1, 2, 3, 4)
PATH = Path(__file__).with_name("behaviour_norms.json")
ROOT = Path(__file__).resolve().parents[2]


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], capture_output=True, text=True, check=True,
                          cwd=ROOT).stdout.strip()


def provenance() -> dict:
    """The commit, the files of ``ngdual/`` that differ from it, and the package versions."""
    changed = (_git("diff", "--name-only", "HEAD", "--", "ngdual").split()
               + _git("ls-files", "--others", "--exclude-standard", "--", "ngdual").split())
    return {"commit": _git("rev-parse", "HEAD"), "modified": sorted(set(changed)),
            "versions": versions()}


def scene_norms(name: str) -> dict:
    """``{"name@level": norms}`` of ``name`` on every level of ``LEVELS``."""
    return {f"{name}@{level}": norms(solve_scene(load_scene(name), level))
            for level in LEVELS}


def update(stored: dict, names: list[str], made: dict) -> dict:
    """``stored`` with the norms of ``names`` replaced (their old levels dropped first)."""
    out = {"norms": dict(stored.get("norms", {})), "made": dict(stored.get("made", {}))}
    for name in names:
        out["norms"] = {case: value for case, value in out["norms"].items()
                        if case.rsplit("@", 1)[0] != name}
        out["norms"].update(scene_norms(name))
        out["made"][name] = made
    return out


def largest_changes(old: dict, new: dict, name: str) -> dict:
    """Per norm, the largest relative change from ``old`` to ``new`` over the levels of ``name``.

    A norm that is zero (or None) in both counts as unchanged; a norm that appears or
    vanishes as an infinite change.
    """
    out: dict[str, float] = {}
    for case, values in new.items():
        if case.rsplit("@", 1)[0] != name or case not in old:
            continue
        for key, value in values.items():
            before = old[case].get(key)
            if before == value:
                change = 0.0
            elif not before or value is None:
                change = float("inf")
            else:
                change = abs(value - before) / abs(before)
            out[key] = max(out.get(key, 0.0), change)
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", metavar="NAME", choices=shipped_scenes(),
                        help="re-make only these shipped scenes (default: all)")
    args = parser.parse_args(argv)
    stored = json.loads(PATH.read_text()) if PATH.exists() else {}
    out = update(stored, args.scenes or shipped_scenes(), provenance())
    PATH.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    for name in args.scenes or shipped_scenes():
        changes = largest_changes(stored.get("norms", {}), out["norms"], name)
        print(name, " ".join(f"{key}={change:.1e}" for key, change in sorted(changes.items())))


if __name__ == "__main__":
    main()
