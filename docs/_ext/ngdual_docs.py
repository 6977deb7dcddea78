"""Sphinx extension of the ngdual site: the API reference from the code, offline MathJax.

Directive
---------
``ngdual-api-reference``
    An autodoc entry for every name of ``ngdual.__all__``.

The scene-key and command-line references are Markdown files in the checkout
(``docs/reference/scene-keys.md``, ``cli-commands.md``), written from the code by
``python -m ngdual.studies.reference`` and checked to be current by
``tests/test_reference_current.py``.

Build steps
-----------
:func:`stage_tutorials` copies ``tutorials/NN_*.py`` into ``docs/tutorials`` (MyST-NB reads
them as notebooks and executes them); :func:`prepare_kernel_environment` sets the quick
mode and the tutorials' output folder for the kernels; after the build, the parts of
Debian's MathJax 2 that the pages load are copied into ``_static/mathjax``.
"""

from __future__ import annotations

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
        if inspect.ismodule(value):
            # a public module: its docstring's first paragraph; its members are in the
            # sections below, whose automodule is :no-index: so that the name is listed once
            summary = inspect.cleandoc(value.__doc__ or "").split("\n\n")[0]
            lines += [f".. py:data:: ngdual.{name}", "   :type: module", ""]
            lines += ["   " + line for line in summary.splitlines()] + [""]
            continue
        kind = "autoclass" if inspect.isclass(value) else "autofunction"
        lines += [f".. {kind}:: ngdual.{name}", ""]
    return lines


class ApiReference(SphinxDirective):
    """The body of :func:`api_reference_rst`, parsed in place."""

    has_content = False

    def run(self) -> list[nodes.Node]:
        container = nodes.container()
        self.state.nested_parse(StringList(api_reference_rst(), source="<generated>"),
                                self.content_offset, container, match_titles=True)
        return container.children


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
    app.add_directive("ngdual-api-reference", ApiReference)
    app.connect("builder-inited", check_mathjax)
    app.connect("autodoc-process-docstring", escape_docstring_bars)
    app.connect("doctree-read", drop_webgui_placeholders)
    app.connect("build-finished", copy_mathjax)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
