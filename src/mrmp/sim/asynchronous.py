"""The asynchronous simulator: Causal-PIBT robots at different, varying speeds over a faulty network.

Policy ``causal`` (:mod:`mrmp.robot.causal_pibt`, Okumura, Tamura and Défago,
AAAI 2021) makes no assumption on timing, so this driver gives it none to rely
on. Time runs in ticks (one tick is the fastest robot's time for one cell). It
is event-driven and seeded:

* every robot has its own *pace*, drawn from the seed (1 to
  :data:`SLOWEST_PACE`): it activates again after a random 1 to ``2 * pace``
  ticks, and its body takes a random ``pace`` to ``2 * pace`` ticks (times the
  cell's cost) for each move, so speeds differ between robots and vary over time;
* every message crosses :class:`~mrmp.sim.network.SimulatedNetwork`, which
  loses, delays, duplicates and reorders it as the scenario's network (and its
  per-link faults) say, through :func:`mrmp.core.faults.message_fates`;
* a body is on its tail until its move ends, then on its head; the referee
  (:class:`~mrmp.sim.referee.Referee`) judges the fleet, in the body's model,
  at the end of every tick;
* a body that turns in place (``policy.body: turning``) and does not face the
  head it may enter first turns toward it a quarter at a time, each turn
  taking a random ``pace`` to ``2 * pace`` ticks, on its tail (which it still
  holds), then drives straight ahead;
* a robot's state goes to the robots whose bodies stand within its state radius
  (the lock radius plus the heartbeat period and the longest delay, in cells:
  the farthest a robot can have come since a peer's last state), found
  through a spatial index (:mod:`mrmp.sim.spatial`).

Each tick: deliver what is due (and the answers sent meanwhile), activate the
robots whose time has come, start the moves the safety layer allows, end the
moves that are done, run the robots' timers and heartbeats, deliver again, and
let the referee judge. Deterministic for a seed. Ends when every body stands
on its goal with its robot contracted (never in a lifelong run), at the tick
limit, or on Ctrl-C, returning what was computed.

Examples
--------
>>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
>>> swap = Scenario(Grid(3, 3, [(1, 1)]), (RobotSpec("A", (0, 0), (2, 2)), RobotSpec("B", (2, 2), (0, 0))),
...                 policy=PolicyOptions(name="causal"), seed=1)
>>> result = AsynchronousSimulator(swap).run()
>>> result.success, result.collisions, result.stop_reason
(True, [], 'all arrived')
"""

from __future__ import annotations

import math
import time
from collections import Counter

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.heading import Heading, right_turns
from mrmp.core.limits import MAX_TICKS
from mrmp.core.result import RobotResult, RunResult
from mrmp.core.scenario import Scenario
from mrmp.core.seeds import Stream, stream_random
from mrmp.robot.causal_pibt import LOCK_RADIUS, CausalRobot
from mrmp.robot.robot import Outgoing
from mrmp.search.flat_map import FlatMap
from mrmp.sim.goals import GoalBook
from mrmp.sim.metrics import shortest_steps
from mrmp.sim.referee import Referee
from mrmp.sim.spatial import SpatialIndex
from mrmp.sim.task_book import hand_out_tasks, task_book
from mrmp.sim.ticking import TickObserver, run_result, run_ticks, scenario_network, send_counted

__all__ = ["SLOWEST_PACE", "AsynchronousSimulator", "causal_timers"]

SLOWEST_PACE = 3
"""The slowest robot's pace: its moves take up to twice this many ticks."""


def causal_timers(delay_max: int) -> tuple[int, int, int, int]:
    """Retry interval, lock timeout, claim timeout and heartbeat period, in ticks, for a network delaying up to ``delay_max``.

    >>> causal_timers(0), causal_timers(2)
    ((1, 30, 4, 4), (5, 150, 16, 10))
    """
    retry = 2 * delay_max + 1
    return retry, 30 * retry, 3 * retry + 1, max(4, 2 * retry)


class AsynchronousSimulator:
    """Runs a scenario with Causal-PIBT robots (see the module docstring).

    Parameters
    ----------
    scenario:
        What to run; its network faults, seed, tick limit and ``lifelong`` apply.
        Robots always enter cells through the safety layer.
    on_tick:
        Called at the end of every tick with the tick and the bodies' cells.
    """

    def __init__(self, scenario: Scenario, on_tick: TickObserver | None = None) -> None:
        self.scenario = scenario
        self.on_tick = on_tick
        grid = scenario.grid
        flat = FlatMap(grid)
        starts = [spec.start for spec in scenario.robots]
        worst = scenario.worst_faults()
        retry, lock_timeout, claim_timeout, self.heartbeat_period = causal_timers(worst.delay_max)
        self._random = stream_random(scenario.seed, Stream.PACES)
        self.paces = [self._random.randint(1, SLOWEST_PACE) for _ in scenario.robots]
        self.body = body_model(scenario.policy.body)
        self.robots = [
            CausalRobot(
                index,
                grid,
                starts,
                spec.goal,
                rng=stream_random(scenario.seed, Stream.TIES, index),
                retry_interval=retry,
                lock_timeout=lock_timeout,
                claim_timeout=claim_timeout,
                flat=flat,
                heading=spec.heading,
                state_radius=LOCK_RADIUS + self.heartbeat_period + worst.delay_max,
                body=self.body,
            )
            for index, spec in enumerate(scenario.robots)
        ]
        self.network = scenario_network(scenario)
        self.referee = Referee(grid, [spec.id for spec in scenario.robots], self.body)
        self.lengths = shortest_steps(scenario)
        self.max_ticks = scenario.max_ticks or self.default_max_ticks()
        self.tick = 0
        self.bodies: list[Cell] = list(starts)
        self.radio = SpatialIndex(starts)
        """Where every body stands: the simulated radio delivers radius broadcasts through it."""
        self._next_activation = [self._random.randint(0, 2 * pace) for pace in self.paces]
        self._arrival_at: list[int | None] = [None] * len(self.robots)
        """When each body's action under way (a move, or a quarter turn toward its head) ends."""
        self._turning_to: list[Heading | None] = [None] * len(self.robots)
        """The heading of each body's quarter turn under way, if it is turning."""
        self._heartbeat_at = [self._random.randint(1, self.heartbeat_period) for _ in self.robots]
        self._results = [
            RobotResult(spec.id, spec.start, spec.goal, path=[spec.start], headings=[spec.heading])
            for spec in scenario.robots
        ]
        self._everyone = range(len(self.robots))
        self._goals = GoalBook(scenario.seed, grid.free_cells() if scenario.lifelong else [])
        self.task_book = task_book(scenario, flat)
        if self.task_book is not None:
            self._count_goals()

    def default_max_ticks(self) -> int:
        """Room for the slowest robot's moves and the lock conversations of a crowd over the scenario's network
        (never more than :data:`~mrmp.core.limits.MAX_TICKS`)."""
        worst = self.scenario.worst_faults()
        longest = max(self.lengths, default=0)
        slowdown = (1 + worst.delay_max) / max(0.05, 1 - worst.loss)
        return min(int(200 + 20 * SLOWEST_PACE * (longest + 2 * len(self.robots)) * slowdown), MAX_TICKS)

    @property
    def all_arrived(self) -> bool:
        """Whether every body stands on its goal and every robot is contracted there."""
        return all(robot.at_goal for robot in self.robots)

    # -- the run ---------------------------------------------------------------------

    def run(self) -> RunResult:
        """Run to the end and return the result (partial on Ctrl-C)."""
        started = time.perf_counter()
        self.referee.check_start(self.bodies)
        stop_reason = run_ticks(self, lambda: self.all_arrived)
        return self._result(stop_reason, time.perf_counter() - started)

    def step(self) -> None:
        """Advance one tick (module docstring)."""
        self.tick += 1
        tick = self.tick
        robots = self.robots
        before = list(self.bodies)
        headings_before = [robot.heading for robot in robots]
        self._drain()
        for robot in robots:
            if self._next_activation[robot.index] <= tick:
                self._send(robot, robot.activate(tick))
                self._next_activation[robot.index] = tick + self._random.randint(1, 2 * self.paces[robot.index])
        self._drain()
        for robot in robots:
            target = robot.motion(tick)
            if target is not None:
                self._start_action(robot, target)
        for robot in robots:
            index = robot.index
            if self._arrival_at[index] == tick:
                self._arrival_at[index] = None
                self._end_action(robot)
            self._send(robot, robot.expire(tick))
            if self._heartbeat_at[index] <= tick:
                self._heartbeat_at[index] = tick + self.heartbeat_period
                self._send(robot, robot.heartbeat())
        self._drain()
        for robot in robots:
            result = self._results[robot.index]
            result.path.append(self.bodies[robot.index])
            result.headings.append(robot.heading)
        self.referee.check_tick(tick, before, self.bodies, headings_before, [robot.heading for robot in robots])
        self._count_goals()
        if self.on_tick is not None:
            self.on_tick(tick, list(self.bodies))

    def _start_action(self, robot: CausalRobot, target: Cell) -> None:
        """Start the body's next action toward ``target``: a quarter turn when it turns in place and does not face it,
        else the move."""
        index = robot.index
        pace = self.paces[index]
        turn = self.body.first_turn(robot.heading, Heading.between(self.bodies[index], target))
        self._turning_to[index] = turn
        if turn is not None:
            self._arrival_at[index] = self.tick + self._random.randint(pace, 2 * pace)
            return
        cost = self.scenario.grid.cost(target)
        self._arrival_at[index] = self.tick + max(1, math.ceil(self._random.randint(pace, 2 * pace) * cost))

    def _end_action(self, robot: CausalRobot) -> None:
        """The body's action is done: after a quarter turn, its next action toward the head; after a move, the arrival."""
        turn = self._turning_to[robot.index]
        if turn is None:
            self._end_move(robot)
            return
        self._results[robot.index].turns += 1
        self._send(robot, robot.turned(turn))
        head = robot.head
        assert head is not None
        self._start_action(robot, head)

    def _end_move(self, robot: CausalRobot) -> None:
        """The body of ``robot`` stands on its head now."""
        index = robot.index
        source = self.bodies[index]
        target = robot.head
        assert target is not None
        heading = Heading.between(source, target)
        if not self.body.turns_in_place:
            self._results[index].turns += right_turns(robot.heading, heading)
        self.bodies[index] = target
        self.radio.move(index, source, target)
        self._send(robot, robot.arrived_at(target, self.tick, heading))

    def _send(self, robot: CausalRobot, outgoing: list[Outgoing]) -> None:
        result = self._results[robot.index]
        for item in outgoing:
            send_counted(self.network, robot.index, item, self._everyone, self.tick, result, self._near)

    def _near(self, sender: int, radius: int) -> list[int]:
        """The robots whose bodies stand within ``radius`` cells of ``sender``'s body."""
        return self.radio.within(self.bodies[sender], radius)

    def _drain(self) -> None:
        """Deliver everything due by this tick, including answers sent meanwhile."""
        robots = self.robots
        while True:
            batch = self.network.deliver(self.tick)
            if not batch:
                return
            for _, recipient, payload in batch:
                robot = robots[recipient]
                self._send(robot, robot.receive_datagram(payload, self.tick))

    def _count_goals(self) -> None:
        robots = self.robots
        if self.task_book is not None:
            hand_out_tasks(self.task_book, self.tick, [robot.tail for robot in robots], self._results, self._set_goal)
            return
        for index in self._goals.arrivals(robot.at_goal for robot in robots):
            self._results[index].goals_reached += 1
            if self.scenario.lifelong:
                robot = robots[index]
                goal = self._goals.next_goal(index, {other.goal for other in robots}, robot.tail)
                if goal is not None:
                    robot.set_goal(goal)

    def _set_goal(self, index: int, goal: Cell) -> None:
        self.robots[index].set_goal(goal)

    def _result(self, stop_reason: str, wall_time: float) -> RunResult:
        cell_time = self.scenario.timing.cell_time
        for result in self._results:
            result.time_s = result.cost * cell_time
        network = self.network.stats.as_dict()
        dropped: Counter[str] = Counter()
        stats: Counter[str] = Counter()
        for robot in self.robots:
            dropped.update(robot.dropped)
            stats.update(robot.stats)
        network["dropped_by_robots"] = sum(dropped.values())
        network.update({f"dropped_{reason}": count for reason, count in sorted(dropped.items())})
        network.update({f"causal_{name}": count for name, count in sorted(stats.items())})
        return run_result(self, self._results, "causal", stop_reason, wall_time, network)
