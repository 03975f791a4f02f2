"""Conflict-Based Search: optimal against a joint-state brute force, limits, infeasibility, headings."""

from __future__ import annotations

import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_centralized_support import (
    assert_valid_plan,
    brute_force_sum_of_costs,
    replay_headings,
)

from mrmp.centralized import PLANNERS, cbs, first_conflict, infeasibility_proof
from mrmp.centralized.cbs import all_conflicts, mdd_layers, min_vertex_cover_size
from mrmp.centralized.plan import as_problem
from mrmp.centralized.space_time_astar import Reservations
from mrmp.core.errors import InputError
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import RobotSpec, Scenario


@st.composite
def instances(draw: st.DrawFn, max_side: int = 4, max_robots: int = 3) -> tuple[Grid, list, list]:
    """A small grid with obstacles, and 2-3 robots with distinct starts and goals."""
    x_size = draw(st.integers(1, max_side))
    y_size = draw(st.integers(2, max_side))
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    blocked = draw(st.sets(st.sampled_from(cells), max_size=len(cells) // 3))
    free = [cell for cell in cells if cell not in blocked]
    robots = draw(st.integers(2, max_robots))
    if len(free) > 9:
        robots = min(robots, 2)  # keeps the brute force fast
    robots = min(robots, len(free))
    robots = max(robots, 1)
    if not free:
        free = [cells[0]]
        blocked.discard(cells[0])
    starts = draw(st.lists(st.sampled_from(free), min_size=robots, max_size=robots, unique=True))
    goals = draw(st.lists(st.sampled_from(free), min_size=robots, max_size=robots, unique=True))
    return Grid(x_size, y_size, blocked), starts, goals


@st.composite
def corridor_instances(draw: st.DrawFn) -> tuple[Grid, list, list]:
    """A corridor (the south row) with passing bays to its north; robots start in the corridor.

    Most of these need waits, detours into a bay, or are impossible (robots
    cannot pass each other without a bay). Two robots only: three robots
    crossing in a corridor is the textbook exponential case of CBS (Li et al.,
    ICAPS 2020), tested separately against the node limit.
    """
    length = draw(st.integers(3, 5))
    bays = draw(st.sets(st.integers(0, length - 1), min_size=1, max_size=2))
    blocked = [(1, y) for y in range(length) if y not in bays]
    corridor = [(0, y) for y in range(length)]
    free = corridor + [(1, y) for y in sorted(bays)]
    robots = 2
    starts = draw(st.lists(st.sampled_from(corridor), min_size=robots, max_size=robots, unique=True))
    goals = draw(st.lists(st.sampled_from(free), min_size=robots, max_size=robots, unique=True))
    if draw(st.booleans()):  # make the robots cross: westmost start gets the eastmost goal, and so on
        by_start = sorted(range(robots), key=lambda i: starts[i][1])
        by_goal = sorted(goals, key=lambda cell: (-cell[1], cell[0]))
        crossed = list(goals)
        for index, goal in zip(by_start, by_goal):
            crossed[index] = goal
        goals = crossed
    return Grid(2, length, blocked), starts, goals


@pytest.mark.slow
@settings(max_examples=200, derandomize=True, deadline=None)
@given(st.one_of(instances(), corridor_instances()))
def test_cbs_sum_of_costs_equals_brute_force(instance: tuple[Grid, list, list]) -> None:
    grid, starts, goals = instance
    optimum = brute_force_sum_of_costs(grid, starts, goals)
    result = cbs(grid, starts, goals, max_nodes=5000 if optimum is not None else 300, time_limit_s=10.0)
    if optimum is None:
        assert result.status in ("infeasible", "limit")
        assert result.paths is None
    else:
        assert_valid_plan(grid, result, starts, goals)
        assert result.sum_of_costs() == optimum


@settings(max_examples=60, derandomize=True, deadline=None)
@given(st.one_of(instances(max_side=3), corridor_instances()))
def test_original_cbs_is_optimal_too(instance: tuple[Grid, list, list]) -> None:
    # improved=False: split the first conflict, no heuristic, no bypass (Sharon et al. 2015 as published)
    grid, starts, goals = instance
    optimum = brute_force_sum_of_costs(grid, starts, goals)
    result = cbs(grid, starts, goals, max_nodes=5000 if optimum is not None else 200, improved=False)
    if optimum is None:
        assert not result.solved
    else:
        assert_valid_plan(grid, result, starts, goals)
        assert result.sum_of_costs() == optimum


@pytest.mark.slow
@settings(max_examples=40, derandomize=True, deadline=None)
@given(instances(max_side=3, max_robots=2))
def test_heading_aware_cbs_is_optimal_for_the_turn_model(instance: tuple[Grid, list, list]) -> None:
    grid, starts, goals = instance
    facing = [Heading.EAST, Heading.SOUTH][: len(starts)]
    optimum = brute_force_sum_of_costs(grid, starts, goals, heading_aware=True, headings=[int(h) for h in facing])
    problem = as_problem(grid, starts, goals, headings=facing)
    result = cbs(problem, max_nodes=3000, time_limit_s=5.0, heading_aware=True)
    if optimum is None:
        assert not result.solved
    else:
        assert_valid_plan(grid, result, starts, goals)
        replay_headings(grid, result, facing)
        assert result.sum_of_costs() == optimum


# corridors with a passing bay: robots must wait, step aside, and never swap
BAY_CASES = [
    (["#.#", "..."], [(0, 0), (0, 2)], [(0, 2), (0, 0)]),
    (["#.##", "...."], [(0, 0), (0, 3)], [(0, 3), (0, 0)]),
    (["#.#", "...", "#.#"], [(1, 0), (1, 2), (2, 1)], [(1, 2), (1, 0), (0, 1)]),
    (["#.#.#", "....."], [(0, 0), (0, 4)], [(0, 4), (0, 0)]),
    ([".#.#.", "....."], [(0, 0), (0, 4), (1, 2)], [(0, 4), (0, 0), (1, 0)]),
    (["....", ".##.", "...."], [(0, 0), (0, 3), (2, 0)], [(0, 3), (2, 3), (0, 0)]),
]


@pytest.mark.parametrize(("rows", "starts", "goals"), BAY_CASES)
def test_cbs_optimal_on_corridors_with_a_bay(rows: list[str], starts: list, goals: list) -> None:
    grid = Grid.from_rows(rows)
    result = cbs(grid, starts, goals)
    assert_valid_plan(grid, result, starts, goals)
    assert result.sum_of_costs() == brute_force_sum_of_costs(grid, starts, goals)
    assert result.planner == "cbs" and result.nodes >= 1


def test_cbs_goal_crossing_with_room_to_wait() -> None:
    grid = Grid.from_rows([".#...", "....."])
    starts, goals = [(0, 0), (0, 3)], [(0, 4), (0, 2)]
    result = cbs(grid, starts, goals)
    assert_valid_plan(grid, result, starts, goals)
    assert result.sum_of_costs() == brute_force_sum_of_costs(grid, starts, goals)


def test_cbs_accepts_a_scenario_and_keeps_its_order() -> None:
    grid = Grid(3, 3)
    scenario = Scenario(grid, (RobotSpec("B", (0, 0), (2, 2)), RobotSpec("A", (2, 2), (0, 0))))
    result = cbs(scenario)
    assert_valid_plan(grid, result, [(0, 0), (2, 2)], [(2, 2), (0, 0)])
    assert result.sum_of_costs() == 8


def test_cbs_is_deterministic() -> None:
    grid = Grid.from_rows(["....", ".@..", "...."])
    starts, goals = [(0, 0), (2, 3), (0, 3)], [(2, 3), (0, 0), (2, 0)]
    first = cbs(grid, starts, goals)
    assert all(cbs(grid, starts, goals).paths == first.paths for _ in range(3))


CROWDED = (Grid.from_rows(["#.#.#", "....."]), [(0, 0), (0, 1), (0, 2), (0, 3), (0, 4)], [(0, 4), (0, 3), (0, 2), (0, 1), (0, 0)])


def test_cbs_stops_at_its_node_limit_and_says_so() -> None:
    grid, starts, goals = CROWDED
    result = cbs(grid, starts, goals, max_nodes=50, time_limit_s=30.0)
    assert result.status == "limit" and not result.solved
    assert result.paths is None
    assert result.nodes == 50
    assert "node limit of 50" in result.message


def test_cbs_stops_at_its_time_limit_and_says_so() -> None:
    grid, starts, goals = CROWDED
    began = time.perf_counter()
    result = cbs(grid, starts, goals, max_nodes=None, time_limit_s=0.2)
    elapsed = time.perf_counter() - began
    assert result.status == "limit"
    assert "time limit of 0.2 s" in result.message
    assert 0.2 <= result.planning_time_s <= elapsed < 30.0  # it stops (a loaded machine only makes it later)


def test_cbs_infeasible_swap_in_1x2_corridor_is_proved() -> None:
    # documented: a cycle-free region filled with robots is proved "infeasible"
    result = cbs(Grid(1, 2), [(0, 0), (0, 1)], [(0, 1), (0, 0)])
    assert result.status == "infeasible"
    assert "cannot move" in result.message
    assert result.paths is None


def test_cbs_infeasible_swap_in_1x3_corridor_ends_at_a_limit() -> None:
    # documented: without a cheap proof CBS ends with "limit", without hanging
    result = cbs(Grid(1, 3), [(0, 0), (0, 2)], [(0, 2), (0, 0)], max_nodes=200, time_limit_s=2.0)
    assert result.status == "limit"


def test_cbs_cannot_prove_a_ring_order_impossible_but_stops() -> None:
    # robots on a ring keep their cyclic order: this exchange is impossible (brute force proves it)
    grid = Grid.from_rows(["....", ".##.", "...."])
    starts, goals = [(0, 0), (0, 3), (2, 0)], [(0, 3), (0, 0), (2, 3)]
    assert brute_force_sum_of_costs(grid, starts, goals) is None
    result = cbs(grid, starts, goals, max_nodes=500, time_limit_s=2.0)
    assert result.status == "limit" and "node limit of 500" in result.message


def test_cbs_unreachable_goal_is_infeasible() -> None:
    grid = Grid.from_rows([".@."])
    result = cbs(grid, [(0, 0)], [(0, 2)])
    assert result.status == "infeasible"
    assert "cannot reach" in result.message


def test_cbs_rejects_shared_goals() -> None:
    with pytest.raises(InputError, match="goal"):
        cbs(Grid(2, 2), [(0, 0), (1, 1)], [(0, 1), (0, 1)])


def test_cbs_robots_already_home() -> None:
    result = cbs(Grid(2, 2), [(0, 0), (1, 1)], [(0, 0), (1, 1)])
    assert result.solved and result.sum_of_costs() == 0 and result.paths == (((0, 0),), ((1, 1),))


def test_heading_aware_cbs_turns_before_moving() -> None:
    grid = Grid.from_rows(["...", "...", "..."])
    starts, goals = [(0, 0), (2, 2)], [(0, 2), (2, 0)]
    facing = [Heading.NORTH, Heading.NORTH]
    result = cbs(as_problem(grid, starts, goals, headings=facing), heading_aware=True)
    assert_valid_plan(grid, result, starts, goals)
    replay_headings(grid, result, facing)
    # A turns right once (NORTH -> EAST) then moves twice; B turns three times to face WEST
    assert result.costs() == (3, 5)
    assert result.sum_of_costs() == brute_force_sum_of_costs(grid, starts, goals, heading_aware=True)


def test_first_conflict_prefers_the_earliest_tick() -> None:
    paths = [[(0, 0), (0, 1), (0, 2)], [(1, 1), (1, 2), (0, 2)], [(0, 2), (0, 1), (0, 0)]]
    conflict, count = first_conflict(paths)
    assert conflict is not None
    assert (conflict.kind, conflict.first, conflict.second, conflict.cells, conflict.tick) == ("vertex", 0, 2, ((0, 1),), 1)
    assert count == 2  # then robots 0 and 1 meet on (0, 2) at tick 2 (robot 2 has left)


def test_first_conflict_finds_swaps_and_parked_robots() -> None:
    conflict, _ = first_conflict([[(0, 0), (0, 0), (0, 1)], [(0, 2), (0, 1), (0, 0)]])
    assert conflict is not None and (conflict.kind, conflict.tick, conflict.cells) == ("edge", 2, ((0, 0), (0, 1)))
    conflict, _ = first_conflict([[(0, 1)], [(0, 3), (0, 2), (0, 1)]])
    assert conflict is not None and (conflict.kind, conflict.tick) == ("vertex", 2)
    assert first_conflict([[(0, 0), (0, 1)], [(0, 1), (0, 2)]]) == (None, 0)  # following is allowed


def test_infeasibility_proof_of_a_full_block_that_could_only_rotate() -> None:
    # a full 2x2 block could only rotate, which robots moving one at a time cannot execute
    grid = Grid(2, 2)
    starts = [(0, 0), (0, 1), (1, 1), (1, 0)]
    goals = [(0, 1), (1, 1), (1, 0), (0, 0)]
    assert brute_force_sum_of_costs(grid, starts, goals) is None
    assert "only a rotation would move them" in (infeasibility_proof(as_problem(grid, starts, goals)) or "")
    assert cbs(grid, starts, goals).status == "infeasible"
    # with a robot on its goal and a free cell, no proof: the others can move
    assert infeasibility_proof(as_problem(grid, starts[:3], goals[:3])) is None


@pytest.mark.parametrize("improved", [True, False])
def test_cbs_splits_rotations_and_is_optimal_among_rotation_free_plans(improved: bool) -> None:
    # the classic optimum (cost 4) turns the 2x2 block in one tick: a rotation conflict, split
    # into one child per robot; the rotation-free optimum (6, from the brute force) remains
    grid = Grid(2, 3)
    block = [(0, 0), (0, 1), (1, 1), (1, 0)]
    goals = block[1:] + block[:1]
    result = cbs(grid, block, goals, improved=improved)
    assert_valid_plan(grid, result, block, goals)
    assert result.sum_of_costs() == brute_force_sum_of_costs(grid, block, goals) == 6
    assert brute_force_sum_of_costs(grid, block, goals, rotations=True) == 4
    rotations = all_conflicts([[cell, goal] for cell, goal in zip(block, goals)], rotations=True)
    assert [(c.kind, c.robots, c.tick) for c in rotations] == [("rotation", (0, 1, 2, 3), 1)]
    assert result.nodes > 1 + 4  # the root and at least one split into four children


@settings(max_examples=40, derandomize=True, deadline=None)
@given(st.integers(0, 10**6))
def test_cbs_with_four_robots_is_optimal_among_rotation_free_plans(seed: int) -> None:
    # four robots on small grids with cycles: rotations would often be cheapest
    import random

    rng = random.Random(seed)
    grid = Grid(2, rng.choice([2, 3]), [])
    free = grid.free_cells()
    starts, goals = rng.sample(free, 4), rng.sample(free, 4)
    optimum = brute_force_sum_of_costs(grid, starts, goals)
    result = cbs(grid, starts, goals, max_nodes=5000, time_limit_s=10.0)
    if optimum is None:
        assert not result.solved
    else:
        assert_valid_plan(grid, result, starts, goals)
        assert result.sum_of_costs() == optimum


def test_planners_registry() -> None:
    assert PLANNERS["cbs"] is cbs
    assert "pp" in PLANNERS


def test_all_conflicts_lists_every_pair_and_tick() -> None:
    paths = [[(0, 0), (0, 1), (0, 2)], [(0, 2), (0, 1), (0, 0)], [(1, 1), (0, 1), (1, 1)]]
    found = all_conflicts(paths)
    assert [(c.kind, c.first, c.second, c.tick) for c in found] == [("vertex", 0, 1, 1), ("vertex", 0, 2, 1)]


def test_mdd_layers_of_a_constrained_robot() -> None:
    # forbidding (0, 1) at tick 1 on a 1x3 corridor: the only 3-tick paths wait first or step back
    grid = Grid(1, 3)
    layers = mdd_layers(grid, (0, 0), (0, 2), 3, Reservations.from_entries(vertex=[((0, 1), 1)]))
    assert [sorted(layer) for layer in layers] == [[(0, 0)], [(0, 0)], [(0, 1)], [(0, 2)]]


def test_min_vertex_cover_on_a_path_and_a_star() -> None:
    assert min_vertex_cover_size([(0, 1), (1, 2), (2, 3), (3, 4)]) == 2
    assert min_vertex_cover_size([(0, i) for i in range(1, 9)]) == 1
    clique = [(i, j) for i in range(5) for j in range(i + 1, 5)]
    assert min_vertex_cover_size(clique) == 4
    # beyond the exact size a matching bound is returned, never more than the truth
    assert min_vertex_cover_size(clique, exact_up_to=1) == 2
