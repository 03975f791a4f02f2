"""A central plan cut into the fleet's shares: one plan-following policy per robot.

The plan's Action Dependency Graph (:mod:`mrmp.centralized.dependencies`,
Hönig et al., RA-L 2019) is cut into each robot's share: its own moves and the
progress of others each move waits for. Every robot then runs
:class:`~mrmp.policies.plan_following.PlanFollowingPolicy` in the simulator
(:mod:`mrmp.experiments.execution`) or live, learning its peers' progress only
from their messages.

Examples
--------
>>> from mrmp.centralized.plan import PlanningResult, pad_paths
>>> plan = PlanningResult("solved", pad_paths([[(0, 0), (0, 1)], [(0, 1), (0, 2)]]), 0.0, "hand")
>>> [policy.moves for policy in plan_policies(plan)]
[[(0, 1)], [(0, 2)]]
"""

from __future__ import annotations

from collections.abc import Sequence

from mrmp.centralized.dependencies import action_dependencies, action_dependents, plan_moves
from mrmp.centralized.plan import PlanningResult
from mrmp.core.errors import MrmpError
from mrmp.policies.plan_following import PlanFollowingPolicy


def plan_policies(plan: PlanningResult, *, following: bool = False, scheduled: bool = False) -> list[PlanFollowingPolicy]:
    """One plan-following policy per robot, in scenario order.

    ``following``: robots guarded by the safety layer's lockstep rule, or
    live bodies followed while they drive, may make a move that follows
    another robot's in the same tick as that one
    (:func:`~mrmp.centralized.dependencies.action_dependencies`).
    ``scheduled``: each move waits for its planned tick too (drivers whose
    time is counted in the plan's ticks: the lockstep simulator).

    Raises
    ------
    MrmpError
        If the plan has no paths (it was not solved).
    """
    if plan.paths is None:
        raise MrmpError(f"{plan.planner}: no plan to execute ({plan.status}: {plan.message})")
    moves, dependencies = action_dependencies(plan.paths, following=following)
    schedules = [plan_moves(path)[1] if scheduled else None for path in plan.paths]
    return [
        PlanFollowingPolicy(robot_moves, needs, waiting, not_before=schedule)
        for robot_moves, needs, waiting, schedule in zip(moves, dependencies, action_dependents(dependencies), schedules)
    ]


def distributed_bytes(policies: Sequence[PlanFollowingPolicy]) -> int:
    """What the fleet receives: per robot, 8 bytes per move (two 32-bit coordinates) and
    12 per dependency (move, robot, progress as 32-bit integers).

    >>> distributed_bytes([PlanFollowingPolicy([(0, 1), (0, 2)], {1: [(1, 1)]})])
    28
    """
    return sum(
        8 * len(policy.moves) + 12 * sum(len(needs) for needs in policy.dependencies.values()) for policy in policies
    )
