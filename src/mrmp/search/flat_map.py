"""A grid in flat form, with cached distance lists: what PIBT works on.

Cells are flat indices ``x * y_size + y``; ``neighbours[i]`` lists the free
4-neighbours of cell ``i`` (NORTH, EAST, SOUTH, WEST). :meth:`FlatMap.distances`
gives, for one goal, the cost of reaching it from every flat cell (entry costs
respected: breadth-first search, or label-correcting search with costs, see
:mod:`mrmp.search.distance`), as a plain list for fast indexing, computed
once per goal and kept. The time spent computing them is counted in
:attr:`FlatMap.table_seconds`.

A table is a pure function of the map and the goal, so a fleet simulated in one
process shares one :class:`FlatMap`; in live mode each robot has its own.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> flat = FlatMap(Grid.from_rows(["...", ".#."]))   # (0, 1) is blocked
>>> flat.index((1, 2)), flat.cell(5)
(5, (1, 2))
>>> flat.neighbours[flat.index((0, 0))]
(3,)
>>> to_corner = flat.distances(flat.index((1, 2)))
>>> to_corner[flat.index((0, 0))], to_corner[flat.index((0, 1))]
(3.0, inf)
>>> flat.tables_computed
1
"""

from __future__ import annotations

import time

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.search.distance import distance_table

__all__ = ["FlatMap"]


class FlatMap:
    """A grid's flat form and its distance lists, computed on demand (module docstring)."""

    __slots__ = ("_tables", "grid", "neighbours", "table_seconds", "y_size")

    def __init__(self, grid: Grid) -> None:
        self.grid = grid
        self.y_size = grid.y_size
        y_size = grid.y_size
        self.neighbours: list[tuple[int, ...]] = [
            tuple(nx * y_size + ny for nx, ny in grid.neighbours((x, y))) if grid.is_free((x, y)) else ()
            for x in range(grid.x_size)
            for y in range(y_size)
        ]
        self._tables: dict[int, list[float]] = {}
        self.table_seconds = 0.0

    def index(self, cell: Cell) -> int:
        """The flat index of ``cell``."""
        return cell[0] * self.y_size + cell[1]

    def cell(self, index: int) -> Cell:
        """The cell of flat index ``index``."""
        x, y = divmod(index, self.y_size)
        return (x, y)

    def distances(self, goal: int) -> list[float]:
        """For every flat cell, the cost to reach the flat cell ``goal`` (``inf`` where it cannot)."""
        table = self._tables.get(goal)
        if table is None:
            started = time.perf_counter()
            table = distance_table(self.grid, self.cell(goal)).array.ravel().tolist()
            self.table_seconds += time.perf_counter() - started
            self._tables[goal] = table
        return table

    @property
    def tables_computed(self) -> int:
        """How many goals have a distance list."""
        return len(self._tables)
