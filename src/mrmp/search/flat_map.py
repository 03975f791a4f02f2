"""A grid's flat form with cached distance lists: what PIBT works on.

A :class:`FlatMap` is a :class:`~mrmp.search.flat_grid.FlatGrid` (cells are
flat indices ``x * y_size + y``; ``neighbours[i]`` lists the free 4-neighbours
of cell ``i``, NORTH, EAST, SOUTH, WEST) that also keeps distance lists.
:meth:`FlatMap.distances` gives, for one goal, the cost of reaching it from
every flat cell (entry costs respected: breadth-first search, or
label-correcting search with costs, see :mod:`mrmp.search.distance`), as a
plain list for fast indexing in the flat grid's distance convention (``inf``
where the goal cannot be reached), computed once per goal and kept;
:meth:`FlatMap.heading_distances` does the same for the heading-aware tables
(turns cost time). The time spent computing them is counted in
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

from mrmp.core.grid import Grid
from mrmp.search.distance import distance_table
from mrmp.search.flat_grid import FlatGrid
from mrmp.search.heading_distance import heading_distances

__all__ = ["FlatMap"]


class FlatMap(FlatGrid):
    """A grid's flat form and its distance lists, computed on demand (module docstring).

    ``entry_costs`` is :attr:`~mrmp.search.flat_grid.FlatGrid.costs`, or
    ``None`` when every cell costs 1 (the plain grids of the thesis).
    """

    __slots__ = ("_heading_tables", "_tables", "entry_costs", "grid", "table_seconds")

    def __init__(self, grid: Grid) -> None:
        super().__init__(grid)
        self.grid = grid
        self.entry_costs: list[float] | None = self.costs if grid.has_costs else None
        self._tables: dict[int, list[float]] = {}
        self._heading_tables: dict[tuple[int, float, bool], list[float]] = {}
        self.table_seconds = 0.0

    def distances(self, goal: int) -> list[float]:
        """For every flat cell, the cost to reach the flat cell ``goal`` (``inf`` where it cannot)."""
        table = self._tables.get(goal)
        if table is None:
            started = time.perf_counter()
            table = distance_table(self.grid, self.cell(goal)).as_list()
            self.table_seconds += time.perf_counter() - started
            self._tables[goal] = table
        return table
    def heading_distances(self, goal: int, turn_cost: float, both_ways: bool = False) -> list[float]:
        """For every state (flat cell ``i``, heading ``h``), at ``4 * i + h - 1``, the heading-aware
        cost to reach the flat cell ``goal`` when a right turn (a quarter turn either way, with
        ``both_ways``) costs ``turn_cost``
        (:func:`~mrmp.search.heading_distance.heading_distances`), computed once per goal and kept.

        >>> from mrmp.core.grid import Grid
        >>> flat = FlatMap(Grid(1, 3))
        >>> flat.heading_distances(2, 0.5)[:4]    # from (0, 0) facing NORTH, EAST, SOUTH, WEST
        [2.5, 2.0, 3.5, 3.0]
        """
        key = (goal, turn_cost, both_ways)
        table = self._heading_tables.get(key)
        if table is None:
            started = time.perf_counter()
            table = heading_distances(self.grid, self.cell(goal), turn_cost, both_ways)
            self.table_seconds += time.perf_counter() - started
            self._heading_tables[key] = table
        return table

    @property
    def tables_computed(self) -> int:
        """How many distance lists have been computed (per goal; heading-aware ones counted apart)."""
        return len(self._tables) + len(self._heading_tables)
