"""The outcome of a run: per-robot trajectories, referee findings and metrics.

Results are plain data shared by the simulator (which fills them), the I/O layer
(which writes them as JSON) and the visualization layer (which draws them).

Metrics follow the standard MAPF definitions (Stern et al., SoCS 2019):

* a robot's *cost* is the first tick from which it stays at its goal until the
  end of the run (the run length if it never settles there);
* *sum of costs* adds the robots' costs, *makespan* is the largest;
* the *lower bound* adds each robot's shortest-path length, ignoring the others.

Examples
--------
>>> robot = RobotResult("A", (0, 0), (0, 2), path=[(0, 0), (0, 1), (0, 1), (0, 2)])
>>> robot.arrival_tick, robot.steps, robot.waits
(3, 2, 1)
"""

from __future__ import annotations

from dataclasses import dataclass, field

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.core.tasks import TaskLog

COLLISION_KINDS = ("vertex", "swap", "obstacle", "off_grid", "jump", "follow", "rotation", "action")
"""What the referee reports: two robots in one cell, two robots exchanging cells,
a robot on a static obstacle, a robot off the grid, a robot moving more than one
cell in one tick; and, by body model (:mod:`mrmp.sim.referee`): a robot entering
a cell another robot left in the same tick (a body that never follows), robots
moving round a cycle of three or more cells at once (a body without rotations),
a robot doing what its headed body cannot do in one tick."""


@dataclass(frozen=True)
class Collision:
    """One violation found by the referee at ``tick`` (the tick whose end state is wrong).

    ``kind`` is one of :data:`COLLISION_KINDS`; ``robots`` and ``cells`` are the
    robots involved and where (for ``follow``: the follower, then the robot it
    followed, and the cell entered; for ``rotation``: the robots in cycle order
    and the cells they left; see :mod:`mrmp.sim.referee`).
    """

    kind: str
    tick: int
    robots: tuple[str, ...]
    cells: tuple[Cell, ...]

    def describe(self) -> str:
        """One line for a person.

        >>> Collision("vertex", 3, ("A", "B"), ((2, 2),)).describe()
        'tick 3: vertex collision of A, B at (2, 2)'
        """
        where = ", ".join(str(cell) for cell in self.cells)
        return f"tick {self.tick}: {self.kind} collision of {', '.join(self.robots)} at {where}"


@dataclass
class RobotResult:
    """What one robot did: its path (one cell per tick, tick 0 first) and counters."""

    id: str
    start: Cell
    goal: Cell
    path: list[Cell] = field(default_factory=list)
    headings: list[Heading] = field(default_factory=list)
    turns: int = 0
    messages_sent: int = 0
    bytes_sent: int = 0
    time_s: float = 0.0
    goals_reached: int = 0

    @property
    def arrived(self) -> bool:
        """Whether the robot ended the run at its goal."""
        return bool(self.path) and self.path[-1] == self.goal

    @property
    def arrival_tick(self) -> int | None:
        """First tick from which the robot stays at its goal, or None if it ends elsewhere."""
        if not self.arrived:
            return None
        tick = len(self.path) - 1
        while tick > 0 and self.path[tick - 1] == self.goal:
            tick -= 1
        return tick

    @property
    def cost(self) -> int:
        """The robot's MAPF cost: its arrival tick, or the run length if it never settled."""
        arrival = self.arrival_tick
        return arrival if arrival is not None else max(len(self.path) - 1, 0)

    @property
    def steps(self) -> int:
        """Moves to another cell, over the whole run."""
        return sum(1 for before, after in zip(self.path, self.path[1:]) if before != after)

    @property
    def waits(self) -> int:
        """Ticks spent standing still before the robot settled at its goal."""
        end = self.cost
        return sum(1 for tick in range(end) if self.path[tick] == self.path[tick + 1])


@dataclass
class RunResult:
    """Everything a run produced. ``to_dict`` in :mod:`mrmp.io.results` gives its JSON form.

    ``mode`` is ``"simulated"`` (lockstep ticks) or ``"live"``; a live run's
    paths are its ground truth sampled every ``tick_seconds`` of wall-clock
    time, its robots' ``time_s`` are wall-clock arrival times, and
    ``ideal_makespan_s`` is the longest single-robot path time at the run's
    speed. Runs executing a central plan carry the wall time spent planning,
    ``planning_time_s``, and the size of the shares of the plan handed to the
    robots (their moves and dependencies), ``plan_bytes``, and the plan's own
    figures, ``plan_sum_of_costs`` and ``plan_makespan`` (what the execution is
    measured against). In a ``lifelong``
    run robots receive new goals as they reach theirs; its figure is the
    ``throughput``, goals reached per tick. A run simulated with
    ``record_messages`` carries its ``message_log``: for each tick (index 0,
    the start, is empty) the ``(sender id, recipient id, kind)`` of every
    message sent during that tick; ``None`` when messages were not recorded.
    ``body`` names the body model the robots planned for and were judged in
    (:mod:`mrmp.core.body`); a robot's ``time_s`` counts its body's actions in
    seconds, so ``time_makespan_s`` and ``time_sum_of_costs_s`` are the
    makespan and the sum of costs in the body's seconds, beside the ticks.
    A lifelong run with a task stream carries its ``tasks``
    (:class:`~mrmp.core.tasks.TaskLog`: tasks finished, errands reached,
    schedules), and a robot's ``goals_reached`` counts its errands.
    """

    scenario: str
    policy: str
    seed: int
    robots: list[RobotResult]
    collisions: list[Collision]
    stop_reason: str
    ticks: int
    lower_bound: int
    wall_time_s: float
    network: dict[str, int] = field(default_factory=dict)
    mode: str = "simulated"
    tick_seconds: float | None = None
    ideal_makespan_s: float | None = None
    planning_time_s: float | None = None
    plan_bytes: int | None = None
    plan_sum_of_costs: int | None = None
    plan_makespan: int | None = None
    lifelong: bool = False
    message_log: list[list[tuple[str, str, str]]] | None = None
    body: str = "omni"
    tasks: TaskLog | None = None

    @property
    def all_arrived(self) -> bool:
        """Whether every robot ended at its goal."""
        return all(robot.arrived for robot in self.robots)

    @property
    def success(self) -> bool:
        """Every robot arrived and the referee found nothing (lifelong: the run lasted its time, without collision)."""
        if self.lifelong:
            return self.stop_reason == "time up" and not self.collisions
        return self.all_arrived and not self.collisions

    @property
    def throughput(self) -> float:
        """Goals reached per tick (lifelong runs; a one-shot run counts each robot's settling)."""
        return sum(robot.goals_reached for robot in self.robots) / self.ticks if self.ticks else 0.0

    @property
    def makespan(self) -> int:
        """The largest robot cost."""
        return max((robot.cost for robot in self.robots), default=0)

    @property
    def sum_of_costs(self) -> int:
        """The sum of robot costs."""
        return sum(robot.cost for robot in self.robots)

    @property
    def time_makespan_s(self) -> float:
        """The largest time a robot's body needed until it settled (moves, turns, waits)."""
        return max((robot.time_s for robot in self.robots), default=0.0)

    @property
    def time_sum_of_costs_s(self) -> float:
        """The sum over robots of the time each robot's body needed until it settled (moves, turns, waits)."""
        return sum(robot.time_s for robot in self.robots)

    @property
    def messages(self) -> int:
        """Messages sent by all robots."""
        return sum(robot.messages_sent for robot in self.robots)

    @property
    def not_arrived(self) -> list[str]:
        """Ids of the robots that ended away from their goal."""
        return [robot.id for robot in self.robots if not robot.arrived]
