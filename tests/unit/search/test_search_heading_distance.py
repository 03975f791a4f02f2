"""Heading-aware distance tables: equal to heading-aware A* from every state; errors named."""

import random

import pytest

from mrmp.core.body import body_model
from mrmp.core.errors import NoPathError
from mrmp.core.grid import Grid
from mrmp.core.heading import HEADINGS, Heading
from mrmp.core.scenario import Timing
from mrmp.search import astar, heading_distance
from mrmp.search.graph import path_cost
from mrmp.search.heading_distance import heading_distances


def random_grid(seed: int) -> Grid:
    rng = random.Random(seed)
    rows = ["".join("@" if rng.random() < 0.2 else "." for _ in range(7)) for _ in range(6)]
    plain = Grid.from_rows(rows)
    costs = {cell: rng.choice((1.0, 1.0, 2.0, 3.5)) for cell in plain.free_cells()}
    return Grid(plain.x_size, plain.y_size, plain.blocked_cells(), costs)


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("turn_cost", [0.0, 0.5, 2.0])
def test_every_state_costs_what_heading_aware_astar_finds(seed, turn_cost):
    grid = random_grid(seed)
    free = grid.free_cells()
    goal = random.Random(seed).choice(free)
    table = heading_distances(grid, goal, turn_cost)
    for cell in free:
        for heading in HEADINGS:
            value = table[4 * (cell[0] * grid.y_size + cell[1]) + int(heading) - 1]
            try:
                expected = astar(grid, cell, goal, heading=heading, timing=Timing(1.0, turn_cost)).cost
            except NoPathError:
                expected = float("inf")
            assert value == pytest.approx(expected), (cell, heading)


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("cell_time", [1.0, 0.4])
def test_a_turning_body_costs_what_its_either_way_table_counts(seed, cell_time):
    """A* for a body that turns a quarter either way in one tick (the ``turning`` body, LoRR's MAPF_T) finds, from
    every state, the cost the backward table with ``both_ways`` counts, in cell times; its path costs that too."""
    grid = random_grid(seed)
    free = grid.free_cells()
    goal = random.Random(seed).choice(free)
    table = heading_distances(grid, goal, 1.0, both_ways=True)
    turning = body_model("turning")
    for cell in free:
        for heading in HEADINGS:
            value = table[4 * (cell[0] * grid.y_size + cell[1]) + int(heading) - 1] * cell_time
            try:
                result = astar(grid, cell, goal, heading=heading, timing=Timing(cell_time, 0.5), body=turning)
            except NoPathError:
                assert value == float("inf"), (cell, heading)
                continue
            assert result.cost == pytest.approx(value), (cell, heading)
            timing = Timing(cell_time, 0.5)
            assert path_cost(grid, result.path, heading=heading, timing=timing, body=turning) == pytest.approx(value)


def test_a_turning_body_turns_the_short_way_where_the_thesis_body_turns_right_three_times():
    corridor = Grid(3, 1)  # a column: north is +x
    turning = astar(corridor, (0, 0), (2, 0), heading=Heading.WEST, timing=Timing(1.0, 1.0), body=body_model("turning"))
    thesis = astar(corridor, (0, 0), (2, 0), heading=Heading.WEST, timing=Timing(1.0, 1.0), body=body_model("thesis"))
    assert (turning.cost, thesis.cost) == (3.0, 3.0)  # one quarter counter-clockwise; one right turn from WEST
    turning = astar(corridor, (0, 0), (2, 0), heading=Heading.EAST, timing=Timing(1.0, 1.0), body=body_model("turning"))
    thesis = astar(corridor, (0, 0), (2, 0), heading=Heading.EAST, timing=Timing(1.0, 1.0), body=body_model("thesis"))
    assert (turning.cost, thesis.cost) == (3.0, 5.0)  # EAST to NORTH: one left quarter, or three right turns
    omni = astar(corridor, (0, 0), (2, 0), heading=Heading.EAST, timing=Timing(1.0, 1.0), body=body_model("omni"))
    assert omni.cost == 2.0


def test_blocked_cells_are_unreachable_and_bad_arguments_are_refused():
    grid = Grid.from_rows([".@.", "..."])
    table = heading_distances(grid, (0, 0), 0.5)
    blocked = 4 * (1 * 3 + 1)  # (1, 1) is the '@' (rows are drawn north up)
    assert list(table[blocked : blocked + 4]) == [float("inf")] * 4
    with pytest.raises(ValueError, match="not a free cell"):
        heading_distances(grid, (1, 1), 0.5)
    with pytest.raises(ValueError, match="must not be negative"):
        heading_distances(grid, (0, 0), -1.0)


def dijkstra_table(grid: Grid, goal, turn_cost: float, both_ways: bool, lanes=None) -> list[float]:
    """Dijkstra over the states, forwards from each state's moves, written apart from the module's search; ``lanes``
    gives a move's extra cost from the cell it enters and its direction."""
    import heapq

    from mrmp.core.heading import quarter_turns, right_turns

    count = right_turns if not both_ways else quarter_turns
    states = [(cell, heading) for cell in grid.free_cells() for heading in HEADINGS]
    cost = {goal_state: 0.0 for goal_state in states if goal_state[0] == goal}
    queue = [(0.0, state) for state in cost]
    incoming: dict = {}
    for cell, facing in states:  # the moves out of (cell, facing), indexed by the state they reach
        for moving in HEADINGS:
            dx, dy = moving.delta
            ahead = (cell[0] + dx, cell[1] + dy)
            if grid.is_free(ahead):
                step = count(facing, moving) * turn_cost + grid.cost(ahead) + (lanes(ahead, moving) if lanes else 0.0)
                incoming.setdefault((ahead, moving), []).append(((cell, facing), step))
    while queue:
        value, state = heapq.heappop(queue)
        if value > cost[state]:
            continue
        for before, step in incoming.get(state, ()):
            if value + step < cost.get(before, float("inf")):
                cost[before] = value + step
                heapq.heappush(queue, (value + step, before))
    table = [float("inf")] * (4 * grid.x_size * grid.y_size)
    for (cell, heading), value in cost.items():
        table[4 * (cell[0] * grid.y_size + cell[1]) + int(heading) - 1] = value
    return table


@pytest.mark.slow
@pytest.mark.parametrize("threshold", [0, 64, 10**9])
@pytest.mark.parametrize("seed", range(4))
def test_large_maps_give_dijkstras_table_whether_waves_run_in_python_or_numpy(monkeypatch, seed, threshold):
    """Waves above the threshold are expanded with numpy, the others in Python: every split gives Dijkstra's table."""
    monkeypatch.setattr(heading_distance, "_VECTOR_THRESHOLD", threshold)
    rng = random.Random(seed)
    rows = ["".join("@" if rng.random() < 0.2 else "." for _ in range(40)) for _ in range(30)]
    plain = Grid.from_rows(rows)
    costs = {cell: rng.choice((1.0, 1.0, 2.0, 0.5)) for cell in plain.free_cells()} if seed % 2 else {}
    grid = Grid(plain.x_size, plain.y_size, plain.blocked_cells(), costs)
    goal = rng.choice(grid.free_cells())
    for turn_cost, both_ways in ((1.0, True), (0.5, False)):
        expected = dijkstra_table(grid, goal, turn_cost, both_ways)
        assert list(heading_distances(grid, goal, turn_cost, both_ways)) == pytest.approx(expected)


def against_crisscross(cell, moving: Heading) -> float:
    """The crisscross lanes as the documentation states them: even rows EAST, odd WEST; even columns NORTH, odd SOUTH."""
    x, y = cell
    if moving in (Heading.EAST, Heading.WEST):
        return 0.0 if moving == (Heading.EAST if x % 2 == 0 else Heading.WEST) else 1.0
    return 0.0 if moving == (Heading.NORTH if y % 2 == 0 else Heading.SOUTH) else 1.0


@pytest.mark.parametrize("seed", range(3))
def test_crisscross_guidance_adds_one_step_to_every_move_against_its_lane(seed):
    rng = random.Random(seed)
    rows = ["".join("@" if rng.random() < 0.2 else "." for _ in range(30)) for _ in range(20)]
    grid = Grid.from_rows(rows)
    goal = rng.choice(grid.free_cells())
    expected = dijkstra_table(grid, goal, 1.0, True, against_crisscross)
    assert list(heading_distances(grid, goal, 1.0, True, "crisscross")) == pytest.approx(expected)
    assert list(heading_distances(grid, goal, 1.0, True, "none")) == list(heading_distances(grid, goal, 1.0, True))
    with pytest.raises(ValueError, match="unknown guidance 'lanes'"):
        heading_distances(grid, goal, 1.0, True, "lanes")
