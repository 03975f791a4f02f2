"""PlanningResult, padding, plan size and input checking."""

from __future__ import annotations

import pytest

from mrmp.centralized.plan import (
    BYTES_PER_CELL,
    PlanningResult,
    as_problem,
    pad_headings,
    pad_paths,
    path_cost,
    plan_size_bytes,
)
from mrmp.core.errors import InputError
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.result import RobotResult
from mrmp.core.scenario import RobotSpec, Scenario


def test_costs_follow_the_standard_definition() -> None:
    # a robot that passes its goal and comes back costs its final arrival
    paths = pad_paths([[(0, 0), (0, 1), (0, 2), (0, 1), (0, 2)], [(1, 0), (1, 1)], [(2, 2)]])
    result = PlanningResult("solved", paths, 0.0, "cbs")
    assert result.costs() == (4, 1, 0)
    assert result.sum_of_costs() == 5 and result.makespan() == 4
    # the same definition as the simulator's RobotResult
    for path in paths:
        assert path_cost(path) == RobotResult("r", path[0], path[-1], path=list(path)).cost


def test_pad_paths_and_headings() -> None:
    assert pad_paths([[(0, 0)], [(1, 1), (1, 2), (1, 3)]]) == (((0, 0),) * 3, ((1, 1), (1, 2), (1, 3)))
    with pytest.raises(ValueError):
        pad_paths([[]])
    assert pad_headings([[Heading.EAST], [Heading.NORTH, Heading.EAST]])[0] == (Heading.EAST, Heading.EAST)


def test_unsolved_results_have_no_costs() -> None:
    result = PlanningResult("limit", None, 0.5, "cbs", nodes=50, message="node limit of 50 reached")
    assert not result.solved
    with pytest.raises(ValueError):
        result.sum_of_costs()
    assert plan_size_bytes(result) == 0


def test_status_is_checked() -> None:
    with pytest.raises(ValueError, match="status"):
        PlanningResult("done", None, 0.0, "cbs")
    with pytest.raises(ValueError, match="paths"):
        PlanningResult("solved", None, 0.0, "cbs")


def test_plan_size_counts_every_cell_of_every_robot() -> None:
    paths = pad_paths([[(0, 0), (0, 1), (0, 2)], [(1, 0)]])
    assert plan_size_bytes(PlanningResult("solved", paths, 0.0, "pp")) == 2 * 3 * BYTES_PER_CELL
    headings = ((Heading.EAST,) * 3, (Heading.NORTH,) * 3)
    assert plan_size_bytes(PlanningResult("solved", paths, 0.0, "pp", headings=headings)) == 2 * 3 * 9


def test_as_problem_from_scenario_and_errors() -> None:
    grid = Grid.from_rows(["..@", "..."])
    scenario = Scenario(grid, (RobotSpec("x", (0, 0), (1, 1), Heading.EAST), RobotSpec("y", (0, 1), (0, 2))))
    problem = as_problem(scenario)
    assert problem.ids == ("x", "y") and problem.headings == (Heading.EAST, Heading.NORTH)
    assert as_problem(problem) is problem
    with pytest.raises(InputError, match="obstacle"):
        as_problem(grid, [(1, 2)], [(0, 0)])
    with pytest.raises(InputError, match="outside"):
        as_problem(grid, [(0, 0)], [(5, 5)])
    with pytest.raises(InputError, match="2 goals for 1 starts"):
        as_problem(grid, [(0, 0)], [(0, 1), (1, 1)])
    with pytest.raises(InputError, match="starts and goals"):
        as_problem(grid)
    with pytest.raises(InputError, match="distinct robot ids"):
        as_problem(grid, [(0, 0), (0, 1)], [(1, 0), (1, 1)], ids=["a", "a"])
