"""What a live robot process costs: CPU seconds per wall second of each ``mrmp agent`` process and of the referee.

Runs fleets live over UDP on loopback (one process per robot, ``--loss``
message loss, ``--time-scale``) on a 32x32 MovingAI map, for each driver of
``--drivers`` (``lacam``: a LaCAM plan executed by the plan-following driver;
``pibt``, ``causal``: the policies' own live drivers) and each fleet of
``--fleets``:

* ``moving``: every robot has its own start and goal (the map's scenario file);
* ``idle``: every robot but the first starts on its goal, so the fleet waits,
  arrived, while one robot crosses the map (what most robots do at the end of a run).

While a run goes on, this process reads every child's CPU time
(``utime + stime`` of ``/proc/PID/stat``) every ``--sample`` seconds and
prints, per run: robots arrived, collisions, wall time; each agent's CPU
seconds per wall second during the fleet's run (from the moment the last robot
began to the moment the first one stopped; mean and maximum over the agents),
the referee's, the CPU seconds an agent spent before the fleet began (start-up:
imports, reading the files, waiting for its peers), an agent's wake-ups per
second (voluntary context switches of all its threads, which depend less on
the machine's load than CPU seconds), all the children's CPU seconds per wall second, and the
one-minute load average at the end. Times are ratios of one machine: compare runs made side by side.

Usage: python bench/live_cpu.py [--robots 16,32] [--drivers lacam,pibt,causal] [--fleets moving,idle]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

from mrmp.centralized.registry import plan_with
from mrmp.core import PolicyOptions, Scenario
from mrmp.core.result import RunResult
from mrmp.io import load_movingai_scenario
from mrmp.io.live_files import read_json
from mrmp.live.launcher import LiveOptions, run_live
from mrmp.live.transport import LiveFaults

MAPS = Path(__file__).resolve().parents[1] / "maps"
TICKS_PER_SECOND = os.sysconf("SC_CLK_TCK")


@dataclass
class Samples:
    """CPU seconds of each child process (by pid) at each sampling time, and what each child is."""

    times: list[float] = field(default_factory=list)
    cpu: dict[int, list[tuple[float, float]]] = field(default_factory=dict)
    wakeups: dict[int, list[tuple[float, float]]] = field(default_factory=dict)
    kind: dict[int, str] = field(default_factory=dict)
    robot: dict[int, int] = field(default_factory=dict)


def children_of(parent: int) -> list[int]:
    """The pids of ``parent``'s children (from ``/proc/*/stat``)."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        if int(fields[1]) == parent:
            found.append(int(entry))
    return found


def wakeups(pid: int) -> int | None:
    """Voluntary context switches of every thread of ``pid`` so far (each is a wake-up after a sleep), or None."""
    total = 0
    try:
        for task in os.listdir(f"/proc/{pid}/task"):
            for line in Path(f"/proc/{pid}/task/{task}/status").read_text().splitlines():
                if line.startswith("voluntary_ctxt_switches:"):
                    total += int(line.split()[1])
    except (OSError, ValueError):
        return None
    return total


def cpu_seconds(pid: int) -> float | None:
    """``utime + stime`` of ``pid`` in seconds, or None once it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / TICKS_PER_SECOND


def describe(pid: int, scenario: Scenario, samples: Samples) -> None:
    """Record whether ``pid`` is the referee or which robot's agent it is."""
    try:
        arguments = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    except OSError:
        return
    text = [argument.decode() for argument in arguments]
    if "referee" in text:
        samples.kind[pid] = "referee"
    elif "agent" in text:
        robot_id = next((argument.split("=", 1)[1] for argument in text if argument.startswith("--robot=")), "")
        ids = [robot.id for robot in scenario.robots]
        if robot_id in ids:
            samples.kind[pid] = "agent"
            samples.robot[pid] = ids.index(robot_id)


def sample(scenario: Scenario, samples: Samples, period: float, done: threading.Event) -> None:
    """Every ``period`` seconds, read the CPU time of every child of this process until ``done``."""
    me = os.getpid()
    while not done.is_set():
        now = time.monotonic()
        for pid in children_of(me):
            if pid not in samples.kind:
                describe(pid, scenario, samples)
            seconds, woken = cpu_seconds(pid), wakeups(pid)
            if seconds is not None and woken is not None and pid in samples.kind:
                samples.cpu.setdefault(pid, []).append((now, seconds))
                samples.wakeups.setdefault(pid, []).append((now, woken))
        samples.times.append(now)
        done.wait(period)


def rate(series: list[tuple[float, float]], begin: float, end: float) -> float | None:
    """CPU seconds per wall second between the first sample at or after ``begin`` and the last at or before ``end``."""
    inside = [point for point in series if begin <= point[0] <= end]
    if len(inside) < 2 or inside[-1][0] - inside[0][0] <= 0:
        return None
    return (inside[-1][1] - inside[0][1]) / (inside[-1][0] - inside[0][0])


def before(series: list[tuple[float, float]], moment: float) -> float | None:
    """CPU seconds spent by the last sample at or before ``moment``."""
    earlier = [seconds for t, seconds in series if t <= moment]
    return earlier[-1] if earlier else None


def fleet(driver: str, robots: int, kind: str) -> Scenario:
    """The scenario of one run (module docstring)."""
    scenario = load_movingai_scenario(MAPS / "random-32-32-20.map", MAPS / "random-32-32-20-random-1.scen", robots)
    if kind == "idle":
        specs = [scenario.robots[0], *(replace(spec, goal=spec.start) for spec in scenario.robots[1:])]
        scenario = scenario.with_changes(robots=tuple(specs), name=f"{scenario.name}-idle")
    if driver in ("pibt", "causal"):
        scenario = scenario.with_changes(policy=PolicyOptions(name=driver))
    return scenario


def measure(driver: str, robots: int, kind: str, arguments: argparse.Namespace) -> None:
    """One run, measured and printed (module docstring)."""
    scenario = fleet(driver, robots, kind)
    plan = plan_with("lacam", scenario, time_limit_s=60) if driver == "lacam" else None
    folder = Path(tempfile.mkdtemp(prefix=f"mrmp-bench-cpu-{driver}-{robots}-"))
    options = LiveOptions(
        results=folder, time_scale=arguments.time_scale, plan=plan, faults=LiveFaults(loss=arguments.loss)
    )
    samples, done = Samples(), threading.Event()
    sampler = threading.Thread(target=sample, args=(scenario, samples, arguments.sample, done), daemon=True)
    children_before = resource.getrusage(resource.RUSAGE_CHILDREN)
    began = time.monotonic()
    sampler.start()
    try:
        result: RunResult = run_live(scenario, options)
    finally:
        done.set()
        sampler.join()
    wall = time.monotonic() - began
    children_after = resource.getrusage(resource.RUSAGE_CHILDREN)
    total = (children_after.ru_utime + children_after.ru_stime) - (children_before.ru_utime + children_before.ru_stime)
    reports = [read_json(path) for path in sorted(folder.glob("agent-*.json"))]
    starts = [float(report["started_at"]) for report in reports if report.get("started_at")]
    ends = [float(report["ended_at"]) for report in reports if report.get("ended_at")]
    fleet_start, fleet_end = (max(starts), min(ends)) if starts and ends else (began, began + wall)
    agents = [pid for pid, what in samples.kind.items() if what == "agent"]
    referee = [pid for pid, what in samples.kind.items() if what == "referee"]
    running = [r for pid in agents if (r := rate(samples.cpu[pid], fleet_start, fleet_end)) is not None]
    woken = [r for pid in agents if (r := rate(samples.wakeups[pid], fleet_start, fleet_end)) is not None]
    startup = [s for pid in agents if (s := before(samples.cpu[pid], fleet_start)) is not None]
    referee_rate = rate(samples.cpu[referee[0]], fleet_start, fleet_end) if referee and referee[0] in samples.cpu else None
    arrived = sum(robot.arrived for robot in result.robots)
    print(
        f"{driver:>6} {kind:>6} {robots:>4} {arrived:>4}/{robots:<4} {len(result.collisions):>4} {wall:>7.1f}"
        f" {fleet_end - fleet_start:>7.1f} {_mean(running):>8} {_max(running):>8} {_fmt(referee_rate):>8}"
        f" {_mean(startup):>8} {_mean(woken, 0):>7} {total / wall:>8.2f} {os.getloadavg()[0]:>6.1f}  {result.stop_reason}",
        flush=True,
    )


def _fmt(value: float | None, digits: int = 3) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def _mean(values: list[float], digits: int = 3) -> str:
    return _fmt(statistics.fmean(values) if values else None, digits)


def _max(values: list[float]) -> str:
    return _fmt(max(values) if values else None)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", default="16,32")
    parser.add_argument("--drivers", default="lacam,pibt,causal")
    parser.add_argument("--fleets", default="moving,idle")
    parser.add_argument("--time-scale", type=float, default=2.0)
    parser.add_argument("--loss", type=float, default=0.1)
    parser.add_argument("--sample", type=float, default=0.5, help="seconds between two readings of the CPU times")
    arguments = parser.parse_args()
    print(
        f"{'driver':>6} {'fleet':>6} {'N':>4} {'arrived':>9} {'coll':>4} {'wall s':>7} {'run s':>7}"
        f" {'agent':>8} {'max':>8} {'referee':>8} {'start-up':>8} {'wakeups':>7} {'all/wall':>8} {'load':>6}  stop"
    )
    print(
        f"{'':>6} {'':>6} {'':>4} {'':>9} {'':>4} {'':>7} {'':>7} {'CPU s/s':>8} {'CPU s/s':>8} {'CPU s/s':>8}"
        f" {'CPU s':>8} {'/s':>7} {'CPU s/s':>8}"
    )
    for robots in [int(text) for text in arguments.robots.split(",")]:
        for driver in arguments.drivers.split(","):
            for kind in arguments.fleets.split(","):
                measure(driver, robots, kind, arguments)
    return 0


if __name__ == "__main__":
    sys.exit(main())
