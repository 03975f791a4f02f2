"""A central LaCAM plan executed live by robot processes on loopback: does the fleet keep the plan's pace?

Plans ``--agents`` robots of a MovingAI scenario (random-32-32-20 by default) with
LaCAM, executes the plan live over ``--transport`` (UDP by default), one robot
process each or ``--robots-per-process`` robots to a process (each with its own
socket, driver and body), with ``--loss`` message loss at
``--time-scale`` times the robots' speed (optionally killing robots: ``--kill
ID@SECONDS``), and prints, per body and time scale: robots arrived, collisions, the
wall makespan against the plan's makespan in seconds at that speed (plan ticks x
cell time / time scale), the plan's live execution bound at that speed and the wall
makespan against it, moves and quarter turns, messages per move
(each message counted once per robot it is for, heartbeats included) and
datagrams per move (what the robots put on the network: one per recipient over
UDP, one for several robots over multicast).

Bodies (``--bodies``, comma-separated; ``docs/protocol.md``, "Body models"):

* ``thesis``: an ``omni`` plan (moves to any neighbour, turns free) driven by the
  thesis's bodies, as every live fleet was before bodies were named: they turn
  right only, which the plan's ticks do not count;
* ``turning``: a plan made for ``turning`` bodies (LoRR's ``MAPF_T``: a quarter turn
  either way in place is a tick of its own) driven by such bodies, which turn toward
  their next cell while they wait.

The live execution bound (:func:`mrmp.centralized.body_time.execution_seconds`) is the
soonest live bodies can carry the plan out, whatever messages cost. The thesis's bodies
cover both cells while they move, so the safety layer hands a cell over once its
occupant has arrived elsewhere: a robot that follows another into a cell it leaves in
the same tick starts once the other has arrived. ``turning`` bodies are followed while
they drive (``docs/protocol.md``, "Following while driving"): a robot starts into a
cell once its occupant has started out, as the plan's model allows, and the bound is
the plan's makespan (``--kill`` runs drive without following, and are bounded so). It
is what the messages are measured against. Before the runs, the bound is printed as a
multiple of the plan's ticks times the cell time (for ``thesis``, also the bound of
bodies that turn in no time: what not following costs).

Usage: python bench/live_plan.py [--agents 48] [--bodies thesis,turning] [--time-scales 2,5] [--loss 0.1] [--kill 3@2]
       [--transport udp|multicast|zenoh] [--robots-per-process K]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

from mrmp.centralized.body_time import execution_seconds
from mrmp.centralized.plan import PlanningResult
from mrmp.centralized.registry import plan_with
from mrmp.core import Scenario
from mrmp.core.body import body_model
from mrmp.io import load_movingai_scenario
from mrmp.live.launcher import LiveOptions, bodies_follow, run_live
from mrmp.live.transport import LiveFaults

MAPS = Path(__file__).resolve().parents[1] / "maps"
PLANNED_BODY = {"thesis": "omni", "turning": "turning"}
"""The body each live body's plan is made for: thesis bodies drive omni plans (no planner plans for them)."""


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", type=Path, default=MAPS / "random-32-32-20.map")
    parser.add_argument("--scen", type=Path, default=MAPS / "random-32-32-20-random-1.scen")
    parser.add_argument("--agents", type=int, default=100)
    parser.add_argument("--bodies", default="thesis,turning", help="comma-separated: thesis, turning")
    parser.add_argument("--time-scales", default="2")
    parser.add_argument("--loss", type=float, default=0.1)
    parser.add_argument("--kill", action="append", default=[], help="ID@SECONDS (repeatable)")
    parser.add_argument("--transport", default="udp", help="how the robots talk: udp, multicast or zenoh")
    parser.add_argument("--robots-per-process", type=int, default=1, help="robots hosted by one process")
    arguments = parser.parse_args()
    bodies = arguments.bodies.split(",")
    unknown = [name for name in bodies if name not in PLANNED_BODY]
    if unknown:
        parser.error(f"--bodies: unknown {', '.join(unknown)}; use thesis, turning")
    loaded = load_movingai_scenario(arguments.map, arguments.scen, arguments.agents)
    kill = {robot: float(seconds) for robot, seconds in (text.split("@") for text in arguments.kill)}
    hosting = LiveOptions(transport=arguments.transport, robots_per_process=arguments.robots_per_process)
    print(
        f"{loaded.name}: {arguments.agents} robots over {hosting.transport}, {hosting.robots_per_process} to a process,"
        f" loss {arguments.loss}, kill {kill}"
    )
    print(
        f"{'body':>7} {'scale':>5} {'arrived':>8} {'coll':>4} {'wall s':>7} {'plan s':>7} {'ratio':>6} {'bound s':>7}"
        f" {'/bound':>6} {'moves':>6} {'turns':>6} {'messages':>9} {'msg/move':>8} {'dgr/move':>8}  stop"
    )
    for name in bodies:
        scenario = loaded.with_changes(policy=replace(loaded.policy, body=PLANNED_BODY[name]))
        plan = plan_with("lacam", scenario, time_limit_s=60)
        if plan.paths is None:
            print(f"{name:>7} lacam: no plan ({plan.status}: {plan.message})")
            continue
        _say_bounds(name, scenario, plan, follows=bodies_follow(scenario, LiveOptions(kill=kill)))
        for scale in [float(text) for text in arguments.time_scales.split(",")]:
            _run(name, scenario, plan, replace(hosting, time_scale=scale, faults=LiveFaults(loss=arguments.loss), kill=kill))
    return 0


def _bound(
    name: str, scenario: Scenario, plan: PlanningResult, scale: float, follows: bool, turn_time: float | None = None
) -> float:
    """The live execution bound of ``plan`` driven by ``name`` bodies (module docstring), in seconds at ``scale``;
    ``follows``: whether bodies that may be followed while they drive are (:func:`~mrmp.live.launcher.bodies_follow`)."""
    assert plan.paths is not None
    headings = [robot.heading for robot in scenario.robots]
    timing = scenario.timing if turn_time is None else replace(scenario.timing, turn_time=turn_time)
    if name == "thesis":
        return execution_seconds(plan.paths, headings, timing, scale)
    return execution_seconds(plan.paths, headings, timing, scale, body=body_model(name), follows=follows)


def _say_bounds(name: str, scenario: Scenario, plan: PlanningResult, follows: bool) -> None:
    """Print the plan's makespan and its live execution bound as a multiple of its ticks times the cell time."""
    ticks = plan.makespan() * scenario.timing.cell_time
    line = f"{name:>7}: {PLANNED_BODY[name]} plan, makespan {plan.makespan()} ticks; live execution bound"
    line += f" {_bound(name, scenario, plan, 1.0, follows) / ticks:.2f} times its ticks x cell time"
    if name == "thesis":
        line += f" ({_bound(name, scenario, plan, 1.0, follows, turn_time=0.0) / ticks:.2f} with bodies turning in no time)"
    print(line)


def _run(name: str, scenario: Scenario, plan: PlanningResult, options: LiveOptions) -> None:
    """Execute ``plan`` live as ``options`` say (time scale, faults, kills, transport, hosting) and print its row."""
    folder = Path(tempfile.mkdtemp(prefix=f"mrmp-bench-plan-{len(scenario.robots)}-"))
    options = replace(options, results=folder, plan=plan)
    scale = options.time_scale
    result = run_live(scenario, options)
    arrived = sum(robot.arrived for robot in result.robots)
    moves = max(1, result.network.get("moves", 0))
    turns = sum(robot.turns for robot in result.robots) if name == "turning" else 0
    planned = plan.makespan() * scenario.timing.cell_time / scale
    bound = _bound(name, scenario, plan, scale, follows=bodies_follow(scenario, options))
    print(
        f"{name:>7} {scale:>5g} {arrived:>4}/{len(result.robots):<3} {len(result.collisions):>4}"
        f" {result.time_makespan_s:>7.2f} {planned:>7.2f} {result.time_makespan_s / planned:>6.2f} {bound:>7.2f}"
        f" {result.time_makespan_s / bound:>6.2f} {moves:>6} {turns:>6} {result.messages:>9}"
        f" {result.messages / moves:>8.1f} {result.network.get('datagrams_sent', 0) / moves:>8.1f}  {result.stop_reason}",
        flush=True,
    )


if __name__ == "__main__":
    sys.exit(main())
