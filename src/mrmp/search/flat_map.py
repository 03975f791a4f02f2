"""A grid's flat form with cached distance lists: what PIBT works on.

A :class:`FlatMap` is a :class:`~mrmp.search.flat_grid.FlatGrid` (cells are
flat indices ``x * y_size + y``; ``neighbours[i]`` lists the free 4-neighbours
of cell ``i``, NORTH, EAST, SOUTH, WEST) that also keeps distance lists.
:meth:`FlatMap.distances` gives, for one goal, the cost of reaching it from
every flat cell (entry costs respected: breadth-first search, or
label-correcting search with costs, see :mod:`mrmp.search.distance`), as an
``array`` indexed like a list in the flat grid's distance convention
(``inf`` where the goal cannot be reached), computed once per goal and kept in
4 bytes an entry where that is exact (:func:`compact`), else 8;
:meth:`FlatMap.heading_distances` does the same for the heading-aware tables
(turns cost time). The time spent computing them is counted in
:attr:`FlatMap.table_seconds`. The lists kept are bounded in bytes
(:data:`TABLE_BUDGET_BYTES`): a lifelong run visits goal after goal, and the
lists of goals no longer used are dropped, least recently used first.

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
from array import array
from collections import OrderedDict

import numpy as np

from mrmp.core.grid import Grid
from mrmp.search.distance import distance_table
from mrmp.search.flat_grid import FlatGrid
from mrmp.search.heading_distance import heading_distances

__all__ = ["TABLE_BUDGET_BYTES", "FlatMap", "compact"]

TABLE_BUDGET_BYTES = 4 * 2**30
"""How many bytes of distance lists one :class:`FlatMap` keeps; beyond it, the lists used least
recently are dropped, to be computed again if asked for."""
_EXACT_IN_SINGLE = 2.0**24
"""Whole numbers below this are exact in a single-precision float."""

_TableKey = tuple[int, float, bool, str] | int
"""A plain list's goal, or a heading-aware list's ``(goal, turn_cost, both_ways, guidance)``."""


class FlatMap(FlatGrid):
    """A grid's flat form and its distance lists, computed on demand (module docstring).

    ``entry_costs`` is :attr:`~mrmp.search.flat_grid.FlatGrid.costs`, or
    ``None`` when every cell costs 1 (the plain grids of the thesis).
    ``budget_bytes`` bounds the memory of the lists kept (:data:`TABLE_BUDGET_BYTES`).

    >>> flat = FlatMap(Grid(1, 4), budget_bytes=32)   # room for two lists of 4 cells, 4 bytes each
    >>> first = flat.distances(0); second = flat.distances(3); third = flat.distances(1)
    >>> flat.tables_kept, flat.tables_computed
    (2, 3)
    >>> flat.distances(0) == first, flat.tables_computed   # dropped, so computed again
    (True, 4)
    """

    __slots__ = ("_kept_bytes", "_tables", "budget_bytes", "entry_costs", "grid", "table_seconds", "tables_computed")

    def __init__(self, grid: Grid, *, budget_bytes: int = TABLE_BUDGET_BYTES) -> None:
        super().__init__(grid)
        self.grid = grid
        self.entry_costs: list[float] | None = self.costs if grid.has_costs else None
        self.budget_bytes = budget_bytes
        self._tables: OrderedDict[_TableKey, array[float]] = OrderedDict()
        self._kept_bytes = 0
        self.table_seconds = 0.0
        self.tables_computed = 0
        """How many distance lists have been computed (per goal; heading-aware ones counted apart; again when dropped)."""

    def distances(self, goal: int) -> array[float]:
        """For every flat cell, the cost to reach the flat cell ``goal`` (``inf`` where it cannot)."""
        table = self._kept(goal)
        if table is None:
            started = time.perf_counter()
            table = distance_table(self.grid, self.cell(goal)).as_array()
            table = self._keep(goal, table, started)
        return table

    def heading_distances(
        self, goal: int, turn_cost: float, both_ways: bool = False, guidance: str = "none"
    ) -> array[float]:
        """For every state (flat cell ``i``, heading ``h``), at ``4 * i + h - 1``, the heading-aware
        cost to reach the flat cell ``goal`` when a right turn (a quarter turn either way, with
        ``both_ways``) costs ``turn_cost``, moves against the lanes of ``guidance`` more
        (:func:`~mrmp.search.heading_distance.heading_distances`), computed once per goal and kept.

        >>> flat = FlatMap(Grid(1, 3))
        >>> list(flat.heading_distances(2, 0.5)[:4])    # from (0, 0) facing NORTH, EAST, SOUTH, WEST
        [2.5, 2.0, 3.5, 3.0]
        """
        key = (goal, turn_cost, both_ways, guidance)
        table = self._kept(key)
        if table is None:
            started = time.perf_counter()
            table = heading_distances(self.grid, self.cell(goal), turn_cost, both_ways, guidance)
            table = self._keep(key, table, started)
        return table

    @property
    def tables_kept(self) -> int:
        """How many distance lists are kept now."""
        return len(self._tables)

    def _kept(self, key: _TableKey) -> array[float] | None:
        """The list kept under ``key``, marked as the one used last; ``None`` when there is none."""
        table = self._tables.get(key)
        if table is not None:
            self._tables.move_to_end(key)
        return table

    def _keep(self, key: _TableKey, table: array[float], started: float) -> array[float]:
        """Keep ``table`` (:func:`compact`), whose computation began at ``started`` (``time.perf_counter``),
        dropping the lists used least recently while the budget is exceeded; the list kept."""
        table = compact(table)
        self.table_seconds += time.perf_counter() - started
        self.tables_computed += 1
        self._tables[key] = table
        self._kept_bytes += table.itemsize * len(table)
        while self._kept_bytes > self.budget_bytes and len(self._tables) > 1:
            _, dropped = self._tables.popitem(last=False)
            self._kept_bytes -= dropped.itemsize * len(dropped)
        return table


def compact(table: array[float]) -> array[float]:
    """``table`` in 4 bytes an entry when that keeps every value exactly (whole numbers below 2**24, and
    ``inf``: every table of a grid without entry costs), else ``table`` itself.

    >>> compact(array("d", [0.0, 3.0, float("inf")])).typecode, compact(array("d", [0.5])).typecode
    ('f', 'd')
    """
    values = np.frombuffer(table, dtype=np.float64)
    finite = values[np.isfinite(values)]
    if finite.size and (np.abs(finite).max() >= _EXACT_IN_SINGLE or not np.array_equal(finite, np.round(finite))):
        return table
    return array("f", values.astype(np.float32).tobytes())
