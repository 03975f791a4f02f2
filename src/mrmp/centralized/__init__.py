"""Centralized multi-robot planners: one planner computes every robot's whole path.

Unlike mrmp's decentralized robots, which decide tick by tick from what they
hear, a centralized planner sees the whole fleet and returns a complete,
collision-free plan (a :class:`PlanningResult`) before anything moves:

* :func:`cbs` -- Conflict-Based Search (Sharon, Stern, Felner & Sturtevant,
  AIJ 2015): least sum of costs, within node and time limits;
* :func:`prioritized` -- prioritized planning (Erdmann & Lozano-Perez 1987;
  Silver 2005): fast, incomplete, reports the robot it could not plan;
* :func:`space_time_astar` -- the single-robot space-time A* both use
  (Silver 2005), with vertex, edge and parking reservations and an optional
  heading-aware (right-turn) time model.

:func:`lacam` -- LaCAM (Okumura, AAAI 2023): complete, quick, suboptimal.

:data:`~mrmp.centralized.registry.PLANNERS` maps the names ``"cbs"``, ``"pp"``
and ``"lacam"`` to the planners; each is called as ``planner(scenario)`` or
``planner(grid, starts, goals)`` with keyword options. Plans are executed by the
fleet through :mod:`mrmp.centralized.execution` (each robot's share) and
:mod:`mrmp.experiments.execution` (in the simulator).

Examples
--------
>>> from mrmp.core.grid import Grid
>>> from mrmp.sim.referee import check_paths
>>> grid = Grid.from_rows(["....", ".@@.", "...."])
>>> starts, goals = [(0, 0), (2, 3)], [(2, 3), (0, 0)]
>>> results = {name: planner(grid, starts, goals) for name, planner in PLANNERS.items()}
>>> {name: (r.status, r.sum_of_costs()) for name, r in results.items()}
{'cbs': ('solved', 10), 'pp': ('solved', 10), 'lacam': ('solved', 14)}
>>> all(check_paths(grid, dict(zip("AB", r.paths))) == [] for r in results.values())
True
"""

from mrmp.centralized.cbs import (
    Conflict,
    all_conflicts,
    cbs,
    first_conflict,
    infeasibility_proof,
)
from mrmp.centralized.lacam import lacam
from mrmp.centralized.plan import (
    STATUSES,
    MapfProblem,
    PlanningResult,
    as_problem,
    pad_headings,
    pad_paths,
    path_cost,
    plan_size_bytes,
)
from mrmp.centralized.prioritized import prioritized, priority_order
from mrmp.centralized.registry import PLANNER_NAMES, PLANNERS, plan_with
from mrmp.centralized.space_time_astar import (
    Reservations,
    SpaceTimeResult,
    heading_distance_table,
    space_time_astar,
)

__all__ = [
    "PLANNERS",
    "PLANNER_NAMES",
    "STATUSES",
    "Conflict",
    "MapfProblem",
    "PlanningResult",
    "Reservations",
    "SpaceTimeResult",
    "all_conflicts",
    "as_problem",
    "cbs",
    "first_conflict",
    "heading_distance_table",
    "infeasibility_proof",
    "lacam",
    "pad_headings",
    "pad_paths",
    "path_cost",
    "plan_size_bytes",
    "plan_with",
    "prioritized",
    "priority_order",
    "space_time_astar",
]
