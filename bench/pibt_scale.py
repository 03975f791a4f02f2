"""Decentralized PIBT at scale: success, quality, speed and messages, per map and number of robots.

For each map and N, the first N agents of each of the map's ``.scen`` files
(``-random-*.scen`` next to the map; maps without one get seeded random
instances) run with policy ``pibt`` in the synchronous-round simulator of its
order of calls (``--sequencing``: ``local``, the default, the robots order
them; ``driver``, the simulator does), and the thesis scenarios run too. One line per (map, N), printed as soon as it is
measured:

* success: share of instances where every robot stood on its goal together;
* SoC/LB: sum of costs over the sum of shortest path lengths (mean over the
  solved instances); makespan (mean);
* ms/step: wall time per simulated step, messages included;
* table ms: distance-table time per robot;
* msg/robot/step: messages (one per recipient) per robot per step;
* LaCAM C++: the first-solution SoC/LB of the C++ LaCAM reference on
  ``-random-1`` where the issue quotes it (for comparison; not measured here).

Every line is also appended to ``--out`` (JSON lines) as it is measured.
``--seeds K`` runs every instance with seeds 0 to K-1 (the seed drives the robots' random tie-breaks;
default 1), so "inst" counts instances times seeds. ``--reach-cap`` sets how far a stalled robot's reach
grows with local sequencing (:attr:`~mrmp.robot.pibt_local.LocalPibtRobot.reach_cap`), ``--stall-from-best``
what counts as a stall (:attr:`~mrmp.robot.pibt_local.LocalPibtRobot.stall_from_best`).

Usage: python bench/pibt_scale.py [--maps DIR] [--only random-32-32-20,empty-32-32] [--seeds K] [--out FILE]
       [--sequencing local|driver] [--radius R] [--reach-cap R] [--stall-from-best]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from statistics import mean

from mrmp.core import PolicyOptions, Scenario
from mrmp.core.map_generators import random_instance as seeded_instance
from mrmp.io import load_movingai_scenario, load_scenario
from mrmp.io.movingai import read_map
from mrmp.robot.pibt_local import LocalPibtRobot
from mrmp.sim.policy_table import pibt_simulator

ROOT = Path(__file__).resolve().parents[1]
AGENTS = {
    "random-32-32-20": [50, 100, 200],
    "empty-32-32": [50, 100, 200, 400],
    "random-32-32-10": [50, 100, 200],
    "maze-32-32-2": [25, 50, 100],
    "room-32-32-4": [25, 50, 100],
    "warehouse-10-20-10-2-1": [100, 200, 400],
    "random-64-64-10": [200, 500, 1000],
    "random-64-64-20": [200, 500],
    "empty-48-48": [200, 500],
    "warehouse-20-40-10-2-1": [200, 500],
    "den520d": [100, 500],
    "Berlin_1_256": [100, 500],
}
LACAM_CPP = {
    ("random-32-32-20", 50): 1.41,
    ("random-32-32-20", 100): 1.44,
    ("random-32-32-20", 200): 2.01,
    ("empty-32-32", 50): 1.22,
    ("empty-32-32", 100): 1.29,
    ("empty-32-32", 200): 1.52,
    ("empty-32-32", 400): 1.94,
}
RANDOM_INSTANCES = 2


def random_instance(map_path: Path, agents: int, instance: int) -> Scenario:
    """``agents`` random starts and goals in the map's largest connected region, drawn with seed ``instance``.

    The run's own seed (the robots' tie-breaks) is 0, as for ``.scen`` instances:
    the instance a bench configuration's ``instances: K`` entry draws
    (:func:`mrmp.experiments.records.build_scenario`), so that ``bench/pibt.yaml``
    reproduces these rows exactly.
    """
    scenario = seeded_instance(read_map(map_path), agents, instance, name=f"{map_path.stem}-i{instance}")
    return scenario.with_changes(seed=0)


def instances(maps: Path, name: str, agents: int) -> list[Scenario]:
    map_path = maps / f"{name}.map"
    scens = sorted(maps.glob(f"{name}-random-*.scen"))
    if scens:
        return [load_movingai_scenario(map_path, scen, agents) for scen in scens]
    return [random_instance(map_path, agents, instance) for instance in range(RANDOM_INSTANCES)]


def measure(
    label: str, agents: int, scenarios: list[Scenario], out: Path | None, seeds: int = 1, policy: PolicyOptions | None = None
) -> None:
    policy = policy or PolicyOptions(name="pibt")
    qualities: list[float] = []  # SoC/LB of the runs that arrived
    makespans: list[int] = []  # makespans of the runs that arrived
    ms_per_step: list[float] = []
    table_ms: list[float] = []
    messages: list[float] = []  # per robot and step
    for scenario, offset in ((scenario, offset) for scenario in scenarios for offset in range(seeds)):
        run = scenario.with_changes(policy=policy, seed=scenario.seed + offset)
        result = pibt_simulator(run).run()
        if result.collisions:
            raise SystemExit(f"{label} N={agents}: the referee found collisions: {result.collisions[:3]}")
        steps = max(1, result.network["steps"])
        if result.success:
            if result.lower_bound:
                qualities.append(result.sum_of_costs / result.lower_bound)
            makespans.append(result.makespan)
        ms_per_step.append(1000 * result.wall_time_s / steps)
        table_ms.append(1000 * (result.planning_time_s or 0.0) / max(1, result.network["distance_tables"]))
        messages.append(result.network["messages"] / (agents * steps))
    success = len(makespans) / len(ms_per_step)
    soc_lb = mean(qualities) if qualities else None
    mean_makespan = mean(makespans) if makespans else None
    lacam_cpp = LACAM_CPP.get((label, agents))
    row = {
        "map": label,
        "agents": agents,
        "instances": len(ms_per_step),
        "success": success,
        "soc_lb": soc_lb,
        "makespan": mean_makespan,
        "ms_per_step": mean(ms_per_step),
        "table_ms": mean(table_ms),
        "messages_per_robot_step": mean(messages),
        "lacam_cpp_soc_lb": lacam_cpp,
        "sequencing": policy.sequencing,
        "radius": policy.radius,
    }
    quality = f"{soc_lb:.3f}" if soc_lb is not None else "-"
    makespan = f"{mean_makespan:.0f}" if mean_makespan is not None else "-"
    reference = f"{lacam_cpp:.2f}" if lacam_cpp is not None else ""
    print(
        f"{label:<24} {agents:>5} {len(ms_per_step):>4} {100 * success:>7.0f}% {quality:>7} {makespan:>8}"
        f" {mean(ms_per_step):>8.2f} {mean(table_ms):>8.3f} {mean(messages):>8.2f} {reference:>9}",
        flush=True,
    )
    if out is not None:
        with out.open("a") as stream:
            stream.write(json.dumps(row) + "\n")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=Path, default=ROOT / "maps", help="folder of .map and .scen files")
    parser.add_argument("--only", default="", help="comma-separated map names (default: all)")
    parser.add_argument("--out", type=Path, default=None, help="append one JSON line per row to this file")
    parser.add_argument("--seeds", type=int, default=1, help="run every instance with seeds 0 to SEEDS-1")
    default = PolicyOptions(name="pibt")
    parser.add_argument("--sequencing", choices=("local", "driver"), default=default.sequencing, help="who orders the calls")
    parser.add_argument("--radius", type=int, default=default.radius, help="the robots' beacon radius")
    parser.add_argument(
        "--reach-cap", type=int, default=LocalPibtRobot.reach_cap, help="largest reach of a stalled robot (local order)"
    )
    parser.add_argument(
        "--stall-from-best",
        action="store_true",
        help="a stall is a step that sets no new record of nearness to the goal (local order)",
    )
    arguments = parser.parse_args()
    if arguments.seeds < 1:
        parser.error(f"--seeds must be at least 1, not {arguments.seeds}")
    if arguments.reach_cap < 0:
        parser.error(f"--reach-cap must be at least 0, not {arguments.reach_cap}")
    LocalPibtRobot.reach_cap = arguments.reach_cap  # the policy table builds the robots: set on their class
    LocalPibtRobot.stall_from_best = arguments.stall_from_best
    policy = PolicyOptions(name="pibt", sequencing=arguments.sequencing, radius=arguments.radius)
    only = {name for name in arguments.only.split(",") if name}
    print(
        f"{'map':<24} {'N':>5} {'inst':>4} {'success':>8} {'SoC/LB':>7} {'makespan':>8}"
        f" {'ms/step':>8} {'table ms':>8} {'msg/r/s':>8} {'LaCAM C++':>9}"
    )
    if not only:
        for path in sorted((ROOT / "examples").glob("thesis-*.yaml")):
            scenario = load_scenario(path)
            measure(path.stem, len(scenario.robots), [scenario], arguments.out, arguments.seeds, policy)
    for name, counts in AGENTS.items():
        if (only and name not in only) or not (arguments.maps / f"{name}.map").exists():
            continue
        for agents in counts:
            measure(name, agents, instances(arguments.maps, name, agents), arguments.out, arguments.seeds, policy)
    return 0


if __name__ == "__main__":
    sys.exit(main())
