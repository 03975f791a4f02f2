"""Figures derived from a scenario before a run: lower bound and default tick limit.

Examples
--------
>>> from mrmp.core import Grid, RobotSpec, Scenario
>>> swap = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))))
>>> shortest_steps(swap)
[4, 4]
>>> default_max_ticks(swap, [4, 4])
64
>>> from mrmp.core import NetworkFaults
>>> default_max_ticks(swap.with_changes(network=NetworkFaults(loss=0.5, delay_max=1)), [4, 4])
768
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from mrmp.core.body import body_model
from mrmp.core.grid import Grid
from mrmp.core.limits import MAX_TICKS
from mrmp.core.scenario import Scenario
from mrmp.search.distance import distance_table
from mrmp.search.heading_distance import heading_distances


def shortest_steps(scenario: Scenario) -> list[int]:
    """Each robot's shortest path length in its body's ticks (ignoring costs and other robots).

    Moves, for bodies that turn as they move (``omni``, and the thesis's
    lockstep ticks); moves and quarter turns from its start heading for bodies
    that turn in place (``turning``: a ``(cell, heading)`` search,
    :func:`~mrmp.search.heading_distance.heading_distances`). Unreachable goals
    count as 0 (validation reports them before a run).

    >>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
    >>> ahead = Scenario(Grid(1, 3), (RobotSpec("A", (0, 0), (0, 2)),))        # facing NORTH, goal to the EAST
    >>> shortest_steps(ahead), shortest_steps(ahead.with_changes(policy=PolicyOptions(name="pibt", body="turning")))
    ([2], [3])
    """
    grid = scenario.grid
    unit = Grid(grid.x_size, grid.y_size, grid.blocked_cells()) if grid.has_costs else grid
    turning = body_model(scenario.policy.body).turns_in_place
    lengths = []
    for robot in scenario.robots:
        if turning:
            x, y = robot.start
            table = heading_distances(unit, robot.goal, 1.0, both_ways=True)
            distance = table[4 * (x * unit.y_size + y) + int(robot.heading) - 1]
        else:
            distance = distance_table(unit, robot.goal).distance(robot.start)
        lengths.append(int(distance) if math.isfinite(distance) else 0)
    return lengths


def default_max_ticks(scenario: Scenario, lengths: Sequence[int]) -> int:
    """The tick limit of a run that sets none: room for detours, waits, crowds and a slow network.

    Four times the longest shortest path, plus two ticks per robot, and never
    fewer than 64; when the safety layer guards moves over a faulty network,
    times the ticks a claim's round trip can take (``2 * delay_max + 1``) and
    the expected number of tries of a claim and its answer (``1 / (1 - loss)^2``);
    never more than :data:`~mrmp.core.limits.MAX_TICKS`.
    """
    longest = max(lengths, default=0)
    ticks = max(64, 4 * longest + 2 * len(scenario.robots))
    if scenario.safety:
        ticks = int(ticks * network_slowdown(scenario))
    return min(ticks, MAX_TICKS)


def network_slowdown(scenario: Scenario) -> float:
    """How many times longer a guarded exchange takes over the scenario's worst faults than over a perfect network.

    A claim's round trip takes up to ``2 * delay_max + 1`` ticks, and a claim and
    its answer both get through with probability ``(1 - loss)^2``.

    >>> from mrmp.core import Grid, NetworkFaults, Scenario
    >>> network_slowdown(Scenario(Grid(2, 2), (), network=NetworkFaults(loss=0.5, delay_max=1)))
    12.0
    """
    worst = scenario.worst_faults()
    if worst.is_perfect:
        return 1.0
    delivered = max(1.0 - worst.loss, 0.05) ** 2
    return (2 * worst.delay_max + 1) / delivered
