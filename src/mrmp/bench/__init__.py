"""Benchmark matrices: many runs of many methods, in worker processes, recorded as they finish.

* :mod:`mrmp.experiments.matrix` -- :class:`~mrmp.experiments.matrix.BenchRun`, one run's parameters and stable id;
* :mod:`mrmp.experiments.records` -- one run executed, and its results record;
* :mod:`mrmp.bench.runner` -- the matrix in worker processes (or on a dask cluster), resumable;
* :mod:`mrmp.bench.summary` -- the per map, method and N summary table of ``mrmp bench``;
* :mod:`mrmp.bench.aggregate` -- the numbers a benchmark report shows.

The configuration file is read by :mod:`mrmp.experiments.bench_config`, the results
files are written by :mod:`mrmp.io.bench_results`.
"""
