"""Distance tables: the cost from every cell to one goal, by one reverse search.

A robot that knows how far every cell is from its goal can pick a best next
step anywhere, detour around a blocked neighbour, or rank alternatives, without
planning again. :func:`distance_table` computes the whole table with one search
backwards from the goal:

* when every free cell costs the same to enter (the thesis's grids), a
  breadth-first search (Moore 1959, "The shortest path through a maze");
* otherwise a label-correcting shortest-path search (Bellman 1958, "On a
  routing problem"; Moore 1959), which gives the same distances as Dijkstra
  (1959, "A note on two problems in connexion with graphs") when all costs are
  positive.

Entering cell ``c`` costs ``cost(c)``, so the forward move ``v -> u`` costs
``cost(u)``: searching backwards from ``u``, every predecessor ``v`` of ``u``
is offered ``distance(u) + cost(u)``. The distance of the goal is 0 and its own
cost never counts.

**Speed.** Each grid is converted once (and cached) to its flat form
(:mod:`mrmp.search.flat_grid`, whose distance convention the tables follow:
``inf`` where the goal cannot be reached), with precomputed reverse-neighbour
tuples and a reverse-neighbour index array. The
search runs wavefront by wavefront: a small wavefront is expanded in a plain
Python loop over the tuples, a large one (more than ``_VECTOR_THRESHOLD``
cells) with a few numpy operations on the index array (gather the neighbours,
drop the seen ones, deduplicate with a scatter/gather "owner" trick). Corridors
stay cheap and open areas go vectorised. Distances are written straight into
an ``array('d')`` shared with the numpy view :attr:`DistanceTable.array`, so
nothing is converted at the end. Tables of a :class:`~mrmp.core.grid.Grid`
are cached per goal (grids are immutable).

Examples
--------
>>> from mrmp.core.grid import Grid
>>> table = distance_table(Grid.from_rows(["...", ".@.", "..."]), (2, 2))
>>> table.distance((0, 0)), table.distance((1, 1))
(4.0, inf)
>>> table.next_cells((0, 0))
[(1, 0), (0, 1)]
>>> table.array.shape
(3, 3)
"""

from __future__ import annotations

import math
import threading
from array import array
from collections import OrderedDict
from typing import Any

import numpy as np
import numpy.typing as npt

from mrmp.core.cell import Cell
from mrmp.core.errors import NoPathError
from mrmp.core.grid import Grid
from mrmp.search.flat_grid import UNREACHABLE, FlatGrid, flat_grid
from mrmp.search.graph import SizedGridMap
from mrmp.search.wavefront import IndexArray, dedupe

__all__ = ["DistanceTable", "distance_table"]

_VECTOR_THRESHOLD = 32
"""Wavefronts larger than this are expanded with numpy; smaller ones in Python."""
_GRID_CACHE_SIZE = 8
"""How many grids keep their flat form cached."""
_TABLE_CACHE_CELLS = 1 << 21
"""How many table cells (8 bytes each) the per-grid table cache may hold in all."""



class _ReverseSearch:
    """A grid's flat form (:class:`~mrmp.search.flat_grid.FlatGrid`) with what the reverse searches need, built once.

    ``reverse[u]`` lists the cells ``v`` with a move ``v -> u``;
    ``reverse_array`` holds the same rows padded with the sentinel index
    ``size`` (one past the last cell); the rows ``*_row`` and ``zero_marks``
    are the initial contents of each search's scratch arrays; ``tables``
    caches the tables already computed, per goal.
    """

    def __init__(self, flat: FlatGrid) -> None:
        size = flat.size
        self.flat = flat
        self.size = size
        reverse_lists: list[list[int]] = [[] for _ in range(size)]
        for v, targets in enumerate(flat.neighbours):
            for u in targets:
                reverse_lists[u].append(v)
        self.reverse = [tuple(row) for row in reverse_lists]
        self.costs = flat.costs
        self.cost_array = np.array([*flat.costs, 0.0])
        width = max((len(row) for row in self.reverse), default=0) or 1
        reverse_array = np.full((size + 1, width), size, dtype=np.intp)
        for u, row in enumerate(self.reverse):
            reverse_array[u, : len(row)] = row
        self.reverse_array = reverse_array
        self.ranks: IndexArray = np.arange((size + 1) * width, dtype=np.intp)
        self.inf_row = array("d", [UNREACHABLE]) * (size + 1)
        self.unseen_row = bytearray(b"\x01") * size + b"\x00"
        self.zero_marks = array("q", [0]) * (size + 1)
        self.tables: OrderedDict[int, DistanceTable] = OrderedDict()
        self.table_limit = max(4, _TABLE_CACHE_CELLS // max(size, 1))
        self.lock = threading.Lock()


def _breadth_first(search: _ReverseSearch, goal: int, step: float) -> array[float]:
    """Distances to ``goal`` when entering any free cell costs ``step`` (hybrid wavefront BFS)."""
    reverse, reverse_array, ranks = search.reverse, search.reverse_array, search.ranks
    dist = array("d", search.inf_row)
    unseen = bytearray(search.unseen_row)
    view = np.frombuffer(dist, dtype=np.float64)
    unseen_view = np.frombuffer(unseen, dtype=np.bool_)
    owner: IndexArray | None = None
    dist[goal] = 0.0
    unseen[goal] = 0
    frontier: list[int] | IndexArray = [goal]
    d = 0.0
    while True:
        d += step
        if isinstance(frontier, list):
            wave: list[int] = []
            append = wave.append
            for u in frontier:
                for v in reverse[u]:
                    if unseen[v]:
                        unseen[v] = 0
                        dist[v] = d
                        append(v)
            if not wave:
                break
            frontier = wave if len(wave) <= _VECTOR_THRESHOLD else np.array(wave, dtype=np.intp)
        else:
            candidates = reverse_array[frontier].ravel()
            candidates = candidates[unseen_view[candidates]]
            if not candidates.size:
                break
            if owner is None:
                owner = np.empty(search.size + 1, dtype=np.intp)
            candidates = dedupe(candidates, owner, ranks)
            unseen_view[candidates] = False
            view[candidates] = d
            frontier = candidates if candidates.size > _VECTOR_THRESHOLD else candidates.tolist()
    return dist


def _label_correcting(search: _ReverseSearch, goal: int) -> array[float]:
    """Distances to ``goal`` with per-cell entry costs (hybrid wavefront Bellman-Ford-Moore)."""
    reverse, reverse_array, ranks = search.reverse, search.reverse_array, search.ranks
    costs, cost_array = search.costs, search.cost_array
    width = reverse_array.shape[1]
    dist = array("d", search.inf_row)
    dist[search.size] = -math.inf  # the padding index is never improved
    view = np.frombuffer(dist, dtype=np.float64)
    marks = array("q", search.zero_marks)  # the round in which a cell was last queued
    owner: IndexArray | None = None
    dist[goal] = 0.0
    frontier: list[int] | IndexArray = [goal]
    rounds = 0
    while True:
        rounds += 1
        if isinstance(frontier, list):
            wave: list[int] = []
            append = wave.append
            for u in frontier:
                offer = dist[u] + costs[u]
                for v in reverse[u]:
                    if offer < dist[v]:
                        dist[v] = offer
                        if marks[v] != rounds:
                            marks[v] = rounds
                            append(v)
            if not wave:
                break
            frontier = wave if len(wave) <= _VECTOR_THRESHOLD else np.array(wave, dtype=np.intp)
        else:
            offers = np.repeat(view[frontier] + cost_array[frontier], width)
            candidates = reverse_array[frontier].ravel()
            better = offers < view[candidates]
            candidates = candidates[better]
            if not candidates.size:
                break
            np.minimum.at(view, candidates, offers[better])
            if owner is None:
                owner = np.empty(search.size + 1, dtype=np.intp)
            candidates = dedupe(candidates, owner, ranks)
            frontier = candidates if candidates.size > _VECTOR_THRESHOLD else candidates.tolist()
    dist[search.size] = math.inf
    return dist


class DistanceTable:
    """The cost from every cell of a grid to one goal.

    Build with :func:`distance_table`. The table is immutable.

    Attributes
    ----------
    goal:
        The cell the distances lead to.
    array:
        A read-only numpy float array shaped ``(x_size, y_size)``;
        ``array[x, y]`` is the distance of ``(x, y)``, ``inf`` where the goal
        cannot be reached (obstacles, other components).

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> table = distance_table(Grid(2, 3), (0, 0))
    >>> table.array.tolist()
    [[0.0, 1.0, 2.0], [1.0, 2.0, 3.0]]
    >>> table.path((1, 2))
    ((1, 2), (0, 2), (0, 1), (0, 0))
    """

    __slots__ = ("_dist", "_flat", "array", "goal")

    def __init__(self, flat: FlatGrid, goal: Cell, dist: array[float]) -> None:
        self.goal = goal
        self._flat = flat
        self._dist = dist
        view = np.frombuffer(dist, dtype=np.float64)[: flat.size].reshape(flat.x_size, flat.y_size)
        view.flags.writeable = False
        self.array: npt.NDArray[np.float64] = view

    @property
    def shape(self) -> tuple[int, int]:
        """``(x_size, y_size)`` of the grid.

        >>> from mrmp.core.grid import Grid
        >>> distance_table(Grid(4, 2), (0, 0)).shape
        (4, 2)
        """
        return (self._flat.x_size, self._flat.y_size)

    def distance(self, cell: Cell) -> float:
        """The cost of a cheapest path from ``cell`` to the goal.

        Parameters
        ----------
        cell:
            Any cell, on the grid or not.

        Returns
        -------
        float
            The sum of entry costs of the cells entered on a cheapest path;
            ``math.inf`` when ``cell`` is blocked, off the grid or cannot reach
            the goal.

        Examples
        --------
        >>> from mrmp.core.grid import Grid
        >>> table = distance_table(Grid(3, 3, costs={(0, 1): 5.0}), (0, 2))
        >>> table.distance((0, 0)), table.distance((0, 1)), table.distance((9, 9))
        (4.0, 1.0, inf)
        """
        index = self._flat.index_on_grid(cell)
        return UNREACHABLE if index is None else self._dist[index]

    def reachable(self, cell: Cell) -> bool:
        """Whether the goal can be reached from ``cell``.

        >>> from mrmp.core.grid import Grid
        >>> table = distance_table(Grid.from_rows([".@."]), (0, 0))
        >>> table.reachable((0, 0)), table.reachable((0, 2))
        (True, False)
        """
        return self.distance(cell) < UNREACHABLE

    def next_cells(self, cell: Cell) -> list[Cell]:
        """The neighbours of ``cell`` that lead to the goal, best first.

        Neighbours are ranked by the cost of reaching the goal through them,
        ``cost(n) + distance(n)`` (the same order as ``distance(n)`` when all
        costs are equal); the first one is a step of a cheapest path, and its
        rank equals ``distance(cell)``. Ties keep the grid's neighbour order
        (NORTH, EAST, SOUTH, WEST). Neighbours that cannot reach the goal are
        left out; a blocked, off-grid or unreachable cell has none.

        Parameters
        ----------
        cell:
            The robot's cell.

        Returns
        -------
        list of Cell
            The free neighbours that can reach the goal, best first.

        Examples
        --------
        >>> from mrmp.core.grid import Grid
        >>> table = distance_table(Grid(3, 3, costs={(1, 2): 9.0}), (2, 2))
        >>> table.next_cells((1, 1))
        [(2, 1), (0, 1), (1, 0), (1, 2)]
        """
        flat, dist = self._flat, self._dist
        index = flat.index_on_grid(cell)
        if index is None or dist[index] == UNREACHABLE:
            return []
        ranked = sorted(
            (flat.costs[n] + dist[n], position, n)
            for position, n in enumerate(flat.neighbours[index])
            if dist[n] < UNREACHABLE
        )
        cells = flat.cells
        return [cells[n] for _, _, n in ranked]

    def as_list(self) -> list[float]:
        """The distances as a list indexed by flat cell (:mod:`mrmp.search.flat_grid`), ``inf`` where unreachable.

        >>> from mrmp.core.grid import Grid
        >>> distance_table(Grid.from_rows([".#."]), (0, 0)).as_list()
        [0.0, inf, inf]
        """
        return self._dist[: self._flat.size].tolist()

    def as_array(self) -> array[float]:
        """The distances as an ``array('d')`` indexed by flat cell: :meth:`as_list` in 8 bytes a cell.

        >>> from mrmp.core.grid import Grid
        >>> distance_table(Grid.from_rows([".#."]), (0, 0)).as_array()
        array('d', [0.0, inf, inf])
        """
        return self._dist[: self._flat.size]

    def path(self, cell: Cell) -> tuple[Cell, ...]:
        """A cheapest path from ``cell`` to the goal, following :meth:`next_cells`.

        Parameters
        ----------
        cell:
            The first cell of the path.

        Returns
        -------
        tuple of Cell
            ``cell`` first, the goal last.

        Raises
        ------
        NoPathError
            If the goal cannot be reached from ``cell``.

        Examples
        --------
        >>> from mrmp.core.grid import Grid
        >>> distance_table(Grid.from_rows(["...", ".@.", "..."]), (0, 2)).path((2, 0))
        ((2, 0), (2, 1), (2, 2), (1, 2), (0, 2))
        """
        if not self.reachable(cell):
            raise NoPathError(f"goal {self.goal} cannot be reached from {cell}")
        path = [cell]
        for _ in range(self._flat.size):
            if path[-1] == self.goal:
                return tuple(path)
            path.append(self.next_cells(path[-1])[0])
        raise NoPathError(f"distance table to {self.goal} does not lead back from {cell}")  # pragma: no cover

    def __repr__(self) -> str:
        return f"<DistanceTable to {self.goal} on {self._flat.x_size}x{self._flat.y_size}>"


_GRIDS: OrderedDict[Any, _ReverseSearch] = OrderedDict()
_GRIDS_LOCK = threading.Lock()


def _reverse_search(grid: SizedGridMap, cache: bool) -> _ReverseSearch:
    """The reverse-search form of ``grid``, from the cache when allowed."""
    if not cache:
        return _ReverseSearch(FlatGrid(grid))
    try:
        with _GRIDS_LOCK:
            search = _GRIDS.get(grid)
            if search is not None:
                _GRIDS.move_to_end(grid)
                return search
    except TypeError:  # unhashable grid
        return _ReverseSearch(FlatGrid(grid))
    search = _ReverseSearch(flat_grid(grid, cache=True))
    with _GRIDS_LOCK:
        _GRIDS[grid] = search
        while len(_GRIDS) > _GRID_CACHE_SIZE:
            _GRIDS.popitem(last=False)
    return search


def distance_table(grid: SizedGridMap, goal: Cell, *, cache: bool | None = None) -> DistanceTable:
    """Compute the cost from every cell of ``grid`` to ``goal``.

    One reverse search from ``goal``: breadth-first (Moore 1959) when every
    free cell costs the same, label-correcting (Bellman 1958; same result as
    Dijkstra 1959) otherwise. See the module docstring for the method.

    Parameters
    ----------
    grid:
        The grid (any :class:`~mrmp.search.graph.SizedGridMap`); it must not
        change while its tables are in use.
    goal:
        The cell every distance leads to.
    cache:
        Whether to reuse the grid's flat form and earlier tables. ``None``
        (the default) caches for :class:`~mrmp.core.grid.Grid`, which is
        immutable, and not for other grid objects.

    Returns
    -------
    DistanceTable
        The distances; ``inf`` where the goal cannot be reached.

    Raises
    ------
    NoPathError
        If ``goal`` is not a free cell of ``grid``.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> grid = Grid.from_rows(["....", ".@@.", "...."])
    >>> table = distance_table(grid, (2, 3))
    >>> table.distance((0, 0)), table.next_cells((1, 0))
    (5.0, [(2, 0), (0, 0)])
    >>> distance_table(grid, (1, 1))
    Traceback (most recent call last):
    ...
    mrmp.core.errors.NoPathError: goal (1, 1) is not a free cell
    """
    if cache is None:
        cache = isinstance(grid, Grid)
    if not grid.is_free(goal):
        raise NoPathError(f"goal {goal} is not a free cell")
    search = _reverse_search(grid, cache)
    flat = search.flat
    index = flat.index(goal)
    if cache:
        with search.lock:
            table = search.tables.get(index)
            if table is not None:
                search.tables.move_to_end(index)
                return table
    step = flat.uniform_cost
    dist = _label_correcting(search, index) if step is None else _breadth_first(search, index, step)
    table = DistanceTable(flat, goal, dist)
    if cache:
        with search.lock:
            search.tables[index] = table
            while len(search.tables) > search.table_limit:
                search.tables.popitem(last=False)
    return table
