"""PIBT sequenced by the driver against PIBT sequenced by the robots, side by side in one process.

For each (map, N) the first N agents of the map's ``-random-1.scen`` run with
policy ``pibt`` twice, over a perfect network, seed 0: with the sequenced
driver (:class:`mrmp.sim.rounds.RoundsSimulator`) and with local sequencing
(:class:`mrmp.sim.local_rounds.LocalRoundsSimulator`). One line each:

* success, SoC/LB, makespan;
* ms/step: wall time per step (the distance tables are computed before it; a
  ratio of the two lines is what to read: both ran in the same process, one
  after the other), and on the local line that ratio (``x drv``: local
  sequencing's ms per step over the driver's);
* rounds/step and msg/robot/step (messages, one per recipient);
* for local sequencing, the robots' own counts per robot and step: rounds
  waited before starting, reservations withdrawn, requests refused, cells
  passed by because their occupant was busy, calls given up for a call of
  higher priority (``aborted``), waits for a robot busy in a call of higher
  priority (``blocked``), steps abandoned, and (over a faulty network)
  retransmissions.

With ``--loss``, ``--duplicate`` or ``--delay-max`` both run over that
network: the sequenced driver's link layer retransmits until every message
arrives; the robots of local sequencing acknowledge, retransmit and abandon
steps themselves.

``--alternate`` times the two orders by stepping them alternately instead, one
step of each in turn in one process, so that both meet the same drifts of a
shared machine's speed: one line per case, ms per step of each and their ratio
(the decisions are the same as in the separate runs).

``--scale`` runs every map and N of ``bench/pibt_scale.py`` (every instance:
each ``-random-*.scen``, or its seeded random instances; the thesis
scenarios first) instead of ``--only``. ``--reach-cap`` and ``--stall-slack``
set how far a stalled robot's reach grows over a perfect network
(:attr:`~mrmp.robot.pibt_local.LocalPibtRobot.reach_cap`,
:attr:`~mrmp.robot.pibt_local.LocalPibtRobot.stall_slack`), ``--stall-from-best``
what counts as a stall (:attr:`~mrmp.robot.pibt_local.LocalPibtRobot.stall_from_best`); ``--order``
runs one order only.

Usage: python bench/pibt_local.py [--maps DIR] [--only random-32-32-20:100,empty-32-32:400 | --scale] [--limit TICKS]
       [--radius R] [--loss P] [--duplicate P] [--delay-max TICKS] [--reach-cap R] [--stall-slack S]
       [--driver-radius R] [--order driver|local] [--stall-from-best] [--alternate]
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
from pathlib import Path

from mrmp.core import NetworkFaults, PolicyOptions, Scenario
from mrmp.io import load_movingai_scenario, load_scenario
from mrmp.robot.pibt_local import LocalPibtRobot
from mrmp.sim.local_rounds import LocalRoundsSimulator
from mrmp.sim.rounds import RoundsSimulator
from pibt_scale import AGENTS, instances

ROOT = Path(__file__).resolve().parents[1]
CASES = ("random-32-32-20:100", "random-32-32-20:200", "empty-32-32:400", "random-64-64-10:1000")


def cases(arguments: argparse.Namespace) -> list[tuple[str, Scenario]]:
    """The (label, scenario) pairs to run: ``--only``'s first N agents of ``-random-1.scen``, or ``--scale``'s."""
    if not arguments.scale:
        chosen = []
        for case in arguments.only.split(","):
            name, _, agents = case.partition(":")
            scen = arguments.maps / f"{name}-random-1.scen"
            chosen.append((name, load_movingai_scenario(arguments.maps / f"{name}.map", scen, int(agents))))
        return chosen
    chosen = [(path.stem, load_scenario(path)) for path in sorted((ROOT / "examples").glob("thesis-*.yaml"))]
    for name, counts in AGENTS.items():
        if (arguments.maps / f"{name}.map").exists():
            for agents in counts:
                chosen.extend((scenario.name, scenario) for scenario in instances(arguments.maps, name, agents))
    return chosen


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=Path, default=ROOT / "maps", help="folder of .map and .scen files")
    parser.add_argument("--only", default=",".join(CASES), help="comma-separated MAP:N cases")
    parser.add_argument("--limit", type=int, default=0, help="stop every run after this many ticks (0: no limit)")
    parser.add_argument(
        "--radius", type=int, default=PolicyOptions(name="pibt").radius, help="beacon radius (local sequencing waits that far)"
    )
    parser.add_argument("--driver-radius", type=int, default=2, help="the sequenced driver's beacon radius (it decides alike)")
    parser.add_argument("--loss", type=float, default=0.0, help="loss probability of every datagram")
    parser.add_argument("--duplicate", type=float, default=0.0, help="duplication probability of every datagram")
    parser.add_argument("--delay-max", type=int, default=0, help="largest delay of a datagram, in ticks")
    parser.add_argument("--scale", action="store_true", help="every map and N of bench/pibt_scale.py instead of --only")
    parser.add_argument("--reach-cap", type=int, default=LocalPibtRobot.reach_cap, help="largest reach of a stalled robot")
    parser.add_argument("--stall-slack", type=int, default=LocalPibtRobot.stall_slack, help="stalled steps before reach grows")
    parser.add_argument("--order", choices=("driver", "local"), default=None, help="run one order only")
    parser.add_argument(
        "--stall-from-best", action="store_true", help="a stall is a step that sets no new record of nearness to the goal"
    )
    parser.add_argument("--alternate", action="store_true", help="time the two orders stepped alternately, one step each")
    arguments = parser.parse_args()

    class Robot(LocalPibtRobot):
        reach_cap = arguments.reach_cap
        stall_slack = arguments.stall_slack
        stall_from_best = arguments.stall_from_best

    class Local(LocalRoundsSimulator):
        robot_type = Robot

    simulators = [(label, simulator) for label, simulator in (("driver", RoundsSimulator), ("local", Local))]
    simulators = [(label, simulator) for label, simulator in simulators if arguments.order in (None, label)]
    if arguments.alternate:
        for name, scenario in cases(arguments):
            alternate(f"{name}:{len(scenario.robots)}", scenario.with_changes(seed=0), dict(simulators), arguments)
        return 0
    print(
        f"{'map':<30} {'N':>5} {'order':>6} {'success':>7} {'SoC/LB':>7} {'mksp':>5} {'ms/step':>8} {'x drv':>6} {'rnd/step':>8}"
        f" {'msg/r/s':>7} {'wait':>6} {'withdr':>7} {'refuse':>7} {'passed':>7} {'abort':>7} {'block':>7}"
        f" {'aband':>6} {'retrans':>7}"
    )
    for name, scenario in cases(arguments):
        agents = len(scenario.robots)
        case = f"{name}:{agents}"
        scenario = scenario.with_changes(
            seed=scenario.seed if arguments.scale else 0,
            network=NetworkFaults(loss=arguments.loss, duplicate=arguments.duplicate, delay_max=arguments.delay_max),
        )
        if arguments.limit:
            scenario = scenario.with_changes(max_ticks=arguments.limit)
        driver_ms = None
        for label, simulator in simulators:
            radius = arguments.driver_radius if label == "driver" else arguments.radius
            result = simulator(scenario.with_changes(policy=PolicyOptions(name="pibt", radius=radius, sequencing=label))).run()
            if result.collisions:
                raise SystemExit(f"{case} {label}: the referee found collisions: {result.collisions[:3]}")
            network = result.network
            steps = max(1, network["steps"])
            per = agents * steps
            soc = f"{result.sum_of_costs / result.lower_bound:.3f}" if result.success else "-"
            mksp = f"{result.makespan}" if result.success else "-"
            ms_per_step = 1000 * result.wall_time_s / steps
            if label == "driver":
                driver_ms = ms_per_step
            ratio = f"{ms_per_step / driver_ms:.2f}" if label == "local" and driver_ms else "-"
            counts = " ".join(
                f"{network.get(key, 0) / per:>{width}.3f}"
                for key, width in (
                    ("waits", 6),
                    ("withdrawn", 7),
                    ("refused", 7),
                    ("passed_busy", 7),
                    ("aborted", 7),
                    ("blocked", 7),
                    ("abandoned", 6),
                    ("retransmissions", 7),
                )
            )
            print(
                f"{name:<30} {agents:>5} {label:>6} {100 * result.success:>6.0f}% {soc:>7} {mksp:>5}"
                f" {ms_per_step:>8.2f} {ratio:>6} {network['rounds'] / steps:>8.1f}"
                f" {network['messages'] / per:>7.2f} {counts}",
                flush=True,
            )
    return 0


def alternate(case: str, scenario: Scenario, simulators: dict[str, type[RoundsSimulator]], arguments: argparse.Namespace) -> None:
    """Step the driver's run and local sequencing's alternately, one step each, and print their ms per step and ratio."""
    runs = {}
    for label, simulator in simulators.items():
        radius = arguments.driver_radius if label == "driver" else arguments.radius
        run = simulator(scenario.with_changes(policy=PolicyOptions(name="pibt", radius=radius, sequencing=label)))
        run.referee.check_start([spec.start for spec in scenario.robots], [spec.heading for spec in scenario.robots])
        runs[label] = run
    spent = dict.fromkeys(runs, 0.0)
    steps = dict.fromkeys(runs, 0)

    def over(run: RoundsSimulator) -> bool:
        return all(robot.at_goal for robot in run.robots) or run.tick >= run.max_ticks

    collecting = gc.isenabled()
    gc.disable()  # as the runs themselves do
    try:
        while not all(over(run) for run in runs.values()):
            for label, run in runs.items():
                if not over(run):
                    started = time.perf_counter()
                    run.step()
                    spent[label] += time.perf_counter() - started
                    steps[label] += 1
    finally:
        if collecting:
            gc.enable()
    per_step = {label: 1000 * spent[label] / max(1, steps[label]) for label in runs}
    line = " ".join(f"{label} {per_step[label]:.2f} ms/step over {steps[label]} steps" for label in runs)
    ratio = f", local / driver {per_step['local'] / per_step['driver']:.2f}" if len(runs) == 2 else ""
    print(f"{case}: stepped alternately: {line}{ratio}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
