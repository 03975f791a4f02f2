"""Dijkstra, greedy best-first and A* (one engine) against independent references."""

from __future__ import annotations

import math
import random

import pytest
from _search_reference import (
    assert_valid_path,
    bellman_ford_to_goal,
    entry_cost,
    grid_with_ends,
    heading_state_dijkstra,
    random_grid,
)
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.core.errors import NoPathError
from mrmp.core.grid import Grid
from mrmp.core.heading import HEADINGS, Heading
from mrmp.core.scenario import Timing
from mrmp.search import (
    ASTAR,
    PLANNERS,
    GridMap,
    SearchResult,
    Strategy,
    astar,
    best_first_search,
    dijkstra,
    greedy_best_first,
    path_cost,
)

OPTIMAL = (dijkstra, astar)
SEARCHES = (dijkstra, greedy_best_first, astar)
SETTINGS = settings(max_examples=150, derandomize=True, deadline=None)


@SETTINGS
@given(grid_with_ends(max_size=8))
def test_optimal_planners_match_bellman_ford(case: tuple[Grid, tuple[int, int], tuple[int, int]]) -> None:
    grid, start, goal = case
    reference = bellman_ford_to_goal(grid, goal)[start]
    for planner in SEARCHES:
        if reference == math.inf:
            with pytest.raises(NoPathError):
                planner(grid, start, goal)
            continue
        result = planner(grid, start, goal)
        assert_valid_path(grid, result.path, start, goal)
        assert result.cost == pytest.approx(entry_cost(grid, result.path))
        assert result.headings is None
        if planner in OPTIMAL:
            assert result.cost == pytest.approx(reference)
        else:
            assert result.cost >= reference - 1e-9


@settings(max_examples=60, derandomize=True, deadline=None)
@given(grid_with_ends(max_size=7))
def test_optimal_planners_match_networkx(case: tuple[Grid, tuple[int, int], tuple[int, int]]) -> None:
    nx = pytest.importorskip("networkx")
    grid, start, goal = case
    graph = nx.DiGraph()
    for x in range(grid.x_size):
        for y in range(grid.y_size):
            if grid.is_free((x, y)):
                graph.add_node((x, y))
                for n in grid.neighbours((x, y)):
                    graph.add_edge((x, y), n, weight=grid.cost(n))
    try:
        expected = nx.dijkstra_path_length(graph, start, goal)
    except nx.NetworkXNoPath:
        expected = math.inf
    for planner in OPTIMAL:
        if expected == math.inf:
            with pytest.raises(NoPathError):
                planner(grid, start, goal)
        else:
            assert planner(grid, start, goal).cost == pytest.approx(expected)


@SETTINGS
@given(grid_with_ends(max_size=7), st.sampled_from(HEADINGS), st.sampled_from([0.0, 0.5, 2.0]), st.sampled_from([1.0, 0.5]))
def test_heading_aware_cost_matches_state_dijkstra(
    case: tuple[Grid, tuple[int, int], tuple[int, int]], heading: Heading, turn_time: float, cell_time: float
) -> None:
    grid, start, goal = case
    timing = Timing(cell_time=cell_time, turn_time=turn_time)
    reference = heading_state_dijkstra(grid, start, goal, heading, timing)
    for planner in SEARCHES:
        if reference == math.inf:
            with pytest.raises(NoPathError):
                planner(grid, start, goal, heading=heading, timing=timing)
            continue
        result = planner(grid, start, goal, heading=heading, timing=timing)
        assert_valid_path(grid, result.path, start, goal)
        assert result.headings is not None and len(result.headings) == len(result.path)
        assert result.headings[0] == heading
        for before, after, facing in zip(result.path, result.path[1:], result.headings[1:]):
            assert Heading.between(before, after) == facing
        assert result.cost == pytest.approx(path_cost(grid, result.path, heading=heading, timing=timing))
        if planner in OPTIMAL:
            assert result.cost == pytest.approx(reference)
        else:
            assert result.cost >= reference - 1e-9


@SETTINGS
@given(grid_with_ends(max_size=7), st.data())
def test_blocked_extras_are_avoided(case: tuple[Grid, tuple[int, int], tuple[int, int]], data: st.DataObject) -> None:
    grid, start, goal = case
    free = grid.free_cells()
    extras = set(data.draw(st.lists(st.sampled_from(free), max_size=len(free) // 3 + 1)))
    extras.add(start)  # the robot's own cell never stops it
    extras.discard(goal)
    reference = bellman_ford_to_goal(grid, goal, blocked=extras - {start})[start]
    for planner in SEARCHES:
        if reference == math.inf:
            with pytest.raises(NoPathError):
                planner(grid, start, goal, blocked=extras)
            continue
        result = planner(grid, start, goal, blocked=extras)
        assert_valid_path(grid, result.path, start, goal, blocked=extras - {start})
        assert start not in result.path[1:]
        if planner in OPTIMAL:
            assert result.cost == pytest.approx(reference)
    heading_reference = heading_state_dijkstra(grid, start, goal, Heading.NORTH, Timing(), blocked=extras - {start})
    if heading_reference < math.inf:
        result = astar(grid, start, goal, blocked=list(extras), heading=Heading.NORTH)
        assert_valid_path(grid, result.path, start, goal, blocked=extras - {start})
        assert result.cost == pytest.approx(heading_reference)


@settings(max_examples=80, derandomize=True, deadline=None)
@given(st.integers(1, 12), st.integers(1, 12), st.data(), st.sampled_from([None, *HEADINGS]))
def test_astar_expands_no_more_than_dijkstra_on_open_grids(
    x_size: int, y_size: int, data: st.DataObject, heading: Heading | None
) -> None:
    grid = Grid(x_size, y_size)
    start = (data.draw(st.integers(0, x_size - 1)), data.draw(st.integers(0, y_size - 1)))
    goal = (data.draw(st.integers(0, x_size - 1)), data.draw(st.integers(0, y_size - 1)))
    a = astar(grid, start, goal, heading=heading)
    d = dijkstra(grid, start, goal, heading=heading)
    assert a.cost == pytest.approx(d.cost)
    assert a.expansions <= d.expansions
    if heading is None:
        assert a.expansions == abs(start[0] - goal[0]) + abs(start[1] - goal[1])  # straight to the goal


@pytest.mark.parametrize("seed", range(4))
def test_astar_expands_no_more_than_dijkstra_on_random_maps(seed: int) -> None:
    rng = random.Random(seed)
    grid = random_grid(rng, 24, 24, obstacle_density=0.2, cost_density=0.3)
    free = grid.free_cells()
    for _ in range(5):
        start, goal = rng.choice(free), rng.choice(free)
        try:
            d = dijkstra(grid, start, goal)
        except NoPathError:
            continue
        a = astar(grid, start, goal)
        assert a.cost == pytest.approx(d.cost)
        assert a.expansions <= d.expansions


def test_walled_off_goal_raises() -> None:
    grid = Grid.from_rows(
        [
            ".....",
            ".@@@.",
            ".@.@.",
            ".@@@.",
            ".....",
        ]
    )
    for planner in PLANNERS.values():
        with pytest.raises(NoPathError):
            planner(grid, (0, 0), (2, 2))
        with pytest.raises(NoPathError):
            planner(grid, (2, 2), (0, 0), heading=Heading.NORTH)
    with pytest.raises(NoPathError, match=r"goal \(2, 2\) cannot be reached"):
        astar(grid, (0, 0), (2, 2))


def test_ends_that_are_not_free() -> None:
    grid = Grid(3, 3, blocked=[(1, 1)])
    for planner in SEARCHES:
        with pytest.raises(NoPathError, match="goal"):
            planner(grid, (0, 0), (1, 1))
        with pytest.raises(NoPathError, match="start"):
            planner(grid, (1, 1), (0, 0))
        with pytest.raises(NoPathError, match="start"):
            planner(grid, (-1, 0), (0, 0))
        with pytest.raises(NoPathError, match="blocked"):
            planner(grid, (0, 0), (2, 2), blocked={(2, 2)})


def test_start_is_goal() -> None:
    for planner in SEARCHES:
        result = planner(Grid(3, 3), (1, 1), (1, 1), blocked={(1, 1)}, heading=Heading.WEST)
        assert result == SearchResult(((1, 1),), 0.0, 0, (Heading.WEST,))


def test_greedy_may_be_longer_than_optimal() -> None:
    grid = Grid.from_rows(["...", ".9.", "..."])
    assert dijkstra(grid, (1, 0), (1, 2)).cost == 4.0
    greedy = greedy_best_first(grid, (1, 0), (1, 2))
    assert greedy.path == ((1, 0), (1, 1), (1, 2))
    assert greedy.cost == 10.0


def test_heading_aware_astar_prefers_fewer_turns() -> None:
    # Facing EAST, going east first costs one NORTH turn (3 right turns);
    # going north first costs 3 + 1 turns.
    result = astar(Grid(5, 5), (0, 0), (4, 4), heading=Heading.EAST, timing=Timing(1.0, 1.0))
    assert result.cost == 8.0 + 3.0
    assert result.path[1] == (0, 1)
    turns_free = astar(Grid(5, 5), (0, 0), (4, 4), heading=Heading.EAST, timing=Timing(1.0, 0.0))
    assert turns_free.cost == 8.0


def test_timing_without_heading_scales_cells_only() -> None:
    grid = Grid(3, 3, costs={(1, 0): 2.0})
    result = astar(grid, (0, 0), (2, 0), timing=Timing(cell_time=0.5, turn_time=100.0))
    assert result.cost == pytest.approx(0.5 * 3.0)
    assert result.headings is None


@pytest.mark.parametrize("planner", SEARCHES)
def test_results_are_reproducible(planner: object) -> None:
    rng = random.Random(7)
    grid = random_grid(rng, 16, 16, obstacle_density=0.15)
    free = grid.free_cells()
    pairs = [(rng.choice(free), rng.choice(free)) for _ in range(10)]
    for start, goal in pairs:
        try:
            first = planner(grid, start, goal, heading=Heading.SOUTH)  # type: ignore[operator]
        except NoPathError:
            continue
        again = planner(Grid(16, 16, grid.blocked_cells()), start, goal, heading=Heading.SOUTH)  # type: ignore[operator]
        assert first == again


def test_ties_prefer_deeper_nodes_then_insertion_order() -> None:
    # On an open grid every shortest path ties; preferring larger g sends A*
    # straight to the goal, and insertion order (neighbours N, E, S, W) makes
    # it go north before east.
    result = astar(Grid(4, 4), (0, 0), (3, 3))
    assert result.expansions == 6
    assert result.path == ((0, 0), (1, 0), (2, 0), (3, 0), (3, 1), (3, 2), (3, 3))


def test_custom_strategy_and_grid_protocol() -> None:
    class Walls:
        """A GridMap that is not a Grid: a 6x6 field with a wall at y == 3 except at x == 5."""

        min_cost = 1.0

        def is_free(self, cell: tuple[int, int]) -> bool:
            x, y = cell
            return 0 <= x < 6 and 0 <= y < 6 and (y != 3 or x == 5)

        def neighbours(self, cell: tuple[int, int]) -> list[tuple[int, int]]:
            x, y = cell
            around = [(x + 1, y), (x, y + 1), (x - 1, y), (x, y - 1)]
            return [n for n in around if self.is_free(n)]

        def cost(self, cell: tuple[int, int]) -> float:
            return 1.0

    walls = Walls()
    assert isinstance(walls, GridMap)
    weighted = Strategy("weighted_astar", lambda g, h: g + 2.0 * h)
    for strategy in (ASTAR, weighted):
        result = best_first_search(walls, (0, 0), (0, 5), strategy)
        assert result.path[0] == (0, 0) and result.path[-1] == (0, 5)
        assert (5, 3) in result.path
    assert best_first_search(walls, (0, 0), (0, 5), ASTAR).cost == 15.0


def test_planners_mapping() -> None:
    assert set(PLANNERS) == {"update_coordinate", "dijkstra", "best_first", "astar"}
    assert PLANNERS["dijkstra"] is dijkstra
    assert PLANNERS["best_first"] is greedy_best_first
    assert PLANNERS["astar"] is astar
    with pytest.raises(TypeError):
        PLANNERS["mine"] = astar  # type: ignore[index]
    grid = Grid(6, 6, blocked=[(2, 2)])
    for planner in PLANNERS.values():
        result = planner(grid, (0, 0), (5, 5), blocked=frozenset({(3, 3)}), heading=Heading.NORTH, timing=Timing())
        assert_valid_path(grid, result.path, (0, 0), (5, 5), blocked={(3, 3)})
        assert result.headings is not None


def test_heading_aware_search_rejects_non_adjacent_moves() -> None:
    class Teleport:
        """A GridMap whose (0, 0) leads straight to (2, 2)."""

        min_cost = 1.0

        def is_free(self, cell: tuple[int, int]) -> bool:
            return 0 <= cell[0] < 3 and 0 <= cell[1] < 3

        def neighbours(self, cell: tuple[int, int]) -> list[tuple[int, int]]:
            return [(2, 2)] if cell == (0, 0) else []

        def cost(self, cell: tuple[int, int]) -> float:
            return 1.0

    assert astar(Teleport(), (0, 0), (2, 2)).path == ((0, 0), (2, 2))
    with pytest.raises(ValueError, match="not adjacent"):
        astar(Teleport(), (0, 0), (2, 2), heading=Heading.NORTH)
