"""The price of turning: the central planners for ``omni`` and for ``turning`` bodies, side by side.

For random-32-32-20 (N = 20, 40 and 100..400) and warehouse-10-20-10-2-1 (N =
300), MovingAI scenario random-1, the first N agents, every robot starting to
face NORTH, this prints for each planner and body:

* ``SoC/LB``: the plan's sum of costs over the lower bound *of its body*: for
  ``omni`` the sum of shortest path lengths, for ``turning`` the sum of every
  robot's best ``(cell, heading)`` path in ticks, turns counted
  (:func:`mrmp.search.heading_distance.heading_distances`);
* ``makespan`` in ticks, and ``turning x``: the execution bound of the plan
  on ``turning`` bodies (:func:`mrmp.centralized.body_time.execution_seconds`,
  one tick per action) in ticks, i.e. how long a fleet of turning robots takes
  to drive it. A plan made for ``omni`` bodies is stretched by the turns it
  ignored; a plan made for ``turning`` bodies must take exactly its makespan;
* ``bad``: the referee's verdict on the plan in its own body's model (0: valid).

PIBT is the central one-step-per-tick planner (:mod:`mrmp.centralized.pibt_plan`),
the reference of the fleet's decentralized ``pibt``; LaCAM is
:mod:`mrmp.centralized.lacam` (the swap technique on for ``omni``; ``turning``
bodies cannot walk backwards, so it is off there); pp is prioritized planning
(:mod:`mrmp.centralized.prioritized`, scenario order) and CBS
(:mod:`mrmp.centralized.cbs`, optimal) runs up to :data:`CBS_MOST` robots.
Counts are deterministic (seed 0); the planning seconds are printed for
orientation only.

Usage: python bench/turning.py [--cases random-32-32-20:100,warehouse-10-20-10-2-1:300] [--time-limit 60]
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from mrmp.centralized.body_time import execution_seconds
from mrmp.centralized.cbs import cbs
from mrmp.centralized.lacam import lacam
from mrmp.centralized.pibt_plan import pibt_plan
from mrmp.centralized.plan import PlanningResult
from mrmp.centralized.prioritized import prioritized
from mrmp.core.body import body_model
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Timing
from mrmp.io.movingai import read_map, read_scen
from mrmp.search.distance import distance_table
from mrmp.search.heading_distance import heading_distances
from mrmp.sim.referee import check_paths

MAPS = Path(__file__).resolve().parent.parent / "maps"
CASES = (
    "random-32-32-20:20,random-32-32-20:40,random-32-32-20:100,random-32-32-20:200,random-32-32-20:300,"
    "random-32-32-20:400,warehouse-10-20-10-2-1:300"
)
CBS_MOST = 20
"""CBS plans only fleets this small (it is exponential in the robots that meet)."""
TURNING = body_model("turning")
TICK = Timing(cell_time=1.0, turn_time=1.0)


def lower_bound(grid: Grid, starts: Sequence[tuple[int, int]], goals: Sequence[tuple[int, int]], body: str) -> float:
    """The sum over robots of the body's shortest way from its start (facing NORTH) to its goal, in ticks."""
    if body == "omni":
        return sum(distance_table(grid, goal).distance(start) for start, goal in zip(starts, goals))
    index = [4 * (start[0] * grid.y_size + start[1]) + int(Heading.NORTH) - 1 for start in starts]
    return sum(heading_distances(grid, goal, 1.0, both_ways=True)[state] for state, goal in zip(index, goals))


def turning_ticks(plan: PlanningResult) -> float:
    """How many ticks turning bodies take to drive ``plan`` (its headings when it has them)."""
    assert plan.paths is not None
    start_headings = [Heading.NORTH] * len(plan.paths)
    return execution_seconds(plan.paths, start_headings, TICK, body=TURNING, heading_paths=plan.headings)


def violations(grid: Grid, plan: PlanningResult, body: str) -> int:
    """How many collisions or illegal actions the referee finds in ``plan``, judged as ``body`` bodies."""
    assert plan.paths is not None
    ids = [str(robot) for robot in range(len(plan.paths))]
    headings = None if plan.headings is None else dict(zip(ids, plan.headings))
    return len(check_paths(grid, dict(zip(ids, plan.paths)), headings, body_model(body)))


def row(grid: Grid, plan: PlanningResult, body: str, bound: float) -> str:
    """One planner's columns: SoC/LB, makespan, turning ticks, referee verdict, seconds."""
    if not plan.solved:
        return f"{plan.status:>7} {'-':>8} {'-':>9} {'-':>4} {plan.planning_time_s:>6.1f}"
    return (
        f"{plan.sum_of_costs() / bound:>7.3f} {plan.makespan():>8} {turning_ticks(plan):>9.0f} "
        f"{violations(grid, plan, body):>4} {plan.planning_time_s:>6.1f}"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=CASES, help="MAP:N pairs, comma-separated (maps in maps/)")
    parser.add_argument("--time-limit", type=float, default=60.0, help="seconds LaCAM may spend per plan")
    arguments = parser.parse_args()
    print(
        f"{'map':<24} {'N':>4} {'planner':<8} {'body':<8} {'LB':>6} "
        f"{'SoC/LB':>7} {'makespan':>8} {'turning x':>9} {'bad':>4} {'plan s':>6}"
    )
    for case in arguments.cases.split(","):
        name, size = case.split(":")
        grid = read_map(MAPS / f"{name}.map")
        robots = read_scen(MAPS / f"{name}-random-1.scen", int(size), grid)
        starts, goals = [robot.start for robot in robots], [robot.goal for robot in robots]
        for body in ("omni", "turning"):
            bound = lower_bound(grid, starts, goals, body)
            limit = arguments.time_limit
            plans = {
                "pibt": pibt_plan(grid, starts, goals, body=body),
                "pp": prioritized(grid, starts, goals, body=body, time_limit_s=limit),
                "lacam": lacam(grid, starts, goals, body=body, swap=body == "omni", time_limit_s=limit),
            }
            if len(starts) <= CBS_MOST:
                plans["cbs"] = cbs(grid, starts, goals, body=body, time_limit_s=limit)
            for planner, plan in plans.items():
                print(f"{name:<24} {size:>4} {planner:<8} {body:<8} {bound:>6.0f} {row(grid, plan, body, bound)}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
