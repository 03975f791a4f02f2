"""Executions keep their plans: on a perfect network the fleet's paths are the planned paths.

The robots follow the plan's Action Dependency Graph through their messages and
the safety layer's lockstep rule lets a robot follow another into a cell in
the tick that one leaves it, so nothing delays a move past its planned tick.
Under loss and delay the execution stays collision-free and only gets later.
"""

from pathlib import Path

import pytest

from mrmp.centralized.execution import plan_policies
from mrmp.centralized.registry import plan_with
from mrmp.core import NetworkFaults
from mrmp.experiments.execution import execute_in_simulator, execution_max_ticks
from mrmp.io.scenario_file import load_movingai_scenario
from mrmp.sim.simulator import LockstepSimulator

MAPS = Path(__file__).resolve().parents[3] / "maps"


def instance(map_name, agents):
    return load_movingai_scenario(MAPS / f"{map_name}.map", MAPS / f"{map_name}-random-1.scen", agents)


def settled(path):
    """A path without the waits at its goal after its last move."""
    path = list(path)
    while len(path) > 1 and path[-1] == path[-2]:
        path.pop()
    return path


@pytest.mark.parametrize(
    ("planner", "map_name", "agents"),
    [
        ("cbs", "random-32-32-20", 8),
        ("cbs", "empty-32-32", 10),
        ("pp", "random-32-32-20", 20),
        ("pp", "room-32-32-4", 15),
        ("lacam", "random-32-32-20", 30),
        ("lacam", "random-32-32-20", 100),
        ("lacam", "warehouse-10-20-10-2-1", 40),
    ],
)
@pytest.mark.slow
def test_the_executed_paths_are_the_planned_paths(planner, map_name, agents):
    scenario = instance(map_name, agents)
    plan = plan_with(planner, scenario, time_limit_s=60)
    assert plan.solved, plan.message
    result = execute_in_simulator(scenario, plan)
    assert result.success and result.collisions == []
    assert [settled(robot.path) for robot in result.robots] == [settled(path) for path in plan.paths]
    assert result.sum_of_costs == plan.sum_of_costs() == result.plan_sum_of_costs
    assert result.makespan == plan.makespan() == result.plan_makespan


def test_without_following_the_execution_loses_its_plan():
    """The check above can fail: under the rule of live bodies every following move costs a tick."""
    scenario = instance("random-32-32-20", 30)
    plan = plan_with("lacam", scenario, time_limit_s=60)
    policies = plan_policies(plan, scheduled=True)
    limited = scenario.with_changes(max_ticks=execution_max_ticks(scenario, plan))
    result = LockstepSimulator(limited, policies=policies, following=False).run()
    assert result.success and result.collisions == []
    assert result.sum_of_costs > plan.sum_of_costs()


@pytest.mark.parametrize(
    ("faults", "bound"),
    [
        (NetworkFaults(loss=0.1), 1.2),
        (NetworkFaults(loss=0.1, delay_min=0, delay_max=1, duplicate=0.05, reorder=0.1), 3.5),
    ],
    ids=["loss", "loss-delay"],
)
@pytest.mark.parametrize("seed", range(2))
def test_under_loss_and_delay_the_execution_stays_safe_and_degrades_gracefully(faults, bound, seed):
    """Measured: about 1.05 times the plan's sum of costs with 10% loss, about 2.5 with a tick of delay too."""
    scenario = instance("random-32-32-20", 30)
    plan = plan_with("lacam", scenario, time_limit_s=60)
    result = execute_in_simulator(scenario.with_changes(network=faults, seed=seed), plan)
    assert result.success and result.collisions == []
    assert plan.sum_of_costs() <= result.sum_of_costs <= bound * plan.sum_of_costs()
