"""A League of Robot Runners problem live: throughput of real robot processes against the simulator's.

Runs one LoRR problem for ``--steps`` steps three ways, side by side, with the
same brains (decentralized ``pibt``, ``turning`` bodies, crisscross guidance,
the problem's defaults):

* the simulator, on a perfect network (the decisions' own throughput);
* live: one ``mrmp agent`` process per robot (``--robots-per-process`` to
  host several), UDP on loopback with ``--loss``, the task desk a thread of
  the launcher (:mod:`mrmp.live.task_desk`);
* the same live fleet on a virtual clock (:mod:`mrmp.live.virtual_time`),
  with the same loss.

It prints tasks finished, errands reached, the throughput ratio to the
simulator's, the referee's collisions and unvisited errands, messages per
robot-step and the wall time. Tasks and errands are counts (deterministic in
the simulator and on the virtual clock); the live row depends on the machine's
load, printed with it.

Default: ``examples/lorr/warehouse-small_24.json`` (24 robots on MovingAI's
warehouse-10-20-10-2-1), 200 steps, 10% loss, time scale 5.

Usage: python bench/live_lorr.py [--problem FILE.json] [--steps 200] [--loss 0.1] [--time-scale 5]
       [--robots N] [--robots-per-process 1] [--no-virtual]
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from mrmp.api import run as simulate
from mrmp.core.result import RunResult
from mrmp.io.lorr import lorr_scenario, read_lorr_problem
from mrmp.live.launcher import LiveOptions, run_live
from mrmp.live.transport import LiveFaults
from mrmp.live.virtual_time import VirtualOptions, run_virtual

PROBLEM = Path(__file__).resolve().parents[1] / "examples" / "lorr" / "warehouse-small_24.json"


def describe(label: str, result: RunResult, simulated_tasks: int, robots: int, steps: int) -> str:
    """One printed row: tasks, errands, throughput ratio, collisions, errands not visited, messages, time."""
    assert result.tasks is not None
    tasks, errands = result.tasks.finished, len(result.tasks.events)
    ratio = f"{tasks / simulated_tasks:.2f}" if simulated_tasks else "-"
    not_visited = result.network.get("tasks_errands_not_visited", "-")
    per_step = result.messages / (robots * steps)
    return (
        f"  {label:<22} tasks {tasks:>4} (x{ratio}), errands {errands:>4}, collisions {len(result.collisions)}, "
        f"errands not visited {not_visited}, messages/robot-step {per_step:.1f}, {result.wall_time_s:.1f} s, "
        f"stop: {result.stop_reason}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problem", type=Path, default=PROBLEM)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--loss", type=float, default=0.1)
    parser.add_argument("--time-scale", type=float, default=5.0)
    parser.add_argument("--robots", type=int, default=None, help="the problem's first N robots (default: its team)")
    parser.add_argument("--robots-per-process", type=int, default=1)
    parser.add_argument("--no-virtual", action="store_true")
    arguments = parser.parse_args()
    problem = read_lorr_problem(arguments.problem)
    if arguments.robots is not None:
        problem = problem.with_team(arguments.robots)
    scenario = lorr_scenario(problem, steps=arguments.steps)
    robots, steps = len(scenario.robots), arguments.steps
    faults = LiveFaults(loss=arguments.loss)
    print(
        f"{scenario.name}: {robots} robots, {steps} steps, pibt ({scenario.policy.sequencing} sequencing, "
        f"{scenario.policy.guidance} guidance), {scenario.policy.body} bodies, loss {arguments.loss:.0%}, "
        f"time scale {arguments.time_scale:g}",
        flush=True,
    )
    simulated = simulate(scenario).run
    assert simulated.tasks is not None
    base = simulated.tasks.finished
    print(describe("simulator", simulated, base, robots, steps), flush=True)
    with tempfile.TemporaryDirectory(prefix="mrmp-live-lorr-") as folder:
        options = LiveOptions(
            time_scale=arguments.time_scale, faults=faults, results=Path(folder) / "live",
            robots_per_process=arguments.robots_per_process, seed=0,
        )  # fmt: skip
        live = run_live(scenario, options)
        load = ", load {:.1f} {:.1f} {:.1f}".format(*os.getloadavg())
        print(describe("live, UDP processes", live, base, robots, steps) + load, flush=True)
        if not arguments.no_virtual:
            virtual_options = VirtualOptions(results=Path(folder) / "virtual", time_scale=arguments.time_scale, faults=faults)
            virtual = run_virtual(scenario, virtual_options)
            print(describe("live, virtual clock", virtual, base, robots, steps) + " (CPU time)", flush=True)


if __name__ == "__main__":
    main()
