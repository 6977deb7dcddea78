"""Sphinx extension of the ngdual site: references generated from the code, offline MathJax.

Directives
----------
``ngdual-scene-reference``
    Every key of a scene file: one table per TOML section with the key, its type and
    default (read from the dataclasses of :mod:`ngdual.scene`, where the defaults live),
    the allowed values (the module's constants) and its meaning (:data:`MEANINGS`). A key
    without a meaning, or a meaning for a key the code does not have, stops the build.
``ngdual-cli-reference``
    Every subcommand and option of :func:`ngdual.cli.parser`, with defaults and help.
``ngdual-api-reference``
    An autodoc entry for every name of ``ngdual.__all__``.

Build steps
-----------
:func:`stage_tutorials` copies ``tutorials/NN_*.py`` into ``docs/tutorials`` (MyST-NB reads
them as notebooks and executes them); :func:`prepare_kernel_environment` sets the quick
mode and the tutorials' output folder for the kernels; after the build, the parts of
Debian's MathJax 2 that the pages load are copied into ``_static/mathjax``.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import re
import shutil
from pathlib import Path

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.errors import ExtensionError
from sphinx.util.docutils import SphinxDirective

QUICK_ENV = "NGDUAL_DOCS_QUICK"
ONLY_ENV = "NGDUAL_DOCS_TUTORIALS"   # e.g. "01,03": build only these tutorials (drafting)
TRUE_WORDS = ("1", "true", "yes", "on")
MATHJAX_SOURCE_ENV = "NGDUAL_MATHJAX_DIR"
MATHJAX_SOURCE = Path("/usr/share/javascript/mathjax")   # Debian: libjs-mathjax, fonts-mathjax
MATHJAX_PARTS = ("MathJax.js", "config/TeX-AMS_CHTML.js", "config/local", "extensions",
                 "jax/input/TeX", "jax/output/CommonHTML", "jax/element",
                 "fonts/HTML-CSS/TeX/woff", "fonts/HTML-CSS/TeX/otf")
MATHJAX_URL = "mathjax/MathJax.js?config=TeX-AMS_CHTML"
MATHJAX_CONFIG = {
    # MyST marks the pages tex2jax_ignore and the maths "math": only Sphinx's math nodes
    # (and notebook outputs) are typeset, never a stray dollar in the text
    "tex2jax": {"inlineMath": [["\\(", "\\)"]], "displayMath": [["\\[", "\\]"]],
                "processRefs": False, "processEnvironments": True,
                "ignoreClass": "tex2jax_ignore|mathjax_ignore",
                "processClass": "tex2jax_process|mathjax_process|math|output_area"},
    "TeX": {"equationNumbers": {"autoNumber": "none"}},
    "CommonHTML": {"linebreaks": {"automatic": True}},
    "messageStyle": "none",
    "menuSettings": {"zoom": "Click"},
}


def quick_mode() -> bool:
    """True when ``NGDUAL_DOCS_QUICK`` asks for the coarse tutorial settings."""
    return os.environ.get(QUICK_ENV, "").strip().lower() in TRUE_WORDS


def mathjax_source() -> Path:
    """The MathJax 2 folder copied into the site (``NGDUAL_MATHJAX_DIR`` or Debian's)."""
    folder = Path(os.environ.get(MATHJAX_SOURCE_ENV, MATHJAX_SOURCE))
    if not (folder / "MathJax.js").is_file():
        raise ExtensionError(
            f"no MathJax at {folder}: the site renders its mathematics offline with Debian's "
            f"MathJax (apt-get install libjs-mathjax fonts-mathjax) or a MathJax 2 folder "
            f"named by {MATHJAX_SOURCE_ENV}")
    return folder


# --- the tutorials -------------------------------------------------------------------------------

def stage_tutorials(docs: Path) -> list[Path]:
    """Copy ``tutorials/NN_*.py`` to ``docs/tutorials/`` (only files whose text changed, so
    that MyST-NB's cache keeps its executed notebooks) and remove stale copies.

    ``NGDUAL_DOCS_TUTORIALS=01,03`` stages only those numbers (for drafting a page)."""
    source = docs.parent / "tutorials"
    target = docs / "tutorials"
    target.mkdir(exist_ok=True)
    only = [n.strip() for n in os.environ.get(ONLY_ENV, "").split(",") if n.strip()]
    wanted = {p.name: p for p in sorted(source.glob("[0-9][0-9]_*.py"))
              if not only or p.name[:2] in only}
    if not wanted:
        raise ExtensionError(f"no tutorials found in {source}")
    for stale in target.glob("[0-9][0-9]_*.py"):
        if stale.name not in wanted:
            stale.unlink()
    staged = []
    for name, path in wanted.items():
        copy = target / name
        text = path.read_bytes()
        if not copy.is_file() or copy.read_bytes() != text:
            copy.write_bytes(text)
        staged.append(copy)
    return staged


def prepare_kernel_environment(build: Path, quick: bool) -> None:
    """The environment the tutorial kernels inherit: quick mode, their output folder."""
    os.environ["NGDUAL_QUICK"] = "1" if quick else "0"
    out = build / ("tutorial-output-quick" if quick else "tutorial-output")
    out.mkdir(parents=True, exist_ok=True)
    os.environ["NGDUAL_TUTORIAL_OUT"] = str(out)
    os.environ.pop("MPLBACKEND", None)   # the kernel chooses its inline backend


# --- the scene reference -------------------------------------------------------------------------

MEANINGS = {
    "name": "Name of the scene in results and titles (default: the file name).",
    "description": "Free text describing the scene; not used by the solver.",
    "geometry.kind": "`thesis-3.46`: the rectangle [-4, 4] x [-1, 1] of Example 3.46 with "
                     "the structured mesh of Table 3.1 (sides `bottom`, `right`, `top`, "
                     "`left`); `polygon`: the polygon of `points`, meshed by netgen. Required.",
    "geometry.level": "Mesh level k: k - 1 uniform refinements of the initial mesh (new "
                      "boundary vertices lie on the curves).",
    "geometry.points": "Polygon vertices [x, y], counter-clockwise; side i runs from "
                       "points[i] to points[i+1] (cyclically). Only for `polygon`.",
    "geometry.labels": "One boundary label per side (letters, digits, `_`, `-`); the "
                       "`[boundary]` table assigns a condition to each label.",
    "geometry.maxh": "Largest element size of the netgen mesh of a `polygon` (level 1).",
    "geometry.arcs": "Table label -> centre [x, y]: those sides are the shorter circular "
                     "arcs around the centre between their end points.",
    "geometry.side_maxh": "Table label -> mesh size on those sides (netgen grades the mesh "
                          "from there to `maxh`).",
    "boundary.dirichlet": "Labels of Gamma_D: prescribed displacement `loads.displacement` "
                          "(at least one side is required).",
    "boundary.neumann": "Labels of Gamma_N: prescribed traction `loads.traction`.",
    "boundary.contact": "Labels of Gamma_C: unilateral contact with the rigid foundation, "
                        "with the friction law of `[friction]`.",
    "material.E": "Young's modulus E > 0 (plane strain).",
    "material.nu": "Poisson's ratio, -1 < nu < 1/2 (plane strain; PEERS does not lock as "
                   "nu -> 1/2).",
    "loads.body_force": "Body force f = [f_x, f_y], formulas in x and y.",
    "loads.traction": "Traction t_0 on Gamma_N, formulas in x and y.",
    "loads.displacement": "Displacement u_D on Gamma_D, formulas in x and y.",
    "contact.gap": "Gap g(x, y) >= 0 between Gamma_C and the foundation, along the outward "
                   "normal (formula; default 0). Give either `gap` or `foundation`.",
    "contact.foundation": "The foundation as a straight line `{point = [x, y], normal = "
                          "[nx, ny]}`, normal pointing towards the body; the gap follows "
                          "from the geometry.",
    "contact.htilde_factor": "h~ / h: the coarse mesh of the boundary multipliers phi, "
                             "lambda_t, lambda_n (3.61) has this many fine edges per edge.",
    "contact.hhat_factor": "h^ / h~ (1 or 2): the mesh of the friction multiplier nu. "
                           "2 is needed when the contact zone reaches the ends of Gamma_C, "
                           "e.g. g = 0 (Lemmas 3.29, 3.31).",
    "contact.ends": "Values of lambda_n, lambda_t at the ends of Gamma_C: `consistent` "
                    "(those the data prescribe where Gamma_C meets Gamma_D, free elsewhere) "
                    "or `thesis` (zero at every end, C_h~ of (3.61)).",
    "contact.discrete_gap": "The gap the discrete problem sees: `nodal` (g_h, the P1 "
                            "interpolant of g on the h~ mesh of lambda_n: no stress without "
                            "load, whatever the shape of g) or `thesis` (g itself in g(tau) of "
                            "(3.32), as in the thesis).",
    "friction.law": "Friction on Gamma_C: `none`, `tresca` (given bound F) or `coulomb` "
                    "(F = mu_f |sigma_n|, fixed point of Remark 3.45).",
    "friction.mu": "Coulomb friction coefficient mu_f >= 0 (> 0 for `coulomb`).",
    "friction.bound": "Tresca bound F(x, y) >= 0 on Gamma_C (formula).",
    "friction.normal_stress": "Which |sigma_n| enters the Coulomb bound: `hat-projection` "
                              "(lumped projection onto the h~ hats; F vanishes where the "
                              "body separates) or `fine-edges` ((3.123) literally).",
    "solver.method": "`auto` (the active-set method), `active-set` (semismooth Newton "
                     "condensed onto Gamma_C) or `uzawa` (Algorithms 3.38 / 3.41).",
    "solver.metric": "Metric of the projection P+ (Remark 3.40): `h12` (H^{1/2}-equivalent, "
                     "mesh-independent iteration counts) or `euclidean`.",
    "solver.rho": "Step rho of Algorithm 3.38 (dimensionless: the metric carries the "
                  "plane-strain modulus).",
    "solver.eps": "Stopping tolerance epsilon of Algorithm 3.38 (relative increment).",
    "solver.max_iter": "Largest number of iterations (Uzawa steps; Coulomb fixed-point "
                       "steps of the active-set method).",
    "solver.rho1": "Step rho_1 of the inner (lambda_n) loop of Algorithm 3.41.",
    "solver.rho2": "Step rho_2 of the nu update of Algorithm 3.41, relative to its "
                   "stability bound: 0 < rho2 < 2.",
    "solver.eps1": "Tolerance epsilon_1 of the inner loop of Algorithm 3.41.",
    "solver.eps2": "Tolerance epsilon_2 of the outer loop of Algorithm 3.41 (on nu or, "
                   "for Coulomb, on F).",
    "solver.loop_order": "`friction-outer` (Algorithm 3.41) or `contact-outer` (the loops "
                         "exchanged, Remark 3.43).",
    "solver.friction_metric": "Diagonal metric of the projection P^Lambda: `mass` (Remark "
                              "3.44) or `jacobi` (mass weighted by the diagonal of the nu "
                              "operator).",
    "solver.condensed": "Iterate Uzawa on the Gamma_C response computed once (`true`) or "
                        "solve the sparse system every step (`false`); the same iterates. "
                        "`auto`: the response for nested Uzawa, sparse solves for "
                        "Algorithm 3.38.",
    "units.length": "Unit of every length of the scene (coordinates, gap, displacements); "
                    "only the labels of plots read it. Not given: no unit is shown.",
    "units.stress": "Unit of E, tractions and stresses; only the labels of plots read it. "
                    "Not given: no unit is shown.",
    "benchmark.kind": "The analytic solution the contact pictures draw against p_h, q_h, "
                      "for the forces the solution carries: `none`, `hertz`, `flat-punch`, "
                      "`cattaneo-mindlin` (needs Coulomb friction) or `wedge`.",
    "benchmark.radius": "Radius R of the cylinder (`hertz`, `cattaneo-mindlin`).",
    "benchmark.half_width": "Half-width a of the rigid flat punch (`flat-punch`).",
    "benchmark.slope": "Slope s of the wedge's flanks, cot of its semi-angle (`wedge`).",
    "benchmark.center": "Point [x, y] of the foundation line where the analytic solution "
                        "is centred.",
    "discretisation.order": "Polynomial order k of PEERS_k (0, 1, 2): stress rows in RT_k "
                            "plus Curl bubbles, u in P_k, the rotation in P_{k+1}; 0 is the "
                            "thesis (see theory/order).",
    "discretisation.multipliers": "Family of phi, lambda_n, lambda_t: `coarse` (P1 on h~, "
                                  "order 0 only), `facet` (discontinuous P_k on the fine "
                                  "edges, lambda_n >= 0 on its Bernstein coefficients, "
                                  "frictionless) or `auto` (coarse at k = 0, facet above).",
}

# the module constant that lists the allowed values of a key
CHOICES = {
    "geometry.kind": "GEOMETRY_KINDS", "contact.ends": "CONTACT_ENDS",
    "contact.discrete_gap": "DISCRETE_GAPS",
    "friction.law": "FRICTION_LAWS", "friction.normal_stress": "NORMAL_STRESSES",
    "solver.method": "SOLVER_METHODS", "solver.metric": "METRICS",
    "solver.loop_order": "LOOP_ORDERS", "solver.friction_metric": "FRICTION_METRICS",
    "units.length": "LENGTH_UNITS", "units.stress": "STRESS_UNITS",
    "benchmark.kind": "BENCHMARK_KINDS", "discretisation.order": "ORDERS",
    "discretisation.multipliers": "MULTIPLIER_FAMILIES",
}


@dataclasses.dataclass
class SceneKey:
    """One key of a scene file."""

    key: str
    type: str
    default: str
    choices: tuple
    meaning: str


def _default(f: dataclasses.Field) -> str:
    if f.default is not dataclasses.MISSING:
        value = f.default
    elif f.default_factory is not dataclasses.MISSING:
        value = f.default_factory()
    else:
        return "required"
    if value is None:
        return "none"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list):
        return "[" + ", ".join(f'"{v}"' if isinstance(v, str) else repr(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{}"
    return repr(value)


def scene_keys() -> list[SceneKey]:
    """Every key a scene file may hold, from :mod:`ngdual.scene` (sections, dataclasses)."""
    from ngdual import scene

    keys = [SceneKey("name", "str", "the file name", (), MEANINGS.get("name", "")),
            SceneKey("description", "str", "none", (), MEANINGS.get("description", ""))]
    keys += [SceneKey(f"boundary.{role}", "list of str", "[]", (),
                      MEANINGS.get(f"boundary.{role}", "")) for role in scene.ROLES]
    for section, cls in scene.SECTIONS.items():
        for f in dataclasses.fields(cls):
            key = f"{section}.{f.name}"
            constant = CHOICES.get(key)
            if constant is not None and not hasattr(scene, constant):
                raise ExtensionError(f"scene reference: ngdual.scene.{constant} (the values "
                                     f"of {key}) is gone; update CHOICES in {__file__}")
            choices = tuple(getattr(scene, constant)) if constant else ()
            kind = str(f.type).replace(" | None", ", optional")
            if key in scene.FORMULAS:
                kind = "formula" if kind.startswith("str") else "list of 2 formulas"
            keys.append(SceneKey(key, kind, _default(f), choices, MEANINGS.get(key, "")))
    missing = [k.key for k in keys if not k.meaning]
    unknown = sorted(set(MEANINGS) - {k.key for k in keys})
    if missing or unknown:
        raise ExtensionError(f"scene reference out of date with ngdual.scene: keys without a "
                             f"meaning {missing}, meanings of keys that do not exist {unknown}; "
                             f"edit MEANINGS in {__file__}")
    return keys


def _cell(text: str) -> str:
    return text.replace("|", "\\|") if text else " "


def scene_reference_rst() -> list[str]:
    """The scene reference as reStructuredText: one list-table per section."""
    lines: list[str] = []
    sections: dict[str, list[SceneKey]] = {}
    for key in scene_keys():
        sections.setdefault(key.key.split(".")[0] if "." in key.key else "(top level)",
                            []).append(key)
    for section, keys in sections.items():
        title = section if section.startswith("(") else f"[{section}]"
        lines += [title, "-" * len(title), "",
                  ".. list-table::", "   :header-rows: 1", "   :widths: 20 12 14 54",
                  "   :class: ngdual-scene-keys", "",
                  "   * - key", "     - type", "     - default", "     - meaning"]
        for k in keys:
            meaning = _rst_code(k.meaning)
            if k.choices:
                meaning += " One of: " + ", ".join(f"``{c}``" for c in k.choices) + "."
            anchor = "scene-key-" + k.key.replace(".", "-").replace("_", "-")
            lines += [f"   * - .. _{anchor}:", "", f"       ``{k.key}``",
                      f"     - {_cell(k.type)}", f"     - ``{k.default}``",
                      f"     - {_cell(meaning)}"]
        lines.append("")
    return lines


def _rst_code(text: str) -> str:
    """Markdown-style `code` in the meanings as reStructuredText ``code``."""
    parts = text.split("`")
    out = []
    for i, part in enumerate(parts):
        out.append(f"``{part}``" if i % 2 and part else part)
    return "".join(out).replace("````", "``")


class _GeneratedRst(SphinxDirective):
    """A directive whose body is reStructuredText generated from the code."""

    has_content = False

    def lines(self) -> list[str]:
        raise NotImplementedError

    def run(self) -> list[nodes.Node]:
        container = nodes.container()
        self.state.nested_parse(StringList(self.lines(), source="<generated>"),
                                self.content_offset, container, match_titles=True)
        return container.children


class SceneReference(_GeneratedRst):
    def lines(self) -> list[str]:
        return scene_reference_rst()


# --- the command line ----------------------------------------------------------------------------

def _option_rows(p: argparse.ArgumentParser) -> list[tuple[str, str, str]]:
    rows = []
    for action in p._actions:
        if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        if action.help == argparse.SUPPRESS:
            continue
        names = ", ".join(action.option_strings) or action.metavar or action.dest
        if action.option_strings and action.nargs != 0:
            metavar = action.metavar or (("{" + ",".join(map(str, action.choices)) + "}")
                                         if action.choices else action.dest.upper())
            names += f" {metavar}" + (" ..." if action.nargs in ("+", "*") else "")
        default = action.default
        if action.nargs == 0 or default in (None, argparse.SUPPRESS) or default == []:
            shown = ""
        else:
            shown = " ".join(map(str, default)) if isinstance(default, list) else str(default)
        text = action.help or ""
        if action.choices and not action.option_strings:
            text += " One of: " + ", ".join(map(str, action.choices)) + "."
        rows.append((names, shown, text))
    return rows


def cli_reference_rst() -> list[str]:
    """``ngdual`` and each subcommand: usage, description and an option table."""
    from ngdual import cli

    def commands(title: str, p: argparse.ArgumentParser, summary: str) -> list[tuple]:
        """``p`` and its subcommands (``ngdual bench`` has its own), depth first."""
        sub = next((a for a in p._actions if isinstance(a, argparse._SubParsersAction)), None)
        if sub is None:
            return [(title, p, summary)]
        helps = {choice.dest: choice.help for choice in sub._choices_actions}
        return [(title, p, summary), *(c for name, q in sub.choices.items()
                                       for c in commands(f"{title} {name}", q,
                                                         helps.get(name) or ""))]

    top = cli.parser()
    parsers = commands("ngdual", top, top.description or "")
    lines: list[str] = []
    for title, p, summary in parsers:
        lines += [title, "-" * len(title), ""]
        if summary:
            summary = summary[0].upper() + summary[1:]
            lines += [_cell(summary if summary.endswith(".") else summary + "."), ""]
        lines += [".. code-block:: text", ""]
        lines += ["   " + line for line in p.format_usage().strip().splitlines()] + [""]
        rows = _option_rows(p)
        if rows:
            lines += [".. list-table::", "   :header-rows: 1", "   :widths: 30 15 55", "",
                      "   * - argument", "     - default", "     - meaning"]
            for names, default, text in rows:
                shown = f"``{default}``" if default else " "
                lines += [f"   * - ``{names}``", f"     - {shown}", f"     - {_cell(text)}"]
            lines.append("")
    return lines


class CliReference(_GeneratedRst):
    def lines(self) -> list[str]:
        return cli_reference_rst()


# --- the public API ------------------------------------------------------------------------------

def api_reference_rst() -> list[str]:
    """One autodoc entry per public name (``ngdual.__all__``), in its order."""
    import inspect

    import ngdual

    lines = []
    for name in ngdual.__all__:
        if name == "__version__":
            continue
        value = getattr(ngdual, name)
        kind = "autoclass" if inspect.isclass(value) else "autofunction"
        lines += [f".. {kind}:: ngdual.{name}", ""]
    return lines


class ApiReference(_GeneratedRst):
    def lines(self) -> list[str]:
        return api_reference_rst()


# --- notebook outputs -----------------------------------------------------------------------------

WEBGUI_REPR = re.compile(r"^<?(netgen\.webgui\.)?WebGuiWidget")


def drop_webgui_placeholders(app, doctree) -> None:
    """Remove the text that stands for NGSolve's interactive webgui view in a static page.

    The view needs a live kernel; the tutorials save the same fields as figures, which the
    pages show. What is left of ``Draw`` in an executed notebook is a placeholder text
    ("<netgen.webgui.WebGuiWidget>: Run `pip install anywidget` ...").
    """
    for block in list(doctree.findall(nodes.literal_block)):
        if "output" in block["classes"] and WEBGUI_REPR.match(block.astext().strip()):
            parent = block.parent
            parent.remove(block)
            if not parent.children and "cell_output" in parent.get("classes", []):
                parent.parent.remove(parent)


# --- docstrings ----------------------------------------------------------------------------------

def _escape_bars(text: str) -> str:
    """``|`` outside ``literals`` as ``\\|``: ASCII mathematics (|sigma_n|) is not a
    reStructuredText substitution reference."""
    parts = text.split("``")
    return "``".join(part if i % 2 else part.replace("|", "\\|")
                     for i, part in enumerate(parts))


def escape_docstring_bars(app, what, name, obj, options, lines) -> None:
    """The docstrings write norms and absolute values in ASCII (``|x|``, ``||u||``); show them
    as written instead of reading them as substitutions. Literal blocks stay untouched."""
    literal_indent = None
    for i, line in enumerate(lines):
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None:
            if line.strip() and indent <= literal_indent:
                literal_indent = None
            else:
                continue
        if line.rstrip().endswith("::"):
            literal_indent = indent
        lines[i] = _escape_bars(line)


# --- MathJax, offline ----------------------------------------------------------------------------

def copy_mathjax(app, exception) -> None:
    """Copy the parts of MathJax 2 the pages load into ``_static/mathjax`` of the build."""
    if exception is not None or app.builder.format != "html":
        return
    source = mathjax_source()
    target = Path(app.outdir) / "_static" / "mathjax"
    for part in MATHJAX_PARTS:
        src = source / part
        if not src.exists():
            continue
        dst = target / part
        dst.parent.mkdir(parents=True, exist_ok=True)
        if src.is_dir():
            shutil.copytree(src, dst, dirs_exist_ok=True)
        else:
            shutil.copy2(src, dst)


def check_mathjax(app) -> None:
    if app.builder.format == "html":
        mathjax_source()


def setup(app):
    app.add_directive("ngdual-scene-reference", SceneReference)
    app.add_directive("ngdual-cli-reference", CliReference)
    app.add_directive("ngdual-api-reference", ApiReference)
    app.connect("builder-inited", check_mathjax)
    app.connect("autodoc-process-docstring", escape_docstring_bars)
    app.connect("doctree-read", drop_webgui_placeholders)
    app.connect("build-finished", copy_mathjax)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
