"""Write ``warehouse-small_24.json``: a League of Robot Runners problem on MovingAI's warehouse-10-20-10-2-1.

The map is MovingAI's (``maps/warehouse-10-20-10-2-1.map``, copied unchanged
from the repository's ``maps/``; see ``maps/README.md``). The problem is made
here, in LoRR's 2024 format, the way the competition's warehouse problems are
laid out: 24 robots on free cells drawn with seed 0, and 2,000 tasks of two
errands each: a pick at a free cell beside a shelf, then a drop at a station
cell of the free strips left and right of the shelves. Tasks are revealed
1.5 times the team at a time, as in the Start-Kit's examples.

Run it again to get the same files: ``python examples/lorr/make_warehouse_small.py``.
"""

from __future__ import annotations

import json
import random
from pathlib import Path

from mrmp.io.lorr import lorr_location
from mrmp.io.movingai import read_map

HERE = Path(__file__).resolve().parent
NAME = "warehouse-small_24"
ROBOTS = 24
TASKS = 2000
STATION_COLUMNS = 10
"""Columns at each side of the map whose free cells are stations (drops)."""


def main() -> None:
    grid = read_map(HERE / "maps" / "warehouse-10-20-10-2-1.map")
    rng = random.Random(0)
    free = [(x, y) for x in range(grid.x_size) for y in range(grid.y_size) if grid.is_free((x, y))]
    beside_shelf = [
        cell for cell in free
        if STATION_COLUMNS <= cell[1] < grid.y_size - STATION_COLUMNS and any(
            grid.in_bounds(near) and grid.is_blocked(near)
            for near in ((cell[0] + 1, cell[1]), (cell[0] - 1, cell[1]), (cell[0], cell[1] + 1), (cell[0], cell[1] - 1))
        )
    ]  # fmt: skip
    stations = [cell for cell in free if cell[1] < STATION_COLUMNS or cell[1] >= grid.y_size - STATION_COLUMNS]
    starts = rng.sample(free, ROBOTS)
    tasks = [(rng.choice(beside_shelf), rng.choice(stations)) for _ in range(TASKS)]
    (HERE / "agents" / f"{NAME}.agents").write_text(
        "# version for LoRR 2024\n" + f"{ROBOTS}\n" + "".join(f"{lorr_location(cell, grid)}\n" for cell in starts)
    )
    (HERE / "tasks" / f"{NAME}.tasks").write_text(
        "# version for LoRR 2024\n"
        + f"{TASKS}\n"
        + "".join(",".join(str(lorr_location(cell, grid)) for cell in task) + "\n" for task in tasks)
    )
    problem = {
        "mapFile": "maps/warehouse-10-20-10-2-1.map",
        "agentFile": f"agents/{NAME}.agents",
        "teamSize": ROBOTS,
        "taskFile": f"tasks/{NAME}.tasks",
        "numTasksReveal": 1.5,
    }
    (HERE / f"{NAME}.json").write_text(json.dumps(problem, indent=4) + "\n")


if __name__ == "__main__":
    main()
