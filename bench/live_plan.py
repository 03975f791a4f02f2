"""A central LaCAM plan executed live, one robot process each, on loopback: does the fleet keep the plan's pace?

Plans ``--agents`` robots of a MovingAI scenario (random-32-32-20 by default) with
LaCAM, executes the plan live over UDP with ``--loss`` message loss at
``--time-scale`` times the robots' speed (optionally killing robots: ``--kill
ID@SECONDS``), and prints, per time scale: robots arrived, collisions, the wall
makespan against the plan's makespan in seconds at that speed (plan ticks x cell
time / time scale), the plan's execution bound at that speed and the wall makespan
against it, moves, and messages per move (datagram-recipients, heartbeats included).

The execution bound (:func:`mrmp.centralized.body_time.execution_seconds`) is the
soonest live bodies can carry the plan out, whatever messages cost: they turn right
only, which the plan's ticks do not count, and cover both cells while they move, so a
robot that follows another into a cell it leaves in the same tick starts once the
other has arrived. It is what the messages are measured against. Before the runs, the
bound is printed as a multiple of the plan's ticks times the cell time, and so is the
bound of bodies that turn in no time (what following alone costs).

Usage: python bench/live_plan.py [--agents 100] [--time-scales 2,5] [--loss 0.1] [--kill 3@2]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

from mrmp.centralized.body_time import execution_seconds
from mrmp.centralized.registry import plan_with
from mrmp.io import load_movingai_scenario
from mrmp.live.launcher import LiveOptions, run_live
from mrmp.live.transport import LiveFaults

MAPS = Path(__file__).resolve().parents[1] / "maps"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", type=Path, default=MAPS / "random-32-32-20.map")
    parser.add_argument("--scen", type=Path, default=MAPS / "random-32-32-20-random-1.scen")
    parser.add_argument("--agents", type=int, default=100)
    parser.add_argument("--time-scales", default="2")
    parser.add_argument("--loss", type=float, default=0.1)
    parser.add_argument("--kill", action="append", default=[], help="ID@SECONDS (repeatable)")
    arguments = parser.parse_args()
    scenario = load_movingai_scenario(arguments.map, arguments.scen, arguments.agents)
    plan = plan_with("lacam", scenario, time_limit_s=60)
    if plan.paths is None:
        print(f"lacam: no plan ({plan.status}: {plan.message})")
        return 1
    kill = {robot: float(seconds) for robot, seconds in (text.split("@") for text in arguments.kill)}
    print(f"{scenario.name}: {arguments.agents} robots, plan makespan {plan.makespan()} ticks,", end=" ")
    print(f"loss {arguments.loss}, kill {kill}")
    headings = [robot.heading for robot in scenario.robots]
    instant_turns = replace(scenario.timing, turn_time=0.0)
    bound_ticks = execution_seconds(plan.paths, headings, scenario.timing) / scenario.timing.cell_time
    following_ticks = execution_seconds(plan.paths, headings, instant_turns) / scenario.timing.cell_time
    print(
        f"execution bound: {bound_ticks / plan.makespan():.2f} times the plan's ticks x cell time"
        f" ({following_ticks / plan.makespan():.2f} with bodies turning in no time: following alone)"
    )
    print(
        f"{'scale':>5} {'arrived':>8} {'coll':>4} {'wall s':>7} {'plan s':>7} {'ratio':>6} {'bound s':>7} {'/bound':>6}"
        f" {'moves':>6}"
        f" {'messages':>9} {'msg/move':>8}  stop"
    )
    for scale in [float(text) for text in arguments.time_scales.split(",")]:
        folder = Path(tempfile.mkdtemp(prefix=f"mrmp-bench-plan-{arguments.agents}-"))
        options = LiveOptions(results=folder, time_scale=scale, plan=plan, faults=LiveFaults(loss=arguments.loss), kill=kill)
        result = run_live(scenario, options)
        arrived = sum(robot.arrived for robot in result.robots)
        moves = max(1, result.network.get("moves", 0))
        planned = plan.makespan() * scenario.timing.cell_time / scale
        bound = execution_seconds(plan.paths, headings, scenario.timing, scale)
        print(
            f"{scale:>5g} {arrived:>4}/{len(result.robots):<3} {len(result.collisions):>4} {result.time_makespan_s:>7.2f}"
            f" {planned:>7.2f} {result.time_makespan_s / planned:>6.2f} {bound:>7.2f} {result.time_makespan_s / bound:>6.2f}"
            f" {moves:>6} {result.messages:>9}"
            f" {result.messages / moves:>8.1f}  {result.stop_reason}",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
