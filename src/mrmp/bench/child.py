"""The process one benchmark run executes in: ``python -m mrmp.bench.child``.

It reads one :class:`~mrmp.experiments.matrix.BenchRun` as one line of JSON on
standard input, builds its scenario, writes :data:`READY` on standard output,
executes the run (:func:`mrmp.experiments.records.execute_run`) and writes its
record as one JSON line on standard output. Running each run in a process of
its own lets the runner kill it when it overruns its time limit, counted from
its readiness, and keeps a crash of one run from taking the benchmark down.
The runner starts it bound to the worker's life (the parent-death signal, set
before it runs anything: :mod:`mrmp.io.lifetime`), so that no run goes on
unsupervised.
"""

from __future__ import annotations

import json
import sys

from mrmp.experiments.matrix import BenchRun
from mrmp.experiments.records import execute_run

READY = "ready"
"""The line the process writes once its imports are done and the run's scenario is built (its timed work begins)."""


def main() -> int:
    """Read a run on stdin, execute it (saying when it is ready), write its record on stdout."""
    run = BenchRun.from_dict(json.loads(sys.stdin.readline()))
    record = execute_run(run, on_ready=lambda: print(READY, flush=True))
    sys.stdout.write("\n" + json.dumps(record, separators=(",", ":")) + "\n")
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
