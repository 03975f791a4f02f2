"""Heading-aware distance tables: the cost to a goal from every (cell, heading) state.

The Khepera III turns only to the right (thesis section 3.5), so a robot's cost to
reach its goal depends on where it faces: facing NORTH, a move WEST first costs
three right turns. :func:`heading_distances` computes, for one goal, the least cost
from every state ``(cell, heading)`` — the heading being the direction the robot
faces on that cell — to the goal cell in any heading, where a move from ``c`` in
direction ``d`` while facing ``h`` costs ``right_turns(h, d) * turn_cost`` plus the
entry cost of the cell entered (the same model as heading-aware A*,
:mod:`mrmp.search.best_first_engine`). It is Dijkstra's algorithm (Dijkstra, 1959)
run backwards from the goal's four states over the state graph.

The table is a flat list: the state of flat cell ``i`` (``x * y_size + y``) facing
heading ``h`` (1-4) is entry ``4 * i + h - 1``; blocked and unreachable states are
``inf``. Policy ``pibt`` with ``heading_aware`` ranks its candidate cells with it
(:func:`mrmp.policies.pibt_rules.heading_candidates`).

With ``both_ways`` a body turns a quarter either way (the ``turning`` body of
:mod:`mrmp.core.body`, LoRR's ``MAPF_T``), so a change of heading costs
``min(r, 4 - r)`` quarter turns instead of ``r`` right turns; with
``turn_cost=1`` the table counts the ticks of MAPF_T's actions (forward, turn,
wait), the distance of the ``(cell, heading)`` search that LoRR's planners use.

Examples
--------
A 1x3 corridor, goal at its east end (0, 2); a right turn costs half a cell:

>>> from mrmp.core.grid import Grid
>>> from mrmp.core.heading import Heading
>>> table = heading_distances(Grid(1, 3), (0, 2), turn_cost=0.5)
>>> def at(cell, heading):
...     return table[4 * (cell[0] * 3 + cell[1]) + int(heading) - 1]
>>> at((0, 0), Heading.EAST), at((0, 0), Heading.NORTH), at((0, 0), Heading.WEST)
(2.0, 2.5, 3.0)
>>> at((0, 2), Heading.SOUTH)
0.0

Turning either way, facing WEST costs two quarter turns, facing NORTH one:

>>> table = heading_distances(Grid(1, 3), (0, 2), turn_cost=1.0, both_ways=True)
>>> at((0, 0), Heading.EAST), at((0, 0), Heading.NORTH), at((0, 0), Heading.WEST)
(2.0, 3.0, 4.0)
"""

from __future__ import annotations

import heapq

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import HEADINGS, quarter_turns, right_turns

__all__ = ["heading_distances"]

_TURNS = [[right_turns(facing, moving) for moving in HEADINGS] for facing in HEADINGS]
"""``_TURNS[h - 1][d - 1]``: right turns from facing ``h`` to facing ``d``."""
_QUARTERS = [[quarter_turns(facing, moving) for moving in HEADINGS] for facing in HEADINGS]
"""``_QUARTERS[h - 1][d - 1]``: quarter turns either way from facing ``h`` to facing ``d``."""


def heading_distances(grid: Grid, goal: Cell, turn_cost: float, both_ways: bool = False) -> list[float]:
    """The least cost from every ``(cell, heading)`` state of ``grid`` to ``goal`` (module docstring).

    Parameters
    ----------
    grid:
        The map (entry costs respected).
    goal:
        The goal cell; any heading on it counts as arrived.
    turn_cost:
        The cost of one right turn, in the unit of entry costs (``turn_time / cell_time``).
    both_ways:
        The body turns a quarter either way at ``turn_cost`` each (module docstring).

    Raises
    ------
    ValueError
        If ``goal`` is not a free cell of the grid, or ``turn_cost`` is negative.
    """
    if not grid.is_free(goal):
        raise ValueError(f"goal {goal} is not a free cell of the grid")
    if turn_cost < 0:
        raise ValueError(f"turn_cost must not be negative, got {turn_cost}")
    y_size = grid.y_size
    inf = float("inf")
    table = [inf] * (4 * grid.x_size * y_size)
    goal_index = goal[0] * y_size + goal[1]
    queue: list[tuple[float, int]] = []
    for heading in range(4):
        table[4 * goal_index + heading] = 0.0
        queue.append((0.0, 4 * goal_index + heading))
    deltas = [heading.delta for heading in HEADINGS]
    counts = _QUARTERS if both_ways else _TURNS
    turns = [[counts[facing][moving] * turn_cost for moving in range(4)] for facing in range(4)]
    while queue:
        cost, state = heapq.heappop(queue)
        if cost > table[state]:
            continue
        cell_index, moving = divmod(state, 4)
        x, y = divmod(cell_index, y_size)
        # the robot entered (x, y) moving in direction `moving`, from the cell behind it
        dx, dy = deltas[moving]
        before = (x - dx, y - dy)
        if not grid.is_free(before):
            continue
        entered = cost + grid.cost((x, y))
        before_index = 4 * (before[0] * y_size + before[1])
        for facing in range(4):
            candidate = entered + turns[facing][moving]
            if candidate < table[before_index + facing]:
                table[before_index + facing] = candidate
                heapq.heappush(queue, (candidate, before_index + facing))
    return table
