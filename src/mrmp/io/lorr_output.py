"""A lifelong run written as the League of Robot Runners writes its runs: the output JSON of the Start-Kit.

The fields are those of the Start-Kit v2.1.0 (the 2024 competition;
``src/CompetitionSystem.cpp``, ``BaseSystem::saveResults``, documented in its
``Input_Output_Format.md``), so that the competition's tools (its PlanViz
visualizer, scripts reading ``numTaskFinished``) read mrmp's runs:

* ``actionModel`` (``"MAPF_T"``), ``version``, ``teamSize``;
* ``start``: every robot's ``[row, column, orientation]`` (``"E"``, ``"S"``, ``"W"``, ``"N"``);
* ``numTaskFinished``, ``sumOfCost`` and ``makespan`` (a robot's cost is the
  number of steps during which it held a task, as the Start-Kit counts it);
* ``numPlannerErrors``, ``numScheduleErrors``, ``numEntryTimeouts``;
* ``actualPaths`` and ``plannerPaths``: every robot's actions, comma-separated:
  ``F`` forward, ``R`` a quarter turn clockwise, ``C`` counter-clockwise, ``W``
  wait (mrmp's robots carry out what they decided: both lists are the same);
* ``plannerTimes``: seconds per step, as measured by the caller;
* ``errors``: ``[robot1, robot2, step, description]`` of every collision the referee found;
* ``actualSchedule`` and ``plannerSchedule``: per robot, ``"step:task,..."`` of each task given, ``step``
  the first step at whose end the robot's errands are checked (as the Start-Kit writes it);
* ``events``: ``[step, robot, task, errands done]``; ``tasks``: ``[task, step revealed, [row, column, ...]]``.

Locations are rows counted from the top and columns, as in LoRR files
(:func:`mrmp.io.lorr.lorr_location`).

Examples
--------
>>> from mrmp.core.heading import Heading
>>> lorr_actions([(0, 0), (0, 0), (0, 1), (0, 1)], [Heading.NORTH, Heading.EAST, Heading.EAST, Heading.NORTH])
'R,F,C'
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from itertools import pairwise
from typing import Any

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.errors import MrmpError
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading, right_turns
from mrmp.core.result import RunResult
from mrmp.io._files import PathLike, atomic_write_text
from mrmp.io.lorr import lorr_location

__all__ = ["lorr_actions", "lorr_output", "write_lorr_output"]

ORIENTATION_LETTERS = {Heading.EAST: "E", Heading.SOUTH: "S", Heading.WEST: "W", Heading.NORTH: "N"}
"""LoRR's orientation letters (``Simulator::starts_to_json``)."""


def lorr_actions(path: Sequence[Cell], headings: Sequence[Heading]) -> str:
    """A robot's actions, one per tick, as LoRR's ``F,R,C,W`` string.

    Raises
    ------
    MrmpError
        If a tick holds a move a ``turning`` body cannot make (a move that is
        not forward, or a turn of more than a quarter).
    """
    actions = []
    for tick, ((before, after), (facing, faced)) in enumerate(zip(pairwise(path), pairwise(headings), strict=True), 1):
        if before != after:
            if facing != faced or (before[0] + facing.delta[0], before[1] + facing.delta[1]) != after:
                raise MrmpError(f"tick {tick}: the move {before} -> {after} facing {facing.name} is not a MAPF_T forward")
            actions.append("F")
        elif facing == faced:
            actions.append("W")
        elif right_turns(facing, faced) == 1:
            actions.append("R")
        elif right_turns(faced, facing) == 1:
            actions.append("C")
        else:
            raise MrmpError(f"tick {tick}: the turn {facing.name} -> {faced.name} is more than a quarter")
    return ",".join(actions)


def lorr_output(result: RunResult, grid: Grid, step_seconds: Sequence[float] = ()) -> dict[str, Any]:
    """The LoRR output JSON of ``result`` on ``grid`` (module docstring), ``step_seconds`` as ``plannerTimes``.

    Raises
    ------
    MrmpError
        If the run had no task stream, or its robots were not ``turning`` bodies.
    """
    if result.tasks is None:
        raise MrmpError("--lorr-output: the run had no task stream (run a LoRR problem file)")
    if not body_model(result.body).turns_in_place:
        raise MrmpError(f"--lorr-output: LoRR's actions are those of turning bodies, this run's were {result.body}")
    log = result.tasks

    def row_column(cell: Cell) -> list[int]:
        return list(divmod(lorr_location(cell, grid), grid.y_size))

    paths = [lorr_actions(robot.path, robot.headings) for robot in result.robots]
    # a task given at the end of tick t is checked from step t + 1 on, which the Start-Kit writes as t + 1
    schedules = [",".join(f"{tick + 1}:{task}" for tick, task in given) for given in log.schedules]
    index_of = {robot.id: index for index, robot in enumerate(result.robots)}
    return {
        "actionModel": "MAPF_T",
        "version": "2024 LoRR",
        "teamSize": len(result.robots),
        "numTaskFinished": log.finished,
        "sumOfCost": sum(log.busy_ticks),
        "makespan": max(log.busy_ticks, default=0),
        "numPlannerErrors": len(result.collisions),
        "numScheduleErrors": 0,
        "numEntryTimeouts": 0,
        "start": [[*row_column(robot.path[0]), ORIENTATION_LETTERS[robot.headings[0]]] for robot in result.robots],
        "actualPaths": paths,
        "plannerPaths": paths,
        "plannerTimes": list(step_seconds),
        "errors": [
            [index_of[collision.robots[0]], index_of[collision.robots[1]] if len(collision.robots) > 1 else -1,
             collision.tick, collision.kind]
            for collision in result.collisions
        ],
        "actualSchedule": schedules,
        "plannerSchedule": schedules,
        "scheduleErrors": [],
        "events": [list(event) for event in log.events],
        "tasks": [
            [task, revealed, [number for cell in errands for number in row_column(cell)]]
            for task, revealed, errands in log.revealed
        ],
    }


def write_lorr_output(result: RunResult, grid: Grid, path: PathLike, step_seconds: Sequence[float] = ()) -> None:
    """Write :func:`lorr_output` to ``path`` (atomically: a crash leaves the old file or the new one)."""
    atomic_write_text(path, json.dumps(lorr_output(result, grid, step_seconds), indent=4) + "\n")
