"""The one table of central planners, by name, with one call shape.

Examples
--------
>>> PLANNER_NAMES
('cbs', 'pp', 'lacam')
>>> from mrmp.core import Grid, RobotSpec, Scenario
>>> swap = Scenario(Grid(3, 3), (RobotSpec("A", (1, 0), (1, 2)), RobotSpec("B", (1, 2), (1, 0))))
>>> plan_with("cbs", swap, time_limit_s=5).sum_of_costs()
6
"""

from __future__ import annotations

from collections.abc import Callable

from mrmp.centralized.cbs import cbs
from mrmp.centralized.lacam import lacam
from mrmp.centralized.plan import PlanningResult
from mrmp.centralized.prioritized import prioritized
from mrmp.core.scenario import Scenario
from mrmp.core.seeds import Stream, derive_seed

PLANNERS: dict[str, Callable[..., PlanningResult]] = {"cbs": cbs, "pp": prioritized, "lacam": lacam}
"""Central planners by name: Conflict-Based Search, prioritized planning, LaCAM. Each is called as
``planner(scenario)`` or ``planner(grid, starts, goals)`` with keyword options."""
PLANNER_NAMES: tuple[str, ...] = tuple(PLANNERS)
"""Every name ``--planner`` accepts."""
_HEADING_AWARE = ("cbs", "pp")


def plan_with(name: str, scenario: Scenario, time_limit_s: float) -> PlanningResult:
    """Plan ``scenario`` with the planner ``name``, for its policy's body (heading-aware when the policy asks for it).

    Raises
    ------
    KeyError
        If ``name`` is not in :data:`PLANNER_NAMES`.
    ValueError
        If the planner does not plan for the scenario's body (every one plans
        for ``omni`` and ``turning``).
    """
    planner = PLANNERS[name]
    body = scenario.policy.body
    if name in _HEADING_AWARE:
        return planner(scenario, time_limit_s=time_limit_s, heading_aware=scenario.policy.heading_aware, body=body)
    return planner(scenario, time_limit_s=time_limit_s, seed=derive_seed(scenario.seed, Stream.PLANNER), body=body)
