"""The flat form of a grid: cells numbered row-major, neighbour tables, obstacle mask, entry costs.

Every planner that loops over cells in Python works on *flat cells*: the cell
``(x, y)`` of a grid with ``y_size`` columns is the integer ``x * y_size + y``,
so per-cell data are plain lists indexed by one integer. :class:`FlatGrid`
builds those lists once per grid: the free 4-neighbours of every cell (in the
grid's order NORTH, EAST, SOUTH, WEST; blocked cells have none), the obstacle
mask, the entry cost of every cell and the cell of every flat index.
:func:`flat_grid` keeps the flat forms of recent
:class:`~mrmp.core.grid.Grid` objects, which are immutable.

**One distance convention.** A distance list is indexed by flat cell and holds
floats: the cost to the goal, and :data:`UNREACHABLE` (``math.inf``) where the
goal cannot be reached (obstacles, other components). Floats are the only type
that holds both the entry costs of costed grids (policy ``pibt`` ranks cells by
them) and the whole-move counts of tick-based planners without a conversion;
``inf`` compares above every finite distance, as the large integer sentinels it
replaces did, so candidate orders and the planners' results stay the same
wherever goals can be reached (every planner checks that before searching).

Examples
--------
>>> from mrmp.core.grid import Grid
>>> flat = FlatGrid(Grid.from_rows(["...", ".#."]))   # (0, 1) is blocked
>>> flat.index((1, 2)), flat.cell(5), flat.size
(5, (1, 2), 6)
>>> flat.neighbours[flat.index((0, 0))], flat.neighbours[flat.index((0, 1))]
((3,), ())
>>> flat.is_free(1), flat.uniform_cost
(False, 1.0)
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from typing import Any, Final

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.search.graph import SizedGridMap

__all__ = ["UNREACHABLE", "FlatGrid", "flat_grid"]

UNREACHABLE: Final[float] = math.inf
"""The distance of a cell from which the goal cannot be reached (module docstring)."""

_CACHE_SIZE = 8
"""How many grids keep their flat form in :func:`flat_grid`'s cache."""


class FlatGrid:
    """A grid as flat cells ``x * y_size + y`` with its neighbour table, obstacle mask and entry costs.

    Parameters
    ----------
    grid:
        Any :class:`~mrmp.search.graph.SizedGridMap`; it is read once.

    Attributes
    ----------
    x_size, y_size, size:
        The grid's extent and its number of cells.
    neighbours:
        For every flat cell, the flat cells of its free 4-neighbours on the
        grid (NORTH, EAST, SOUTH, WEST for :class:`~mrmp.core.grid.Grid`);
        ``()`` for blocked cells.
    free:
        The obstacle mask: ``free[i]`` is 1 where cell ``i`` is free, 0 where blocked.
    costs:
        For every flat cell, the cost of entering it, as the grid states it
        (searches never read it on blocked cells, which are never entered).
    uniform_cost:
        The entry cost shared by every free cell, or ``None`` when they differ.
    cells:
        The cell of every flat index (``cells[i] == cell(i)``), for hot loops.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> flat = FlatGrid(Grid(2, 2, costs={(1, 1): 3.0}))
    >>> flat.neighbours, flat.costs, flat.uniform_cost
    ([(2, 1), (3, 0), (3, 0), (1, 2)], [1.0, 1.0, 1.0, 3.0], None)
    """

    __slots__ = ("cells", "costs", "free", "neighbours", "size", "uniform_cost", "x_size", "y_size")

    def __init__(self, grid: SizedGridMap) -> None:
        x_size, y_size = grid.x_size, grid.y_size
        self.x_size = x_size
        self.y_size = y_size
        self.size = x_size * y_size
        self.cells: list[Cell] = [(x, y) for x in range(x_size) for y in range(y_size)]
        self.free = bytearray(self.size)
        self.neighbours: list[tuple[int, ...]] = []
        self.costs: list[float] = []
        free_costs: set[float] = set()
        for index, cell in enumerate(self.cells):
            if grid.is_free(cell):
                self.free[index] = 1
                self.neighbours.append(
                    tuple(nx * y_size + ny for nx, ny in grid.neighbours(cell) if 0 <= nx < x_size and 0 <= ny < y_size)
                )
                cost = float(grid.cost(cell))
                self.costs.append(cost)
                free_costs.add(cost)
            else:
                self.neighbours.append(())
                self.costs.append(float(grid.cost(cell)))  # never entered: kept as the grid states it
        self.uniform_cost: float | None = next(iter(free_costs)) if len(free_costs) == 1 else None

    def index(self, cell: Cell) -> int:
        """The flat index of ``cell`` (which must lie on the grid).

        >>> from mrmp.core.grid import Grid
        >>> FlatGrid(Grid(3, 4)).index((2, 1))
        9
        """
        return cell[0] * self.y_size + cell[1]

    def index_on_grid(self, cell: Cell) -> int | None:
        """The flat index of ``cell``, or ``None`` when it lies off the grid.

        >>> from mrmp.core.grid import Grid
        >>> flat = FlatGrid(Grid(3, 4))
        >>> flat.index_on_grid((2, 1)), flat.index_on_grid((3, 0))
        (9, None)
        """
        x, y = cell
        if 0 <= x < self.x_size and 0 <= y < self.y_size:
            return x * self.y_size + y
        return None

    def cell(self, index: int) -> Cell:
        """The cell of flat index ``index`` (inverse of :meth:`index`).

        >>> from mrmp.core.grid import Grid
        >>> FlatGrid(Grid(3, 4)).cell(9)
        (2, 1)
        """
        return self.cells[index]

    def is_free(self, index: int) -> bool:
        """Whether flat cell ``index`` is free (not an obstacle).

        >>> from mrmp.core.grid import Grid
        >>> FlatGrid(Grid.from_rows([".#"])).is_free(1)
        False
        """
        return self.free[index] == 1

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.x_size}x{self.y_size}>"


_CACHE: OrderedDict[Any, FlatGrid] = OrderedDict()
_CACHE_LOCK = threading.Lock()


def flat_grid(grid: SizedGridMap, *, cache: bool | None = None) -> FlatGrid:
    """The flat form of ``grid``, kept for the last few grids when ``cache`` allows.

    Parameters
    ----------
    grid:
        The grid; it must not change while its flat form is in use.
    cache:
        Whether to keep and reuse the flat form. ``None`` (the default) caches
        for :class:`~mrmp.core.grid.Grid`, which is immutable, and not for
        other grid objects.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> flat_grid(Grid(2, 2)) is flat_grid(Grid(2, 2))
    True
    """
    if cache is None:
        cache = isinstance(grid, Grid)
    if not cache:
        return FlatGrid(grid)
    try:
        with _CACHE_LOCK:
            flat = _CACHE.get(grid)
            if flat is not None:
                _CACHE.move_to_end(grid)
                return flat
    except TypeError:  # unhashable grid
        return FlatGrid(grid)
    flat = FlatGrid(grid)
    with _CACHE_LOCK:
        _CACHE[grid] = flat
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)
    return flat
