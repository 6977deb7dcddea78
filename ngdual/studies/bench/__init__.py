"""``ngdual bench``: what the solvers cost and how well the discrete spaces are posed.

One module per benchmark, each a function ``run(...)`` that returns the benchmark's
records with the package versions and the machine (:func:`~.measure.header`) and a
``COLUMNS`` table of what ``ngdual bench NAME`` prints:

* :mod:`~.limit_ratio` (``limit-ratio``): every contact solver against one linear solve of
  the same matrix, per level (Example 3.46 without and with friction);
* :mod:`~.levels` (``levels``): one scene on a sequence of levels, each in its own process
  (unknowns, iterations, times, peak memory, norms);
* :mod:`~.estimator_cost` (``estimator-cost``): the estimator (4.50) against one linear
  solve;
* :mod:`~.infsup` (``infsup``): the discrete inf-sup constants of the boundary multipliers;
* :mod:`~.primal_peer` (``primal-peer``): the primal Nitsche peer against Hertz and
  Cattaneo-Mindlin;
* :mod:`~.adaptive` (``adaptive``): every phase of an adaptive step against one linear
  solve of its mesh.

:mod:`~.measure` is how they measure (median times, peak memory, a fresh process, the
machine).
"""
