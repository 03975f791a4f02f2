"""The single-robot planners by name: Dijkstra, greedy best-first, A*, update-coordinate.

Dijkstra, greedy best-first and A* are thin wrappers around the one engine in
:mod:`mrmp.search.best_first_engine`; they differ only in the priority function.
All four planners share the call shape :class:`mrmp.search.graph.Planner` and
are listed in :data:`PLANNERS` under the names the thesis's chapter 1 uses.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> grid = Grid.from_rows(["....", ".@@.", "...."])
>>> sorted(PLANNERS)
['astar', 'best_first', 'dijkstra', 'update_coordinate']
>>> [PLANNERS[name](grid, (0, 0), (2, 3)).cost for name in sorted(PLANNERS)]
[5.0, 5.0, 5.0, 5.0]
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from types import MappingProxyType

from mrmp.core.body import BodyModel
from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.core.scenario import Timing
from mrmp.search.best_first_engine import ASTAR, DIJKSTRA, GREEDY_BEST_FIRST, best_first_search
from mrmp.search.graph import GridMap, Planner
from mrmp.search.result import SearchResult
from mrmp.search.update_coordinate import update_coordinate_path

__all__ = ["PLANNERS", "astar", "dijkstra", "greedy_best_first"]


def dijkstra(
    grid: GridMap,
    start: Cell,
    goal: Cell,
    *,
    blocked: Collection[Cell] = frozenset(),
    heading: Heading | None = None,
    timing: Timing | None = None,
    body: BodyModel | None = None,
) -> SearchResult:
    """Find a cheapest path by uniform-cost search (Dijkstra 1959, "A note on two problems in connexion with graphs").

    Nodes are expanded in order of their cost so far ``g``; the first time the
    goal is popped its cost is minimal because every entry cost is positive.

    Parameters
    ----------
    grid:
        The grid; entering a cell costs ``grid.cost(cell)``.
    start, goal:
        The path's ends.
    blocked:
        Extra cells to treat as obstacles; ``start`` is always allowed.
    heading:
        The robot's heading on ``start``; when given, right turns cost
        ``timing.turn_time`` each and the result carries the headings.
    timing:
        Cell and turn durations; ``Timing()`` when omitted.
    body:
        The body model whose turns a heading-aware search charges
        (:mod:`mrmp.search.best_first_engine`); right turns when omitted.

    Returns
    -------
    SearchResult
        A cheapest path, its cost and the number of expanded nodes.

    Raises
    ------
    NoPathError
        If ``start`` or ``goal`` is not free or the goal cannot be reached.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> grid = Grid.from_rows(["...", ".9.", "..."])
    >>> result = dijkstra(grid, (1, 0), (1, 2))
    >>> result.path, result.cost
    (((1, 0), (2, 0), (2, 1), (2, 2), (1, 2)), 4.0)
    """
    return best_first_search(grid, start, goal, DIJKSTRA, blocked=blocked, heading=heading, timing=timing, body=body)


def greedy_best_first(
    grid: GridMap,
    start: Cell,
    goal: Cell,
    *,
    blocked: Collection[Cell] = frozenset(),
    heading: Heading | None = None,
    timing: Timing | None = None,
    body: BodyModel | None = None,
) -> SearchResult:
    """Find a path by greedy best-first search (Pearl 1984, *Heuristics*).

    Nodes are expanded in order of their estimated distance to the goal ``h``
    only (the manhattan bound of :mod:`mrmp.search.best_first_engine`), so the
    search heads straight for the goal and usually expands few nodes, but the
    path it returns need not be the cheapest.

    Parameters
    ----------
    grid:
        The grid; entering a cell costs ``grid.cost(cell)``.
    start, goal:
        The path's ends.
    blocked:
        Extra cells to treat as obstacles; ``start`` is always allowed.
    heading:
        The robot's heading on ``start``; when given, right turns cost
        ``timing.turn_time`` each and the result carries the headings.
    timing:
        Cell and turn durations; ``Timing()`` when omitted.
    body:
        The body model whose turns a heading-aware search charges
        (:mod:`mrmp.search.best_first_engine`); right turns when omitted.

    Returns
    -------
    SearchResult
        A path (maybe not the cheapest), its actual cost and the number of
        expanded nodes.

    Raises
    ------
    NoPathError
        If ``start`` or ``goal`` is not free or the goal cannot be reached.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> grid = Grid.from_rows(["...", ".9.", "..."])
    >>> greedy_best_first(grid, (1, 0), (1, 2)).cost   # straight through the 9
    10.0
    """
    return best_first_search(grid, start, goal, GREEDY_BEST_FIRST, blocked=blocked, heading=heading, timing=timing, body=body)


def astar(
    grid: GridMap,
    start: Cell,
    goal: Cell,
    *,
    blocked: Collection[Cell] = frozenset(),
    heading: Heading | None = None,
    timing: Timing | None = None,
    body: BodyModel | None = None,
) -> SearchResult:
    """Find a cheapest path by A* (Hart, Nilsson & Raphael 1968).

    Nodes are expanded in order of ``g + h`` where ``h`` is ``manhattan *
    min_cost * cell_time`` (plus, when heading-aware, the fewest right turns
    that face every direction the path must take, times ``turn_time``). Both
    terms never overestimate and are consistent (see
    :mod:`mrmp.search.best_first_engine`), so the path is a cheapest one, and
    A* expands no node Dijkstra would not.

    Parameters
    ----------
    grid:
        The grid; entering a cell costs ``grid.cost(cell)``.
    start, goal:
        The path's ends.
    blocked:
        Extra cells to treat as obstacles; ``start`` is always allowed.
    heading:
        The robot's heading on ``start``; when given, the search runs over
        ``(cell, heading)`` states, right turns cost ``timing.turn_time`` each
        and the result carries the headings.
    timing:
        Cell and turn durations; ``Timing()`` when omitted.
    body:
        The body model whose turns a heading-aware search charges
        (:mod:`mrmp.search.best_first_engine`); right turns when omitted.

    Returns
    -------
    SearchResult
        A cheapest path, its cost and the number of expanded nodes.

    Raises
    ------
    NoPathError
        If ``start`` or ``goal`` is not free or the goal cannot be reached.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> from mrmp.core.heading import Heading
    >>> grid = Grid(5, 5)
    >>> astar(grid, (0, 0), (4, 4)).cost
    8.0
    >>> turning = astar(grid, (0, 0), (4, 4), heading=Heading.NORTH, timing=Timing(1.0, 0.5))
    >>> turning.cost, turning.path[:6]   # north first, then one right turn
    (8.5, ((0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (4, 1)))
    >>> astar(grid, (0, 0), (4, 4), blocked={(0, 1), (1, 0)})
    Traceback (most recent call last):
    ...
    mrmp.core.errors.NoPathError: no path: goal (4, 4) cannot be reached (searched 1 states)
    """
    return best_first_search(grid, start, goal, ASTAR, blocked=blocked, heading=heading, timing=timing, body=body)


PLANNERS: Mapping[str, Planner] = MappingProxyType(
    {
        "update_coordinate": update_coordinate_path,
        "dijkstra": dijkstra,
        "best_first": greedy_best_first,
        "astar": astar,
    }
)
"""Every single-robot planner by name (read-only); all share the :class:`~mrmp.search.graph.Planner` call shape."""
