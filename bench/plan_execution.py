"""LaCAM plans executed by the fleet in the lockstep simulator: planned against executed sum of costs.

For random-32-32-20 (MovingAI, scenario random-1, the first N agents) the plan
of LaCAM (``mrmp.centralized.lacam``) is executed by the robots through its
Action Dependency Graph and the safety layer (``mrmp.experiments.execution``),
on a perfect network and with 10% loss (seed 0). Printed per N: the plan's sum
of costs, the executed sums of costs and their ratios to the plan's, the
execution's success and messages per robot-move (perfect, lossy). Counts are deterministic;
the wall time of each execution is printed for orientation only.

Usage: python bench/plan_execution.py [--sizes 100,200] [--loss 0.1]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from mrmp.centralized.registry import plan_with
from mrmp.core import NetworkFaults
from mrmp.core.result import RunResult
from mrmp.experiments.execution import execute_in_simulator
from mrmp.io.scenario_file import load_movingai_scenario

MAPS = Path(__file__).resolve().parent.parent / "maps"


def per_move(result: RunResult) -> float:
    """Messages per robot-move of a run."""
    return result.messages / max(1, sum(robot.steps for robot in result.robots))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,200", help="fleet sizes, comma-separated")
    parser.add_argument("--loss", type=float, default=0.1, help="loss rate of the lossy execution")
    arguments = parser.parse_args()
    print(
        f"{'N':>4} {'plan SoC':>9} {'perfect':>8} {'ratio':>6} {'lossy':>8} {'ratio':>6} "
        f"{'success':>8} {'msgs/move':>10} {'lossy':>6} {'wall s':>7}"
    )
    for size in [int(text) for text in arguments.sizes.split(",")]:
        scenario = load_movingai_scenario(MAPS / "random-32-32-20.map", MAPS / "random-32-32-20-random-1.scen", size)
        plan = plan_with("lacam", scenario, time_limit_s=60)
        if not plan.solved:
            print(f"{size:>4} no plan ({plan.status}: {plan.message})")
            continue
        planned = plan.sum_of_costs()
        started = time.perf_counter()
        perfect = execute_in_simulator(scenario, plan)
        lossy = execute_in_simulator(scenario.with_changes(network=NetworkFaults(loss=arguments.loss), seed=0), plan)
        wall = time.perf_counter() - started
        print(
            f"{size:>4} {planned:>9} {perfect.sum_of_costs:>8} {perfect.sum_of_costs / planned:>6.2f} "
            f"{lossy.sum_of_costs:>8} {lossy.sum_of_costs / planned:>6.2f} "
            f"{'yes' if perfect.success and lossy.success else 'no':>8} {per_move(perfect):>10.1f} {per_move(lossy):>6.1f} "
            f"{wall:>7.1f}",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
