"""``ngdual figures``: the figures and tables of Sections 3.4 and 4.2, regenerated.

:mod:`~.plan` (every size derived from the finest level K, the scenes and cases),
:mod:`~.tasks` (the studies: lists of sweep tasks), :mod:`~.numbers` (numbers derived
from records), :mod:`~.truth` (true errors against an overkill), :mod:`~.output` (the
:class:`Context` a figure script works with), :mod:`~.index` (``index.md``, markdown
tables, the README gallery), :mod:`~.run` (the run: sweep, scripts, index) and
:mod:`~.kit` (what several figure scripts share). The figure scripts themselves are
``figures/*.py`` (found by :func:`ngdual.studies.sources.scripts_folder`); the names below
and :mod:`~.kit` are what they import.
"""

from .index import markdown_table, write_gallery
from .numbers import best, errors, outcome, require, richardson_check
from .output import Context
from .plan import (
    DEFAULT_MAX_LEVEL,
    PROBLEM_TITLES,
    SCENES,
    THESIS_MAX_LEVEL,
    TRUTH_PROBLEMS,
    Plan,
)
from .run import run_figures, script_main
from .tasks import (
    adaptive_task,
    gap_tasks,
    manufactured_tasks,
    rho_tasks,
    solve,
    studies,
    truth_solve,
)
from .truth import true_error_study

__all__ = ["DEFAULT_MAX_LEVEL", "PROBLEM_TITLES", "SCENES", "THESIS_MAX_LEVEL",
           "TRUTH_PROBLEMS", "Context", "Plan", "adaptive_task", "best", "errors", "gap_tasks",
           "manufactured_tasks", "markdown_table", "outcome", "require", "rho_tasks",
           "richardson_check", "run_figures", "script_main", "solve", "studies",
           "true_error_study", "truth_solve", "write_gallery"]
