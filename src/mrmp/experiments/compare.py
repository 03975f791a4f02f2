"""One scenario, every way: decentralized policies against central planners.

The thesis (chapter 5) argues that the decentralized approach beats a
centralized one in complexity, speed and synchronization, without measuring it.
:func:`compare_methods` measures it on one scenario: each decentralized policy
runs in the lockstep simulator (guarded by the safety layer); each central
planner plans, and the fleet then executes its plan through the plan's action
dependencies in the same simulator. Each row gives success, makespan, sum of
costs over the lower bound, planning wall time, execution wall time, messages
sent and, for central planners, the size of the plan to distribute (every
robot's share: its moves and the dependencies it waits for).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

from mrmp.centralized.registry import PLANNER_NAMES, plan_with
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.experiments.execution import execute_in_simulator
from mrmp.sim.policy_table import policy_names
from mrmp.sim.simulator import simulate


@dataclass
class ComparisonRow:
    """One method's outcome on the scenario."""

    method: str
    kind: str
    success: bool
    status: str
    makespan: int | None
    sum_of_costs: int | None
    lower_bound: int
    cost_ratio: float | None
    planning_time_s: float | None
    run_time_s: float
    messages: int
    plan_bytes: int | None


def compare_methods(scenario: Scenario, time_limit_s: float = 30.0) -> list[ComparisonRow]:
    """Run every decentralized policy and every central planner (with execution) on ``scenario``.

    Every policy runs with the scenario's policy settings (``resolve``,
    ``heading_aware``, ...), only its name replaced.
    """
    rows: list[ComparisonRow] = []
    for name in policy_names():
        result = simulate(scenario.with_changes(policy=replace(scenario.policy, name=name)))
        rows.append(_row(name, "decentralized", result, result.stop_reason))
    for name in PLANNER_NAMES:
        started = time.perf_counter()
        plan = plan_with(name, scenario, time_limit_s=time_limit_s)
        if not plan.solved:
            rows.append(
                ComparisonRow(name, "centralized", False, plan.status, None, None, 0, None, plan.planning_time_s,
                              time.perf_counter() - started - plan.planning_time_s, 0, None)
            )
            continue
        result = execute_in_simulator(scenario, plan)
        rows.append(_row(name, "centralized", result, result.stop_reason))
    lower_bound = max((row.lower_bound for row in rows), default=0)
    for row in rows:
        row.lower_bound = lower_bound
    return rows


def _row(method: str, kind: str, result: RunResult, status: str) -> ComparisonRow:
    ratio = result.sum_of_costs / result.lower_bound if result.success and result.lower_bound else None
    return ComparisonRow(
        method,
        kind,
        result.success,
        status,
        result.makespan if result.success else None,
        result.sum_of_costs if result.success else None,
        result.lower_bound,
        ratio,
        result.planning_time_s,
        result.wall_time_s,
        result.messages,
        result.plan_bytes,
    )
