"""The optional dependencies: what one command needs beyond ``nd.solve`` and ``nd.adapt``.

``install_requires`` holds the packages of the numerical pipeline (NGSolve, NumPy, SciPy,
cvxpy with its Clarabel, cvxopt's CHOLMOD, threadpoolctl) and of the ``ngdual solve``
command (matplotlib for its pictures, tqdm for its progress bar). A package that only one
command needs lives in an extra of ``setup.cfg`` and is imported inside the function that
needs it through :func:`require`, so that a missing one names the extra to install:

* ``studies``: dask.distributed, the parallel runner of ``ngdual sweep``;
* ``metis``: pymetis, the nested-dissection ordering of the active-set factorisation;
* ``tutorials``: Jupyter (nbconvert, ipykernel, the webgui widgets), to run the notebooks
  that ``ngdual tutorials --notebooks`` writes with the core install;
* ``docs``, ``test``: the documentation site and the test suite.
"""

from __future__ import annotations

import importlib
from types import ModuleType


class MissingExtraError(ImportError):
    """An optional package is not installed; the message names the extra that installs it."""


def require(module: str, extra: str) -> ModuleType:
    """Import ``module``, or raise :class:`MissingExtraError` naming the extra that installs it.

    Parameters
    ----------
    module : str
        The dotted module name, e.g. ``"dask.distributed"``.
    extra : str
        The extra of ``setup.cfg`` that installs it, e.g. ``"studies"``.

    >>> require("json", "test").dumps([1])
    '[1]'
    >>> require("no_such_module", "studies")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ngdual.extras.MissingExtraError: no_such_module is not installed; ... "ngdual[studies]" ...
    """
    try:
        return importlib.import_module(module)
    except ImportError as err:
        raise MissingExtraError(
            f"{module} is not installed; it comes with the {extra!r} extra: "
            f'pip install "ngdual[{extra}]" (in a checkout: pip install -e ".[{extra}]")'
        ) from err
