"""Distance tables against plain reference searches."""

from __future__ import annotations

import math
import random
from collections.abc import Mapping
from itertools import pairwise

import numpy as np
import pytest
from _search_reference import bellman_ford_to_goal, bfs_to_goal, dijkstra_to_goal, grids, random_grid
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.core.errors import NoPathError
from mrmp.core.grid import Grid
from mrmp.search import DistanceTable, SizedGridMap, dijkstra, distance_table


def assert_matches(table: DistanceTable, grid: Grid, reference: Mapping[tuple[int, int], float]) -> None:
    expected = np.full((grid.x_size, grid.y_size), math.inf)
    for (x, y), value in reference.items():
        expected[x, y] = value
    assert table.array.shape == (grid.x_size, grid.y_size)
    np.testing.assert_allclose(table.array, expected, rtol=1e-12, atol=0)
    for cell in [(0, 0), (grid.x_size - 1, grid.y_size - 1), (grid.x_size // 2, grid.y_size // 2)]:
        assert table.distance(cell) == pytest.approx(reference.get(cell, math.inf))


@settings(max_examples=150, derandomize=True, deadline=None)
@given(grids(max_size=9), st.data())
def test_matches_bellman_ford_on_small_grids(grid: Grid, data: st.DataObject) -> None:
    free = grid.free_cells()
    if not free:
        return
    goal = data.draw(st.sampled_from(free))
    table = distance_table(grid, goal)
    assert table.goal == goal
    assert_matches(table, grid, bellman_ford_to_goal(grid, goal))


@pytest.mark.parametrize(
    ("size", "density"),
    [((70, 70), 0.0), ((64, 64), 0.1), ((64, 64), 0.3), ((40, 90), 0.2), ((1, 200), 0.0), ((120, 3), 0.05)],
)
def test_matches_bfs_on_large_unit_grids(size: tuple[int, int], density: float) -> None:
    # Wavefronts here grow past the vectorisation threshold, so both the
    # Python and the numpy code paths run.
    rng = random.Random(hash((size, density)) & 0xFFFF)
    grid = random_grid(rng, *size, obstacle_density=density)
    free = grid.free_cells()
    for goal in rng.sample(free, 3):
        assert_matches(distance_table(grid, goal, cache=False), grid, bfs_to_goal(grid, goal))


@pytest.mark.parametrize(("size", "density", "cost_density"), [((64, 64), 0.1, 0.3), ((50, 70), 0.2, 1.0), ((80, 80), 0.0, 0.05)])
def test_matches_dijkstra_on_large_cost_grids(size: tuple[int, int], density: float, cost_density: float) -> None:
    rng = random.Random(int(density * 100) + size[0])
    grid = random_grid(rng, *size, obstacle_density=density, cost_density=cost_density)
    free = grid.free_cells()
    for goal in rng.sample(free, 3):
        assert_matches(distance_table(grid, goal, cache=False), grid, dijkstra_to_goal(grid, goal))


def test_uniform_costs_other_than_one() -> None:
    grid = Grid(4, 5, costs={(x, y): 2.5 for x in range(4) for y in range(5)})
    table = distance_table(grid, (0, 0))
    assert table.distance((3, 4)) == 7 * 2.5
    assert_matches(table, grid, bellman_ford_to_goal(grid, (0, 0)))


def test_fractional_costs() -> None:
    rng = random.Random(3)
    costs = {(x, y): rng.choice([0.1, 0.25, 1.0, 3.7]) for x in range(20) for y in range(20)}
    blocked = {(rng.randrange(20), rng.randrange(20)) for _ in range(40)} - {(5, 5)}
    grid = Grid(20, 20, blocked, costs)
    assert_matches(distance_table(grid, (5, 5)), grid, dijkstra_to_goal(grid, (5, 5)))


def test_agrees_with_the_dijkstra_planner() -> None:
    rng = random.Random(11)
    grid = random_grid(rng, 20, 20, obstacle_density=0.2, cost_density=0.4)
    free = grid.free_cells()
    goal = rng.choice(free)
    table = distance_table(grid, goal)
    for start in rng.sample(free, 25):
        try:
            expected = dijkstra(grid, start, goal).cost
        except NoPathError:
            expected = math.inf
        assert table.distance(start) == pytest.approx(expected)


def test_blocked_unreachable_and_off_grid_cells_are_infinite() -> None:
    grid = Grid.from_rows(["..@..", "..@..", "..@.."])
    table = distance_table(grid, (0, 0))
    assert table.distance((0, 2)) == math.inf  # an obstacle
    assert table.distance((0, 4)) == math.inf  # the other side
    assert table.distance((5, 0)) == math.inf  # off the grid
    assert table.distance((-1, 0)) == math.inf
    assert table.reachable((2, 1)) and not table.reachable((2, 3))
    assert np.isinf(table.array[:, 2:]).all()
    assert table.next_cells((0, 4)) == [] and table.next_cells((0, 2)) == [] and table.next_cells((7, 7)) == []
    with pytest.raises(NoPathError):
        table.path((0, 4))


def test_goal_must_be_free() -> None:
    grid = Grid(3, 3, blocked=[(1, 1)])
    with pytest.raises(NoPathError, match="goal"):
        distance_table(grid, (1, 1))
    with pytest.raises(NoPathError, match="goal"):
        distance_table(grid, (3, 0))


@settings(max_examples=80, derandomize=True, deadline=None)
@given(grids(max_size=8), st.data())
def test_next_cells_and_path(grid: Grid, data: st.DataObject) -> None:
    free = grid.free_cells()
    if not free:
        return
    goal = data.draw(st.sampled_from(free))
    cell = data.draw(st.sampled_from(free))
    table = distance_table(grid, goal)
    ranked = table.next_cells(cell)
    if table.distance(cell) == math.inf:
        assert ranked == []
        return
    assert set(ranked) == {n for n in grid.neighbours(cell) if table.distance(n) < math.inf}
    through = [grid.cost(n) + table.distance(n) for n in ranked]
    assert through == sorted(through)
    if cell != goal:
        assert through[0] == pytest.approx(table.distance(cell))
    path = table.path(cell)
    assert path[0] == cell and path[-1] == goal
    assert sum(grid.cost(c) for c in path[1:]) == pytest.approx(table.distance(cell))
    for before, after in pairwise(path):
        assert after in grid.neighbours(before)


def test_next_cells_ties_keep_neighbour_order() -> None:
    table = distance_table(Grid(3, 3), (2, 2))
    assert table.next_cells((0, 0)) == [(1, 0), (0, 1)]
    assert table.next_cells((1, 1)) == [(2, 1), (1, 2), (0, 1), (1, 0)]


def test_array_is_read_only() -> None:
    table = distance_table(Grid(3, 3), (0, 0))
    assert table.shape == (3, 3)
    assert table.array.dtype == np.float64
    with pytest.raises(ValueError):
        table.array[0, 0] = 5.0


def test_cache_reuses_tables_of_equal_grids() -> None:
    grid = Grid(6, 6, blocked=[(2, 2)])
    first = distance_table(grid, (0, 0))
    assert distance_table(grid, (0, 0)) is first
    assert distance_table(Grid(6, 6, blocked=[(2, 2)]), (0, 0)) is first
    assert distance_table(Grid(6, 6, blocked=[(2, 3)]), (0, 0)) is not first
    assert distance_table(Grid(6, 6, blocked=[(2, 2)], costs={(0, 0): 3.0}), (0, 0)).distance((5, 5)) == 12.0
    fresh = distance_table(grid, (0, 0), cache=False)
    assert fresh is not first
    np.testing.assert_array_equal(fresh.array, first.array)


def test_one_way_grid_map_uses_reverse_moves() -> None:
    class OneWay:
        """A SizedGridMap (not a Grid) where robots may not move WEST (y decreasing)."""

        x_size = 4
        y_size = 5
        min_cost = 1.0

        def is_free(self, cell: tuple[int, int]) -> bool:
            return 0 <= cell[0] < self.x_size and 0 <= cell[1] < self.y_size and cell != (1, 2)

        def neighbours(self, cell: tuple[int, int]) -> list[tuple[int, int]]:
            x, y = cell
            return [n for n in [(x + 1, y), (x, y + 1), (x - 1, y)] if self.is_free(n)]

        def cost(self, cell: tuple[int, int]) -> float:
            return 2.0 if cell[0] == 3 else 1.0

    one_way = OneWay()
    assert isinstance(one_way, SizedGridMap)
    table = distance_table(one_way, (0, 4))
    assert table.distance((0, 0)) == 4.0
    assert table.distance((3, 4)) == 3.0
    assert table.distance((0, 5)) == math.inf
    # nothing east of the goal's column can come back west
    one_way_goal = distance_table(one_way, (2, 0))
    assert one_way_goal.distance((0, 0)) == 2.0
    assert one_way_goal.distance((0, 1)) == math.inf
    assert one_way_goal.path((3, 0)) == ((3, 0), (2, 0))


@pytest.mark.parametrize("costs", [False, True])
def test_wavefront_that_ends_wide(costs: bool) -> None:
    # A diamond around the goal: the last wavefront is the whole rim (80 cells),
    # so the search ends while expanding wavefronts with numpy.
    radius = 20
    centre = (radius, radius)
    blocked = [
        (x, y)
        for x in range(2 * radius + 1)
        for y in range(2 * radius + 1)
        if abs(x - radius) + abs(y - radius) > radius
    ]
    grid = Grid(2 * radius + 1, 2 * radius + 1, blocked, {(radius, 0): 3.0} if costs else None)
    table = distance_table(grid, centre, cache=False)
    assert_matches(table, grid, dijkstra_to_goal(grid, centre))
    assert table.distance((0, radius)) == radius


def test_unhashable_grid_maps_are_not_cached() -> None:
    class Unhashable:
        __hash__ = None  # type: ignore[assignment]
        x_size = 3
        y_size = 3
        min_cost = 1.0

        def __init__(self) -> None:
            self.grid = Grid(3, 3, blocked=[(1, 1)])

        def is_free(self, cell: tuple[int, int]) -> bool:
            return self.grid.is_free(cell)

        def neighbours(self, cell: tuple[int, int]) -> list[tuple[int, int]]:
            return self.grid.neighbours(cell)

        def cost(self, cell: tuple[int, int]) -> float:
            return 1.0

    grid = Unhashable()
    first = distance_table(grid, (0, 0), cache=True)
    assert first.distance((2, 2)) == 4.0
    assert distance_table(grid, (0, 0), cache=True) is not first


def test_table_cache_is_bounded(monkeypatch: pytest.MonkeyPatch) -> None:
    from mrmp.search import distance as distance_module

    monkeypatch.setattr(distance_module, "_TABLE_CACHE_CELLS", 4 * 30)
    monkeypatch.setattr(distance_module, "_GRIDS", type(distance_module._GRIDS)())
    grid = Grid(5, 6, blocked=[(4, 5)], name="bounded-cache")
    first = distance_table(grid, (0, 0))
    for goal in [(0, y) for y in range(1, 6)]:
        distance_table(grid, goal)
    again = distance_table(grid, (0, 0))
    assert again is not first
    np.testing.assert_array_equal(again.array, first.array)
    assert repr(again) == "<DistanceTable to (0, 0) on 5x6>"
