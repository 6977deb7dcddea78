"""Every tutorial and solution uses the public API only: ``import ngdual as nd``.

A student reads the tutorials with ``import ngdual as nd``, NumPy, matplotlib and NGSolve
(its drawing, its coefficient functions) and nothing else: no ``from ngdual.<module>
import ...``, no ``nd.<name>`` outside ``nd.__all__``, no other third-party package
(SciPy and cvxpy, core dependencies, where a tutorial writes an algorithm by hand). The
files are parsed, not run (that is ``test_tutorials.py``), so this answers in a second.
"""

import ast
import sys
from pathlib import Path

import pytest

import ngdual as nd

TUTORIALS = Path(__file__).resolve().parents[1] / "tutorials"
FILES = sorted(TUTORIALS.glob("[0-9][0-9]_*.py")) + sorted(
    (TUTORIALS / "solutions").glob("[0-9][0-9]_*.py"))
# NumPy, matplotlib, NGSolve; SciPy's sparse LU and cvxpy's QP modelling where a tutorial
# writes an algorithm of the thesis by hand (core dependencies, install_requires)
THIRD_PARTY = {"numpy", "matplotlib", "ngsolve", "netgen", "scipy", "cvxpy"}


def foreign_imports(tree: ast.AST) -> list[str]:
    """The imports of ``tree`` other than ``import ngdual as nd``, the standard library and
    :data:`THIRD_PARTY`, as ``line: statement``."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules = [(alias.name, alias.asname) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            modules = [(("." * node.level) + (node.module or ""), None)]
        else:
            continue
        for module, asname in modules:
            top = module.split(".")[0]
            if module == "ngdual" and isinstance(node, ast.Import) and asname == "nd":
                continue
            if top != "ngdual" and (top in THIRD_PARTY or top in sys.stdlib_module_names):
                continue
            found.append(f"{node.lineno}: {ast.unparse(node)}")
    return found


def private_names(tree: ast.AST) -> list[str]:
    """The ``nd.<name>`` of ``tree`` that are not in ``nd.__all__`` (``nd.peers``, say)."""
    return [f"{node.lineno}: nd.{node.attr}" for node in ast.walk(tree)
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
            and node.value.id == "nd" and node.attr not in nd.__all__]


def test_there_are_tutorials_and_solutions_to_check():
    assert len(FILES) >= 20 and any(path.parent.name == "solutions" for path in FILES)


@pytest.mark.parametrize("path", FILES, ids=lambda path: path.name)
def test_a_tutorial_imports_only_ngdual_as_nd_numpy_matplotlib_and_ngsolve(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    assert foreign_imports(tree) == [], path.name
    assert private_names(tree) == [], path.name


def test_the_check_finds_an_internal_import_and_an_internal_name():
    tree = ast.parse("import ngdual as nd\nfrom ngdual.mesh import build_mesh\n"
                     "import ngdual.forms\nfrom ngdual import post\nimport pandas\n"
                     "import numpy as np\nimport json\nnd.peers.STRESS\nnd.solve\n")
    assert foreign_imports(tree) == ["2: from ngdual.mesh import build_mesh",
                                     "3: import ngdual.forms", "4: from ngdual import post",
                                     "5: import pandas"]
    assert private_names(tree) == ["8: nd.peers"]
