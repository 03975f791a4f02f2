"""Run results as JSON: plain dictionaries, atomic files, and the way back to a :class:`RunResult`.

A saved run holds the per-robot trajectories, so it can be re-animated or
re-scored later without running again; with a grid it also holds the map.

Examples
--------
>>> from mrmp.core.result import RobotResult, RunResult
>>> robot = RobotResult("A", (0, 0), (0, 1), path=[(0, 0), (0, 1)])
>>> run = RunResult("demo", "thesis", 0, [robot], [], "all_arrived", 1, 1, 0.01)
>>> data = result_to_dict(run)
>>> data["success"], data["makespan"], data["robots"][0]["path"]
(True, 1, [[0, 0], [0, 1]])
>>> result_from_dict(data) == run
True
"""

from __future__ import annotations

import json
import sys
from collections.abc import Mapping
from typing import Any

from mrmp.core.errors import InputError, Problem
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.limits import MAX_RECORD_FILE_BYTES
from mrmp.core.result import Collision, RobotResult, RunResult
from mrmp.io._files import PathLike, atomic_write_text, read_text

FORMAT_VERSION = 1
"""Written as ``format`` in every result file."""


def _robot_to_dict(robot: RobotResult) -> dict[str, Any]:
    """The JSON form of one robot's result (derived metrics included)."""
    return {
        "id": robot.id,
        "start": list(robot.start),
        "goal": list(robot.goal),
        "arrived": robot.arrived,
        "arrival_tick": robot.arrival_tick,
        "cost": robot.cost,
        "steps": robot.steps,
        "turns": robot.turns,
        "waits": robot.waits,
        "messages_sent": robot.messages_sent,
        "bytes_sent": robot.bytes_sent,
        "time_s": robot.time_s,
        "goals_reached": robot.goals_reached,
        "path": [list(cell) for cell in robot.path],
        "headings": [Heading(heading).name for heading in robot.headings],
    }


def _collision_to_dict(collision: Collision) -> dict[str, Any]:
    """The JSON form of one referee finding."""
    return {
        "kind": collision.kind,
        "tick": collision.tick,
        "robots": list(collision.robots),
        "cells": [list(cell) for cell in collision.cells],
    }


def result_to_dict(result: RunResult, grid: Grid | None = None) -> dict[str, Any]:
    """The JSON-ready form of a run: summary metrics, collisions and every robot's trajectory.

    Parameters
    ----------
    result:
        The run.
    grid:
        When given, the map is stored too (``map``: name, sizes and rows,
        northmost row first) so the run can be drawn from the file alone.

    Returns
    -------
    dict
        Keys ``format``, ``scenario``, ``policy``, ``seed``, ``success``,
        ``stop_reason``, ``ticks``, ``makespan``, ``sum_of_costs``,
        ``lower_bound``, ``time_makespan_s``, ``time_sum_of_costs_s``, ``body``, ``messages``, ``network``,
        ``wall_time_s``, ``collisions`` (each ``{kind, tick, robots, cells}``),
        ``robots`` (each ``{id, start, goal, arrived, arrival_tick, cost, steps,
        turns, waits, messages_sent, bytes_sent, time_s, path, headings}``),
        for a run that recorded its messages ``message_log`` (per tick, a
        list of ``[sender, recipient, kind]``) and, with a grid, ``map``.
        Cells are ``[x, y]`` lists, headings names.

    Examples
    --------
    >>> run = RunResult("s", "thesis", 3, [], [Collision("vertex", 2, ("A", "B"), ((1, 1),))], "collision", 2, 0, 0.0)
    >>> result_to_dict(run)["collisions"]
    [{'kind': 'vertex', 'tick': 2, 'robots': ['A', 'B'], 'cells': [[1, 1]]}]
    """
    data: dict[str, Any] = {
        "format": FORMAT_VERSION,
        "scenario": result.scenario,
        "policy": result.policy,
        "seed": result.seed,
        "success": result.success,
        "stop_reason": result.stop_reason,
        "ticks": result.ticks,
        "makespan": result.makespan,
        "sum_of_costs": result.sum_of_costs,
        "lower_bound": result.lower_bound,
        "time_makespan_s": result.time_makespan_s,
        "time_sum_of_costs_s": result.time_sum_of_costs_s,
        "body": result.body,
        "messages": result.messages,
        "network": dict(result.network),
        "wall_time_s": result.wall_time_s,
        "mode": result.mode,
        "tick_seconds": result.tick_seconds,
        "ideal_makespan_s": result.ideal_makespan_s,
        "planning_time_s": result.planning_time_s,
        "plan_bytes": result.plan_bytes,
        "plan_sum_of_costs": result.plan_sum_of_costs,
        "plan_makespan": result.plan_makespan,
        "lifelong": result.lifelong,
        "throughput": result.throughput,
        "collisions": [_collision_to_dict(collision) for collision in result.collisions],
        "robots": [_robot_to_dict(robot) for robot in result.robots],
    }
    if result.message_log is not None:
        data["message_log"] = [[list(entry) for entry in entries] for entries in result.message_log]
    if grid is not None:
        data["map"] = {"name": grid.name, "x_size": grid.x_size, "y_size": grid.y_size, "rows": grid.to_rows()}
    return data


def result_to_json(result: RunResult, grid: Grid | None = None) -> str:
    """The JSON text of :func:`result_to_dict` (indented, ending with a newline).

    >>> run = RunResult("s", "thesis", 0, [], [], "all_arrived", 0, 0, 0.0)
    >>> json.loads(result_to_json(run))["stop_reason"]
    'all_arrived'
    """
    return json.dumps(result_to_dict(result, grid), indent=2) + "\n"


def write_result_json(result: RunResult, path_or_dash: PathLike, grid: Grid | None = None) -> None:
    """Write a run as JSON to a file (atomically) or, for ``"-"``, to standard output.

    The file is written to a temporary file in the same folder and then moved
    over ``path_or_dash``, so an interrupted run never leaves half a file.

    Parameters
    ----------
    result:
        The run.
    path_or_dash:
        The file to create or replace, or ``"-"`` for standard output.
    grid:
        Optionally the map, stored with the run (see :func:`result_to_dict`).

    Raises
    ------
    InputError
        If the file cannot be written.
    """
    text = result_to_json(result, grid)
    if str(path_or_dash) == "-":
        sys.stdout.write(text)
        sys.stdout.flush()
        return
    atomic_write_text(path_or_dash, text)


# -- reading back ----------------------------------------------------------------------


class _Fields:
    """Typed access to a JSON object, raising an :class:`InputError` naming the field."""

    def __init__(self, data: Any, path: str, source: str) -> None:
        if not isinstance(data, Mapping):
            raise InputError(Problem(source, f"{path or 'result'}: expected an object, got {type(data).__name__}"))
        self.data = data
        self.path = path
        self.source = source

    def _fail(self, key: str, expected: str) -> InputError:
        where = f"{self.path}.{key}" if self.path else key
        got = type(self.data[key]).__name__ if key in self.data else "nothing"
        return InputError(Problem(self.source, f"{where}: expected {expected}, got {got}"))

    def get(self, key: str, kind: type | tuple[type, ...], expected: str, default: Any = ...) -> Any:
        """``data[key]`` if it has the right type (bools are not numbers), else raise."""
        if key not in self.data and default is not ...:
            return default
        value = self.data.get(key)
        if isinstance(value, kind) and not (isinstance(value, bool) and bool not in _as_tuple(kind)):
            return value
        raise self._fail(key, expected)

    def cell(self, key: str) -> tuple[int, int]:
        """A cell from ``[x, y]``."""
        return _cell(self.data.get(key), f"{self.path}.{key}" if self.path else key, self.source)


def _as_tuple(kind: type | tuple[type, ...]) -> tuple[type, ...]:
    return kind if isinstance(kind, tuple) else (kind,)


def _cell(value: Any, where: str, source: str) -> tuple[int, int]:
    """A cell from a two-integer list, or raise naming ``where``."""
    if (
        isinstance(value, (list, tuple))
        and len(value) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) for v in value)
    ):
        return (value[0], value[1])
    raise InputError(Problem(source, f"{where}: expected a cell [x, y], got {value!r}"))


def _robot_from_dict(data: Any, path: str, source: str) -> RobotResult:
    """One robot's result from its JSON form (derived metrics are recomputed, not read)."""
    fields = _Fields(data, path, source)
    path_cells = fields.get("path", list, "a list of cells", [])
    headings = fields.get("headings", list, "a list of heading names", [])
    try:
        parsed_headings = [Heading.parse(heading) for heading in headings]
    except ValueError as error:
        raise InputError(Problem(source, f"{path}.headings: {error}")) from None
    return RobotResult(
        id=str(fields.get("id", (str, int), "a string")),
        start=fields.cell("start"),
        goal=fields.cell("goal"),
        path=[_cell(cell, f"{path}.path[{tick}]", source) for tick, cell in enumerate(path_cells)],
        headings=parsed_headings,
        turns=fields.get("turns", int, "an integer", 0),
        messages_sent=fields.get("messages_sent", int, "an integer", 0),
        bytes_sent=fields.get("bytes_sent", int, "an integer", 0),
        time_s=float(fields.get("time_s", (int, float), "a number", 0.0)),
        goals_reached=fields.get("goals_reached", int, "an integer", 0),
    )


def _collision_from_dict(data: Any, path: str, source: str) -> Collision:
    """One referee finding from its JSON form."""
    fields = _Fields(data, path, source)
    robots = fields.get("robots", list, "a list of robot ids")
    cells = fields.get("cells", list, "a list of cells")
    return Collision(
        kind=fields.get("kind", str, "a string"),
        tick=fields.get("tick", int, "an integer"),
        robots=tuple(str(robot) for robot in robots),
        cells=tuple(_cell(cell, f"{path}.cells[{index}]", source) for index, cell in enumerate(cells)),
    )


def result_from_dict(data: Mapping[str, Any], source: str = "result") -> RunResult:
    """Rebuild a :class:`RunResult` from :func:`result_to_dict`'s output (the inverse).

    Derived values (``success``, ``makespan``, a robot's ``cost`` ...) are
    recomputed from the trajectories, not read.

    Parameters
    ----------
    data:
        The dictionary (for example parsed from a result file).
    source:
        Where it came from, used to name problems.

    Returns
    -------
    RunResult
        The run, equal to the one that was saved.

    Raises
    ------
    InputError
        If a field is missing or of the wrong type (the problem names the field).

    Examples
    --------
    >>> result_from_dict({"scenario": "s"}, "run.json")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: run.json: policy: expected a string, got nothing
    """
    fields = _Fields(data, "", source)
    robots = fields.get("robots", list, "a list of robots", [])
    collisions = fields.get("collisions", list, "a list of collisions", [])
    network = fields.get("network", Mapping, "an object", {})
    return RunResult(
        scenario=fields.get("scenario", str, "a string"),
        policy=fields.get("policy", str, "a string"),
        seed=fields.get("seed", int, "an integer", 0),
        robots=[_robot_from_dict(robot, f"robots[{index}]", source) for index, robot in enumerate(robots)],
        collisions=[_collision_from_dict(c, f"collisions[{index}]", source) for index, c in enumerate(collisions)],
        stop_reason=fields.get("stop_reason", str, "a string", ""),
        ticks=fields.get("ticks", int, "an integer", 0),
        lower_bound=fields.get("lower_bound", int, "an integer", 0),
        wall_time_s=float(fields.get("wall_time_s", (int, float), "a number", 0.0)),
        network=dict(network),
        mode=fields.get("mode", str, "a string", "simulated"),
        tick_seconds=_optional_number(fields.get("tick_seconds", (int, float, type(None)), "a number or null", None)),
        ideal_makespan_s=_optional_number(
            fields.get("ideal_makespan_s", (int, float, type(None)), "a number or null", None)
        ),
        planning_time_s=_optional_number(
            fields.get("planning_time_s", (int, float, type(None)), "a number or null", None)
        ),
        plan_bytes=fields.get("plan_bytes", (int, type(None)), "an integer or null", None),
        plan_sum_of_costs=fields.get("plan_sum_of_costs", (int, type(None)), "an integer or null", None),
        plan_makespan=fields.get("plan_makespan", (int, type(None)), "an integer or null", None),
        lifelong=fields.get("lifelong", bool, "true or false", False),
        body=fields.get("body", str, "a string", "omni"),
        message_log=_message_log(fields.get("message_log", (list, type(None)), "a list of ticks or null", None), source),
    )


def _message_log(ticks: list[Any] | None, source: str) -> list[list[tuple[str, str, str]]] | None:
    """A message log from its JSON form: per tick, ``[sender, recipient, kind]`` strings.

    >>> _message_log([[], [["A", "B", "state"]]], "run.json")
    [[], [('A', 'B', 'state')]]
    >>> _message_log([[["A", "B"]]], "run.json")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: run.json: message_log[0][0]: expected [sender, recipient, kind] strings, got ['A', 'B']
    """
    if ticks is None:
        return None
    log: list[list[tuple[str, str, str]]] = []
    for tick, entries in enumerate(ticks):
        if not isinstance(entries, list):
            raise InputError(Problem(source, f"message_log[{tick}]: expected a list of messages, got {type(entries).__name__}"))
        parsed: list[tuple[str, str, str]] = []
        for number, entry in enumerate(entries):
            if not (isinstance(entry, list) and len(entry) == 3 and all(isinstance(part, str) for part in entry)):
                raise InputError(
                    Problem(source, f"message_log[{tick}][{number}]: expected [sender, recipient, kind] strings, got {entry!r}")
                )
            parsed.append((entry[0], entry[1], entry[2]))
        log.append(parsed)
    return log


def _optional_number(value: Any) -> float | None:
    return None if value is None else float(value)


def grid_from_result_dict(data: Mapping[str, Any]) -> Grid | None:
    """The map stored in a result dictionary, or None if it was saved without one.

    >>> grid_from_result_dict({"map": {"name": "m", "rows": [".@", ".."]}}).blocked_cells()
    [(1, 1)]
    """
    stored = data.get("map")
    if not isinstance(stored, Mapping) or not isinstance(stored.get("rows"), list):
        return None
    try:
        return Grid.from_rows([str(row) for row in stored["rows"]], name=str(stored.get("name", "")))
    except ValueError as error:
        raise InputError(Problem("map.rows", str(error))) from None


def read_result_json(path: PathLike) -> tuple[RunResult, Grid | None]:
    """Read a result file written by :func:`write_result_json`.

    Parameters
    ----------
    path:
        The JSON file.

    Returns
    -------
    tuple[RunResult, Grid | None]
        The run and, if it was saved with one, its map.

    Raises
    ------
    InputError
        If the file cannot be read, is not valid JSON (naming the line), or
        does not describe a run.
    """
    source = str(path)
    text = read_text(path, MAX_RECORD_FILE_BYTES)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise InputError(Problem(f"{source}:{error.lineno}", f"invalid JSON: {error.msg}")) from None
    except RecursionError:
        raise InputError(Problem(source, "invalid JSON: nested too deeply")) from None
    if not isinstance(data, Mapping):
        raise InputError(Problem(source, f"expected a JSON object describing a run, got {type(data).__name__}"))
    return result_from_dict(data, source), grid_from_result_dict(data)
