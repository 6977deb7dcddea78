"""Run machinery: it only calls the numerical pipeline of :mod:`ngdual`, never the reverse.

:mod:`~.sweep` (many solves as dask tasks, one record on disk each), :mod:`~.figures`
(``ngdual figures``), :mod:`~.bench` (``ngdual bench``), :mod:`~.variants` (solver
variants spelled as scene overrides), :mod:`~.primal_peer` (the independent primal solver
of the work-precision study) and :mod:`~.tutorials` (helpers of the lecture tutorials and
``ngdual tutorials``).
"""
