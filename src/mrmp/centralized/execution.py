"""Executing a central plan with the fleet: one plan-following policy per robot.

The plan's Action Dependency Graph (:mod:`mrmp.centralized.dependencies`,
Hönig et al., RA-L 2019) is cut into each robot's share: its own moves and the
progress of others each move waits for. Every robot then runs
:class:`~mrmp.policies.plan_following.PlanFollowingPolicy` in the simulator or
live, learning its peers' progress only from their messages.

Examples
--------
>>> from mrmp.core import Grid, RobotSpec, Scenario
>>> from mrmp.centralized.plan import PlanningResult, pad_paths
>>> scenario = Scenario(Grid(1, 3), (RobotSpec("A", (0, 0), (0, 1)), RobotSpec("B", (0, 1), (0, 2))))
>>> plan = PlanningResult("solved", pad_paths([[(0, 0), (0, 1)], [(0, 1), (0, 2)]]), 0.0, "hand")
>>> result = execute_in_simulator(scenario, plan)
>>> result.success, [robot.path for robot in result.robots]
(True, [[(0, 0), (0, 0), (0, 1)], [(0, 1), (0, 2), (0, 2)]])
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from mrmp.centralized.dependencies import action_dependencies
from mrmp.centralized.plan import PlanningResult
from mrmp.core.errors import MrmpError
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.policies.plan_following import PlanFollowingPolicy
from mrmp.sim.simulator import simulate


def plan_policies(plan: PlanningResult) -> list[PlanFollowingPolicy]:
    """One plan-following policy per robot, in scenario order.

    Raises
    ------
    MrmpError
        If the plan has no paths (it was not solved).
    """
    if plan.paths is None:
        raise MrmpError(f"{plan.planner}: no plan to execute ({plan.status}: {plan.message})")
    moves, dependencies = action_dependencies(plan.paths)
    return [PlanFollowingPolicy(robot_moves, needs) for robot_moves, needs in zip(moves, dependencies)]


def distributed_bytes(policies: Sequence[PlanFollowingPolicy]) -> int:
    """What the fleet receives: per robot, 8 bytes per move (two 32-bit coordinates) and
    12 per dependency (move, robot, progress as 32-bit integers).

    >>> distributed_bytes([PlanFollowingPolicy([(0, 1), (0, 2)], {1: [(1, 1)]})])
    28
    """
    return sum(
        8 * len(policy.moves) + 12 * sum(len(needs) for needs in policy.dependencies.values()) for policy in policies
    )


def execute_in_simulator(scenario: Scenario, plan: PlanningResult) -> RunResult:
    """Run the fleet following ``plan`` in the lockstep simulator (with the scenario's network faults)."""
    policies = plan_policies(plan)
    size = distributed_bytes(policies)
    result = simulate(scenario, policies=policies)
    return replace(result, planning_time_s=plan.planning_time_s, plan_bytes=size, policy=plan.planner)
