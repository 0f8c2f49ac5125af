"""Batch identification and Monte Carlo studies, from one core to a Dask cluster.

- :func:`lptv.montecarlo` (:mod:`lptv.batch.study`): R noise realisations of a design, fitted
  by one or several methods; bias, variance against the Cramer-Rao bound, coverage.
- :func:`lptv.identify_many` (:mod:`lptv.batch.records`): the same fit on many files or arrays,
  one row of results per record, failures reported in their row.
- :func:`lptv.select` (:mod:`lptv.batch.selection`): a grid of structures fitted on one data set
  and ranked, guided by the HTF estimate;
- :func:`run_tasks` (:mod:`lptv.batch.executors`): the engine under them all, for studies of your
  own: chunked tasks on ``"serial"``, ``"processes"`` (default) or a Dask cluster, results in
  order, a progress bar with an ETA.
- :mod:`lptv.batch.warm`: the process pool kept between calls of lptv's own tasks (its
  workers warm: lptv and scipy.signal imported), :func:`shutdown_pool` to end it; the Dask
  worker plugin that warms a cluster's workers (:mod:`lptv.batch.dask_plugin`).

pandas (tables), tqdm (progress bars), dask.distributed (clusters) and pyarrow (Parquet) are
optional: ``pip install 'lptv[batch]'``. Without them the fits still run, serially or on local
processes, and the results are NumPy arrays and plain dicts.
"""
from .executors import Failure, available_cores, chunk_sizes, default_chunk_size, run_tasks
from .records import BatchResult, identify_many
from .study import MonteCarloResult, montecarlo
from .warm import shutdown_pool

__all__ = ["BatchResult", "Failure", "MonteCarloResult", "available_cores", "chunk_sizes",
           "default_chunk_size", "identify_many", "montecarlo", "run_tasks", "shutdown_pool"]
