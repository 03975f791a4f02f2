"""The process one benchmark run executes in: ``python -m mrmp.bench.child``.

It reads one :class:`~mrmp.experiments.matrix.BenchRun` as JSON on standard input,
executes it (:func:`mrmp.experiments.records.execute_run`) and writes its record as
one JSON line on standard output. Running each run in a process of its own
lets the runner kill it when it overruns its time limit, and keeps a crash of
one run from taking the benchmark down. The process also ends when the
worker that started it dies (the parent-death signal, set before it starts,
and checked again here: :mod:`mrmp.io.lifetime`), so that no run goes on
unsupervised.
"""

from __future__ import annotations

import json
import os
import signal
import sys

from mrmp.experiments.matrix import BenchRun
from mrmp.experiments.records import execute_run
from mrmp.io.lifetime import die_with_parent, parent_pid


def _end_with_parent() -> None:
    """Ask to be killed when the worker that started this run ends; end now if it already has."""
    if die_with_parent(signal.SIGKILL) and os.getppid() != parent_pid():
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
