"""Sweeps: many independent solves as dask tasks, each leaving its own record on disk.

:mod:`~ngdual.studies.sweep.work` computes a task (the domain work),
:mod:`~ngdual.studies.sweep.records` names, writes and reads its record (the disk) and
:mod:`~ngdual.studies.sweep.runner` schedules the missing ones on a dask cluster.
"""

from .records import Task, estimator, load_arrays, load_record
from .runner import Runner, run_task
from .work import execute

__all__ = ["Runner", "Task", "estimator", "execute", "load_arrays", "load_record", "run_task"]
