"""The process one benchmark run executes in: ``python -m mrmp.bench.child``.

It reads one :class:`~mrmp.experiments.matrix.BenchRun` as JSON on standard input,
executes it (:func:`mrmp.experiments.records.execute_run`) and writes its record as
one JSON line on standard output. Running each run in a process of its own
lets the runner kill it when it overruns its time limit, and keeps a crash of
one run from taking the benchmark down. On Linux the process also ends when
the worker that started it dies (``PR_SET_PDEATHSIG``), so that no run goes on
unsupervised.
"""

from __future__ import annotations

import json
import os
import signal
import sys

from mrmp.experiments.matrix import BenchRun
from mrmp.experiments.records import execute_run

PARENT_VARIABLE = "MRMP_BENCH_PARENT"
"""The environment variable naming the process id of the worker that started the run."""


def _end_with_parent() -> None:
    """Ask Linux to kill this process when its parent dies; end now if it already has."""
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    parent = int(os.environ.get(PARENT_VARIABLE, os.getppid()))
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:
        os._exit(1)


def main() -> int:
    """Read a run on stdin, execute it, write its record on stdout."""
    _end_with_parent()
    run = BenchRun.from_dict(json.loads(sys.stdin.read()))
    record = execute_run(run)
    sys.stdout.write("\n" + json.dumps(record, separators=(",", ":")) + "\n")
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
