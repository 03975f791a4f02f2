"""Nothing is left running: ``kill -9`` of a live launcher or of a benchmark takes every process it started with it.

Each test starts the real command, finds the processes it started in
``/proc`` (children, and their children), kills the command with SIGKILL (it
can clean nothing up), and waits until every one of them has ended. A zombie
that nobody reaped counts as ended: it runs nothing any more.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from polling import PATIENCE

WAIT = 4 * PATIENCE
"""Seconds a test waits at most for the processes to start or end (a bound on a hang only: a busy machine is slow)."""

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
MAPS = ROOT / "maps"


def _stat(pid: int) -> tuple[str, int] | None:
    """(state, parent pid) of a process, or None when it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return fields[0], int(fields[1])


def ended(pid: int) -> bool:
    stat = _stat(pid)
    return stat is None or stat[0] in ("Z", "X")


def children(pid: int) -> list[int]:
    """The running processes whose parent is ``pid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            stat = _stat(int(entry.name))
            if stat is not None and stat[1] == pid and stat[0] not in ("Z", "X"):
                found.append(int(entry.name))
    return found


def descendants(pid: int) -> list[int]:
    """The running processes started by ``pid``, by its children, and so on."""
    found, frontier = [], [pid]
    while frontier:
        below = [child for parent in frontier for child in children(parent)]
        found += below
        frontier = below
    return found


def command_line(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def wait_for(condition, step: float = 0.005) -> bool:
    """Whether ``condition()`` became true within :data:`WAIT` seconds (a bound on a hang only)."""
    deadline = time.monotonic() + WAIT
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(step)
    return True


def left_running(pids: list[int]) -> list[int]:
    """The processes of ``pids`` still running once they had :data:`WAIT` seconds to end."""
    wait_for(lambda: all(ended(pid) for pid in pids), step=0.02)
    return [pid for pid in pids if not ended(pid)]


@pytest.fixture
def start():
    """Start ``python -m mrmp ARGUMENTS``; whatever a failing test leaves of it and its processes is killed at the end."""
    started: list[tuple[subprocess.Popen[bytes], set[int]]] = []

    def launch(*arguments: object) -> subprocess.Popen[bytes]:
        process = subprocess.Popen(
            [sys.executable, "-m", "mrmp", *map(str, arguments)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
        )  # fmt: skip
        started.append((process, set()))
        return process

    launch.seen = lambda process, pids: next(seen for known, seen in started if known is process).update(pids)
    yield launch
    for process, seen in started:
        for pid in [process.pid, *descendants(process.pid), *seen]:
            if not ended(pid):
                os.kill(pid, signal.SIGKILL)
        process.wait()


def kill(process: subprocess.Popen[bytes]) -> None:
    os.kill(process.pid, signal.SIGKILL)
    process.wait()


def live_launcher(start, results: Path) -> subprocess.Popen[bytes]:
    return start("run", EXAMPLES / "thesis-swap.yaml", "--live", "--time-scale", "0.5", "--results", results)


def test_a_launcher_killed_as_soon_as_it_started_its_processes_leaves_none_running(tmp_path, start):
    launcher = live_launcher(start, tmp_path / "run")
    assert wait_for(lambda: len(children(launcher.pid)) == 3), "the launcher did not start a referee and two robots"
    started = children(launcher.pid)
    start.seen(launcher, started)
    kill(launcher)  # the robots are still starting Python: not one line of mrmp has run in them yet
    assert left_running(started) == []


def test_a_launcher_killed_while_its_robots_move_leaves_none_running_and_they_write_what_they_have(tmp_path, start):
    results = tmp_path / "run"
    launcher = live_launcher(start, results)

    def moving() -> bool:
        reports = [results / f"agent-{index}.json" for index in range(2)]
        return all(report.exists() and json.loads(report.read_text()).get("started_at") for report in reports)

    assert wait_for(moving, step=0.05), "the fleet did not start"
    started = children(launcher.pid)
    start.seen(launcher, started)
    assert len(started) == 3
    kill(launcher)
    assert left_running(started) == []
    assert (results / "referee.json").exists()  # the referee finished: it noticed its parent was gone
    for index in range(2):
        assert json.loads((results / f"agent-{index}.json").read_text())["stop_reason"] == "interrupted"


def slow_bench(folder: Path) -> Path:
    """A benchmark of four long runs: CBS with 60 robots on a crowded map searches until its time limit."""
    config = folder / "slow.yaml"
    config.write_text(
        f"maps:\n  - map: {MAPS / 'random-32-32-20.map'}\n    scen: [{MAPS / 'random-32-32-20-random-1.scen'}]\n"
        "agents: [60]\npolicies: [cbs]\nseeds: [0, 1, 2, 3]\ntime_limit: 600\n"
    )
    return config


def runs_of(pid: int) -> list[int]:
    """The processes running one benchmark run each (``python -m mrmp.bench.child``) below ``pid``."""
    return [process for process in descendants(pid) if "mrmp.bench.child" in command_line(process)]


def test_a_benchmark_killed_while_its_workers_run_leaves_no_worker_and_no_run(tmp_path, start):
    bench = start("bench", slow_bench(tmp_path), "--out", tmp_path / "out", "--workers", "2")
    assert wait_for(lambda: len(runs_of(bench.pid)) == 2, step=0.05), "the workers did not start their runs"
    started = descendants(bench.pid)  # the workers (and any helper of the pool) and the runs
    start.seen(bench, started)
    kill(bench)
    assert left_running(started) == []


def test_a_benchmark_killed_as_soon_as_its_workers_exist_leaves_none_waiting(tmp_path, start):
    bench = start("bench", slow_bench(tmp_path), "--out", tmp_path / "out", "--workers", "2")
    assert wait_for(lambda: len(descendants(bench.pid)) >= 2), "the workers did not start"
    workers = descendants(bench.pid)
    kill(bench)  # the workers are starting, or waiting for work on the pool's call queue
    started = workers + [run for worker in workers for run in descendants(worker)]  # and what a worker started since
    start.seen(bench, started)
    assert len(workers) >= 2 and left_running(started) == []
