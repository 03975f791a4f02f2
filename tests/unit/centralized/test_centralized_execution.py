"""Executing central plans through the Action Dependency Graph, under loss and delay."""

import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.centralized.dependencies import action_dependencies
from mrmp.centralized.execution import plan_policies
from mrmp.centralized.plan import PlanningResult, pad_paths
from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.experiments.execution import execute_in_simulator
from mrmp.sim.referee import check_paths
from mrmp.sim.simulator import simulate


def visit_order(paths):
    """For every cell, the robots that enter it, in order (consecutive repeats merged)."""
    order = {}
    length = max(len(path) for path in paths)
    for tick in range(length):
        for robot, path in enumerate(paths):
            cell = path[min(tick, len(path) - 1)]
            sequence = order.setdefault(cell, [])
            if (not sequence or sequence[-1] != robot) and (tick == 0 or path[min(tick - 1, len(path) - 1)] != cell):
                sequence.append(robot)
    return order


@st.composite
def solved_instances(draw):
    """A random scenario and a collision-free plan for it (from a guarded simulator run that succeeded)."""
    rng = random.Random(draw(st.integers(0, 10**6)))
    x_size, y_size = draw(st.integers(3, 7)), draw(st.integers(3, 7))
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    count = draw(st.integers(2, 6))
    starts, goals = rng.sample(cells, count), rng.sample(cells, count)
    robots = tuple(RobotSpec(f"r{i}", s, g) for i, (s, g) in enumerate(zip(starts, goals)))
    scenario = Scenario(Grid(x_size, y_size), robots, policy=PolicyOptions(name="astar"))
    run = simulate(scenario)
    return scenario, run


@settings(max_examples=60, derandomize=True, deadline=None)
@given(solved_instances(), st.sampled_from([
    NetworkFaults(),
    NetworkFaults(loss=0.3, delay_min=0, delay_max=3, duplicate=0.2, reorder=0.3),
]), st.integers(0, 100))
def test_plans_execute_without_collision_in_the_planned_order(instance, faults, seed):
    scenario, run = instance
    if not run.success:
        return  # only collision-free, complete plans are plans
    plan = PlanningResult("solved", pad_paths([robot.path for robot in run.robots]), 0.0, "replay")
    for guarded in (True, False):
        result = execute_in_simulator(scenario.with_changes(network=faults, seed=seed, safety=guarded), plan)
        assert result.collisions == [] and result.success, result.stop_reason
        executed = [robot.path for robot in result.robots]
        assert visit_order(executed) == visit_order(plan.paths)  # every cell is visited in the plan's order
        assert result.planning_time_s == 0.0 and result.plan_bytes > 0


def test_dependencies_point_backwards_in_time_and_refuse_colliding_plans():
    paths = [
        [(0, 0), (0, 1), (0, 2), (0, 2)],
        [(0, 1), (0, 2), (0, 3), (0, 3)],
        [(1, 1), (1, 1), (1, 1), (0, 1)],
    ]
    assert check_paths(Grid(2, 4), {str(i): p for i, p in enumerate(paths)}) == []
    moves, needs = action_dependencies(paths)
    assert moves[2] == [(0, 1)]
    assert needs[0] == {0: [(1, 1)], 1: [(1, 2)]}
    assert needs[2] == {0: [(0, 2), (1, 1)]}  # robot 2 enters (0, 1) after robots 0 and 1 have left it
    with pytest.raises(ValueError, match="never leaves"):
        action_dependencies([[(0, 0), (0, 1)], [(0, 1), (0, 1)]])


def test_unsolved_plan_cannot_be_executed():
    from mrmp.core.errors import MrmpError

    with pytest.raises(MrmpError, match="no plan to execute"):
        plan_policies(PlanningResult("limit", None, 0.1, "cbs", message="node limit 50 reached"))


def test_execution_with_total_loss_waits_rather_than_collides():
    scenario = Scenario(Grid(1, 4), (RobotSpec("A", (0, 0), (0, 2)), RobotSpec("B", (0, 1), (0, 3))))
    plan = PlanningResult("solved", pad_paths([[(0, 0), (0, 1), (0, 2)], [(0, 1), (0, 2), (0, 3)]]), 0.0, "hand")
    result = execute_in_simulator(scenario.with_changes(network=NetworkFaults(loss=1.0), safety=False), plan)
    assert result.collisions == [] and not result.success
    assert result.robots[0].path[-1] == (0, 0)  # A never hears that B left (0, 1), so it never enters it
    assert check_paths(scenario.grid, {r.id: r.path for r in result.robots}) == []
