"""Executing a central plan with the fleet in the lockstep simulator.

Each robot follows its share of the plan (:func:`mrmp.centralized.execution.plan_policies`:
its own moves and the progress of others each move waits for, from the plan's
Action Dependency Graph, Hönig et al., RA-L 2019), learning its peers' progress
only from their messages, under the scenario's network faults. Guarded robots
make a move that follows another's in the same tick as that one (the safety
layer's lockstep rule), and no move before its planned tick: on a perfect
network the executed paths are the planned paths; late messages only delay.

Examples
--------
>>> from mrmp.core import Grid, RobotSpec, Scenario
>>> from mrmp.centralized.plan import PlanningResult, pad_paths
>>> scenario = Scenario(Grid(1, 3), (RobotSpec("A", (0, 0), (0, 1)), RobotSpec("B", (0, 1), (0, 2))))
>>> plan = PlanningResult("solved", pad_paths([[(0, 0), (0, 1)], [(0, 1), (0, 2)]]), 0.0, "hand")
>>> result = execute_in_simulator(scenario, plan)
>>> result.success, [robot.path for robot in result.robots]   # A follows B in the same tick, as planned
(True, [[(0, 0), (0, 1)], [(0, 1), (0, 2)]])
"""

from __future__ import annotations

from dataclasses import replace

from mrmp.centralized.execution import distributed_bytes, plan_policies
from mrmp.centralized.plan import PlanningResult
from mrmp.core.limits import MAX_TICKS
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.sim.metrics import default_max_ticks, network_slowdown, shortest_steps
from mrmp.sim.simulator import TickObserver, simulate

__all__ = ["execute_in_simulator", "execution_max_ticks"]


def execution_max_ticks(scenario: Scenario, plan: PlanningResult) -> int:
    """The tick limit of a plan's execution when the scenario sets none.

    Following robots wait for each other's progress messages, so an execution
    takes longer than its plan (a crowded 34-tick plan took 127 ticks with the
    safety layer on): ``64 + 8 * plan length``, times the network's slowdown of a
    claim's round trip (:func:`~mrmp.sim.metrics.network_slowdown`) when guarded,
    and never less than the simulator's own default (nor more than
    :data:`~mrmp.core.limits.MAX_TICKS`).

    >>> from mrmp.core import Grid, RobotSpec, Scenario
    >>> from mrmp.centralized.plan import PlanningResult
    >>> scenario = Scenario(Grid(1, 3), (RobotSpec("A", (0, 0), (0, 2)),))
    >>> execution_max_ticks(scenario, PlanningResult("solved", [[(0, 0), (0, 1), (0, 2)]], 0.0, "hand"))
    80
    """
    length = max((len(path) - 1 for path in plan.paths or ()), default=0)
    ticks = 64 + 8 * length
    if scenario.safety:
        ticks = int(ticks * network_slowdown(scenario))
    return min(max(ticks, default_max_ticks(scenario, shortest_steps(scenario))), MAX_TICKS)


def execute_in_simulator(
    scenario: Scenario,
    plan: PlanningResult,
    *,
    record_messages: bool = False,
    on_tick: TickObserver | None = None,
) -> RunResult:
    """Run the fleet following ``plan`` in the lockstep simulator (with the scenario's network faults).

    ``record_messages`` and ``on_tick`` are passed to :func:`~mrmp.sim.simulator.simulate`.
    """
    policies = plan_policies(plan, following=scenario.safety, scheduled=True)
    size = distributed_bytes(policies)
    if scenario.max_ticks is None:
        scenario = scenario.with_changes(max_ticks=execution_max_ticks(scenario, plan))
    result = simulate(scenario, policies=policies, record_messages=record_messages, on_tick=on_tick)
    return replace(
        result,
        planning_time_s=plan.planning_time_s,
        plan_bytes=size,
        policy=plan.planner,
        plan_sum_of_costs=plan.sum_of_costs(),
        plan_makespan=plan.makespan(),
    )
