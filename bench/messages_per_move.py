"""Messages per robot-move and per robot-tick in the lockstep simulator, by kind, and its cost against pibt's.

Runs reactive A*, the thesis policy and the execution of a LaCAM plan, guarded,
on MovingAI instances (the first N agents of scenario 1; random-32-32-20 holds
at most 409, so N=1000 runs on random-64-64-20), on a perfect network, and
prints for each run the moves made, the datagrams sent per robot-move, split
into states and the safety layer's claims, replies, handoffs, releases and their
acknowledgements, and the datagrams per robot-tick (whether the robot moves or
not). Counts are deterministic. States go to the robots within the policy's
interaction radius (``docs/protocol.md``, "Neighbourhoods"), so these figures
do not grow with N; the targets are at most 40 per move and 30 per robot-tick.

Then, side by side in one run (``--ratio``), the lockstep simulator's wall time
per robot-tick for astar and thesis against the synchronous rounds' wall time
per robot-step of pibt on the same instance: a ratio, each the best of
``--repeat`` runs, since absolute times depend on the machine and its load.

With ``--loud`` each instance runs a second time without the savings of a
perfect network (every robot's state every tick, refused claims sent again
every tick: :class:`~mrmp.sim.simulator.LockstepSimulator`, ``quiet=False``),
and the row says whether both runs made the same paths and what the loud one
cost per move.

Usage: python bench/messages_per_move.py [--instances random-32-32-20:10,100,400;random-64-64-20:400,1000]
       [--policies astar,thesis,lacam] [--max-ticks 100] [--ratio random-32-32-20:200] [--repeat 3] [--loud]
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

from mrmp.centralized.execution import plan_policies
from mrmp.centralized.registry import plan_with
from mrmp.core import PolicyOptions
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.experiments.execution import execute_in_simulator
from mrmp.io.scenario_file import load_movingai_scenario
from mrmp.sim.simulator import LockstepSimulator, simulate

MAPS = Path(__file__).resolve().parent.parent / "maps"
SAFETY_KINDS = ("claim", "reply", "handoff", "release", "releaseack")
PLANNERS = ("lacam", "pp", "cbs")


def instance(name: str, size: int) -> Scenario:
    """The first ``size`` agents of ``maps/NAME-random-1.scen`` on ``maps/NAME.map``."""
    return load_movingai_scenario(MAPS / f"{name}.map", MAPS / f"{name}-random-1.scen", size)


def run(scenario: Scenario, policy: str, max_ticks: int, record: bool, quiet: bool = True) -> RunResult | None:
    """One guarded run on a perfect network: a per-robot policy, or the execution of a planner's plan.

    ``quiet=False`` runs the robots without the savings of a perfect network (states every tick,
    refused claims sent again every tick; :class:`~mrmp.sim.simulator.LockstepSimulator`).
    """
    if policy in PLANNERS:
        plan = plan_with(policy, scenario, time_limit_s=60.0)
        if plan.paths is None:
            return None
        scenario = scenario.with_changes(max_ticks=max_ticks)
        if quiet:
            return execute_in_simulator(scenario, plan, record_messages=record)
        policies = plan_policies(plan, following=scenario.safety, scheduled=True)
        return LockstepSimulator(scenario, policies=policies, record_messages=record, quiet=False).run()
    scenario = scenario.with_changes(policy=PolicyOptions(name=policy), max_ticks=max_ticks)
    if quiet:
        return simulate(scenario, record_messages=record)
    return LockstepSimulator(scenario, record_messages=record, quiet=False).run()


def counts(arguments: argparse.Namespace) -> None:
    kinds_header = " ".join(f"{kind:>10}" for kind in SAFETY_KINDS)
    print(
        f"{'map':>16} {'policy':>7} {'N':>5} {'ticks':>5} {'arrived':>7} {'moves':>7} {'state':>7} {kinds_header} {'safety':>7}"
        f" {'per move':>8} {'per r-tick':>10}" + ("  quiet/loud paths, per move" if arguments.loud else "")
    )
    for part in arguments.instances.split(";"):
        name, sizes = part.split(":")
        for policy in arguments.policies.split(","):
            for size in [int(text) for text in sizes.split(",")]:
                result = run(instance(name, size), policy, arguments.max_ticks, record=True)
                loud = None
                if arguments.loud:
                    loud = run(instance(name, size), policy, arguments.max_ticks, record=True, quiet=False)
                if result is None:
                    print(f"{name:>16} {policy:>7} {size:>5}   no plan")
                    continue
                kinds = Counter(kind for tick in result.message_log or [] for _, _, kind in tick)
                moves = max(1, sum(robot.steps for robot in result.robots))
                arrived = sum(1 for robot in result.robots if robot.path[-1] == robot.goal)
                safety = sum(kinds[kind] for kind in SAFETY_KINDS)
                total = sum(kinds.values())
                print(
                    f"{name:>16} {policy:>7} {size:>5} {result.ticks:>5} {arrived:>7} {moves:>7} {kinds['state'] / moves:>7.1f} "
                    + " ".join(f"{kinds[kind] / moves:>10.2f}" for kind in SAFETY_KINDS)
                    + f" {safety / moves:>7.2f} {total / moves:>8.1f} {total / (size * max(1, result.ticks)):>10.2f}"
                    + ("" if loud is None else f"  {_same(result, loud):>9} {_per_move(loud):>7.1f}")
                )


def _same(quiet: RunResult, loud: RunResult) -> str:
    """Whether two runs made the same paths."""
    return "same" if [robot.path for robot in quiet.robots] == [robot.path for robot in loud.robots] else "differ"


def _per_move(result: RunResult) -> float:
    """Datagrams per robot-move of a run with a message log."""
    moves = max(1, sum(robot.steps for robot in result.robots))
    return sum(len(tick) for tick in result.message_log or []) / moves


def ratio(arguments: argparse.Namespace) -> None:
    name, size_text = arguments.ratio.split(":")
    size = int(size_text)
    scenario = instance(name, size)
    best: dict[str, float] = {}
    for _ in range(arguments.repeat):
        for policy in ("pibt", "astar", "thesis"):
            result = run(scenario, policy, arguments.max_ticks, record=False)
            assert result is not None
            per_robot_tick = result.wall_time_s / (size * max(1, result.ticks))
            best[policy] = min(best.get(policy, per_robot_tick), per_robot_tick)
    print(f"\nwall time per robot-tick on {name}, N={size}, best of {arguments.repeat} (side by side):")
    for policy, seconds in best.items():
        print(f"{policy:>7} {1e6 * seconds:>9.1f} us   {seconds / best['pibt']:>5.1f} x pibt")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--instances", default="random-32-32-20:10,100,400;random-64-64-20:400,1000")
    parser.add_argument("--policies", default="astar,thesis,lacam")
    parser.add_argument("--max-ticks", type=int, default=100)
    parser.add_argument("--ratio", default="random-32-32-20:200", help="MAP:N of the side-by-side timing ('' to skip)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument(
        "--loud", action="store_true", help="also run each instance with states every tick and refused claims resent"
    )
    arguments = parser.parse_args()
    if arguments.instances:
        counts(arguments)
    if arguments.ratio:
        ratio(arguments)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
