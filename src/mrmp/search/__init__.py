"""Single-robot planners on a 4-connected grid, and distance tables.

The thesis's chapter 1 lists the planners a robot may use; its future work 1
attaches costs to cells ("A*, Best First ... costs can be attached to the
paths"). This layer provides them, all with one call shape
(:class:`~mrmp.search.graph.Planner`) over a small grid protocol
(:class:`~mrmp.search.graph.GridMap`):

* :func:`update_coordinate_path`: the thesis's own L-shaped method
  (sections 3.1 and 3.2), x first then y, no search;
* :func:`dijkstra` (Dijkstra 1959), :func:`greedy_best_first` (Pearl 1984) and
  :func:`astar` (Hart, Nilsson & Raphael 1968): one best-first engine
  (:mod:`mrmp.search.best_first_engine`) with three priority functions,
  optionally heading-aware (right turns cost time);
* :func:`distance_table`: the cost from every cell to one goal;
* :class:`FlatGrid` (:mod:`mrmp.search.flat_grid`): the one flat form of a grid
  (row-major cell numbers, neighbour tables, obstacle mask) that the tables,
  the PIBTs and LaCAM index by, with one distance convention (:data:`UNREACHABLE`).

:data:`PLANNERS` maps the names ``update_coordinate``, ``dijkstra``,
``best_first`` and ``astar`` to the planners; :data:`mrmp.search.choices.SEARCH_TABLE`
is the table of them a per-robot policy chooses from (``policy.search``, ``mrmp run
--search``), with the names the setting accepts and each search's properties.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> grid = Grid.from_rows(["....", ".@@.", "...."])
>>> PLANNERS["astar"](grid, (0, 0), (2, 3)).path
((0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (2, 3))
>>> distance_table(grid, (2, 3)).distance((0, 0))
5.0
"""

from mrmp.search.best_first_engine import (
    ASTAR,
    DIJKSTRA,
    GREEDY_BEST_FIRST,
    PriorityFunction,
    Strategy,
    best_first_search,
)
from mrmp.search.distance import DistanceTable, distance_table
from mrmp.search.flat_grid import UNREACHABLE, FlatGrid, flat_grid
from mrmp.search.graph import GridMap, Planner, SizedGridMap, path_cost, path_headings
from mrmp.search.planners import PLANNERS, astar, dijkstra, greedy_best_first
from mrmp.search.result import SearchResult
from mrmp.search.update_coordinate import update_coordinate_cells, update_coordinate_path

__all__ = [
    "ASTAR",
    "DIJKSTRA",
    "GREEDY_BEST_FIRST",
    "PLANNERS",
    "UNREACHABLE",
    "DistanceTable",
    "FlatGrid",
    "GridMap",
    "Planner",
    "PriorityFunction",
    "SearchResult",
    "SizedGridMap",
    "Strategy",
    "astar",
    "best_first_search",
    "dijkstra",
    "distance_table",
    "flat_grid",
    "greedy_best_first",
    "path_cost",
    "path_headings",
    "update_coordinate_cells",
    "update_coordinate_path",
]
