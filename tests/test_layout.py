"""The layout shows the architecture: data flows one way through the pipeline.

scene -> mesh -> spaces (PEERS, boundary meshes, Gamma_C) -> forms -> what a solver returns
(``Solution``) -> solvers -> the fields and
norms of a solution -> estimator ->
marking -> adaptive loop -> post-processing -> verification; run machinery (studies, CLI)
only calls the pipeline. Every import inside ``ngdual/`` (also those inside functions) is
read from the source; a module may import its own stage or earlier ones, never a later one.
"""

import ast
import re
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "ngdual"

# (stage, module prefixes), in the order the data flows
STAGES = [
    ("foundation", ["expr", "extras", "geometry", "tolerances", "rates", "sparse",
                    "loop_defaults"]),
    ("scene", ["scene", "scenes"]),
    ("mesh", ["mesh", "io"]),
    ("spaces", ["peers", "boundary", "contact"]),
    ("forms", ["forms", "friction", "quadrature_check"]),
    # the size of a run: the mesh of a level and the unknowns of the spaces' variant
    ("budget", ["budget"]),
    ("solution", ["solution"]),
    ("solvers", ["solvers", "checks"]),
    ("quantities", ["quantities", "trace"]),
    ("estimator", ["estimator", "goal"]),
    ("marking", ["marking"]),
    ("afem", ["afem", "accuracy"]),
    ("post", ["post", "summary", "plot"]),
    ("verification", ["verification"]),
    ("run machinery", ["studies", "cli", "__main__"]),
]


def stage_of(module: str) -> int:
    """Index in STAGES of ``ngdual.<module>`` (dotted, without the package name)."""
    head = module.split(".")[0]
    for index, (_, prefixes) in enumerate(STAGES):
        if head in prefixes:
            return index
    raise LookupError(module)


def modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if parts:
            out[".".join(parts)] = path
    return out


def imported(module: str, path: Path) -> set[str]:
    """The ngdual modules ``module`` imports (relative imports resolved)."""
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
                if not target.startswith("ngdual"):
                    continue
                target = target[len("ngdual"):].lstrip(".")
            # "from . import x" names a module x; "from .m import f" names m
            names = [f"{target}.{a.name}".strip(".") if not node.module else target
                     for a in node.names]
        else:
            continue
        for name in names:
            if name.startswith("ngdual"):
                name = name[len("ngdual"):].lstrip(".")
            if name:
                found.add(name)
    return found


def test_every_module_of_ngdual_has_a_place_in_the_data_flow():
    unplaced = []
    for module in modules():
        try:
            stage_of(module)
        except LookupError:
            unplaced.append(module)
    assert not unplaced, f"modules without a stage in tests/test_layout.py: {unplaced}"


@pytest.mark.parametrize("module", sorted(modules()))
def test_no_module_reaches_back_up_the_data_flow(module):
    path = modules()[module]
    own = stage_of(module)
    later = {name: STAGES[stage_of(name)][0] for name in imported(module, path)
             if name.split(".")[0] in {p for _, ps in STAGES for p in ps}
             and stage_of(name) > own}
    assert not later, (f"ngdual.{module} ({STAGES[own][0]}) imports later stages: {later}")


def test_no_solver_reads_the_scene():
    """Solvers receive explicit settings: ``problem.scene`` appears in no solver
    module except the dispatch that builds the settings from it."""
    readers = [p.name for p in (PACKAGE / "solvers").glob("*.py")
               if p.name not in ("dispatch.py", "settings.py") and ".scene" in p.read_text()]
    assert not readers, readers


# where the multiplier family is a name: the scene that states it, the module that builds the
# spaces from it, the boundary meshes themselves and Gamma_C's gap interpolation per mesh
FAMILY_READERS = ("scene/", "forms/spaces.py", "boundary/", "contact.py", "studies/",
                  "peers.py")
FAMILY_QUESTION = re.compile(r"family\s*[!=]=|isinstance\([^)]*(FacetMesh|CoarseOrderMesh|"
                             r"CoarseMesh)\b")


def test_no_module_asks_which_multiplier_family_it_runs_on():
    """One method, configured (STYLE.md): the order and the multiplier family are read where
    the spaces are built; the rest of the code asks the multiplier space what it is
    (``traces``, ``curve_normal``), never which family it is."""
    asking = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.startswith(FAMILY_READERS):
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split("#")[0]
            if FAMILY_QUESTION.search(code):
                asking.append(f"{rel}:{number}: {line.strip()}")
    assert not asking, asking


# where the order k and the multiplier family are read from the scene: the scene that states
# and validates them and the module that builds the spaces from them
DISCRETISATION_READERS = ("scene/", "forms/spaces.py")
DISCRETISATION_FIELDS = {"order", "family", "multipliers"}


def discretisation_reads(tree: ast.AST) -> list[int]:
    """Lines of ``tree`` that read ``<x>.discretisation.order`` (``.family``,
    ``.multipliers``), directly or through a name bound to ``<x>.discretisation``."""
    def is_discretisation(node):
        return isinstance(node, ast.Attribute) and node.attr == "discretisation"

    bound = {target.id for node in ast.walk(tree)
             if isinstance(node, (ast.Assign, ast.AnnAssign)) and is_discretisation(node.value)
             for target in (node.targets if isinstance(node, ast.Assign) else [node.target])
             if isinstance(target, ast.Name)}
    return sorted(node.lineno for node in ast.walk(tree)
                  if isinstance(node, ast.Attribute) and node.attr in DISCRETISATION_FIELDS
                  and (is_discretisation(node.value)
                       or isinstance(node.value, ast.Name) and node.value.id in bound))


def test_the_order_and_the_multiplier_family_are_read_where_the_spaces_are_built():
    """One method, configured (STYLE.md): ``[discretisation]`` is read by
    :func:`ngdual.forms.spaces.variant_of`; the rest of the code asks the variant or the
    spaces (``spaces.order``, ``spaces.family``)."""
    reading = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.startswith(DISCRETISATION_READERS):
            continue
        reading += [f"{rel}:{line}" for line in discretisation_reads(ast.parse(path.read_text()))]
    assert not reading, reading


def test_the_check_finds_a_direct_and_a_named_read_of_the_discretisation():
    tree = ast.parse("k = scene.discretisation.order\n"
                     "disc = pb.scene.discretisation\n"
                     "f(disc.family, disc.multipliers)\n"
                     "spaces.order, variant.family, other.order\n"
                     "replace(scene.discretisation, order=1)\n")
    assert discretisation_reads(tree) == [1, 3, 3]
