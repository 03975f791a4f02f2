"""Live ``pibt`` fleets of real processes hosting several robots each, beside the same fleet on a virtual clock.

Each case runs the fleet live (``mrmp run --live``'s launcher, UDP on
loopback), ``--robots-per-process`` robots to an ``mrmp agent`` process, each
robot with its own socket, brain and body: so 100 or 200 robots fit 2 cores in
a handful of processes. It prints, per case: robots arrived, the referee's
collisions, the wall makespan against the simulator's and the execution bound
(:func:`live_virtual.simulated_seconds`: the simulator's decisions carried out
by live bodies with no time for messages), moves, messages per move, the
robots' own counts, and the machine's load; then the same fleet on the virtual
clock (:mod:`mrmp.live.virtual_time`: a processor per robot, no shared
machine) for comparison. Times are only comparable side by side on one
machine: the load is printed with every row.

Cases (``--cases``, comma-separated ``MAP:ROBOTS``): as ``bench/live_virtual.py``.

Usage: python bench/live_hosted.py [--cases random-64-64-10:100] [--robots-per-process 25] [--loss 0.1]
       [--time-scale 5] [--synchronizer clock|local] [--body omni|turning] [--no-virtual]
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from live_virtual import case_scenario, fleet_parser, simulated_seconds
from mrmp.core.result import RunResult
from mrmp.live.launcher import LiveOptions, run_live
from mrmp.live.transport import LiveFaults
from mrmp.live.virtual_time import VirtualOptions, run_virtual


def describe(label: str, result: RunResult, ticks: int, simulated: float, bound: float | None, load: str) -> str:
    """One printed row: a run against the simulator and the execution bound."""
    network = result.network
    moves = max(1, network.get("moves", 0))
    makespan = result.time_makespan_s
    bound_text = "-" if bound is None else f"{bound:.2f} s (x{makespan / bound:.2f})"
    arrived = sum(robot.arrived for robot in result.robots)
    return (
        f"  {label}: arrived {arrived}/{len(result.robots)}, collisions {len(result.collisions)}, makespan {makespan:.2f} s; "
        f"simulator {ticks} ticks = {simulated:.2f} s (x{makespan / simulated:.2f}), execution bound {bound_text}; "
        f"moves {moves}, messages/move {result.messages / moves:.1f}, held {network.get('safety_pibt_held', 0)}, "
        f"gave up {network.get('safety_pibt_gave_up', 0)}, abandoned {network.get('safety_pibt_abandoned', 0)}, "
        f"retransmissions {network.get('safety_pibt_retransmissions', 0)}; stop: {result.stop_reason}{load}"
    )


def row(case: str, arguments: argparse.Namespace) -> None:
    scenario = case_scenario(case, arguments.synchronizer, arguments.body)
    faults = LiveFaults(loss=arguments.loss)
    ticks, bound = simulated_seconds(scenario, arguments.time_scale)
    simulated = ticks * scenario.timing.cell_time / arguments.time_scale
    per_process = arguments.robots_per_process
    processes = -(-len(scenario.robots) // per_process)
    print(
        f"{scenario.name}: live pibt (steps end by {arguments.synchronizer}), {scenario.policy.body} bodies, "
        f"loss {arguments.loss:.0%}, time scale {arguments.time_scale:g}, {processes} processes of {per_process} robots",
        flush=True,
    )
    before = os.getloadavg()[0]
    options = LiveOptions(
        results=Path(tempfile.mkdtemp(prefix=f"mrmp-hosted-{scenario.name}-")), time_scale=arguments.time_scale,
        faults=faults, seed=arguments.seed, robots_per_process=per_process,
    )  # fmt: skip
    live = run_live(scenario, options)
    load = f"; load {before:.1f} -> {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; results in {options.results}"
    print(describe("UDP processes", live, ticks, simulated, bound, load), flush=True)
    if arguments.virtual:
        folder = Path(tempfile.mkdtemp(prefix=f"mrmp-virtual-{scenario.name}-"))
        virtual = run_virtual(
            scenario, VirtualOptions(results=folder, time_scale=arguments.time_scale, faults=faults, seed=arguments.seed)
        )
        print(describe("virtual clock", virtual, ticks, simulated, bound, f"; results in {folder}"), flush=True)


def main() -> int:
    parser = fleet_parser(__doc__.splitlines()[0], "random-64-64-10:100")
    parser.add_argument("--robots-per-process", type=int, default=25)
    parser.add_argument("--no-virtual", dest="virtual", action="store_false", help="only the live run")
    arguments = parser.parse_args()
    for case in arguments.cases.split(","):
        row(case, arguments)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
