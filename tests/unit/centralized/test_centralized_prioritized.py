"""Prioritized planning: valid plans, the robot it cannot plan, orders, horizon, headings."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_centralized_cbs import corridor_instances, instances
from test_centralized_support import (
    assert_valid_plan,
    brute_force_sum_of_costs,
    replay_headings,
)

from mrmp.centralized import PLANNERS, prioritized, priority_order
from mrmp.centralized.plan import as_problem
from mrmp.core.errors import InputError
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import RobotSpec, Scenario

# A corridor (south row) with one bay north of (0, 1). Robot "A" starts in the bay, its goal
# (0, 2) lies in the corridor; "B" must traverse the corridor through (0, 2) to (0, 3).
# Planned first, A parks on (0, 2) at tick 2 and cuts B off for good; B first, both succeed.
BAY = Grid.from_rows(["#.##", "...."])
BAY_SCENARIO = Scenario(BAY, (RobotSpec("A", (1, 1), (0, 2)), RobotSpec("B", (0, 0), (0, 3))))


def test_pp_names_the_robot_it_cannot_plan() -> None:
    result = prioritized(BAY_SCENARIO)
    assert result.status == "failed" and not result.solved
    assert result.failed_robot == "B"
    assert result.paths is None
    assert "robot B" in result.message and "priority 2 of 2" in result.message
    assert result.nodes > 0


def test_pp_with_another_order_solves_the_same_instance() -> None:
    for order in ("longest_first", ["B", "A"]):
        result = prioritized(BAY_SCENARIO, order=order)
        assert_valid_plan(BAY, result, [(1, 1), (0, 0)], [(0, 2), (0, 3)])
        assert result.failed_robot is None
    # and CBS agrees the instance is solvable at that cost
    assert prioritized(BAY_SCENARIO, order=["B", "A"]).sum_of_costs() == brute_force_sum_of_costs(
        BAY, [(1, 1), (0, 0)], [(0, 2), (0, 3)]
    )


def test_pp_lower_priority_robot_waits_for_a_crossing_before_settling() -> None:
    # B's goal (0, 2) is on A's way; B (lower priority) must not settle there before A passes
    grid = Grid.from_rows(["..#..", "....."])
    starts, goals = [(0, 0), (1, 3)], [(0, 4), (0, 2)]
    result = prioritized(grid, starts, goals)
    assert_valid_plan(grid, result, starts, goals)
    assert result.paths is not None
    a_at_goal_of_b = max(t for t, cell in enumerate(result.paths[0]) if cell == (0, 2))
    assert result.costs()[1] > a_at_goal_of_b


@settings(max_examples=120, derandomize=True, deadline=None)
@given(st.one_of(instances(), corridor_instances()))
def test_pp_plans_are_valid_and_never_beat_the_optimum(instance: tuple[Grid, list, list]) -> None:
    grid, starts, goals = instance
    result = prioritized(grid, starts, goals)
    optimum = brute_force_sum_of_costs(grid, starts, goals)
    if result.solved:
        assert_valid_plan(grid, result, starts, goals)
        assert optimum is not None and result.sum_of_costs() >= optimum
    elif result.status == "infeasible":
        assert optimum is None
    else:
        assert result.status == "failed"
        assert result.failed_robot in {str(i) for i in range(len(starts))}


def test_pp_horizon_too_short_fails_with_a_message() -> None:
    grid = Grid(1, 6)
    result = prioritized(grid, [(0, 0)], [(0, 5)], max_time=3)
    assert result.status == "failed" and result.failed_robot == "0"
    assert "horizon" in result.message
    assert prioritized(grid, [(0, 0)], [(0, 5)], max_time=5).solved


def test_pp_time_limit() -> None:
    grid = Grid(20, 20)
    starts = [(0, y) for y in range(20)]
    goals = [(19, 19 - y) for y in range(20)]
    result = prioritized(grid, starts, goals, time_limit_s=0.0)
    assert result.status == "limit"
    assert "time limit" in result.message


def test_pp_reports_proved_infeasibility() -> None:
    assert prioritized(Grid.from_rows([".@."]), [(0, 0)], [(0, 2)]).status == "infeasible"
    result = prioritized(Grid(1, 2), [(0, 0), (0, 1)], [(0, 1), (0, 0)])
    assert result.status == "infeasible" and result.failed_robot is None and "cannot move" in result.message


def test_priority_orders() -> None:
    problem = as_problem(Grid(1, 6), [(0, 0), (0, 1), (0, 2)], [(0, 1), (0, 5), (0, 3)])
    assert priority_order(problem) == [0, 1, 2]
    assert priority_order(problem, "longest_first") == [1, 0, 2]
    assert priority_order(problem, ["2", "0", "1"]) == [2, 0, 1]
    with pytest.raises(InputError, match="unknown priority order"):
        priority_order(problem, "random")
    with pytest.raises(InputError, match="once"):
        priority_order(problem, ["0", "0", "1"])


def test_pp_heading_aware_respects_the_turn_model() -> None:
    grid = Grid.from_rows(["....", ".@..", "...."])
    starts, goals = [(0, 0), (2, 3), (0, 3)], [(2, 3), (0, 0), (2, 0)]
    facing = [Heading.NORTH, Heading.SOUTH, Heading.WEST]
    result = prioritized(as_problem(grid, starts, goals, headings=facing), heading_aware=True)
    assert_valid_plan(grid, result, starts, goals)
    replay_headings(grid, result, facing)


def test_pp_is_registered_and_deterministic() -> None:
    assert PLANNERS["pp"] is prioritized
    grid = Grid.from_rows(["....", ".@..", "...."])
    starts, goals = [(0, 0), (2, 3), (0, 3)], [(2, 3), (0, 0), (2, 0)]
    assert prioritized(grid, starts, goals).paths == prioritized(grid, starts, goals).paths
