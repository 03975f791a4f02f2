"""Central plans on disk: what a planner hands to the fleet.

* A *plan file* is the whole plan, for the record: ``{"format": 1, "planner": ...,
  "status": ..., "planning_time_s": ..., "robots": [{"id": ..., "path": [[x, y],
  ...]}, ...]}``, robots in scenario order.
* A *share* is what one robot receives: ``{"format": 1, "robot": id, "moves":
  [[x, y], ...], "dependencies": [[move, robot index, progress], ...]}``, its own
  moves and, for each, the progress of other robots it must wait for
  (:mod:`mrmp.centralized.dependencies`); optionally ``"dependents": [[completed
  moves, robot index, move], ...]``, the moves of others that wait for its
  progress (whom its states must reach).

Plans are written from anything shaped like a planner's answer (:class:`Plan`:
a :class:`mrmp.centralized.plan.PlanningResult` is one) and read back as a
:class:`PlanFile`, so that this module needs nothing from the planners.

Examples
--------
>>> import tempfile, pathlib
>>> plan = PlanFile("solved", (((0, 0), (0, 1)), ((1, 1), (1, 1))), 0.25, "cbs")
>>> path = pathlib.Path(tempfile.mkdtemp()) / "plan.json"
>>> write_plan(path, plan, ["A", "B"])
>>> read_plan(path, ["A", "B"]).paths
(((0, 0), (0, 1)), ((1, 1), (1, 1)))
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

from mrmp.core.cell import Cell
from mrmp.core.errors import InputError, Problem
from mrmp.io._files import PathLike, atomic_write_text, read_text

Paths = Sequence[Sequence[Cell]]
"""One path per robot, one cell per tick."""


class Plan(Protocol):
    """What :func:`write_plan` needs of a plan (a planner's answer)."""

    @property
    def status(self) -> str: ...

    @property
    def paths(self) -> Paths | None: ...

    @property
    def planning_time_s(self) -> float: ...

    @property
    def planner(self) -> str: ...


@dataclass(frozen=True)
class PlanFile:
    """A plan as a plan file holds it: always solved, with every robot's path."""

    status: str
    paths: tuple[tuple[Cell, ...], ...]
    planning_time_s: float
    planner: str


def write_plan(path: PathLike, plan: Plan, robot_ids: Sequence[str]) -> None:
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


def read_plan(path: PathLike, robot_ids: Sequence[str]) -> PlanFile:
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
    except (ValueError, KeyError, TypeError, IndexError, RecursionError) as error:
        raise InputError(Problem(where, f"not a plan file: {error}")) from None
    if ids != list(robot_ids):
        raise InputError(Problem(where, f"the plan is for robots {ids}, the scenario has {list(robot_ids)}"))
    if any(not path for path in paths) or len({len(path) for path in paths}) > 1:
        raise InputError(Problem(where, "every robot's path must be non-empty and of the same length"))
    return PlanFile("solved", paths, seconds, planner)


def _rows(table: Mapping[int, Sequence[tuple[int, int]]]) -> list[list[int]]:
    return [[key, robot, value] for key, pairs in sorted(table.items()) for robot, value in pairs]


def _table(rows: object) -> dict[int, list[tuple[int, int]]]:
    table: dict[int, list[tuple[int, int]]] = {}
    for key, robot, value in rows:  # type: ignore[attr-defined]
        table.setdefault(int(key), []).append((int(robot), int(value)))
    return table


def write_share(
    path: PathLike,
    robot_id: str,
    moves: Sequence[Cell],
    dependencies: Mapping[int, Sequence[tuple[int, int]]],
    dependents: Mapping[int, Sequence[tuple[int, int]]] | None = None,
) -> None:
    """Write one robot's share of a plan, atomically (with its dependents, when given).

    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "plan-A.json"
    >>> write_share(path, "A", [(0, 1), (0, 2)], {1: [(1, 1)]})
    >>> read_share(path, "A"), read_share_dependents(path, "A")
    (([(0, 1), (0, 2)], {1: [(1, 1)]}), None)
    >>> write_share(path, "A", [(0, 1), (0, 2)], {1: [(1, 1)]}, dependents={2: [(1, 0)]})
    >>> read_share_dependents(path, "A")
    {2: [(1, 0)]}
    """
    data: dict[str, object] = {
        "format": 1,
        "robot": robot_id,
        "moves": [list(cell) for cell in moves],
        "dependencies": _rows(dependencies),
    }
    if dependents is not None:
        data["dependents"] = _rows(dependents)
    atomic_write_text(path, json.dumps(data) + "\n")


def read_share(path: PathLike, robot_id: str) -> tuple[list[Cell], dict[int, list[tuple[int, int]]]]:
    """Read the share of robot ``robot_id``: its moves and its dependencies.

    Raises
    ------
    InputError
        If the file is not a share, or is another robot's (naming the file).
    """
    where = str(path)
    try:
        data = json.loads(read_text(path))
        owner = str(data["robot"])
        moves = [(int(cell[0]), int(cell[1])) for cell in data["moves"]]
        dependencies = _table(data["dependencies"])
    except (ValueError, KeyError, TypeError, IndexError, RecursionError) as error:
        raise InputError(Problem(where, f"not a robot's share of a plan: {error}")) from None
    if owner != robot_id:
        raise InputError(Problem(where, f"this share belongs to robot {owner!r}, not {robot_id!r}"))
    return moves, dependencies


def read_share_dependents(path: PathLike, robot_id: str) -> dict[int, list[tuple[int, int]]] | None:
    """The dependents of robot ``robot_id``'s share (None when the share does not list them).

    Raises
    ------
    InputError
        If the file is not a share, is another robot's, or its dependents are malformed (naming the file).
    """
    read_share(path, robot_id)
    try:
        rows = json.loads(read_text(path)).get("dependents")
        return None if rows is None else _table(rows)
    except (ValueError, KeyError, TypeError, IndexError, AttributeError, RecursionError) as error:
        raise InputError(Problem(str(path), f"not a robot's share of a plan: dependents: {error}")) from None
