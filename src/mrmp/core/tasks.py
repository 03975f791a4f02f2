"""Task streams: the endless errands of a lifelong run, as the League of Robot Runners gives them.

In a LoRR problem (MAPF-Competition/Start-Kit, ``src/TaskManager.cpp``) a
*task* is a sequence of *errands*, cells a robot visits in order; the task
is finished when its robot stands on its last errand at the end of a tick.
The world keeps ``reveal`` tasks revealed at all times: at the start the
first ``reveal`` tasks of the list, and each time tasks finish, as many more;
the list is read round and round (task ``i`` has the errands of list entry
``i mod len(list)``), so the stream never ends. A *scheduler* gives revealed
tasks to robots without one (:mod:`mrmp.sim.task_book`).

A :class:`TaskStream` is the part of a scenario that says all this; its
run-time state (what is revealed, who does what) lives in the simulator's
task book.

Examples
--------
>>> stream = TaskStream(errands=(((0, 1),), ((2, 2), (0, 0))), reveal=3)
>>> stream.task_errands(0), stream.task_errands(3)
(((0, 1),), ((2, 2), (0, 0)))
>>> from mrmp.core.grid import Grid
>>> [str(problem) for problem in task_problems(stream, Grid(2, 2))]
['tasks.errands[1][0]: cell (2, 2) is outside the 2x2 grid']
"""

from __future__ import annotations

from dataclasses import dataclass, field

from mrmp.core.cell import Cell
from mrmp.core.errors import Problem
from mrmp.core.grid import Grid

__all__ = ["DEFAULT_SCHEDULER", "MAX_REVEALED", "TaskLog", "TaskStream", "task_problems"]

DEFAULT_SCHEDULER = "greedy"
"""The scheduler a task stream names when it names none (the Start-Kit's default)."""

MAX_REVEALED = 1_000_000
"""The most tasks a stream may keep revealed at once."""


@dataclass(frozen=True)
class TaskStream:
    """The tasks of a lifelong run (module docstring).

    Attributes
    ----------
    errands:
        The task list: each task's errand cells, in the order they are visited.
    reveal:
        How many tasks are kept revealed (LoRR: ``int(numTasksReveal * teamSize)``).
    scheduler:
        The name of the scheduler that gives tasks to robots
        (:data:`mrmp.sim.task_book.SCHEDULER_TABLE`).
    """

    errands: tuple[tuple[Cell, ...], ...]
    reveal: int
    scheduler: str = DEFAULT_SCHEDULER

    def task_errands(self, task_id: int) -> tuple[Cell, ...]:
        """The errands of task ``task_id`` (the list read round and round)."""
        return self.errands[task_id % len(self.errands)]


def task_problems(stream: TaskStream, grid: Grid) -> list[Problem]:
    """Every problem with ``stream`` on ``grid``, each named by its field path (``tasks.``...)."""
    problems: list[Problem] = []
    if not stream.errands:
        problems.append(Problem("tasks.errands", "a task stream needs at least one task"))
    if not 1 <= stream.reveal <= MAX_REVEALED:
        problems.append(Problem("tasks.reveal", f"must be between 1 and {MAX_REVEALED} tasks, got {stream.reveal}"))
    size = f"{grid.x_size}x{grid.y_size}"
    for task, errands in enumerate(stream.errands):
        if not errands:
            problems.append(Problem(f"tasks.errands[{task}]", "a task has at least one errand"))
        for index, cell in enumerate(errands):
            where = f"tasks.errands[{task}][{index}]"
            if not grid.in_bounds(cell):
                problems.append(Problem(where, f"cell {cell} is outside the {size} grid"))
            elif grid.is_blocked(cell):
                problems.append(Problem(where, f"cell {cell} is an obstacle"))
        if len(problems) >= 10:
            break
    return problems


@dataclass
class TaskLog:
    """What happened to a run's tasks, as LoRR's output reports it (filled in as the run goes).

    Attributes
    ----------
    finished:
        Tasks finished (LoRR's ``numTaskFinished``, the competition's score).
    events:
        ``(tick, robot index, task id, errands done)`` each time a robot
        reached its task's next errand (LoRR's ``events``).
    revealed:
        ``(task id, tick revealed, errand cells)`` of every task revealed so far, by id.
    schedules:
        For every robot, ``(tick, task id)`` each time it was given a task (LoRR's ``actualSchedule``).
    busy_ticks:
        For every robot, the ticks during which it held a task (LoRR's per-robot cost).
    """

    finished: int = 0
    events: list[tuple[int, int, int, int]] = field(default_factory=list)
    revealed: list[tuple[int, int, tuple[Cell, ...]]] = field(default_factory=list)
    schedules: list[list[tuple[int, int]]] = field(default_factory=list)
    busy_ticks: list[int] = field(default_factory=list)
