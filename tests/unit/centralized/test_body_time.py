"""The execution bound of a plan: its action dependency graph timed with live bodies' moves."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import pytest

from mrmp.centralized.body_time import execution_seconds
from mrmp.centralized.dependencies import PlanDeadlockError
from mrmp.centralized.registry import plan_with
from mrmp.core import Timing
from mrmp.core.heading import Heading, right_turns
from mrmp.io import load_movingai_scenario

MAPS = Path(__file__).resolve().parents[3] / "maps"
NO_TURNS = Timing(cell_time=1.0, turn_time=0.0)


@pytest.mark.parametrize("robots", [1, 2, 5])
def test_a_train_of_robots_moving_together_is_driven_one_robot_after_the_other(robots):
    """Robots in a row each move one cell north at tick 1: each starts when the one ahead has arrived."""
    paths = [[(robots - index, 0), (robots - index + 1, 0)] for index in range(robots)]
    assert execution_seconds(paths, [Heading.NORTH] * robots, NO_TURNS) == robots


def test_a_move_waits_for_the_robot_that_left_its_cell_earlier_not_for_the_plan_s_ticks():
    """Robot 1 waits three ticks in the plan for robot 0 to leave (0, 1); its body need not."""
    paths = [[(0, 1), (1, 1), (1, 1), (1, 1)], [(0, 0), (0, 0), (0, 0), (0, 1)]]
    assert execution_seconds(paths, [Heading.NORTH, Heading.EAST], NO_TURNS) == 2.0


def test_turns_are_right_turns_and_time_scales_divide():
    paths = [[(1, 1), (0, 1), (0, 0)]]  # south, then west
    timing = Timing(cell_time=1.0, turn_time=0.5)
    turns = right_turns(Heading.NORTH, Heading.SOUTH) + right_turns(Heading.SOUTH, Heading.WEST)
    assert execution_seconds(paths, [Heading.NORTH], timing) == 2 + 0.5 * turns
    assert execution_seconds(paths, [Heading.NORTH], timing, time_scale=4.0) == (2 + 0.5 * turns) / 4


def test_a_rotation_has_no_execution():
    paths = [[(0, 0), (0, 1)], [(0, 1), (1, 1)], [(1, 1), (1, 0)], [(1, 0), (0, 0)]]
    with pytest.raises(PlanDeadlockError):
        execution_seconds(paths, [Heading.NORTH] * 4, NO_TURNS)


def test_a_lacam_plan_takes_at_least_each_robot_s_own_drive_and_turns_never_shorten_it():
    scenario = load_movingai_scenario(MAPS / "random-32-32-20.map", MAPS / "random-32-32-20-random-1.scen", 30)
    plan = plan_with("lacam", scenario, time_limit_s=30)
    assert plan.paths is not None
    headings = [robot.heading for robot in scenario.robots]
    without_turns = execution_seconds(plan.paths, headings, NO_TURNS)
    with_turns = execution_seconds(plan.paths, headings, Timing(cell_time=1.0, turn_time=0.5))
    longest_drive = max(sum(1 for a, b in pairwise(path) if a != b) for path in plan.paths)
    assert without_turns >= longest_drive
    assert with_turns > without_turns
