"""The 4-connected grid world: bounds, static obstacles and per-cell costs.

Axes (thesis section 3.2): a cell is ``(x, y)``; x grows to the NORTH, y grows
to the EAST. A grid has ``x_size`` values of x (``0 .. x_size - 1``, the
thesis's ``Xmax = x_size - 1``) and ``y_size`` values of y.

**The one mapping to MovingAI (column, row).** MovingAI maps are drawn with
row 0 at the top and columns growing to the right. mrmp draws north up and east
to the right, so a MovingAI map of ``height`` rows and ``width`` columns is a
grid with ``x_size = height`` and ``y_size = width``, and::

    x = height - 1 - row        y = column

:func:`cell_from_movingai` and :func:`movingai_from_cell` are the only code
that performs this conversion; everything else speaks thesis axes.

Costs: entering a cell costs ``cost(cell)`` (1 by default, thesis future work 1:
"costs can be attached to the paths").

Examples
--------
>>> grid = Grid.from_rows(["..@", "...", "..."])
>>> grid.x_size, grid.y_size
(3, 3)
>>> grid.is_free((2, 2)), grid.is_free((0, 2))
(False, True)
>>> grid.neighbours((0, 0))
[(1, 0), (0, 1)]
>>> cell_from_movingai(column=2, row=0, height=3)
(2, 2)
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable, Mapping, Sequence

from mrmp.core.cell import Cell
from mrmp.core.limits import MAX_GRID_CELLS

FREE_SYMBOLS = frozenset(".GS")
"""MovingAI symbols of passable terrain."""
BLOCKED_SYMBOLS = frozenset("@OTW")
"""MovingAI symbols of impassable terrain (out of bounds, trees, water)."""
COST_SYMBOLS = {str(digit): float(digit) for digit in range(1, 10)}
"""mrmp's extension for inline maps: a digit is a passable cell with that entry cost."""

_DIRECTIONS: tuple[Cell, ...] = ((1, 0), (0, 1), (-1, 0), (0, -1))  # NORTH, EAST, SOUTH, WEST


def cell_from_movingai(column: int, row: int, height: int) -> Cell:
    """Convert MovingAI's (column, row) on a map of ``height`` rows to ``(x, y)``.

    >>> cell_from_movingai(0, 0, height=32)
    (31, 0)
    """
    return (height - 1 - row, column)


def movingai_from_cell(cell: Cell, height: int) -> tuple[int, int]:
    """Convert ``(x, y)`` to MovingAI's (column, row) on a map of ``height`` rows.

    >>> movingai_from_cell((31, 0), height=32)
    (0, 0)
    """
    return (cell[1], height - 1 - cell[0])


def grid_size_problem(x_size: int, y_size: int) -> str | None:
    """Why a grid of ``x_size`` by ``y_size`` cells is too large (:data:`~mrmp.core.limits.MAX_GRID_CELLS`), or None.

    >>> grid_size_problem(32, 32) is None
    True
    >>> grid_size_problem(100_000, 100_000)
    'a map of 100000x100000 = 10000000000 cells is larger than the bound of 4194304 cells (2048 x 2048)'
    """
    cells = x_size * y_size
    if cells <= MAX_GRID_CELLS:
        return None
    side = math.isqrt(MAX_GRID_CELLS)
    return f"a map of {x_size}x{y_size} = {cells} cells is larger than the bound of {MAX_GRID_CELLS} cells ({side} x {side})"


def connected_regions(grid: Grid, origins: Iterable[Cell]) -> tuple[dict[Cell, int], list[list[Cell]]]:
    """Label the 4-connected free regions that contain ``origins``, by breadth-first search.

    Returns the label of every cell in those regions and each region's cells
    (its first origin first, then in breadth-first order).

    >>> grid = Grid.from_rows(["..@.."])
    >>> labels, regions = connected_regions(grid, [(0, 0), (0, 4), (0, 1)])
    >>> labels[(0, 1)] == labels[(0, 0)] != labels[(0, 4)], regions
    (True, [[(0, 0), (0, 1)], [(0, 4), (0, 3)]])
    """
    labels: dict[Cell, int] = {}
    regions: list[list[Cell]] = []
    for origin in origins:
        if origin in labels:
            continue
        label = len(regions)
        region = [origin]
        labels[origin] = label
        queue = deque([origin])
        while queue:
            cell = queue.popleft()
            for neighbour in grid.neighbours(cell):
                if neighbour not in labels:
                    labels[neighbour] = label
                    region.append(neighbour)
                    queue.append(neighbour)
        regions.append(region)
    return labels, regions


class Grid:
    """A rectangular 4-connected grid with blocked cells and entry costs.

    Parameters
    ----------
    x_size, y_size:
        Number of x values (north-south extent) and y values (east-west extent).
    blocked:
        Cells that no robot may enter (static obstacles).
    costs:
        Entry cost of cells whose cost is not 1. Every cost must be positive.
    name:
        A label for reports (for example the map's file name).

    Raises
    ------
    ValueError
        If a size is not positive, the grid has more than
        :data:`~mrmp.core.limits.MAX_GRID_CELLS` cells, a blocked cell is
        outside the grid, or a cost is not positive.

    Examples
    --------
    >>> grid = Grid(5, 5)
    >>> grid.x_max, grid.y_max, len(grid.free_cells())
    (4, 4, 25)
    >>> Grid(2, 2, costs={(1, 1): 3.0}).cost((1, 1))
    3.0
    """

    __slots__ = ("_blocked", "_costs", "_neighbours", "name", "x_size", "y_size")

    def __init__(
        self,
        x_size: int,
        y_size: int,
        blocked: Iterable[Cell] = (),
        costs: Mapping[Cell, float] | None = None,
        name: str = "",
    ) -> None:
        if x_size <= 0 or y_size <= 0:
            raise ValueError(f"grid size must be positive, got {x_size}x{y_size}")
        problem = grid_size_problem(x_size, y_size)
        if problem is not None:
            raise ValueError(problem)
        self.x_size = x_size
        self.y_size = y_size
        self.name = name
        self._blocked = bytearray(x_size * y_size)
        for cell in blocked:
            if not self.in_bounds(cell):
                raise ValueError(f"blocked cell {cell} is outside the {x_size}x{y_size} grid")
            self._blocked[cell[0] * y_size + cell[1]] = 1
        self._costs: dict[Cell, float] = {}
        for cell, cost in (costs or {}).items():
            if not self.in_bounds(cell):
                raise ValueError(f"cost given for cell {cell} outside the grid")
            if not cost > 0:
                raise ValueError(f"cost of cell {cell} must be positive, got {cost}")
            if cost != 1.0:
                self._costs[cell] = float(cost)
        self._neighbours: dict[Cell, list[Cell]] = {}

    # -- construction from pictures -------------------------------------------------

    @classmethod
    def from_rows(cls, rows: Sequence[str], name: str = "") -> Grid:
        """Build a grid from rows of symbols, the first row being the northmost.

        ``.``, ``G`` and ``S`` are free, ``@``, ``O``, ``T``, ``W`` and ``#`` are
        blocked, a digit ``1``-``9`` is free with that entry cost.

        Raises
        ------
        ValueError
            If the rows are empty, of unequal length, or hold an unknown symbol
            (the message names the row and column).

        >>> Grid.from_rows(["#.", ".."]).is_free((1, 0))
        False
        """
        if not rows:
            raise ValueError("a map needs at least one row")
        width = len(rows[0])
        height = len(rows)
        blocked: list[Cell] = []
        costs: dict[Cell, float] = {}
        for row_index, row in enumerate(rows):
            if len(row) != width:
                raise ValueError(f"row {row_index} has {len(row)} symbols, expected {width}")
            for column, symbol in enumerate(row):
                cell = cell_from_movingai(column, row_index, height)
                if symbol in FREE_SYMBOLS:
                    continue
                if symbol in BLOCKED_SYMBOLS or symbol == "#":
                    blocked.append(cell)
                elif symbol in COST_SYMBOLS:
                    costs[cell] = COST_SYMBOLS[symbol]
                else:
                    raise ValueError(f"row {row_index}, column {column}: unknown map symbol {symbol!r}")
        return cls(height, width, blocked, costs, name=name)

    def to_rows(self) -> list[str]:
        """Draw the grid as rows of symbols, northmost row first (inverse of :meth:`from_rows`).

        >>> Grid.from_rows(["@.", ".2"]).to_rows()
        ['@.', '.2']
        """
        rows = []
        for row in range(self.x_size):
            symbols = []
            for column in range(self.y_size):
                cell = cell_from_movingai(column, row, self.x_size)
                if self.is_blocked(cell):
                    symbols.append("@")
                elif cell in self._costs and self._costs[cell] in COST_SYMBOLS.values():
                    symbols.append(str(int(self._costs[cell])))
                else:
                    symbols.append(".")
            rows.append("".join(symbols))
        return rows

    # -- queries --------------------------------------------------------------------

    @property
    def x_max(self) -> int:
        """The largest x (the thesis's Xmax)."""
        return self.x_size - 1

    @property
    def y_max(self) -> int:
        """The largest y (the thesis's Ymax)."""
        return self.y_size - 1

    @property
    def has_costs(self) -> bool:
        """Whether any cell costs other than 1 to enter."""
        return bool(self._costs)

    def in_bounds(self, cell: Cell) -> bool:
        """Whether ``cell`` lies on the grid."""
        return 0 <= cell[0] < self.x_size and 0 <= cell[1] < self.y_size

    def is_blocked(self, cell: Cell) -> bool:
        """Whether ``cell`` is on the grid and a static obstacle."""
        return self.in_bounds(cell) and self._blocked[cell[0] * self.y_size + cell[1]] == 1

    def is_free(self, cell: Cell) -> bool:
        """Whether a robot may stand on ``cell``: on the grid and not blocked."""
        x, y = cell
        return 0 <= x < self.x_size and 0 <= y < self.y_size and not self._blocked[x * self.y_size + y]

    def cost(self, cell: Cell) -> float:
        """The cost of entering ``cell`` (1 unless set)."""
        return self._costs.get(cell, 1.0)

    @property
    def min_cost(self) -> float:
        """The smallest entry cost of any cell (for admissible heuristics)."""
        return min(1.0, *self._costs.values()) if self._costs else 1.0

    def neighbours(self, cell: Cell) -> list[Cell]:
        """Free 4-neighbours of ``cell`` in the order NORTH, EAST, SOUTH, WEST.

        The list is cached and must not be modified.
        """
        cached = self._neighbours.get(cell)
        if cached is None:
            x, y = cell
            cached = [(x + dx, y + dy) for dx, dy in _DIRECTIONS if self.is_free((x + dx, y + dy))]
            self._neighbours[cell] = cached
        return cached

    def free_cells(self) -> list[Cell]:
        """Every free cell, in increasing (x, y) order."""
        return [(x, y) for x in range(self.x_size) for y in range(self.y_size) if not self._blocked[x * self.y_size + y]]

    def blocked_cells(self) -> list[Cell]:
        """Every blocked cell, in increasing (x, y) order."""
        return [(x, y) for x in range(self.x_size) for y in range(self.y_size) if self._blocked[x * self.y_size + y]]

    def costs(self) -> dict[Cell, float]:
        """The cells whose entry cost is not 1, with their cost."""
        return dict(self._costs)

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Grid)
            and (self.x_size, self.y_size) == (other.x_size, other.y_size)
            and self._blocked == other._blocked
            and self._costs == other._costs
        )

    def __hash__(self) -> int:
        return hash((self.x_size, self.y_size, bytes(self._blocked)))

    def __repr__(self) -> str:
        label = f" {self.name!r}" if self.name else ""
        return f"<Grid{label} {self.x_size}x{self.y_size}, {len(self.blocked_cells())} blocked>"
