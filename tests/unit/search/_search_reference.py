"""Independent reference implementations and grid generators for the search tests.

Nothing here imports :mod:`mrmp.search`: the references are deliberately plain
(Bellman-Ford relaxation, a textbook Dijkstra over explicit states) so that
they can judge the planners.
"""

from __future__ import annotations

import heapq
import math
import random
from collections.abc import Collection, Iterable
from itertools import pairwise

from hypothesis import strategies as st

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import HEADINGS, Heading, right_turns
from mrmp.core.scenario import Timing


def random_grid(
    rng: random.Random,
    x_size: int,
    y_size: int,
    obstacle_density: float = 0.2,
    cost_density: float = 0.0,
    max_cost: int = 9,
) -> Grid:
    """A grid with random obstacles and random integer entry costs."""
    blocked = [(x, y) for x in range(x_size) for y in range(y_size) if rng.random() < obstacle_density]
    costs = {
        (x, y): float(rng.randint(1, max_cost))
        for x in range(x_size)
        for y in range(y_size)
        if rng.random() < cost_density
    }
    return Grid(x_size, y_size, blocked, costs)


@st.composite
def grids(draw: st.DrawFn, max_size: int = 8, costs: bool = True, min_size: int = 1) -> Grid:
    """A hypothesis strategy for small grids with obstacles and (optionally) costs."""
    x_size = draw(st.integers(min_size, max_size))
    y_size = draw(st.integers(min_size, max_size))
    seed = draw(st.integers(0, 2**32 - 1))
    density = draw(st.sampled_from([0.0, 0.1, 0.25, 0.4]))
    cost_density = draw(st.sampled_from([0.0, 0.3, 1.0])) if costs else 0.0
    return random_grid(random.Random(seed), x_size, y_size, density, cost_density)


@st.composite
def grid_with_ends(draw: st.DrawFn, max_size: int = 8, costs: bool = True) -> tuple[Grid, Cell, Cell]:
    """A grid with at least one free cell, and a free start and goal on it."""
    grid = draw(grids(max_size=max_size, costs=costs).filter(lambda g: len(g.free_cells()) > 0))
    free = grid.free_cells()
    start = draw(st.sampled_from(free))
    goal = draw(st.sampled_from(free))
    return grid, start, goal


def bellman_ford_to_goal(grid: Grid, goal: Cell, blocked: Collection[Cell] = frozenset()) -> dict[Cell, float]:
    """Cost of a cheapest path from every free cell to ``goal`` by plain Bellman-Ford relaxation.

    Uses only forward moves ``v -> u`` from ``grid.neighbours(v)`` costing
    ``grid.cost(u)``; cells in ``blocked`` can be left but not entered.
    """
    free = [cell for cell in _all_cells(grid) if grid.is_free(cell)]
    dist = {cell: math.inf for cell in free}
    if goal in dist:
        dist[goal] = 0.0
    changed = True
    while changed:
        changed = False
        for v in free:
            for u in grid.neighbours(v):
                if u in blocked or u not in dist:
                    continue
                offer = grid.cost(u) + dist[u]
                if offer < dist[v]:
                    dist[v] = offer
                    changed = True
    return dist


def dijkstra_to_goal(grid: Grid, goal: Cell) -> dict[Cell, float]:
    """Cost from every free cell to ``goal`` by a textbook Dijkstra on the explicitly reversed graph."""
    reverse: dict[Cell, list[Cell]] = {}
    for v in _all_cells(grid):
        if grid.is_free(v):
            for u in grid.neighbours(v):
                reverse.setdefault(u, []).append(v)
    dist = {goal: 0.0}
    heap = [(0.0, goal)]
    done: set[Cell] = set()
    while heap:
        d, u = heapq.heappop(heap)
        if u in done:
            continue
        done.add(u)
        for v in reverse.get(u, []):
            offer = d + grid.cost(u)
            if offer < dist.get(v, math.inf):
                dist[v] = offer
                heapq.heappush(heap, (offer, v))
    return dist


def bfs_to_goal(grid: Grid, goal: Cell) -> dict[Cell, int]:
    """Number of moves from every cell to ``goal`` (plain BFS, unit costs, symmetric moves)."""
    dist = {goal: 0}
    frontier = [goal]
    while frontier:
        nxt = []
        for cell in frontier:
            for n in grid.neighbours(cell):
                if n not in dist:
                    dist[n] = dist[cell] + 1
                    nxt.append(n)
        frontier = nxt
    return dist


def heading_state_dijkstra(
    grid: Grid,
    start: Cell,
    goal: Cell,
    heading: Heading,
    timing: Timing,
    blocked: Collection[Cell] = frozenset(),
) -> float:
    """Cheapest cost from ``(start, heading)`` to ``goal`` (any heading) over explicit (cell, heading) states.

    A move from ``(c, h)`` to the neighbour ``n`` in direction ``d`` costs
    ``right_turns(h, d) * turn_time + cell_time * cost(n)``. Returns ``inf`` if
    the goal cannot be reached.
    """
    best = {(start, heading): 0.0}
    heap: list[tuple[float, int, Cell, Heading]] = [(0.0, 0, start, heading)]
    counter = 1
    done: set[tuple[Cell, Heading]] = set()
    while heap:
        g, _, cell, facing = heapq.heappop(heap)
        if (cell, facing) in done:
            continue
        done.add((cell, facing))
        if cell == goal:
            return g
        for direction in HEADINGS:
            n = direction.ahead(cell)
            if not grid.is_free(n) or n in blocked:
                continue
            offer = g + right_turns(facing, direction) * timing.turn_time + timing.cell_time * grid.cost(n)
            if offer < best.get((n, direction), math.inf):
                best[(n, direction)] = offer
                heapq.heappush(heap, (offer, counter, n, direction))
                counter += 1
    return math.inf


def assert_valid_path(
    grid: Grid,
    path: Iterable[Cell],
    start: Cell,
    goal: Cell,
    blocked: Collection[Cell] = frozenset(),
) -> None:
    """Assert ``path`` runs from ``start`` to ``goal`` over 4-adjacent free cells, avoiding ``blocked``."""
    cells = list(path)
    assert cells[0] == start
    assert cells[-1] == goal
    for before, after in pairwise(cells):
        assert abs(before[0] - after[0]) + abs(before[1] - after[1]) == 1, (before, after)
        assert grid.is_free(after), after
        assert after not in blocked, after


def entry_cost(grid: Grid, path: Iterable[Cell]) -> float:
    """Sum of entry costs of the cells entered along ``path``."""
    cells = list(path)
    return sum(grid.cost(cell) for cell in cells[1:])


def _all_cells(grid: Grid) -> list[Cell]:
    return [(x, y) for x in range(grid.x_size) for y in range(grid.y_size)]
