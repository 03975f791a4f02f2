"""Central plans on disk: what a planner hands to the fleet.

A plan file is a JSON object ``{"format": 1, "planner": ..., "status": ...,
"planning_time_s": ..., "robots": [{"id": ..., "path": [[x, y], ...]}, ...]}``,
robots in scenario order. Each robot of a live fleet reads its own path from it
(and computes the dependencies it must wait for from the others' paths).

Examples
--------
>>> import tempfile, pathlib
>>> from mrmp.centralized.plan import PlanningResult
>>> plan = PlanningResult("solved", (((0, 0), (0, 1)), ((1, 1), (1, 1))), 0.25, "cbs")
>>> path = pathlib.Path(tempfile.mkdtemp()) / "plan.json"
>>> write_plan(path, plan, ["A", "B"])
>>> read_plan(path, ["A", "B"]).paths
(((0, 0), (0, 1)), ((1, 1), (1, 1)))
"""

from __future__ import annotations

import json
from collections.abc import Sequence

from mrmp.centralized.plan import PlanningResult
from mrmp.core.errors import InputError, Problem
from mrmp.io._files import PathLike, atomic_write_text, read_text


def write_plan(path: PathLike, plan: PlanningResult, robot_ids: Sequence[str]) -> None:
    """Write a solved plan, atomically.

    Raises
    ------
    ValueError
        If the plan has no paths.
    """
    if plan.paths is None:
        raise ValueError(f"{plan.planner} found no plan to write ({plan.status})")
    data = {
        "format": 1,
        "planner": plan.planner,
        "status": plan.status,
        "planning_time_s": plan.planning_time_s,
        "robots": [{"id": robot, "path": [list(cell) for cell in cells]} for robot, cells in zip(robot_ids, plan.paths)],
    }
    atomic_write_text(path, json.dumps(data) + "\n")


def read_plan(path: PathLike, robot_ids: Sequence[str]) -> PlanningResult:
    """Read a plan for the robots ``robot_ids`` (the scenario's, in order).

    Raises
    ------
    InputError
        If the file is not a plan for exactly these robots (naming the file and the problem).
    """
    where = str(path)
    try:
        data = json.loads(read_text(path))
        robots = data["robots"]
        ids = [str(robot["id"]) for robot in robots]
        paths = tuple(tuple((int(cell[0]), int(cell[1])) for cell in robot["path"]) for robot in robots)
        planner, seconds = str(data["planner"]), float(data["planning_time_s"])
    except (ValueError, KeyError, TypeError, IndexError) as error:
        raise InputError(Problem(where, f"not a plan file: {error}")) from None
    if ids != list(robot_ids):
        raise InputError(Problem(where, f"the plan is for robots {ids}, the scenario has {list(robot_ids)}"))
    if any(not path for path in paths) or len({len(path) for path in paths}) > 1:
        raise InputError(Problem(where, "every robot's path must be non-empty and of the same length"))
    return PlanningResult("solved", paths, seconds, planner)
