"""Distance tables: wall time per table (one goal, every cell) on benchmark maps.

Each table is computed for a new goal (distinct goals only: tables of goals seen
before are cached); the grid's one-time setup (its flat neighbour arrays, kept
for every later table) is timed separately, by the first table. Prints the
median and the worst over the first N distinct goals of the map's
``-random-1.scen``.

Usage: python bench/distance_tables.py [--goals 200]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

from mrmp.io import load_movingai_scenario
from mrmp.search.distance import distance_table

MAPS = Path(__file__).resolve().parents[1] / "maps"
NAMES = ["random-64-64-10", "random-32-32-20", "maze-32-32-2", "warehouse-10-20-10-2-1"]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--goals", type=int, default=200)
    arguments = parser.parse_args()
    print(f"{'map':<24} {'cells':>6} {'setup ms':>9} {'median ms':>10} {'worst ms':>9}")
    for name in NAMES:
        scenario = load_movingai_scenario(MAPS / f"{name}.map", MAPS / f"{name}-random-1.scen", None)
        goals = list(dict.fromkeys(robot.goal for robot in scenario.robots))[: arguments.goals + 1]
        started = time.perf_counter()
        distance_table(scenario.grid, goals[0])  # builds the grid's flat neighbour arrays, kept for later tables
        setup = time.perf_counter() - started
        times = []
        for goal in goals[1:]:
            started = time.perf_counter()
            distance_table(scenario.grid, goal)
            times.append(time.perf_counter() - started)
        cells = len(scenario.grid.free_cells())
        print(f"{name:<24} {cells:>6} {1000 * setup:>9.2f} {1000 * statistics.median(times):>10.3f} {1000 * max(times):>9.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
