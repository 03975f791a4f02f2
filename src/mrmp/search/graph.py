"""The small grid protocol that planners search, and the shape of a planner.

Planners never read files: they take any object that answers four questions
about a 4-connected grid (:class:`GridMap`). :class:`mrmp.core.grid.Grid`
satisfies it, and so does any wrapper a robot builds around it (for example a
grid that also treats cells reserved by other robots as blocked).

Every planner of :mod:`mrmp.search` has the same call shape
(:class:`Planner`), so the robot layer can pick one by name from
:data:`mrmp.search.PLANNERS`.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> isinstance(Grid(3, 3), GridMap), isinstance(Grid(3, 3), SizedGridMap)
(True, True)
>>> check_endpoints(Grid.from_rows(["..", ".@"]), (1, 1), (0, 1))
Traceback (most recent call last):
...
mrmp.core.errors.NoPathError: goal (0, 1) is not a free cell
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from itertools import pairwise
from typing import Protocol, runtime_checkable

from mrmp.core.body import BodyModel
from mrmp.core.cell import Cell
from mrmp.core.errors import NoPathError
from mrmp.core.heading import Heading, right_turns
from mrmp.core.scenario import Timing
from mrmp.search.result import SearchResult

__all__ = ["GridMap", "Planner", "SizedGridMap", "check_endpoints", "path_cost", "path_headings"]


@runtime_checkable
class GridMap(Protocol):
    """What a planner needs to know about a 4-connected grid.

    ``neighbours(cell)`` lists the free cells a robot on ``cell`` may move to
    in one step (NORTH, EAST, SOUTH, WEST order for :class:`~mrmp.core.grid.Grid`);
    ``cost(cell)`` is the cost of *entering* ``cell``; ``min_cost`` is a lower
    bound on every entry cost (used by admissible heuristics).

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> grid: GridMap = Grid(2, 2, costs={(1, 1): 0.5})
    >>> grid.is_free((1, 1)), grid.neighbours((0, 0)), grid.cost((1, 1)), grid.min_cost
    (True, [(1, 0), (0, 1)], 0.5, 0.5)
    """

    def is_free(self, cell: Cell) -> bool:
        """Whether a robot may stand on ``cell`` (on the grid and not an obstacle)."""
        ...

    def neighbours(self, cell: Cell) -> Sequence[Cell]:
        """The free cells one step from ``cell``."""
        ...

    def cost(self, cell: Cell) -> float:
        """The positive cost of entering ``cell``."""
        ...

    @property
    def min_cost(self) -> float:
        """A positive lower bound on :meth:`cost` over all cells."""
        ...


@runtime_checkable
class SizedGridMap(GridMap, Protocol):
    """A :class:`GridMap` that also knows its extent (needed for whole-grid tables).

    Cells are ``(x, y)`` with ``0 <= x < x_size`` and ``0 <= y < y_size``.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> grid: SizedGridMap = Grid(4, 2)
    >>> grid.x_size, grid.y_size
    (4, 2)
    """

    x_size: int
    y_size: int


class Planner(Protocol):
    """The call shape shared by every single-robot planner of :mod:`mrmp.search`.

    Parameters
    ----------
    grid:
        The grid to plan on.
    start, goal:
        The robot's cell and the cell it must reach.
    blocked:
        Extra cells to treat as obstacles (for example cells other robots
        occupy); ``start`` is always allowed.
    heading:
        The robot's current heading. When given, the planner charges
        ``timing.turn_time`` per right turn and returns the headings.
    timing:
        How long a cell and a right turn take (``Timing()`` when omitted).
    body:
        The body model (:mod:`mrmp.core.body`) whose turns a heading-aware
        planner charges instead of right turns: a ``turning`` body turns a
        quarter either way, one cell time each.

    Returns
    -------
    SearchResult
        The path from ``start`` to ``goal`` (both included) and its cost.

    Raises
    ------
    NoPathError
        If the planner finds no path.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> from mrmp.search import PLANNERS
    >>> planner: Planner = PLANNERS["astar"]
    >>> planner(Grid(2, 2), (0, 0), (1, 1)).cost
    2.0
    """

    def __call__(
        self,
        grid: GridMap,
        start: Cell,
        goal: Cell,
        *,
        blocked: Collection[Cell] = ...,
        heading: Heading | None = None,
        timing: Timing | None = None,
        body: BodyModel | None = None,
    ) -> SearchResult:
        """Plan a path from ``start`` to ``goal``."""
        ...


def check_endpoints(grid: GridMap, start: Cell, goal: Cell, blocked: Collection[Cell] = frozenset()) -> None:
    """Raise :class:`NoPathError` unless ``start`` and ``goal`` can be ends of a path.

    ``start`` must be a free cell of ``grid`` (it may be in ``blocked``: a robot
    may always leave the cell it stands on); ``goal`` must be free and not in
    ``blocked``.

    Parameters
    ----------
    grid:
        The grid.
    start, goal:
        The path's ends.
    blocked:
        Extra obstacles.

    Raises
    ------
    NoPathError
        Naming the offending end.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> check_endpoints(Grid(3, 3), (0, 0), (2, 2))
    >>> check_endpoints(Grid(3, 3), (0, 0), (2, 2), blocked={(2, 2)})
    Traceback (most recent call last):
    ...
    mrmp.core.errors.NoPathError: goal (2, 2) is blocked
    """
    if not grid.is_free(start):
        raise NoPathError(f"start {start} is not a free cell")
    if not grid.is_free(goal):
        raise NoPathError(f"goal {goal} is not a free cell")
    if goal != start and goal in blocked:
        raise NoPathError(f"goal {goal} is blocked")


def path_headings(path: Sequence[Cell], heading: Heading) -> tuple[Heading, ...]:
    """The robot's heading on each cell of ``path`` when it starts facing ``heading``.

    A robot turns to face a neighbour before moving there, so its heading on
    ``path[i]`` (``i >= 1``) is the direction of the move into ``path[i]``.

    Parameters
    ----------
    path:
        4-adjacent cells, the start first.
    heading:
        The heading on ``path[0]``.

    Returns
    -------
    tuple of Heading
        One heading per cell of ``path``.

    Raises
    ------
    ValueError
        If two consecutive cells are not 4-adjacent.

    Examples
    --------
    >>> [h.name for h in path_headings([(0, 0), (1, 0), (1, 1)], Heading.EAST)]
    ['EAST', 'NORTH', 'EAST']
    """
    headings = [heading]
    for before, after in pairwise(path):
        headings.append(Heading.between(before, after))
    return tuple(headings)


def path_cost(
    grid: GridMap,
    path: Sequence[Cell],
    *,
    heading: Heading | None = None,
    timing: Timing | None = None,
    body: BodyModel | None = None,
) -> float:
    """The cost of following ``path``, as every planner of :mod:`mrmp.search` counts it.

    The sum of ``cost(cell)`` over every cell entered (all but ``path[0]``),
    times ``timing.cell_time`` when ``timing`` is given; when ``heading`` is
    given, plus ``timing.turn_time`` per right turn (thesis section 3.3: the
    robot only turns right, ``(h2 - h) mod 4`` turns from ``h`` to ``h2``), or,
    with a ``body``, the body's turns at its time per quarter turn.

    Parameters
    ----------
    grid:
        Supplies the entry costs.
    path:
        4-adjacent cells, the start first.
    heading:
        The heading on ``path[0]``; ``None`` to ignore turns.
    timing:
        Cell and turn durations; ``Timing()`` when omitted.
    body:
        The body model whose turns count (:mod:`mrmp.core.body`); right turns when omitted.

    Returns
    -------
    float
        The path's cost.

    Raises
    ------
    ValueError
        If ``heading`` is given and two consecutive cells are not 4-adjacent.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> grid = Grid(3, 3, costs={(1, 1): 3.0})
    >>> path_cost(grid, [(0, 0), (0, 1), (1, 1)])
    4.0
    >>> path_cost(grid, [(0, 0), (0, 1), (1, 1)], heading=Heading.NORTH, timing=Timing(2.0, 0.5))
    10.0
    >>> from mrmp.core.body import body_model
    >>> path_cost(grid, [(0, 0), (0, 1), (1, 1)], heading=Heading.NORTH, timing=Timing(2.0, 0.5), body=body_model("turning"))
    12.0
    """
    timing = timing or Timing()
    total = timing.cell_time * sum(grid.cost(cell) for cell in path[1:])
    if heading is not None:
        headings = path_headings(path, heading)
        if body is None:
            turn_time = timing.turn_time
            turns = sum(right_turns(before, after) for before, after in pairwise(headings))
        else:
            turn_time = body.turn_ticks(timing.turn_time, timing.cell_time) * timing.cell_time
            turns = sum(body.quarter_turns(before, after) for before, after in pairwise(headings))
        total += turn_time * turns
    return total
