"""The task desk's messages: how a live robot of a lifelong run learns its tasks and tells what it did.

In a lifelong run with a task stream (the League of Robot Runners' problems,
:mod:`mrmp.core.tasks`) the tasks come from the world, not from the robots:
a *task desk* (:mod:`mrmp.live.task_desk`) keeps the revealed tasks and gives
them to robots, as a warehouse's management system or the competition's task
manager does. It gives a robot errand cells to visit; it never moves, orders
or asks a robot, and it knows of a robot only what the robot reports. On the
wire the desk is the member whose index is the fleet's size (one past the
last robot).

* :class:`TaskReportMessage`, robot to desk: the task the robot holds (or
  :data:`NO_TASK`), how many of its errands it has reached, the step at
  whose end it reached the last of them, and the cell it stands on (which
  the desk's scheduler weighs when the robot is free). A robot without a task, or whose
  progress the desk has not acknowledged, sends it again every retry interval
  (:class:`mrmp.robot.task_taker.TaskTaker`).
* :class:`TaskMessage`, desk to robot: the answer to every report, the task
  the desk has the robot do (its id, its errands and how many the desk knows
  it has reached), or :data:`NO_TASK` while it has none for it. It is the
  report's acknowledgement too: the robot stops repeating once the desk's
  count of its errands reached is its own.

Both are idempotent: a lost, repeated or late copy changes nothing that a
newer one does not (a report of fewer errands than the desk knows, or a task
older than the robot's, is ignored).

>>> from mrmp.protocol.codec import decode, encode
>>> decode(encode(TaskMessage(24, 3, task=7, done=1, errands=((2, 3), (4, 5)))))
TaskMessage(sender=24, seq=3, task=7, done=1, errands=((2, 3), (4, 5)))
>>> decode(encode(TaskReportMessage(0, 9, task=7, done=2, step=41, cell=(4, 5))))
TaskReportMessage(sender=0, seq=9, task=7, done=2, step=41, cell=(4, 5))
>>> len(encode(TaskReportMessage(0, 9, task=NO_TASK, done=0, step=0, cell=(0, 0))))
27
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from mrmp.core.cell import Cell
from mrmp.protocol.messages import MAX_VISITED_CELLS, Message
from mrmp.protocol.wire import DecodeError, WireFormat, register

__all__ = ["MAX_ERRANDS", "NO_TASK", "TASK", "TASK_REPORT", "TaskMessage", "TaskReportMessage"]

NO_TASK = -1
"""The task id on the wire of "no task"."""

MAX_ERRANDS = MAX_VISITED_CELLS
"""The most errands a task may have to travel live (one datagram carries them all)."""


@dataclass(frozen=True, slots=True)
class TaskMessage(Message):
    """The desk to a robot: do task ``task`` (``NO_TASK``: none yet), whose ``errands`` the desk knows it has
    reached the first ``done`` of."""

    sender: int
    seq: int
    task: int
    done: int
    errands: tuple[Cell, ...]


@dataclass(frozen=True, slots=True)
class TaskReportMessage(Message):
    """A robot to the desk: it holds task ``task`` (``NO_TASK``: none) and has reached ``done`` of its errands,
    the last at the end of step ``step``; it stands on ``cell``."""

    sender: int
    seq: int
    task: int
    done: int
    step: int
    cell: Cell


def _unpack_task(sender: int, seq: int, fields: tuple[Any, ...], errands: tuple[Cell, ...]) -> TaskMessage:
    task, done = fields
    if task < NO_TASK or not 0 <= done <= len(errands) or (task == NO_TASK) != (not errands):
        raise DecodeError("malformed", f"task {task} with {done} of {len(errands)} errands done")
    return TaskMessage(sender, seq, task, done, errands)


def _unpack_report(sender: int, seq: int, fields: tuple[Any, ...], _: tuple[Cell, ...]) -> TaskReportMessage:
    task, done, step, x, y = fields
    if task < NO_TASK or done > MAX_ERRANDS or (task == NO_TASK and done):
        raise DecodeError("malformed", f"task {task} with {done} errands done")
    return TaskReportMessage(sender, seq, task, done, step, (x, y))


TASK = register(
    WireFormat(19, TaskMessage, "!iBB", lambda m: (m.task, m.done), _unpack_task, cells=lambda m: m.errands)
)
"""Type 19: task (i32), done (1 byte), count (1 byte), count errand cells: 16 + 8 * count bytes."""
TASK_REPORT = register(
    WireFormat(20, TaskReportMessage, "!iBIii", lambda m: (m.task, m.done, m.step, *m.cell), _unpack_report)
)
"""Type 20: task (i32), done (1 byte), step (u32), cell: 27 bytes."""
