"""Rotations: plans the robots cannot execute one move at a time, refused and never planned.

A rotation is a cycle of robots that each enter, at one tick, the cell the next
one leaves. The Action Dependency Graph of such a plan has a cycle
(:mod:`mrmp.centralized.dependencies`), so its execution would deadlock; every
central planner must return rotation-free plans, which then execute to the end.
"""

from __future__ import annotations

import random
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_centralized_support import assert_valid_plan, moves_round_a_cycle

from mrmp.centralized import cbs, lacam, prioritized
from mrmp.centralized.dependencies import (
    PlanDeadlockError,
    Rotation,
    action_dependencies,
    check_executable,
    find_rotations,
)
from mrmp.centralized.plan import PlanningResult, pad_paths
from mrmp.centralized.space_time_astar import Reservations, space_time_astar
from mrmp.core import Grid, RobotSpec, Scenario
from mrmp.core.errors import MrmpError
from mrmp.experiments.execution import execute_in_simulator
from mrmp.io.scenario_file import load_movingai_scenario

MAPS = Path(__file__).resolve().parents[3] / "maps"
BLOCK = [(0, 0), (0, 1), (1, 1), (1, 0)]
TURNED = BLOCK[1:] + BLOCK[:1]


def scenario_of(grid: Grid, starts, goals) -> Scenario:
    return Scenario(grid, tuple(RobotSpec(f"r{i}", s, g) for i, (s, g) in enumerate(zip(starts, goals))))


def assert_executes(scenario: Scenario, plan: PlanningResult) -> None:
    """The plan has no rotation, and the fleet following it arrives without a collision."""
    assert plan.solved, plan.message
    assert plan.paths is not None and find_rotations(plan.paths) == []
    # robots following one another wait for each other's messages: executing takes longer
    # than the plan's ticks, so the tick limit follows the plan's length
    limit = 64 + 8 * len(plan.paths[0]) if plan.paths else 64
    result = execute_in_simulator(scenario.with_changes(max_ticks=limit), plan)
    assert result.collisions == []
    assert result.success, result.stop_reason
    assert [robot.path[-1] for robot in result.robots] == [robot.goal for robot in scenario.robots]


# -- the dependency graph refuses rotations ---------------------------------------------


def test_a_hand_made_rotation_is_refused_with_robots_tick_and_cells():
    # robots 0-3 wait at first; at tick 2 they turn the block, robot 4 waits elsewhere
    paths = [[cell, cell, goal] for cell, goal in zip(BLOCK, TURNED)] + [[(2, 0), (2, 1), (2, 1)]]
    assert find_rotations(paths) == [Rotation(2, (0, 1, 2, 3), tuple(BLOCK))]
    with pytest.raises(PlanDeadlockError) as caught:
        action_dependencies(paths)
    error = caught.value
    assert isinstance(error, MrmpError) and isinstance(error, ValueError)
    assert error.robots == (0, 1, 2, 3) and error.ticks == (2, 2, 2, 2) and error.cells == tuple(TURNED)
    message = str(error)
    assert "robots 0, 1, 2, 3" in message and "at tick 2" in message and "rotation" in message
    assert "robot 3 enters (0, 0) after robot 0 leaves it" in message
    # the executor refuses it before any robot moves, instead of deadlocking
    scenario = scenario_of(Grid(3, 2), [path[0] for path in paths], [path[-1] for path in paths])
    with pytest.raises(PlanDeadlockError):
        execute_in_simulator(scenario, PlanningResult("solved", pad_paths(paths), 0.0, "hand"))


def test_following_chains_are_not_rotations_and_execute():
    # three robots follow one another round the block into its free cell, in one tick
    paths = [[cell, goal] for cell, goal in zip(BLOCK[:3], TURNED[:3])]
    assert find_rotations(paths) == []
    _moves, needs = action_dependencies(paths)
    assert needs[0] == {0: [(1, 1)]} and needs[1] == {0: [(2, 1)]} and needs[2] == {}
    scenario = scenario_of(Grid(2, 2), BLOCK[:3], TURNED[:3])
    assert_executes(scenario, PlanningResult("solved", pad_paths(paths), 0.0, "hand"))


def test_find_rotations_reports_each_cycle_of_a_tick_and_swaps_on_request():
    two_blocks = [(0, 0), (0, 1), (1, 1), (1, 0), (0, 3), (0, 4), (1, 4), (1, 3)]
    turned = two_blocks[1:4] + two_blocks[:1] + two_blocks[5:] + two_blocks[4:5]
    paths = [[cell, goal, goal] for cell, goal in zip(two_blocks, turned)]
    paths.append([(3, 0), (3, 1), (3, 0)])  # a robot going back and forth alone
    paths.append([(4, 0), (4, 1)])  # and a shorter path (staying on its last cell)
    paths.append([(4, 1), (4, 0)])  # swapping with it
    found = find_rotations(paths)
    assert [(r.tick, r.robots) for r in found] == [(1, (0, 1, 2, 3)), (1, (4, 5, 6, 7)), (1, (9, 10))]
    assert [(r.tick, r.robots) for r in find_rotations(paths, min_robots=3)] == [(1, (0, 1, 2, 3)), (1, (4, 5, 6, 7))]


def test_a_swap_is_refused_too():
    with pytest.raises(PlanDeadlockError, match="a swap"):
        action_dependencies([[(0, 0), (0, 1)], [(0, 1), (0, 0)]])


def test_check_executable_names_one_cycle_among_waiting_robots():
    # robot 2 waits for robot 0, which waits in a cycle with robot 1: the cycle is 0, 1
    moves = [[(0, 1)], [(0, 0)], [(5, 5)]]
    needs = [{0: [(1, 1)]}, {0: [(0, 1)]}, {0: [(0, 1)]}]
    with pytest.raises(PlanDeadlockError) as caught:
        check_executable(moves, needs, [[4], [4], [6]])
    assert caught.value.robots == (0, 1) and caught.value.ticks == (4, 4)
    check_executable([*moves[:1], [(0, 0)]], [{0: [(1, 1)]}, {}])  # robot 1 goes first: fine


# -- space-time A* refuses the move that closes a cycle -----------------------------------


def test_space_time_astar_does_not_close_a_rotation_but_may_follow():
    # Three robots turn three quarters of the block at tick 1; then robot 1 moves on to (2, 1)
    # and robot 2 follows it back into (1, 1). Robot 3, on (1, 0), must leave at tick 1.
    table = Reservations()
    table.reserve_path([(0, 0), (0, 1)])
    table.reserve_path([(0, 1), (1, 1), (2, 1)])
    table.reserve_path([(1, 1), (1, 0), (1, 1)])
    assert table.closes_rotation((1, 0), (0, 0), 1) and not table.closes_rotation((1, 0), (0, 0), 2)
    # its goal (0, 0) at tick 1 would close the cycle: it steps aside to (2, 0) and comes back,
    # following robot 2 out of (1, 0) at tick 2
    result = space_time_astar(Grid(3, 2), (1, 0), (0, 0), table)
    assert result.path == ((1, 0), (2, 0), (1, 0), (0, 0))
    # without room to step aside it has no path (PP's incompleteness, not a rotation)
    assert space_time_astar(Grid(2, 2), (1, 0), (0, 0), table).status == "unreachable"
    # following a robot that does not come round is allowed: (0, 1) is entered as it is left
    chain = Reservations()
    chain.reserve_path([(0, 1), (1, 1)])
    assert space_time_astar(Grid(2, 3), (0, 2), (0, 0), chain).path == ((0, 2), (0, 1), (0, 0))


# -- every planner plans around rotations ---------------------------------------------------


def test_cbs_and_lacam_turn_the_block_without_a_rotation():
    grid = Grid(2, 3)
    scenario = scenario_of(grid, BLOCK, TURNED)
    for plan in (cbs(scenario), cbs(scenario, improved=False), lacam(scenario), lacam(scenario, swap=False)):
        assert_valid_plan(grid, plan, BLOCK, TURNED)
        assert_executes(scenario, plan)


def test_every_planner_refuses_the_full_block():
    scenario = scenario_of(Grid(2, 2), BLOCK, TURNED)
    assert cbs(scenario).status == "infeasible"
    assert prioritized(scenario).status == "infeasible"
    assert lacam(scenario).status == "infeasible"


def test_prioritized_planning_plans_around_the_rotation_it_would_make():
    # Without the rule, robot 3 (planned last) would close a cycle of four at tick 2 with robots
    # 0, 2 and 1, for a sum of costs of 8; it goes round by (1, 3) instead (sum of costs 9).
    grid = Grid(2, 4)
    starts, goals = [(0, 3), (1, 0), (0, 1), (1, 2)], [(0, 1), (1, 2), (1, 1), (0, 2)]
    plan = prioritized(grid, starts, goals)
    assert_valid_plan(grid, plan, starts, goals)
    assert plan.paths is not None and plan.paths[3] == ((1, 2), (1, 3), (0, 3), (0, 2))
    assert plan.sum_of_costs() == 9
    assert_executes(scenario_of(grid, starts, goals), plan)
    # in a 2x3 grid the last robot of the block has no way round: PP fails (it is incomplete)
    assert prioritized(Grid(2, 3), BLOCK, TURNED).status == "failed"


def test_lacam_on_random_32_32_20_with_60_robots_executes():
    scenario = load_movingai_scenario(MAPS / "random-32-32-20.map", MAPS / "random-32-32-20-random-1.scen", 60)
    assert_executes(scenario, lacam(scenario))


def test_lacam_on_maze_32_32_2_with_40_robots_executes():
    scenario = load_movingai_scenario(MAPS / "maze-32-32-2.map", MAPS / "maze-32-32-2-random-1.scen", 40)
    assert_executes(scenario, lacam(scenario))


@st.composite
def small_maps(draw: st.DrawFn) -> Scenario:
    """A random map of at most 5x5 cells with a fifth blocked, and 2-8 robots with random starts and goals."""
    rng = random.Random(draw(st.integers(0, 2**32 - 1)))
    x_size, y_size = draw(st.integers(2, 5)), draw(st.integers(2, 5))
    blocked = [(x, y) for x in range(x_size) for y in range(y_size) if rng.random() < 0.2]
    grid = Grid(x_size, y_size, blocked)
    free = grid.free_cells()
    count = min(draw(st.integers(2, 8)), len(free))
    return scenario_of(grid, rng.sample(free, count), rng.sample(free, count))


@pytest.mark.slow
@settings(max_examples=60, derandomize=True, deadline=None)
@given(small_maps())
def test_lacam_and_pp_plans_are_rotation_free_and_execute(scenario):
    starts = [robot.start for robot in scenario.robots]
    goals = [robot.goal for robot in scenario.robots]
    for plan in (lacam(scenario, time_limit_s=5.0), prioritized(scenario)):
        if not plan.solved:
            continue
        assert_valid_plan(scenario.grid, plan, starts, goals)
        assert plan.paths is not None
        assert not any(
            moves_round_a_cycle([path[tick - 1] for path in plan.paths], [path[tick] for path in plan.paths])
            for tick in range(1, len(plan.paths[0]))
        )
        assert_executes(scenario, plan)
