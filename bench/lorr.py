"""mrmp's fleet against the League of Robot Runners' own planner, on the competition's problems, side by side.

For each case (a problem of the Start-Kit's ``example_problems``, optionally
with fewer robots than its ``teamSize``) this runs, on the same problem for
the same number of steps:

* the Start-Kit's default entry (its greedy scheduler and its planner: PIBT
  with traffic-flow guide paths, C++, Release build), through the Start-Kit's
  own simulator (``build/lifelong -s STEPS -t PLAN_MS``);
* mrmp, once per sequencing of ``--sequencings`` and guidance of ``--guidances``
  (default: all four): ``pibt`` computed by the robots' messages in the ``turning``
  body, the robots ordering their calls themselves (``local``, fully decentralized)
  or the simulator starting them in priority order (``driver``), their tables
  guided by lanes (``crisscross``, :mod:`mrmp.search.guidance`) or not (``none``),
  the same greedy scheduler (:mod:`mrmp.sim.task_book`), in the simulator
  (:func:`mrmp.io.lorr.lorr_scenario`);

and prints, one row per sequencing and guidance, the tasks each finished (LoRR's score, ``numTaskFinished``), their
ratio, the seconds per step (the Start-Kit's mean ``plannerTimes``; mrmp's
wall time of the whole run over its steps, robots, messages and task book
included) and their ratio, mrmp's collisions and its messages per robot-step.
One step is one LoRR action (the 2024 rules: Start-Kit v2.1.0). Each row is
appended to ``--out`` (JSON lines) as soon as it is measured; the Start-Kit's
processes end with the script, however it is killed.

The Start-Kit is not shipped with mrmp: give its source tree (v2.1.0,
MAPF-Competition/Start-Kit commit 5ea4fa1, MIT license) with ``--start-kit``;
it is built in its own ``build/`` folder when ``build/lifelong`` is missing
(cmake, a C++17 compiler and Boost: program_options, system, filesystem, log).
The default planner spends what its time limit allows on the guide paths;
``--plan-ms`` sets that limit (on random-32-32-20 with 100 robots, 500 steps,
it finished 899 tasks at its default 1000 ms and 902 at 100 ms).

Usage: python bench/lorr.py --start-kit PATH [--cases random.domain/random_32_32_20_100.json,...] [--steps 500]
       [--sequencings local,driver] [--guidances crisscross,none]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from mrmp.core.errors import InputError
from mrmp.core.options import GUIDANCES, SEQUENCINGS
from mrmp.io.lifetime import preexec_dying_with
from mrmp.io.lorr import load_lorr_scenario
from mrmp.sim.simulator import simulate

CASES = (
    "random.domain/random_32_32_20_100.json,"
    "warehouse.domain/warehouse_large_5000.json:200,"
    "warehouse.domain/sortation_large_2000.json:200"
)
"""The Start-Kit v2.1.0 example problems measured by default, ``:N`` keeping the first N robots (about 6 minutes
here, for both sequencings and both guidances). ``warehouse.domain/warehouse_large_5000.json:1000``,
``city.domain/paris_1_256_250.json`` and ``game.domain/brc202d_500.json`` (5 GB) take 2 to 6 minutes more each."""
MOST_STEPS = 100_000


@dataclass
class Row:
    """One case measured both ways."""

    problem: str
    robots: int
    steps: int
    sequencing: str
    guidance: str
    start_kit_tasks: int
    mrmp_tasks: int
    start_kit_step_s: float
    mrmp_step_s: float
    mrmp_collisions: int
    mrmp_messages_per_robot_step: float

    @property
    def task_ratio(self) -> float:
        return self.mrmp_tasks / self.start_kit_tasks if self.start_kit_tasks else float("nan")

    @property
    def time_ratio(self) -> float:
        return self.mrmp_step_s / self.start_kit_step_s if self.start_kit_step_s else float("nan")


def fail(message: str) -> int:
    """Print ``error: message`` on stderr; the exit code of bad input."""
    print(f"error: {message}", file=sys.stderr)
    return 2


def build(start_kit: Path) -> Path:
    """The Start-Kit's ``lifelong`` program, built (Release) in ``start_kit/build`` if it is not there yet."""
    program = start_kit / "build" / "lifelong"
    if program.exists():
        return program
    log = start_kit / "build-mrmp.log"
    print(f"building the Start-Kit in {start_kit / 'build'} (log: {log}) ...", flush=True)
    with log.open("w") as output:
        for command in (
            ["cmake", "-B", "build", ".", "-DPYTHON=false", "-DCMAKE_BUILD_TYPE=Release"],
            ["make", "-C", "build", "-j2"],
        ):
            subprocess.run(
                command, cwd=start_kit, stdout=output, stderr=subprocess.STDOUT, check=True,
                preexec_fn=preexec_dying_with(signal.SIGKILL),
            )  # fmt: skip
    return program


def case_problem(start_kit: Path, case: str, scratch: Path) -> tuple[Path, str]:
    """The problem file of ``case`` (``DOMAIN/FILE.json[:N]``) and its name; with ``:N`` a copy keeping N robots.

    The copy is written in ``scratch``, its files named relative to it (LoRR
    resolves them from the problem's folder), so that nothing is written into
    the Start-Kit's tree.
    """
    name, _, robots = case.partition(":")
    problem = start_kit / "example_problems" / name
    if not problem.is_file():
        raise InputError(f"--cases: {problem} is not a file")
    if not robots:
        return problem, problem.stem
    if not robots.isdigit() or int(robots) < 1:
        raise InputError(f"--cases: {case}: N must be a positive whole number")
    data = json.loads(problem.read_text())
    if int(robots) > data["teamSize"]:
        raise InputError(f"--cases: {case}: the problem has {data['teamSize']} robots")
    data["teamSize"] = int(robots)
    back = os.path.relpath(problem.parent, scratch)
    for field in ("mapFile", "agentFile", "taskFile"):
        data[field] = f"{back}/{data[field]}"
    copy = scratch / f"{problem.stem}-{robots}.json"
    copy.write_text(json.dumps(data, indent=4))
    return copy, f"{problem.stem}:{robots}"


def start_kit_run(program: Path, problem: Path, steps: int, plan_ms: int, scratch: Path) -> tuple[int, float]:
    """Tasks finished and mean planner seconds per step of the Start-Kit's default entry on ``problem``."""
    output = scratch / f"{problem.stem}-start-kit.json"
    command = [str(program), "-i", str(problem), "-o", str(output), "-s", str(steps), "-t", str(plan_ms)]
    command += ["-l", str(scratch / f"{problem.stem}-start-kit.log")]
    subprocess.run(
        command, cwd=scratch, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True,
        preexec_fn=preexec_dying_with(signal.SIGKILL),
    )  # fmt: skip
    result = json.loads(output.read_text())
    times = result.get("plannerTimes") or [0.0]
    return int(result["numTaskFinished"]), sum(times) / len(times)


def measure(
    program: Path, start_kit: Path, case: str, steps: int, plan_ms: int, fleets: list[tuple[str, str]], scratch: Path
) -> Iterator[Row]:
    """One case, the Start-Kit first, then mrmp once per ``(sequencing, guidance)`` of ``fleets``: each row as soon as
    it is measured."""
    problem, name = case_problem(start_kit, case, scratch)
    start_kit_tasks, start_kit_step = start_kit_run(program, problem, steps, plan_ms, scratch)
    lorr = load_lorr_scenario(problem, steps)
    robots = len(lorr.robots)
    for sequencing, guidance in fleets:
        scenario = lorr.with_changes(policy=replace(lorr.policy, sequencing=sequencing, guidance=guidance))
        started = time.perf_counter()
        result = simulate(scenario)
        wall = time.perf_counter() - started
        assert result.tasks is not None
        yield Row(
            name, robots, steps, sequencing, guidance, start_kit_tasks, result.tasks.finished, start_kit_step,
            wall / max(1, result.ticks), len(result.collisions), result.messages / max(1, result.ticks * robots),
        )  # fmt: skip


def listed(text: str, known: tuple[str, ...], option: str) -> list[str]:
    """The comma-separated names of ``text``, each one of ``known``.

    Raises
    ------
    InputError
        Naming ``option`` when a name is not known.
    """
    names = text.split(",")
    if any(name not in known for name in names):
        raise InputError(f"{option}: expected some of {', '.join(known)}, got {text!r}")
    return names


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--start-kit", type=Path, required=True, help="the Start-Kit v2.1.0 source tree")
    parser.add_argument("--cases", default=CASES, help="DOMAIN/FILE.json[:N], comma-separated (in its example_problems)")
    parser.add_argument("--steps", type=int, default=500, help="steps of every run")
    parser.add_argument("--plan-ms", type=int, default=100, help="the Start-Kit planner's time limit per step (ms)")
    parser.add_argument("--sequencings", default="local,driver", help="mrmp's orders of calls, comma-separated")
    parser.add_argument("--guidances", default="crisscross,none", help="mrmp's lanes, comma-separated")
    parser.add_argument("--out", type=Path, default=Path("lorr-results.jsonl"), help="JSON lines, one per case")
    arguments = parser.parse_args()
    try:
        sequencings = listed(arguments.sequencings, SEQUENCINGS, "--sequencings")
        guidances = listed(arguments.guidances, GUIDANCES, "--guidances")
    except InputError as error:
        return fail(str(error))
    fleets = [(sequencing, guidance) for sequencing in sequencings for guidance in guidances]
    start_kit = arguments.start_kit.resolve()
    if not (start_kit / "CMakeLists.txt").is_file() or not (start_kit / "default_planner").is_dir():
        return fail(f"--start-kit: {start_kit} is not a Start-Kit source tree (no CMakeLists.txt and default_planner/)")
    if not 1 <= arguments.steps <= MOST_STEPS:
        return fail(f"--steps: must be between 1 and {MOST_STEPS}, got {arguments.steps}")
    if not 1 <= arguments.plan_ms <= 60_000:
        return fail(f"--plan-ms: must be between 1 and 60000, got {arguments.plan_ms}")
    try:
        program = build(start_kit)
    except (OSError, subprocess.CalledProcessError) as error:
        return fail(f"--start-kit: building the Start-Kit failed ({error}); see {start_kit / 'build-mrmp.log'}")
    print(
        f"{'problem':<26} {'N':>5} {'steps':>5} {'sequencing':>10} {'guidance':>10} {'SK tasks':>8} {'mrmp tasks':>10} "
        f"{'ratio':>6} {'SK s/step':>9} {'mrmp s/step':>11} {'ratio':>6} {'coll':>4} {'msg/robot-step':>14}",
        flush=True,
    )
    with tempfile.TemporaryDirectory(prefix="mrmp-lorr-") as folder:
        scratch = Path(folder)
        for case in arguments.cases.split(","):
            rows = measure(program, start_kit, case, arguments.steps, arguments.plan_ms, fleets, scratch)
            try:
                for row in rows:
                    write_row(arguments.out, row)
            except InputError as error:
                return fail(str(error))
            except subprocess.CalledProcessError as error:
                return fail(f"{case}: the Start-Kit failed with exit code {error.returncode}")
    return 0


def write_row(out: Path, row: Row) -> None:
    """Append ``row`` to ``out`` (JSON lines), then print it."""
    with out.open("a") as stream:
        stream.write(json.dumps({**asdict(row), "task_ratio": row.task_ratio, "time_ratio": row.time_ratio}) + "\n")
    print(
        f"{row.problem:<26} {row.robots:>5} {row.steps:>5} {row.sequencing:>10} {row.guidance:>10} "
        f"{row.start_kit_tasks:>8} {row.mrmp_tasks:>10} {row.task_ratio:>6.3f} {row.start_kit_step_s:>9.4f} "
        f"{row.mrmp_step_s:>11.4f} {row.time_ratio:>6.2f} {row.mrmp_collisions:>4} {row.mrmp_messages_per_robot_step:>14.2f}",
        flush=True,
    )


if __name__ == "__main__":
    raise SystemExit(main())
