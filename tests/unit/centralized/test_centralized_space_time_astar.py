"""Space-time A*: reservations, goal waiting, horizon, exhaustion, limits, heading model."""

from __future__ import annotations

import random
from collections import deque

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.centralized.space_time_astar import (
    Reservations,
    heading_distance_table,
    hop_distance_table,
    space_time_astar,
)
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading


def respects(path: tuple, table: Reservations) -> bool:
    for tick, cell in enumerate(path):
        if table.blocks(cell, tick):
            return False
        if tick and path[tick - 1] != cell and table.forbids_move(path[tick - 1], cell, tick):
            return False
    # after the path ends the robot stays on its goal forever
    return table.last_vertex_time(path[-1]) < len(path) - 1


def reference_arrival(grid: Grid, start: tuple, goal: tuple, table: Reservations, horizon: int) -> int | None:
    """Least arrival tick by breadth-first search over (cell, t), t <= horizon, independent of A*."""
    earliest = table.last_vertex_time(goal) + 1
    if goal in table.parked or table.blocks(start, 0):
        return None
    seen = {(start, 0)}
    queue = deque([(start, 0)])
    while queue:
        cell, tick = queue.popleft()
        if cell == goal and tick >= earliest:
            return tick
        if tick == horizon:
            continue
        x, y = cell
        for target in [cell, (x + 1, y), (x, y + 1), (x - 1, y), (x, y - 1)]:
            if not grid.is_free(target) or table.blocks(target, tick + 1):
                continue
            if target != cell and table.forbids_move(cell, target, tick + 1):
                continue
            if (target, tick + 1) not in seen:
                seen.add((target, tick + 1))
                queue.append((target, tick + 1))
    return None


@settings(max_examples=150, derandomize=True, deadline=None)
@given(st.integers(0, 10_000))
def test_arrival_tick_matches_a_breadth_first_reference(seed: int) -> None:
    rng = random.Random(seed)
    x_size, y_size = rng.randint(1, 5), rng.randint(2, 5)
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    blocked = set(rng.sample(cells, rng.randint(0, len(cells) // 4)))
    free = [c for c in cells if c not in blocked]
    if len(free) < 2:
        return
    grid = Grid(x_size, y_size, blocked)
    start, goal = rng.sample(free, 2)
    table = Reservations()
    for _ in range(rng.randint(0, 12)):
        table.forbid_vertex(rng.choice(free), rng.randint(1, 8))
    for _ in range(rng.randint(0, 4)):
        a = rng.choice(free)
        neighbours = grid.neighbours(a)
        if neighbours:
            table.forbid_edge(a, rng.choice(neighbours), rng.randint(1, 8))
    if rng.random() < 0.3:
        other = rng.choice([c for c in free if c not in (start, goal)] or [start])
        if other not in (start, goal):
            table.park(other, rng.randint(0, 6))
    horizon = 8 + len(free) + 1  # the world is static after tick 8: any path arrives within |free| more ticks
    expected = reference_arrival(grid, start, goal, table, horizon)
    result = space_time_astar(grid, start, goal, table)
    if expected is None:
        assert result.status == "unreachable"
    else:
        assert result.found and result.path is not None
        assert result.cost == expected
        assert result.path[0] == start and result.path[-1] == goal
        assert respects(result.path, table)
        for before, after in zip(result.path, result.path[1:]):
            assert after == before or after in grid.neighbours(before)


def test_robot_waits_out_a_vertex_reservation() -> None:
    grid = Grid(1, 3)
    table = Reservations.from_entries(vertex=[((0, 1), 1)])
    assert space_time_astar(grid, (0, 0), (0, 2), table).path == ((0, 0), (0, 0), (0, 1), (0, 2))


def test_edge_reservation_forbids_that_move_only() -> None:
    grid = Grid(1, 2)
    table = Reservations.from_entries(edge=[((0, 0), (0, 1), 1)])
    assert space_time_astar(grid, (0, 0), (0, 1), table).path == ((0, 0), (0, 0), (0, 1))


def test_goal_reservation_later_delays_arrival() -> None:
    # someone crosses the goal at tick 6: the robot may only settle at tick 7 or later
    grid = Grid(2, 3)
    table = Reservations.from_entries(vertex=[((0, 2), 6)])
    result = space_time_astar(grid, (0, 0), (0, 2), table)
    assert result.cost == 7
    assert result.path is not None and result.path[6] != (0, 2)


def test_parked_robot_on_the_goal_makes_it_unreachable() -> None:
    table = Reservations.from_entries(parked=[((0, 2), 5)])
    assert space_time_astar(Grid(3, 3), (0, 0), (0, 2), table).status == "unreachable"


def test_parked_robot_blocks_a_corridor_after_it_arrives_only() -> None:
    grid = Grid(1, 4)
    early = Reservations.from_entries(parked=[((0, 1), 1)])
    late = Reservations.from_entries(parked=[((0, 1), 2)])
    assert space_time_astar(grid, (0, 0), (0, 3), early).status == "unreachable"
    assert space_time_astar(grid, (0, 0), (0, 3), late).cost == 3


def test_reserve_path_forbids_swaps_and_parks_the_end() -> None:
    table = Reservations()
    table.reserve_path([(0, 1), (0, 0)])
    grid = Grid(2, 2)
    result = space_time_astar(grid, (0, 0), (0, 1), table)
    assert result.path is not None and result.path[1] != (0, 1)  # no swap at tick 1
    assert table.parked == {(0, 0): 1}
    assert repr(table).startswith("<Reservations")


def test_horizon_and_limits() -> None:
    grid = Grid(1, 8)
    assert space_time_astar(grid, (0, 0), (0, 7), max_time=6).status == "horizon"
    assert space_time_astar(grid, (0, 0), (0, 7), max_time=7).found
    assert space_time_astar(grid, (0, 0), (0, 7), max_expansions=2).status == "expansions"
    big = Grid(40, 40)
    table = Reservations.from_entries(parked=[((39, 39), 0)])
    assert space_time_astar(big, (0, 0), (39, 39), table).status == "unreachable"
    slow = space_time_astar(big, (0, 0), (39, 38), Reservations.from_entries(vertex=[((39, 38), 5000)]), deadline=0.0)
    assert slow.status == "deadline"


def test_unreachable_goal_proved_quickly_without_horizon() -> None:
    grid = Grid.from_rows([".@."])
    result = space_time_astar(grid, (0, 0), (0, 2))
    assert result.status == "unreachable" and result.expansions == 0


def test_invalid_cells_raise() -> None:
    with pytest.raises(ValueError, match="start"):
        space_time_astar(Grid.from_rows(["@."]), (0, 0), (0, 1))
    with pytest.raises(ValueError, match="goal"):
        space_time_astar(Grid(2, 2), (0, 0), (5, 5))


def test_result_cost_without_path_raises() -> None:
    result = space_time_astar(Grid.from_rows([".@."]), (0, 0), (0, 2))
    with pytest.raises(ValueError):
        _ = result.cost


def test_entry_costs_do_not_change_ticks() -> None:
    grid = Grid(1, 3, costs={(0, 1): 9.0})
    assert space_time_astar(grid, (0, 0), (0, 2)).cost == 2
    assert hop_distance_table(grid, (0, 2)).distance((0, 0)) == 2.0


def test_conflict_avoidance_breaks_ties_without_costing_time() -> None:
    grid = Grid(2, 2)
    plain = space_time_astar(grid, (0, 0), (1, 1))
    assert plain.path == ((0, 0), (1, 0), (1, 1))  # NORTH first by the grid's order
    avoid = Reservations()
    avoid.reserve_path([(1, 0), (1, 0), (1, 0)])  # someone stands on (1, 0)
    detour = space_time_astar(grid, (0, 0), (1, 1), avoid=avoid)
    assert detour.path == ((0, 0), (0, 1), (1, 1))


def replay(path: tuple, headings: tuple) -> None:
    for tick in range(1, len(path)):
        if path[tick] == path[tick - 1]:
            assert headings[tick] in (headings[tick - 1], Heading(int(headings[tick - 1]) % 4 + 1))
        else:
            assert headings[tick] == headings[tick - 1] and headings[tick - 1].ahead(path[tick - 1]) == path[tick]


def test_heading_aware_turns_cost_ticks() -> None:
    grid = Grid(3, 3)
    result = space_time_astar(grid, (2, 2), (0, 2), heading_aware=True, heading=Heading.NORTH)
    assert result.path is not None and result.headings is not None
    # NORTH -> SOUTH takes two right turns, then two moves
    assert result.cost == 4
    assert [h.name for h in result.headings] == ["NORTH", "EAST", "SOUTH", "SOUTH", "SOUTH"]
    replay(result.path, result.headings)


@settings(max_examples=60, derandomize=True, deadline=None)
@given(st.integers(0, 10_000))
def test_heading_aware_paths_replay_and_match_the_static_table(seed: int) -> None:
    rng = random.Random(seed)
    grid = Grid(rng.randint(2, 5), rng.randint(2, 5))
    cells = grid.free_cells()
    start, goal = rng.sample(cells, 2)
    heading = Heading(rng.randint(1, 4))
    result = space_time_astar(grid, start, goal, heading_aware=True, heading=heading)
    assert result.path is not None and result.headings is not None
    assert result.headings[0] == heading
    replay(result.path, result.headings)
    assert result.cost == heading_distance_table(grid, goal)[(start, heading)]
    # and a reservation on its path makes it no faster
    table = Reservations.from_entries(vertex=[(result.path[1], 1)]) if result.path[1] != start else Reservations()
    again = space_time_astar(grid, start, goal, table, heading_aware=True, heading=heading)
    assert again.path is not None and again.cost >= result.cost
    replay(again.path, again.headings)
