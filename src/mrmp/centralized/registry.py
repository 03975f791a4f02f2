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

_HEADING_AWARE: dict[str, Callable[..., PlanningResult]] = {"cbs": cbs, "pp": prioritized}
PLANNER_NAMES: tuple[str, ...] = ("cbs", "pp", "lacam")
"""Every name ``--planner`` accepts: Conflict-Based Search, prioritized planning, LaCAM."""


def plan_with(name: str, scenario: Scenario, time_limit_s: float) -> PlanningResult:
    """Plan ``scenario`` with the planner ``name`` (heading-aware when the scenario's policy asks for it).

    Raises
    ------
    KeyError
        If ``name`` is not in :data:`PLANNER_NAMES`.
    """
    if name == "lacam":
        return lacam(scenario, time_limit_s=time_limit_s, seed=scenario.seed)
    return _HEADING_AWARE[name](scenario, time_limit_s=time_limit_s, heading_aware=scenario.policy.heading_aware)
