"""Sphinx configuration of the ngdual documentation site.

Build (quick mode: the tutorials run on their coarse settings, as in the test suite)::

    NGDUAL_DOCS_QUICK=1 python -m sphinx -W --keep-going -b html docs docs/_build/html

Everything is local: MathJax comes from Debian's ``libjs-mathjax`` and is copied into
the build (no CDN), the tutorials (``tutorials/*.py``, jupytext percent scripts) are
executed by MyST-NB, and the scene, command-line and API references are generated from
the code by ``_ext/ngdual_docs.py``.
"""

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))

import ngdual_docs  # noqa: E402

import ngdual  # noqa: E402

QUICK = ngdual_docs.quick_mode()
ngdual_docs.stage_tutorials(DOCS)
ngdual_docs.prepare_kernel_environment(DOCS / "_build", QUICK)

project = "ngdual"
author = "the ngdual developers"
copyright = "2026, the ngdual developers"
release = version = ngdual.__version__

extensions = [
    "myst_nb",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx_copybutton",
    "ngdual_docs",
]

exclude_patterns = ["_build", "_ext", "conf.py", "**/.ipynb_checkpoints"]
html_static_path = ["_static"]
html_css_files = ["ngdual.css"]

# --- MyST and MyST-NB: jupytext percent scripts are notebooks ------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
myst_dmath_double_inline = True
myst_update_mathjax = False          # MyST's settings are MathJax 3's; ngdual_docs has MathJax 2's
nb_custom_formats = {".py": ["jupytext.reads", {"fmt": "py:percent"}]}
nb_execution_mode = "cache"
nb_execution_cache_path = str(DOCS / "_build" / (".jupyter_cache-quick" if QUICK
                                                 else ".jupyter_cache-full"))
nb_execution_timeout = 600 if QUICK else 7200
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_kernel_rgx_aliases = {".*": "python3"}
# interactive NGSolve views need a live kernel: the static pages show the saved figures
nb_ipywidgets_js = {}
nb_mime_priority_overrides = [("*", "application/vnd.jupyter.widget-view+json", None)]

# --- API reference -------------------------------------------------------------------------------
autodoc_member_order = "bysource"
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
numpydoc_validation_checks = set()

# --- mathematics, offline ------------------------------------------------------------------------
mathjax_path = ngdual_docs.MATHJAX_URL
mathjax2_config = ngdual_docs.MATHJAX_CONFIG
mathjax_options = {}

# --- HTML ----------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"ngdual {version}"
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
    "secondary_sidebar_items": ["page-toc"],
}
html_favicon = "_static/favicon.svg"
html_context = {"default_mode": "light"}   # a fresh browser profile has no stored mode
html_sidebars = {"index": [], "installation": []}
html_show_sourcelink = False

# the kernels' debugger warns about frozen modules on stderr otherwise
os.environ.setdefault("PYDEVD_DISABLE_FILE_VALIDATION", "1")
