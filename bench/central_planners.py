"""Central planners on MovingAI benchmarks: planning time and sum of costs over the lower bound.

For each (map, number of agents), the first N agents of the map's
``-random-1.scen`` are planned by each planner (first solution; every plan is
checked by the referee). Prints one line per run.

Usage: python bench/central_planners.py [--planners lacam,pp,cbs] [--time-limit 30]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mrmp.centralized.registry import plan_with
from mrmp.io import load_movingai_scenario
from mrmp.sim.metrics import shortest_steps
from mrmp.sim.referee import check_paths

MAPS = Path(__file__).resolve().parents[1] / "maps"
INSTANCES = [
    ("random-32-32-20", 50),
    ("random-32-32-20", 100),
    ("random-32-32-20", 200),
    ("empty-32-32", 50),
    ("empty-32-32", 100),
    ("empty-32-32", 200),
    ("empty-32-32", 400),
    ("warehouse-10-20-10-2-1", 200),
    ("random-64-64-10", 1000),
]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planners", default="lacam")
    parser.add_argument("--time-limit", type=float, default=30.0)
    arguments = parser.parse_args()
    print(f"{'map':<24} {'N':>5} {'planner':>7} {'status':>10} {'time s':>8} {'SoC/LB':>7} {'makespan':>8} {'referee':>8}")
    for name, agents in INSTANCES:
        scenario = load_movingai_scenario(MAPS / f"{name}.map", MAPS / f"{name}-random-1.scen", agents)
        lower_bound = sum(shortest_steps(scenario))
        for planner in arguments.planners.split(","):
            plan = plan_with(planner, scenario, time_limit_s=arguments.time_limit)
            if plan.solved and plan.paths is not None:
                verdict = check_paths(scenario.grid, {robot.id: path for robot, path in zip(scenario.robots, plan.paths)})
                ratio, makespan = f"{plan.sum_of_costs() / lower_bound:.3f}", str(plan.makespan())
                judged = "ok" if not verdict else f"{len(verdict)} bad"
            else:
                ratio, makespan, judged = "-", "-", "-"
            print(
                f"{name:<24} {agents:>5} {planner:>7} {plan.status:>10} {plan.planning_time_s:>8.3f}"
                f" {ratio:>7} {makespan:>8} {judged:>8}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
