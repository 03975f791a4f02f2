"""Run a benchmark matrix in worker processes, recording every run as it ends, resumably.

Each run executes in a fresh child process (``python -m mrmp.bench.child``)
started by a worker of a :class:`concurrent.futures.ProcessPoolExecutor`, or
by a worker of an existing dask.distributed cluster (``dask_address``). The
worker kills the child when it overruns the run's time limit (plus
:data:`KILL_GRACE_S` for the record's transfer), counted from the moment the
child says it is ready (its imports done and the run's scenario built, which a
loaded machine makes slow), which gives a record with status ``timeout``; a
child that dies, or does not get ready within :data:`STARTUP_LIMIT_S`, gives
status ``error`` with the last line it wrote.

The main process appends each record to ``results.jsonl`` as soon as it
arrives (flushed and fsynced). On start, runs whose id already has a record
there are skipped, so a benchmark stopped by Ctrl-C or a kill resumes where it
stopped; ``retry_errors`` also runs again those whose last record is an
``error``. Ctrl-C (or SIGTERM) stops the workers and their children and
leaves every finished record on disk. A main process that dies any other way
(SIGKILL) takes its workers and their runs with it: a worker gets the
parent-death signal and watches the main process, and a run's process gets
the parent-death signal before it runs anything (:mod:`mrmp.io.lifetime`). At
the end ``results.csv`` is regenerated from ``results.jsonl``.
"""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Generator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any

from mrmp.bench.child import READY
from mrmp.experiments.matrix import BenchRun
from mrmp.experiments.records import base_record
from mrmp.io.lifetime import die_with_parent, preexec_dying_with, watch_parent

KILL_GRACE_S = 2.0
"""Seconds a run's process may exceed its time limit, counted from its readiness, before it is killed."""

STARTUP_LIMIT_S = 600.0
"""Seconds a run's process may take to get ready (start, import mrmp, build the run's scenario) before it is killed."""

Say = Callable[[str], None]
"""Where the runner's notes go (one line each)."""


def run_isolated(run: BenchRun) -> dict[str, Any]:
    """Execute ``run`` in a child process, killed when over its time limit; return its record.

    The time limit counts from the child's readiness (:data:`mrmp.bench.child.READY`:
    its imports done and the run's scenario built), so that neither the start-up
    of its interpreter on a loaded machine nor reading the map eats the run's time.

    Examples
    --------
    >>> run = BenchRun("gen:random-12x12-p0.10-s0", 3, "pp", instance=0, time_limit_s=20,
    ...                generator=(("density", 0.1), ("height", 12), ("kind", "random"), ("seed", 0), ("width", 12)))
    >>> record = run_isolated(run)
    >>> record["status"], record["kind"], record["collisions"]
    ('done', 'centralized', 0)
    """
    global _CHILD
    child = subprocess.Popen(
        [sys.executable, "-m", "mrmp.bench.child"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=preexec_dying_with(signal.SIGKILL),
    )
    _CHILD = child
    try:
        if not _ready(child, run):
            child.kill()
            errors = child.communicate()[1]
            return base_record(run, "error", _failure(child, errors, f"not ready after {STARTUP_LIMIT_S:g} s"))
        started = time.perf_counter()
        output, errors = child.communicate(timeout=run.time_limit_s + KILL_GRACE_S)
    except subprocess.TimeoutExpired:
        child.kill()
        child.communicate()
        return base_record(run, "timeout", f"killed after {time.perf_counter() - started:.1f} s (limit {run.time_limit_s:g} s)")
    finally:
        _CHILD = None
    lines = [line for line in output.splitlines() if line.strip()]
    if child.returncode == 0 and lines:
        try:
            record = json.loads(lines[-1])
            if isinstance(record, dict) and record.get("run_id") == run.run_id:
                return record
        except json.JSONDecodeError:
            pass
    return base_record(run, "error", _failure(child, errors, "no message"))


def _failure(child: subprocess.Popen[str], errors: str, otherwise: str) -> str:
    """One line on a run's process that gave no record: its status and the last line it wrote (else ``otherwise``)."""
    last = next((line.strip() for line in reversed(errors.splitlines()) if line.strip()), otherwise)
    return f"the run's process ended with status {child.returncode}: {last}"[:300]


def _ready(child: subprocess.Popen[str], run: BenchRun) -> bool:
    """Give ``child`` its run; whether it wrote :data:`~mrmp.bench.child.READY` within :data:`STARTUP_LIMIT_S`."""
    assert child.stdin is not None and child.stdout is not None
    try:
        child.stdin.write(json.dumps(run.to_dict()) + "\n")
        child.stdin.flush()
    except BrokenPipeError:  # the child is gone already
        return False
    expected, line = (READY + "\n").encode(), b""
    deadline = time.monotonic() + STARTUP_LIMIT_S
    while expected.startswith(line) and line != expected:
        readable, _, _ = select.select([child.stdout], [], [], max(0.0, deadline - time.monotonic()))
        # byte by byte, past any buffer: what follows the line is left for communicate()
        byte = os.read(child.stdout.fileno(), 1) if readable else b""
        if not byte:
            return False
        line += byte
    return line == expected


_CHILD: subprocess.Popen[str] | None = None
"""The child process a pool worker is waiting for (killed when the worker is told to stop)."""


def _stop_worker(signum: int, frame: FrameType | None) -> None:
    """SIGTERM in a pool worker: kill the running child and leave at once."""
    if _CHILD is not None and _CHILD.poll() is None:
        _CHILD.kill()
    os._exit(128 + signum)


def _init_worker(main: int) -> None:
    """A pool worker ignores Ctrl-C (the main process decides), stops its child on SIGTERM, and ends with ``main``.

    The worker asks for SIGTERM when its parent ends and watches the main
    process: either way, once the main process is gone the worker kills its
    run and exits, instead of waiting for work for ever.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _stop_worker)
    die_with_parent(signal.SIGTERM)
    watch_parent(lambda: _stop_worker(signal.SIGTERM, None), main)


def _pool_records(runs: Sequence[BenchRun], workers: int) -> Generator[dict[str, Any], None, None]:
    """Records of ``runs`` from a local process pool, in the order they finish."""
    executor = ProcessPoolExecutor(max_workers=workers, initializer=_init_worker, initargs=(os.getpid(),))
    finished = False
    try:
        pending: set[Future[dict[str, Any]]] = {executor.submit(run_isolated, run) for run in runs}
        while pending:
            done, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            for future in done:
                yield future.result()
        finished = True
    finally:
        if not finished:
            for process in list(getattr(executor, "_processes", {}).values()):
                if process.is_alive():
                    process.terminate()
        executor.shutdown(wait=True, cancel_futures=True)


def _dask_records(runs: Sequence[BenchRun], address: Any) -> Generator[dict[str, Any], None, None]:
    """Records of ``runs`` from a dask.distributed cluster at ``address``, in the order they finish."""
    try:
        from distributed import Client, as_completed
    except ImportError:
        from mrmp.core.errors import InputError, Problem

        raise InputError(Problem("--dask", "needs dask.distributed: in a checkout, .venv/bin/pip install -e '.[dask]'")) from None
    client = address if hasattr(address, "submit") else Client(address)
    futures = []
    try:
        futures = [client.submit(run_isolated, run, pure=False) for run in runs]
        for future in as_completed(futures):
            yield future.result()
    finally:
        client.cancel([future for future in futures if not future.done()])
        if client is not address:
            client.close()


@dataclass
class BenchOutcome:
    """What a benchmark invocation did.

    Attributes
    ----------
    total:
        Runs in the matrix.
    resumed:
        Runs skipped because ``results.jsonl`` already had them.
    ran:
        Runs executed and recorded now.
    interrupted:
        Whether Ctrl-C or SIGTERM stopped it early.
    failure:
        Why the runs could not go on (a worker process or the cluster lost), or None.
    records:
        The latest record of every run of the matrix that has one.
    """

    total: int
    resumed: int
    ran: int = 0
    interrupted: bool = False
    failure: str | None = None
    records: list[dict[str, Any]] = field(default_factory=list)


def _raise_interrupt(signum: int, frame: FrameType | None) -> None:
    raise KeyboardInterrupt


def run_bench(
    runs: Sequence[BenchRun],
    out_dir: Path,
    workers: int | None = None,
    dask_address: Any = None,
    retry_errors: bool = False,
    say: Say = print,
    progress: bool = True,
) -> BenchOutcome:
    """Run every run of the matrix not yet recorded in ``out_dir/results.jsonl``.

    Parameters
    ----------
    runs:
        The matrix.
    out_dir:
        The output folder (created if needed): ``results.jsonl`` and ``results.csv``.
    workers:
        Local worker processes (default: the number of CPUs).
    dask_address:
        A dask.distributed scheduler address (or a ``Client``); when given the
        runs go to that cluster instead of local workers.
    retry_errors:
        Run again the runs whose last record has status ``error``.
    say:
        Where notes go (resumed runs, interruption).
    progress:
        Show a progress bar (runs done/total, elapsed, ETA) on standard error.

    Returns
    -------
    BenchOutcome
        Counts and the latest record of each run of the matrix.

    Raises
    ------
    InputError
        If the output folder cannot be made, or ``results.jsonl`` is unreadable or cannot be written.
    """
    from mrmp.io.bench_results import RESULTS_CSV, RESULTS_JSONL, append_record, latest_records, read_records, write_csv

    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        from mrmp.core.errors import InputError, Problem

        raise InputError(Problem(str(out_dir), f"cannot create the output folder: {error.strerror or error}")) from None
    results_path = out_dir / RESULTS_JSONL
    existing = {record["run_id"]: record for record in latest_records(read_records(results_path, repair=True))}
    keep = {run_id for run_id, record in existing.items() if not (retry_errors and record.get("status") == "error")}
    pending = [run for run in runs if run.run_id not in keep]
    outcome = BenchOutcome(total=len(runs), resumed=len(runs) - len(pending))
    if outcome.resumed:
        say(f"resumed: {outcome.resumed} of {len(runs)} runs already done")
    previous_handler = signal.getsignal(signal.SIGTERM)
    in_main_thread = _in_main_thread()
    if in_main_thread:
        signal.signal(signal.SIGTERM, _raise_interrupt)
    source: Generator[dict[str, Any], None, None] | None = None
    try:
        if pending:
            if dask_address is not None:
                source = _dask_records(pending, dask_address)
            else:
                source = _pool_records(pending, max(1, workers or os.cpu_count() or 1))
            with _ProgressBar(progress, len(runs), outcome.resumed) as advance:
                for record in source:
                    append_record(results_path, record)
                    outcome.ran += 1
                    advance(f"{record['map']} N={record['agents']} {record['policy']}: {record['status']}")
    except KeyboardInterrupt:
        outcome.interrupted = True
    except (OSError, RuntimeError) as error:  # a worker process died, the cluster went away
        outcome.failure = f"{type(error).__name__}: {error}".splitlines()[0]
    finally:
        if source is not None:
            try:
                source.close()
            except KeyboardInterrupt:
                outcome.interrupted = True
        if in_main_thread:
            signal.signal(signal.SIGTERM, previous_handler)
    everything = read_records(results_path)
    write_csv(out_dir / RESULTS_CSV, everything)
    wanted = {run.run_id for run in runs}
    outcome.records = [record for record in latest_records(everything) if record["run_id"] in wanted]
    if outcome.failure is not None:
        say(f"stopped: {outcome.failure}; {outcome.resumed + outcome.ran} of {len(runs)} runs are recorded in "
            f"{results_path}; run the same command again to resume")  # fmt: skip
    if outcome.interrupted:
        say(f"interrupted: {outcome.resumed + outcome.ran} of {len(runs)} runs are recorded in {results_path}; "
            "run the same command again to resume")  # fmt: skip
    return outcome


def _in_main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


class _ProgressBar:
    """A rich progress bar on standard error (or nothing), advanced once per recorded run."""

    def __init__(self, shown: bool, total: int, completed: int) -> None:
        self.shown = shown
        self.total = total
        self.completed = completed
        self.progress: Any = None

    def __enter__(self) -> Callable[[str], None]:
        if not self.shown:
            return lambda description: None
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

        self.progress = Progress(
            TextColumn("runs"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
            TextColumn("{task.description}"),
            console=Console(stderr=True),
            transient=False,
        )
        self.progress.start()
        task = self.progress.add_task("", total=self.total, completed=self.completed)

        def advance(description: str) -> None:
            self.progress.update(task, advance=1, description=description)

        return advance

    def __exit__(self, *exc_info: object) -> None:
        if self.progress is not None:
            self.progress.stop()
