"""Experiments: what is run, and how, above the simulators and the central planners.

* :mod:`mrmp.experiments.execution` -- a central plan executed by the fleet in the lockstep simulator;
* :mod:`mrmp.experiments.compare` -- one scenario solved every way (``mrmp compare``);
* :mod:`mrmp.experiments.matrix` -- :class:`~mrmp.experiments.matrix.BenchRun`, one benchmark run's parameters and stable id;
* :mod:`mrmp.experiments.bench_config` -- a benchmark configuration file read and expanded into runs;
* :mod:`mrmp.experiments.records` -- one benchmark run executed exactly as ``mrmp run`` would, and its record.
* :mod:`mrmp.experiments.trade_places` -- the thesis's trade of places for every pair of cells (``bench/thesis_pairs.py``).

This layer may import core, search, policies, centralized, sim and io; nothing
below it imports it (``mrmp.bench`` runs its runs in worker processes).
"""
