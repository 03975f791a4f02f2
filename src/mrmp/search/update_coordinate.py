"""The thesis's "update coordinate method": an L-shaped path, x first, then y.

Section 3.1 (item 4) of the thesis plans a robot's route by updating one
coordinate at a time, and section 3.2 (assumption 2) fixes the order: the robot
first changes its x coordinate one cell at a time until it equals the goal's x,
then changes y the same way. The path is the straight "L" through the corner
``(goal_x, start_y)``. It is not a search: it visits exactly the cells of the
path and fails if one of them is blocked.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> update_coordinate_path(Grid(5, 5), (0, 0), (2, 1)).path
((0, 0), (1, 0), (2, 0), (2, 1))
"""

from __future__ import annotations

from collections.abc import Collection

from mrmp.core.body import BodyModel
from mrmp.core.cell import Cell, step_toward
from mrmp.core.errors import NoPathError
from mrmp.core.heading import Heading
from mrmp.core.scenario import Timing
from mrmp.search.graph import GridMap, check_endpoints, path_cost, path_headings
from mrmp.search.result import SearchResult

__all__ = ["update_coordinate_cells", "update_coordinate_path"]


def update_coordinate_cells(start: Cell, goal: Cell) -> tuple[Cell, ...]:
    """The cells of the update-coordinate L from ``start`` to ``goal``, ignoring obstacles.

    Parameters
    ----------
    start, goal:
        The path's ends.

    Returns
    -------
    tuple of Cell
        ``start``, then the cells reached by stepping x toward ``goal[0]``, then
        those reached by stepping y toward ``goal[1]``.

    Examples
    --------
    >>> update_coordinate_cells((4, 4), (3, 2))
    ((4, 4), (3, 4), (3, 3), (3, 2))
    """
    x, y = start
    cells = [start]
    while x != goal[0]:
        x = step_toward(x, goal[0])
        cells.append((x, y))
    while y != goal[1]:
        y = step_toward(y, goal[1])
        cells.append((x, y))
    return tuple(cells)


def update_coordinate_path(
    grid: GridMap,
    start: Cell,
    goal: Cell,
    *,
    blocked: Collection[Cell] = frozenset(),
    heading: Heading | None = None,
    timing: Timing | None = None,
    body: BodyModel | None = None,
) -> SearchResult:
    """Plan with the thesis's update-coordinate method (sections 3.1 item 4, 3.2 assumption 2).

    Step x toward the goal's x until they are equal, then step y toward the
    goal's y. The method never detours, so a blocked cell on the L means there
    is no such path.

    Parameters
    ----------
    grid:
        The grid.
    start, goal:
        The path's ends.
    blocked:
        Extra cells to treat as obstacles (``start`` is always allowed).
    heading:
        The robot's heading on ``start``; when given, the result carries the
        headings and its cost includes ``timing.turn_time`` per right turn.
    timing:
        Cell and turn durations; ``Timing()`` when omitted.
    body:
        The body model whose turns the cost counts (:func:`~mrmp.search.graph.path_cost`); right turns when omitted.

    Returns
    -------
    SearchResult
        The L-shaped path, its cost, and ``expansions`` = the number of cells
        visited (``len(path)``).

    Raises
    ------
    NoPathError
        If ``start`` or ``goal`` is not free, or a cell of the L is an obstacle
        or in ``blocked``; the message names that cell.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> result = update_coordinate_path(Grid(5, 5), (0, 0), (4, 4))
    >>> result.path
    ((0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (4, 1), (4, 2), (4, 3), (4, 4))
    >>> result.cost, result.expansions
    (8.0, 9)
    >>> update_coordinate_path(Grid.from_rows([".....", ".....", "@....", ".....", "....."]), (0, 0), (4, 4))
    Traceback (most recent call last):
    ...
    mrmp.core.errors.NoPathError: update-coordinate path from (0, 0) to (4, 4) is blocked at (2, 0)
    """
    check_endpoints(grid, start, goal, blocked)
    path = update_coordinate_cells(start, goal)
    for cell in path[1:]:
        if not grid.is_free(cell) or cell in blocked:
            raise NoPathError(f"update-coordinate path from {start} to {goal} is blocked at {cell}")
    cost = path_cost(grid, path, heading=heading, timing=timing, body=body)
    headings = None if heading is None else path_headings(path, heading)
    return SearchResult(path=path, cost=cost, expansions=len(path), headings=headings)
