"""Path cost and expansions of each single-robot search on the standard maps.

For the first N start-goal pairs of each standard map's ``-random-1.scen``
(MovingAI), every search of ``mrmp.search.choices.SEARCH_TABLE`` plans one
robot's path with no other robot on the map. Prints, per map and search: how
many paths it found, their total cost against the cheapest (a distance table's),
how many are dearer than the cheapest, and the mean expansions (nodes popped;
for the update coordinate method, the cells of its L). Counts are deterministic.

Usage: python bench/search_costs.py [--pairs 100]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from mrmp.core.errors import NoPathError
from mrmp.io import load_movingai_scenario
from mrmp.search.choices import SEARCH_TABLE
from mrmp.search.distance import distance_table

MAPS = Path(__file__).resolve().parents[1] / "maps"
STANDARD_MAPS = ["random-32-32-20", "empty-32-32", "maze-32-32-2", "room-32-32-4", "warehouse-10-20-10-2-1", "den520d"]
"""The maps of ``bench/standard.yaml``."""


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=100)
    arguments = parser.parse_args()
    print("| map | search | found | cost / cheapest | dearer | mean expansions |")
    print("|---|---|---:|---:|---:|---:|")
    for name in STANDARD_MAPS:
        scenario = load_movingai_scenario(MAPS / f"{name}.map", MAPS / f"{name}-random-1.scen", arguments.pairs)
        grid = scenario.grid
        pairs = [(robot.start, robot.goal) for robot in scenario.robots]
        cheapest = {pair: distance_table(grid, pair[1]).distance(pair[0]) for pair in pairs}
        for choice in SEARCH_TABLE.values():
            found = dearer = expansions = 0
            cost = optimum = 0.0
            for start, goal in pairs:
                try:
                    result = choice.planner(grid, start, goal)
                except NoPathError:
                    continue
                found += 1
                cost += result.cost
                optimum += cheapest[(start, goal)]
                dearer += result.cost > cheapest[(start, goal)]
                expansions += result.expansions
            ratio = f"{cost / optimum:.3f}" if found else "-"
            mean = f"{expansions / found:.0f}" if found else "-"
            print(f"| {name} | {choice.name} | {found}/{len(pairs)} | {ratio} | {dearer} | {mean} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
