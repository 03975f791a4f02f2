"""Live ``pibt`` (local sequencing, one process per robot) against the simulator, and beside live ``causal``.

For each case: run the scenario live (``mrmp run --live``'s launcher, loopback)
and in the simulator, and print whether every robot arrived, the referee's
collisions, the wall-clock makespan, the simulator's makespan in ticks times
the cell time (at the run's time scale) and their ratio (the target: at most
1.5), the live run's ideal (the longest single-robot path at that speed), moves,
messages per move, and the live robots' own counts (steps begun held, steps
abandoned, retransmissions). The machine's load (1-minute load average before
and after each run, and the number of cores) is printed with every row: times
are only comparable side by side on one machine.

The simulator runs the same scenario with ``pibt``'s local sequencing over a
perfect network (``LocalRoundsSimulator``); its makespan counts steps of one
tick, each one cell time long.

Cases (``--cases``, comma-separated):

* ``udp24``, ``zenoh24``: 24 robots of ``examples/causal-32.yaml`` (16x16 map
  with obstacles), 20% loss, over UDP or Zenoh;
* ``udp64``: 64 robots on the same map (starts and goals drawn with seed 0), 10% loss;
* ``side``: ``examples/causal-32.yaml`` (32 robots, perfect network) live with ``pibt``
  and with ``causal``, side by side.

Usage: python bench/live_pibt.py [--cases udp24,zenoh24,udp64,side] [--time-scale 2]
"""

from __future__ import annotations

import argparse
import os
import random
import sys
import tempfile
import time
from pathlib import Path

from mrmp.core import NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.core.result import RunResult
from mrmp.io.scenario_file import load_scenario
from mrmp.live.launcher import LiveOptions, run_live
from mrmp.live.transport import LiveFaults
from mrmp.sim.local_rounds import LocalRoundsSimulator

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "causal-32.yaml"


def example(count: int | None = None, policy: str = "pibt") -> Scenario:
    """``examples/causal-32.yaml`` with its first ``count`` robots (all by default), policy ``policy``."""
    scenario = load_scenario(EXAMPLE)
    robots = scenario.robots if count is None else scenario.robots[:count]
    return scenario.with_changes(robots=robots, policy=PolicyOptions(name=policy), name=f"{scenario.name}-{len(robots)}")


def drawn(count: int, seed: int = 0) -> Scenario:
    """``count`` robots on the example's map, starts and goals drawn from its free cells with ``seed``."""
    scenario = load_scenario(EXAMPLE)
    grid = scenario.grid
    free = [(x, y) for x in range(grid.x_size) for y in range(grid.y_size) if grid.is_free((x, y))]
    rng = random.Random(seed)
    starts, goals = rng.sample(free, count), rng.sample(free, count)
    robots = tuple(RobotSpec(f"r{i}", start, goal) for i, (start, goal) in enumerate(zip(starts, goals, strict=True)))
    return scenario.with_changes(robots=robots, policy=PolicyOptions(name="pibt"), name=f"drawn-{count}")


def simulated_makespan(scenario: Scenario) -> int:
    """The makespan in ticks of ``pibt`` with local sequencing over a perfect network."""
    local = scenario.with_changes(policy=PolicyOptions(name="pibt", sequencing="local"), network=NetworkFaults())
    result = LocalRoundsSimulator(local).run()
    return result.makespan if result.success else -1


def live(scenario: Scenario, transport: str, loss: float, time_scale: float) -> tuple[RunResult, float, float, float]:
    """Run ``scenario`` live; return the result, the load average before and after, and the wall time."""
    before = os.getloadavg()[0]
    folder = Path(tempfile.mkdtemp(prefix=f"mrmp-live-pibt-{scenario.name}-"))
    options = LiveOptions(transport=transport, time_scale=time_scale, faults=LiveFaults(loss=loss), results=folder)
    began = time.monotonic()
    result = run_live(scenario, options)
    return result, before, os.getloadavg()[0], time.monotonic() - began


def row(label: str, scenario: Scenario, transport: str, loss: float, time_scale: float, compare: bool = True) -> None:
    result, load_before, load_after, _ = live(scenario, transport, loss, time_scale)
    cell = scenario.timing.cell_time / time_scale
    network = result.network
    moves = max(1, network.get("moves", 0))
    arrived = sum(robot.arrived for robot in result.robots)
    if compare:
        ticks = simulated_makespan(scenario)
        simulated = ticks * cell
        ratio = f"{result.time_makespan_s / simulated:.2f}" if ticks > 0 else "-"
        sim_text = f"{ticks} ticks = {simulated:.2f} s"
    else:
        sim_text, ratio = "-", "-"
    print(
        f"{label}: {scenario.policy.name} {len(scenario.robots)} robots over {transport}, loss {loss:.0%}, "
        f"time scale {time_scale:g} (cell {cell:.2f} s): arrived {arrived}/{len(scenario.robots)}, "
        f"collisions {len(result.collisions)}, wall makespan {result.time_makespan_s:.2f} s, "
        f"simulator {sim_text}, ratio {ratio}, ideal {result.ideal_makespan_s or 0:.2f} s "
        f"(x{result.time_makespan_s / (result.ideal_makespan_s or 1):.2f}), moves {moves}, "
        f"messages/move {result.messages / moves:.1f}, held {network.get('safety_pibt_held', 0)}, "
        f"abandoned {network.get('safety_pibt_abandoned', 0)}, "
        f"retransmissions {network.get('safety_pibt_retransmissions', 0)}, stop: {result.stop_reason}; "
        f"load {load_before:.1f} -> {load_after:.1f} on {os.cpu_count()} cores",
        flush=True,
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="udp24,zenoh24,udp64,side")
    parser.add_argument("--time-scale", type=float, default=2.0)
    arguments = parser.parse_args()
    scale = arguments.time_scale
    for case in arguments.cases.split(","):
        if case == "udp24":
            row(case, example(24), "udp", 0.2, scale)
        elif case == "zenoh24":
            row(case, example(24), "zenoh", 0.2, scale)
        elif case == "udp64":
            row(case, drawn(64), "udp", 0.1, scale)
        elif case == "side":
            row(case, example(), "udp", 0.0, scale)
            row(case, example(policy="causal"), "udp", 0.0, scale, compare=False)
        else:
            print(f"unknown case {case!r}", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
