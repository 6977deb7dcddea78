"""Every tutorial and solution uses the public API only: ``import ngdual as nd``.

A student reads the tutorials with ``import ngdual as nd``, NumPy, matplotlib and NGSolve's
own drawing (``ngsolve.webgui``, ``netgen.webgui``) and nothing else: no ``from
ngdual.<module> import ...``, no ``nd.<name>`` outside ``nd.__all__``, no other package,
not even of the standard library (what a tutorial needs beyond NumPy, ngdual offers). The
files are parsed, not run (that is ``test_tutorials.py``), so this answers in a second.
"""

import ast
from pathlib import Path

import pytest

import ngdual as nd

TUTORIALS = Path(__file__).resolve().parents[1] / "tutorials"
FILES = sorted(TUTORIALS.glob("[0-9][0-9]_*.py")) + sorted(
    (TUTORIALS / "solutions").glob("[0-9][0-9]_*.py"))
# NumPy and matplotlib with their submodules, NGSolve's drawing in a notebook
ALLOWED = ("numpy", "matplotlib", "ngsolve.webgui", "netgen.webgui", "__future__")


def allowed(module: str) -> bool:
    """Whether ``module`` is one of :data:`ALLOWED` or a submodule of one."""
    return any(module == name or module.startswith(f"{name}.") for name in ALLOWED)


def foreign_imports(tree: ast.AST) -> list[str]:
    """The imports of ``tree`` other than ``import ngdual as nd`` and :data:`ALLOWED`, as
    ``line: statement``."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules = [(alias.name, alias.asname) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            modules = [(("." * node.level) + (node.module or ""), None)]
        else:
            continue
        for module, asname in modules:
            if module == "ngdual" and isinstance(node, ast.Import) and asname == "nd":
                continue
            if allowed(module):
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


def name_of(path: Path) -> str:
    return path.relative_to(TUTORIALS).as_posix()


@pytest.mark.parametrize("path", FILES, ids=name_of)
def test_a_tutorial_imports_only_ngdual_as_nd_numpy_matplotlib_and_ngsolve_drawing(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    assert foreign_imports(tree) == [], path.name
    assert private_names(tree) == [], path.name


def test_the_check_finds_an_internal_import_and_an_internal_name():
    tree = ast.parse("import ngdual as nd\nfrom ngdual.mesh import build_mesh\n"
                     "import ngdual.forms\nfrom ngdual import post\nimport pandas\n"
                     "import numpy as np\nimport json\nnd.peers.STRESS\nnd.solve\n")
    assert foreign_imports(tree) == ["2: from ngdual.mesh import build_mesh",
                                     "3: import ngdual.forms", "4: from ngdual import post",
                                     "5: import pandas", "7: import json"]
    assert private_names(tree) == ["8: nd.peers"]


def test_the_check_refuses_scipy_cvxpy_and_ngsolve_but_not_its_drawing():
    tree = ast.parse("import scipy.sparse.linalg as spla\nimport cvxpy as cp\n"
                     "import ngsolve as ngs\nfrom ngsolve import CF\n"
                     "from ngsolve.webgui import Draw\nfrom netgen.webgui import Draw\n"
                     "import matplotlib.pyplot as plt\nfrom matplotlib.colors import LogNorm\n"
                     "from __future__ import annotations\nimport numpyx\n")
    assert foreign_imports(tree) == ["1: import scipy.sparse.linalg as spla",
                                     "2: import cvxpy as cp", "3: import ngsolve as ngs",
                                     "4: from ngsolve import CF", "10: import numpyx"]
