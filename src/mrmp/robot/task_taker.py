"""A live robot's side of the task desk: the task it holds, its errands reached, its reports (sans-IO).

In a live lifelong run the tasks come from the task desk
(:mod:`mrmp.protocol.tasks`, :mod:`mrmp.live.task_desk`). A robot's
:class:`TaskTaker` keeps the task the desk gave it and follows the League of
Robot Runners' rule (MAPF-Competition/Start-Kit, ``src/TaskManager.cpp``), as
the simulator's task book does (:mod:`mrmp.sim.task_book`): a robot standing
on its task's next errand at the end of a step has reached it, and heads for
the errand after it; a robot that reached the last one has finished the task
and is free until the desk gives it another. A free robot's goal is the cell
it stands on.

The robot advances through its task's errands by itself, at once; the desk
learns of them by :class:`~mrmp.protocol.tasks.TaskReportMessage`, sent at
once on every change, and again every ``retry`` seconds while the desk has
not acknowledged it (its :class:`~mrmp.protocol.tasks.TaskMessage` names the
robot's task with as many errands done) or while the robot has no task to do.
A task message of another task is taken only by a free robot, and never one
it has finished already (a late copy).

Examples
--------
>>> from mrmp.protocol.tasks import TaskMessage
>>> taker = TaskTaker(index=0, desk=2, retry=0.1)
>>> [message.task for message in taker.due(0.0, (0, 0), step=0)]   # free: asks for a task
[-1]
>>> taker.take(TaskMessage(2, 1, task=5, done=0, errands=((0, 1), (0, 2))))
True
>>> taker.goal((0, 0)), taker.step_ended(3, (0, 1)), taker.goal((0, 1))
((0, 1), True, (0, 2))
>>> [(m.task, m.done, m.step) for m in taker.due(0.05, (0, 1), step=4)]   # at once: the desk does not know yet
[(5, 1, 3)]
>>> taker.due(0.1, (0, 1), step=4)                                        # not again before the retry interval
[]
>>> taker.take(TaskMessage(2, 2, task=5, done=1, errands=((0, 1), (0, 2))))   # acknowledged
False
>>> taker.due(0.5, (0, 1), step=8)
[]
"""

from __future__ import annotations

import math
from collections import Counter

from mrmp.core.cell import Cell
from mrmp.protocol.tasks import NO_TASK, TaskMessage, TaskReportMessage

__all__ = ["TaskTaker"]


class TaskTaker:
    """One robot's task, its progress and its reports to the desk (module docstring).

    Parameters
    ----------
    index:
        The robot's index (the sender of its reports).
    desk:
        The desk's index on the wire (the fleet's size).
    retry:
        Seconds between two sends of a report the desk has not acknowledged, or of a free robot's.
    """

    def __init__(self, index: int, desk: int, retry: float) -> None:
        self.index = index
        self.desk = desk
        self.retry = retry
        self.task = NO_TASK
        self.errands: tuple[Cell, ...] = ()
        self.done = 0
        """How many of the task's errands the robot has reached."""
        self.acknowledged = 0
        """How many of them the desk knows it has reached."""
        self.reached_at = 0
        """The step at whose end the robot reached its last errand."""
        self.finished: set[int] = set()
        """The tasks the robot has finished (a late copy of one is not taken again)."""
        self.stats: Counter[str] = Counter()
        self._changed = True
        self._sent_at = -math.inf
        self._ended = 0
        """The last step whose end the robot was told of with an errand reached."""

    @property
    def busy(self) -> bool:
        """Whether the robot holds a task with errands still to reach."""
        return self.task != NO_TASK and self.done < len(self.errands)

    def goal(self, present: Cell) -> Cell:
        """Where the robot heads: its task's next errand, or, free, the cell it stands on (``present``)."""
        return self.errands[self.done] if self.busy else present

    def step_ended(self, step: int, present: Cell) -> bool:
        """Step ``step`` ends with the robot on ``present``: whether it reached its task's next errand there.

        Told as soon as the robot knows (it may be told again for the same
        step: only the first time counts).
        """
        if step <= self._ended or not self.busy or present != self.errands[self.done]:
            return False
        self._ended = step
        self.done += 1
        self.reached_at = step
        self.stats["errands_reached"] += 1
        if self.done == len(self.errands):
            self.finished.add(self.task)
            self.stats["tasks_finished"] += 1
        self._changed = True
        return True

    def take(self, message: TaskMessage) -> bool:
        """Take in the desk's message; whether it gave the robot a new task."""
        if message.task == self.task:
            self.acknowledged = max(self.acknowledged, message.done)
            return False
        if message.task == NO_TASK or message.task in self.finished or self.busy:
            return False  # nothing to do yet, a late copy of a finished task, or news older than the task held
        self.task, self.errands = message.task, message.errands
        self.done = self.acknowledged = message.done
        self.stats["tasks_taken"] += 1
        self._changed = True
        return True

    def due(self, now: float, present: Cell, step: int) -> list[TaskReportMessage]:
        """The report to send at ``now`` (sequence number 0: the robot numbers it), if one is due.

        One is due at once after a change, and every ``retry`` seconds while the
        desk has not acknowledged the robot's progress or the robot is free.
        """
        waiting = self.done > self.acknowledged or not self.busy
        if not (self._changed or (waiting and self._sent_at + self.retry <= now)):
            return []
        self._changed = False
        self._sent_at = now
        self.stats["reports_sent"] += 1
        reached_at = self.reached_at if self.task != NO_TASK else step
        return [TaskReportMessage(self.index, 0, self.task, self.done, reached_at, present)]
