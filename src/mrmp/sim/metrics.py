"""Figures derived from a scenario before a run: lower bound and default tick limit.

Examples
--------
>>> from mrmp.core import Grid, RobotSpec, Scenario
>>> swap = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))))
>>> shortest_steps(swap)
[4, 4]
>>> default_max_ticks(swap, [4, 4])
64
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from mrmp.core.grid import Grid
from mrmp.core.scenario import Scenario
from mrmp.search.distance import distance_table


def shortest_steps(scenario: Scenario) -> list[int]:
    """Each robot's shortest path length in moves (ignoring costs and other robots).

    Unreachable goals count as 0 (validation reports them before a run).
    """
    grid = scenario.grid
    unit = Grid(grid.x_size, grid.y_size, grid.blocked_cells()) if grid.has_costs else grid
    lengths = []
    for robot in scenario.robots:
        distance = distance_table(unit, robot.goal).distance(robot.start)
        lengths.append(int(distance) if math.isfinite(distance) else 0)
    return lengths


def default_max_ticks(scenario: Scenario, lengths: Sequence[int]) -> int:
    """The tick limit of a run that sets none: room for detours, waits and crowds.

    Four times the longest shortest path, plus two ticks per robot, and never
    fewer than 64.
    """
    longest = max(lengths, default=0)
    return max(64, 4 * longest + 2 * len(scenario.robots))
