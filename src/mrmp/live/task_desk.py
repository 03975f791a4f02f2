"""The task desk of a live lifelong run: the world's task manager, answering the robots' reports (sans-IO).

The League of Robot Runners' tasks come from the world (its task manager and
scheduler, MAPF-Competition/Start-Kit ``src/TaskManager.cpp`` and
``default_planner/scheduler.cpp``); live, a :class:`TaskDesk` plays that part
over the network, with the simulator's task book (:mod:`mrmp.sim.task_book`)
and scheduler. It knows of a robot only what the robot reports
(:class:`~mrmp.protocol.tasks.TaskReportMessage`) and answers every report
with the task it has the robot do (:class:`~mrmp.protocol.tasks.TaskMessage`).
It never moves, orders or asks a robot: the robots plan their way by
themselves, as in the simulator.

What it does, as the task book does at the end of a tick:

* at the start (step 0), it reveals the first tasks and schedules every robot
  from its start cell;
* it sends a robot the task it gave it at once, and again every ``retry``
  seconds until the robot's report names that task (:meth:`TaskDesk.due`):
  a robot learns its first task before its first step, as the simulator's
  robots do, and a free robot its next one as soon as it is given;
* a report of errands reached that the desk did not know logs them (an
  event each, at the report's step: an errand reached while the report of
  the one before was still unacknowledged is logged at the later step), and
  a finished task frees its robot; tasks are then revealed, and the free
  robots scheduled from the cells they last reported;
* a task finished after the run's last step is not counted
  (:attr:`finished`), as the competition counts only the steps it runs.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> from mrmp.core.tasks import TaskStream
>>> from mrmp.protocol.tasks import TaskReportMessage
>>> desk = TaskDesk(TaskStream(errands=(((0, 3),), ((0, 1), (0, 2))), reveal=2), Grid(1, 4), [(0, 0)], steps=10)
>>> desk.due(0.0)                                       # robot 0 was given task 1, nearer: told at once
[(0, TaskMessage(sender=1, seq=1, task=1, done=0, errands=((0, 1), (0, 2))))]
>>> desk.due(0.05), len(desk.due(0.1))                  # and again every retry interval, until it names it
([], 1)
>>> desk.take(TaskReportMessage(0, 1, task=1, done=0, step=1, cell=(0, 0))).task, desk.due(1.0)
(1, [])
>>> desk.take(TaskReportMessage(0, 2, task=1, done=2, step=4, cell=(0, 2)))    # both errands: task 1 finished
TaskMessage(sender=1, seq=4, task=0, done=0, errands=((0, 3),))
>>> desk.finished, desk.book.log.events
(1, [(4, 0, 1, 1), (4, 0, 1, 2)])
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.tasks import TaskStream
from mrmp.protocol.tasks import MAX_ERRANDS, NO_TASK, TaskMessage, TaskReportMessage
from mrmp.search.flat_map import FlatMap
from mrmp.sim.task_book import TaskBook

__all__ = ["TaskDesk", "desk_problem"]


def desk_problem(stream: TaskStream) -> str | None:
    """Why the desk cannot hand out ``stream`` live, or None when it can (a task message carries a whole task).

    >>> desk_problem(TaskStream(errands=(((0, 0),) * 49,), reveal=1))
    'task 0 has 49 errands; a live task has at most 48'
    """
    for task, errands in enumerate(stream.errands):
        if len(errands) > MAX_ERRANDS:
            return f"task {task} has {len(errands)} errands; a live task has at most {MAX_ERRANDS}"
    return None


class TaskDesk:
    """The desk of one live run (module docstring).

    Parameters
    ----------
    stream:
        The run's task stream.
    grid:
        The map (the scheduler's distances).
    starts:
        Every robot's start cell, by index.
    steps:
        The run's steps: tasks finished after the last are not counted.
    retry:
        Seconds between two sends of a task its robot has not named in a report yet.
    flat:
        The map's flat form, when the caller has one already (its distance lists serve the scheduler); made here
        from ``grid`` otherwise.
    """

    def __init__(
        self,
        stream: TaskStream,
        grid: Grid,
        starts: Sequence[Cell],
        steps: int,
        retry: float = 0.1,
        flat: FlatMap | None = None,
    ) -> None:
        self.book = TaskBook(stream, flat if flat is not None else FlatMap(grid), len(starts))
        self.index = len(starts)
        """The desk's index on the wire: one past the last robot's."""
        self.steps = steps
        self.retry = retry
        self.named = [NO_TASK] * len(starts)
        """The task each robot's newest report named."""
        self._told_at = [-math.inf] * len(starts)
        self.cells = list(starts)
        """Where each robot stood when it last reported (its start until then)."""
        self.finished = 0
        """Tasks finished within the run's steps (LoRR's ``numTaskFinished``)."""
        self.reports = 0
        self.changes = 0
        """How many reports changed the desk's book (a writer of the book can skip the others)."""
        self._seq = 0
        self.book.reveal(0)
        self.book.schedule(0, self.cells)

    def take(self, report: TaskReportMessage) -> TaskMessage:
        """Take in robot ``report.sender``'s report; the desk's answer to it (its task, or none)."""
        robot = report.sender
        self.reports += 1
        self.cells[robot] = report.cell
        self.named[robot] = report.task
        task = self.book.task_of[robot]
        if task is not None and report.task == task.task_id and report.done > task.next_errand:
            self._reached(robot, report.done - task.next_errand, report.step)
        elif task is None and self.book.schedule(report.step, self.cells):
            self.changes += 1
        return self._answer(robot)

    def _reached(self, robot: int, errands: int, step: int) -> None:
        """Robot ``robot`` reached ``errands`` more errands of its task, the last at step ``step``."""
        self.changes += 1
        for _ in range(errands):
            task = self.book.reach(robot, step)
        if self.book.task_of[robot] is None:  # finished
            self.finished += step <= self.steps
            self.cells[robot] = task.errands[-1]
            self.book.reveal(step)
            self.book.schedule(step, self.cells)

    def due(self, now: float) -> list[tuple[int, TaskMessage]]:
        """``(robot, message)`` for every robot to tell its task at ``now``: one whose newest report does not
        name the task the desk gave it, told last ``retry`` seconds ago or more (as :meth:`next_due` reckons)."""
        due = []
        for robot, task in enumerate(self.book.task_of):
            if task is not None and self.named[robot] != task.task_id and self._told_at[robot] + self.retry <= now:
                self._told_at[robot] = now
                due.append((robot, self._answer(robot)))
        return due

    def next_due(self) -> float:
        """When :meth:`due` has something to send next, at the earliest (``inf``: nothing)."""
        return min(
            (self._told_at[robot] + self.retry for robot, task in enumerate(self.book.task_of)
             if task is not None and self.named[robot] != task.task_id),
            default=math.inf,
        )  # fmt: skip

    def _answer(self, robot: int) -> TaskMessage:
        self._seq += 1
        task = self.book.task_of[robot]
        if task is None:
            return TaskMessage(self.index, self._seq, NO_TASK, 0, ())
        return TaskMessage(self.index, self._seq, task.task_id, task.next_errand, task.errands)

    def summary(self) -> dict[str, Any]:
        """What the desk saw, JSON-ready: tasks finished within the steps, and the book's events and schedules."""
        log = self.book.log
        return {
            "steps": self.steps,
            "finished": self.finished,
            "finished_in_all": log.finished,
            "reports": self.reports,
            "events": [list(event) for event in log.events],
            "schedules": [[list(entry) for entry in robot] for robot in log.schedules],
            "revealed": [[task, tick, [list(cell) for cell in errands]] for task, tick, errands in log.revealed],
        }
