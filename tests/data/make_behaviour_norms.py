"""Write ``behaviour_norms.json``: the result.json norms of every shipped scene, levels 1-4.

Computed once, before the layout work of issue 16, and stored; ``tests/test_behaviour_unchanged.py``
compares every later version of the code against it (to 1e-10). Re-run only when a change of the
numerics is intended, and say so in the commit.
"""

import json
import subprocess
from pathlib import Path

from ngdual.io import versions
from ngdual.quantities import norms
from ngdual.scene import load_scene, shipped_scenes
from ngdual.solvers import solve_scene

LEVELS = (1, 2, 3, 4)


def main() -> None:
    commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                            cwd=Path(__file__).parent).stdout.strip()
    out = {"commit": commit, "versions": versions(), "norms": {}}
    for name in shipped_scenes():
        for level in LEVELS:
            solution = solve_scene(load_scene(name), level)
            out["norms"][f"{name}@{level}"] = norms(solution)
            print(name, level, out["norms"][f"{name}@{level}"], flush=True)
    path = Path(__file__).with_name("behaviour_norms.json")
    path.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
