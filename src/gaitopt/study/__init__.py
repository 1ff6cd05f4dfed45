"""gaitopt.study: sweeps of many walking problems (plan, worker, executors, driver), their
summary table, and the paper's findings checked on a sweep.

Modules: :mod:`~gaitopt.study.plan` (the grid and its warm-start chains),
:mod:`~gaitopt.study.worker` (one point, solved where the executor runs it),
:mod:`~gaitopt.study.executors` (local processes, Dask, this process),
:mod:`~gaitopt.study.driver` (:func:`~gaitopt.study.driver.run_sweep`),
:mod:`~gaitopt.study.summary` (``summary.csv`` and the directory layout),
:mod:`~gaitopt.study.findings` (the paper's findings with stable ids).
"""
