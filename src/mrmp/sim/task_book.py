"""The world's task manager in lifelong runs with a task stream: errands reached, tasks revealed and scheduled.

It plays the League of Robot Runners' task manager (MAPF-Competition/Start-Kit
v2.1.0, ``src/TaskManager.cpp``) and its scheduler, and nothing more: at the
end of every tick it looks at where the robots stand (their public positions,
as the competition's system does), and

1. every robot on its task's next errand advances to the errand after it (an
   *event*); a robot on its task's last errand finishes the task and is free;
2. tasks are revealed until :attr:`~mrmp.core.tasks.TaskStream.reveal` are
   revealed and unfinished;
3. the scheduler gives revealed tasks that nobody has to free robots;

then it hands each robot its goal: its task's next errand, or, for a robot
without a task, the cell it stands on. The robots plan their own way there; the
task book never moves, orders or asks a robot.

Schedulers are entries of :data:`SCHEDULER_TABLE`. ``greedy`` is the
Start-Kit's default (``default_planner/scheduler.cpp``): each free robot in
turn takes the free task whose errands it can finish soonest (the sum of the
shortest-path distances from its cell through the errands, headings ignored),
the earliest revealed one among equals. The Start-Kit takes its free robots in
the order of a C++ hash set; mrmp takes them by index.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> from mrmp.core.tasks import TaskStream
>>> from mrmp.search.flat_map import FlatMap
>>> stream = TaskStream(errands=(((0, 3),), ((0, 1), (0, 2))), reveal=2)
>>> book = TaskBook(stream, FlatMap(Grid(1, 4)), robots=1)
>>> book.update(0, [(0, 0)])          # robot 0 takes task 1, nearer through its errands
TaskUpdate(reached=[], goals={0: (0, 1)})
>>> book.update(1, [(0, 1)])          # first errand done: on to the second
TaskUpdate(reached=[0], goals={0: (0, 2)})
>>> book.update(2, [(0, 2)])          # task 1 finished, task 2 revealed; task 0 is nearer
TaskUpdate(reached=[0], goals={0: (0, 3)})
>>> book.log.finished, book.log.events
(1, [(1, 0, 1, 1), (2, 0, 1, 2)])
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise

from mrmp.core.cell import Cell
from mrmp.core.errors import InputError
from mrmp.core.result import RobotResult
from mrmp.core.scenario import Scenario, task_stream_problems
from mrmp.core.tasks import TaskLog, TaskStream
from mrmp.search.flat_map import FlatMap

__all__ = ["SCHEDULER_TABLE", "Scheduler", "Task", "TaskBook", "TaskUpdate", "greedy_schedule", "hand_out_tasks", "task_book"]

@dataclass
class Task:
    """One revealed task: its errands, the next one to visit, and its robot (None: free)."""

    task_id: int
    errands: tuple[Cell, ...]
    revealed_at: int
    next_errand: int = 0
    robot: int | None = None


@dataclass
class TaskUpdate:
    """What a tick changed: the robots that reached an errand, and the new goal of every robot whose goal changed."""

    reached: list[int]
    goals: dict[int, Cell]


Scheduler = Callable[[Sequence[int], Sequence[Task], Sequence[Cell], FlatMap], dict[int, int]]
"""``scheduler(free robots, free tasks, robots' cells, flat map) -> {robot: task id}``."""


def greedy_schedule(
    free_robots: Sequence[int], free_tasks: Sequence[Task], cells: Sequence[Cell], flat: FlatMap
) -> dict[int, int]:
    """The Start-Kit's default scheduler (module docstring): each free robot takes its soonest-finished free task.

    >>> from mrmp.core.grid import Grid
    >>> tasks = [Task(0, ((0, 3),), 0), Task(1, ((0, 2), (0, 0)), 0)]
    >>> greedy_schedule([0, 1], tasks, [(0, 0), (0, 1)], FlatMap(Grid(1, 4)))   # robot 0: 3 < 4; robot 1 takes the rest
    {0: 0, 1: 1}
    """
    tails = {task.task_id: _errand_length(task.errands, flat) for task in free_tasks}
    left = list(free_tasks)
    chosen: dict[int, int] = {}
    for robot in free_robots:
        here = flat.index(cells[robot])
        best: Task | None = None
        best_length = float("inf")
        for task in left:
            length = flat.distances(flat.index(task.errands[0]))[here] + tails[task.task_id]
            if length < best_length:
                best, best_length = task, length
        if best is not None:
            chosen[robot] = best.task_id
            left.remove(best)
    return chosen


def _errand_length(errands: tuple[Cell, ...], flat: FlatMap) -> float:
    """The shortest-path length from a task's first errand through the others, in order."""
    return sum(
        flat.distances(flat.index(after))[flat.index(before)] for before, after in pairwise(errands)
    )


SCHEDULER_TABLE: dict[str, Scheduler] = {"greedy": greedy_schedule}
"""Every scheduler by name (``TaskStream.scheduler``): one entry per scheduler."""


class TaskBook:
    """The task manager of one run (module docstring); ``log`` holds what LoRR's output reports.

    Parameters
    ----------
    stream:
        The scenario's task stream.
    flat:
        The map's flat form (its distance lists serve the scheduler).
    robots:
        How many robots the run has.
    """

    def __init__(self, stream: TaskStream, flat: FlatMap, robots: int) -> None:
        if stream.scheduler not in SCHEDULER_TABLE:
            raise ValueError(f"unknown scheduler {stream.scheduler!r}: use one of {', '.join(sorted(SCHEDULER_TABLE))}")
        self.stream = stream
        self.flat = flat
        self._scheduler = SCHEDULER_TABLE[stream.scheduler]
        self.open: dict[int, Task] = {}  # revealed and unfinished, by id (in reveal order)
        self.task_of: list[Task | None] = [None] * robots
        self.goals: list[Cell | None] = [None] * robots
        self.log = TaskLog(schedules=[[] for _ in range(robots)], busy_ticks=[0] * robots)
        self._next_id = 0

    def update(self, tick: int, cells: Sequence[Cell]) -> TaskUpdate:
        """The end of tick ``tick`` (0: before the first), the robots standing on ``cells``: see the module docstring."""
        if tick > 0:
            for robot, task in enumerate(self.task_of):
                if task is not None:
                    self.log.busy_ticks[robot] += 1
        reached = [
            robot
            for robot, task in enumerate(self.task_of)
            if task is not None and cells[robot] == task.errands[task.next_errand]
        ]
        for robot in reached:
            self.reach(robot, tick)
        self.reveal(tick)
        self.schedule(tick, cells)
        return TaskUpdate(reached, self._new_goals(cells))

    def reach(self, robot: int, tick: int) -> Task:
        """Robot ``robot`` reached its task's next errand at the end of ``tick``: log the event; a robot that
        reached the last one finishes the task and is free. Its task (finished or not).

        Raises
        ------
        ValueError
            If the robot has no task.
        """
        task = self.task_of[robot]
        if task is None:
            raise ValueError(f"robot {robot} has no task to reach an errand of")
        task.next_errand += 1
        self.log.events.append((tick, robot, task.task_id, task.next_errand))
        if task.next_errand == len(task.errands):
            self.log.finished += 1
            del self.open[task.task_id]
            self._give(robot, None, tick)
        return task

    def reveal(self, tick: int) -> None:
        """Reveal tasks at ``tick`` until :attr:`~mrmp.core.tasks.TaskStream.reveal` are revealed and unfinished."""
        while len(self.open) < self.stream.reveal:
            task = Task(self._next_id, self.stream.task_errands(self._next_id), tick)
            self.open[task.task_id] = task
            self.log.revealed.append((task.task_id, tick, task.errands))
            self._next_id += 1

    def schedule(self, tick: int, cells: Sequence[Cell]) -> list[int]:
        """Give free tasks to the free robots at ``tick`` by the stream's scheduler (the free robots standing on
        ``cells``, by robot index); the robots given a task."""
        free_robots = [robot for robot, task in enumerate(self.task_of) if task is None]
        if not free_robots:
            return []
        free_tasks = [task for task in self.open.values() if task.robot is None]
        given = self._scheduler(free_robots, free_tasks, cells, self.flat)
        for robot, task_id in given.items():
            task = self.open[task_id]
            if task.robot is not None or self.task_of[robot] is not None:
                raise ValueError(f"scheduler {self.stream.scheduler} gave task {task_id} or robot {robot} twice")
            self._give(robot, task, tick)
        return list(given)

    def _give(self, robot: int, task: Task | None, tick: int) -> None:
        self.task_of[robot] = task
        if task is not None:
            task.robot = robot
            self.log.schedules[robot].append((tick, task.task_id))

    def _new_goals(self, cells: Sequence[Cell]) -> dict[int, Cell]:
        changed: dict[int, Cell] = {}
        for robot, task in enumerate(self.task_of):
            goal = cells[robot] if task is None else task.errands[task.next_errand]
            if goal != self.goals[robot]:
                self.goals[robot] = changed[robot] = goal
        return changed


def hand_out_tasks(
    book: TaskBook,
    tick: int,
    cells: Sequence[Cell],
    results: Sequence[RobotResult],
    set_goal: Callable[[int, Cell], None],
) -> None:
    """Update ``book`` at the end of ``tick``: count each errand reached in ``results``; ``set_goal(index, goal)`` each change."""
    update = book.update(tick, cells)
    for index in update.reached:
        results[index].goals_reached += 1
    for index, goal in update.goals.items():
        set_goal(index, goal)


def task_book(scenario: Scenario, flat: FlatMap | None = None) -> TaskBook | None:
    """The task book of ``scenario`` (None when it has no task stream), on ``flat`` (made here when not given).

    Raises
    ------
    InputError
        If the stream has problems (:func:`~mrmp.core.scenario.task_stream_problems`).
    """
    if scenario.tasks is None:
        return None
    problems = task_stream_problems(scenario)
    if problems:
        raise InputError(problems)
    return TaskBook(scenario.tasks, flat if flat is not None else FlatMap(scenario.grid), len(scenario.robots))
