"""Decentralized ``pibt`` for ``turning`` bodies: the driver's order of calls against the robots' own, side by side.

For each case (a MovingAI map of ``maps/`` and its random-1 scenario's first N
agents), the fleet's ``pibt`` plans for bodies that turn in place (LoRR's
``MAPF_T``, swap off) over a perfect network, seed 0, one tick per step, with
each order of calls (``--orders``):

* ``driver``: the simulator starts the calls in priority order (the central
  generator's decisions, a move cancelled by a chain of stays);
* ``clock``: local sequencing, steps on a common clock (the ahead-or-stay rule,
  ``docs/protocol.md``, "Planning for ``turning`` bodies");
* ``local``: local sequencing with the local synchronizer (each robot ends its steps).

It prints the robots that arrived, the makespan (the tick limit when some did
not), the sum of costs, the lower bound (each robot's best ``(cell, heading)``
path, turns counted), the referee's collisions and the messages per
robot-step. Counts are deterministic; the seconds are for orientation only.

Usage: python bench/pibt_turning.py [--cases random-32-32-20:100,random-32-32-20:200] [--orders driver,clock,local]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from mrmp.core import PolicyOptions
from mrmp.io.scenario_file import load_movingai_scenario
from mrmp.sim.policy_table import pibt_simulator

MAPS = Path(__file__).resolve().parent.parent / "maps"
ORDERS = {"driver": ("driver", "clock"), "clock": ("local", "clock"), "local": ("local", "local")}
"""Each order of calls: its ``sequencing`` and ``synchronizer``."""


def row(map_name: str, agents: int, order: str) -> str:
    """One case run with one order of calls, as a line of the table."""
    sequencing, synchronizer = ORDERS[order]
    scenario = load_movingai_scenario(MAPS / f"{map_name}.map", MAPS / f"{map_name}-random-1.scen", agents)
    policy = PolicyOptions(name="pibt", body="turning", swap=False, sequencing=sequencing, synchronizer=synchronizer)
    began = time.perf_counter()
    result = pibt_simulator(scenario.with_changes(policy=policy, seed=0)).run()
    arrived = sum(robot.arrived for robot in result.robots)
    per_step = result.messages / max(1, agents * result.makespan)
    return (
        f"{map_name:24} {agents:5} {order:7} {arrived:4}/{agents:<4} {result.makespan:8} {result.sum_of_costs:8} "
        f"{result.lower_bound:7} {len(result.collisions):10} {per_step:15.1f} {time.perf_counter() - began:8.1f}"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="random-32-32-20:100,random-32-32-20:200", help="MAP:N pairs, comma-separated")
    parser.add_argument("--orders", default="driver,clock,local", help="orders of calls: driver, clock, local")
    arguments = parser.parse_args()
    orders = arguments.orders.split(",")
    unknown = [order for order in orders if order not in ORDERS]
    if unknown:
        print(f"error: --orders: unknown {', '.join(unknown)}; known: {', '.join(ORDERS)}", file=sys.stderr)
        return 2
    cases = []
    for case in arguments.cases.split(","):
        name, _, count = case.partition(":")
        if not (MAPS / f"{name}.map").exists() or not count.isdigit() or int(count) < 1:
            print(f"error: --cases: {case!r} is not MAP:N with a map of maps/ and N at least 1", file=sys.stderr)
            return 2
        cases.append((name, int(count)))
    print(f"{'map':24} {'N':>5} {'order':7} {'arrived':>9} {'makespan':>8} {'SoC':>8} {'LB':>7} "
          f"{'collisions':>10} {'msg/robot-step':>15} {'seconds':>8}")  # fmt: skip
    for name, count in cases:
        for order in orders:
            print(row(name, count, order), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
