"""``pibt`` with a local synchronizer: every robot ends its own steps, and the simulator is only a network, a clock and bodies.

:class:`SynchronizedRoundsSimulator` runs
:class:`~mrmp.robot.pibt_synchronized.SynchronizedPibtRobot` brains
(``policy.synchronizer: local``). Unlike
:class:`~mrmp.sim.local_rounds.LocalRoundsSimulator` and
:class:`~mrmp.sim.live_rounds.LiveRoundsSimulator`, it has no steps of its own:
each robot is in a step of its own, which it ends when it says so
(:attr:`~mrmp.robot.pibt_synchronized.SynchronizedPibtRobot.step_done`). A
tick is:

1. every robot's timers run (:meth:`~mrmp.robot.pibt_reliable.ReliablePibtRobot.on_tick`,
   the tick passed in), and every robot acts;
2. every datagram due is delivered, encoded, over the scenario's seeded
   :class:`~mrmp.sim.network.SimulatedNetwork` (lost, delayed, duplicated or
   reordered as it says), and its recipient acts, round after round until
   nothing more is due in this tick;
3. the *bodies*: every robot whose step is done enters the cell it decided on
   when that cell holds no body, or holds one that leaves it in this tick
   (never two bodies trading cells, never two entering one cell); the others wait, counted as
   ``body_waits``. Each robot whose body moved (or that decided to stay)
   begins its next step at once.

The simulator never reads a brain's private state to order or wait for the
robots: it asks each brain only whether its step is done and which cell it
decided on (what its body is told to do). It audits two things, which
``docs/protocol.md``, "A local synchronizer", argues stay 0: the ticks at
which two robots that decided for good, and have not yet moved, decided on
the same cell (staying on it included) or on each other's
(``conflicting_decisions``), and the robots that ended a step on a cell that
another robot ended the same step on, or trading cells with it
(``conflicting_steps``).

The result's ``network`` holds the network's counts, the robots' own
(``late_acks``, ``ahead``, ``pulled``, ``retransmissions``, ``acks``, ``waits`` ...),
``steps`` (the most steps a robot ended) and ``abandoned`` (always 0: a robot
never ends a step undecided).

Deterministic for a seed.

Examples
--------
>>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
>>> from mrmp.core.scenario import NetworkFaults
>>> swap = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))),
...                 policy=PolicyOptions(name="pibt", synchronizer="local"))
>>> result = SynchronizedRoundsSimulator(swap).run()
>>> result.success, result.sum_of_costs, result.network["conflicting_decisions"], result.network["conflicting_steps"]
(True, 11, 0, 0)
>>> lossy = swap.with_changes(network=NetworkFaults(loss=0.3, delay_max=2))
>>> result = SynchronizedRoundsSimulator(lossy).run()
>>> result.success, result.network["lost"] > 0, result.network["retransmissions"] > 0
(True, True, True)
"""

from __future__ import annotations

from collections import Counter

from mrmp.core.result import RunResult
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_reliable import ReliablePibtRobot
from mrmp.robot.pibt_synchronized import SynchronizedPibtRobot
from mrmp.sim.live_rounds import LiveRoundsSimulator
from mrmp.sim.rounds import NO_ROBOT

__all__ = ["SynchronizedRoundsSimulator"]

ROBOT_COUNTS = ("late_acks", "ahead", "pulled")
"""The robots' own counts reported in the result's ``network`` besides those of
:class:`~mrmp.sim.local_rounds.LocalRoundsSimulator`."""
SIMULATOR_COUNTS = ("body_waits", "conflicting_decisions", "conflicting_steps")
"""The simulator's counts reported in the result's ``network``: bodies that waited, and the two audits."""


class SynchronizedRoundsSimulator(LiveRoundsSimulator):
    """Robots in steps of their own, each ending its step when it knows its neighbours are done (module docstring).

    Parameters are those of :class:`~mrmp.sim.live_rounds.LiveRoundsSimulator`;
    ``step_ticks`` only sizes the default tick limit (the ticks a step may take).
    """

    robot_type = SynchronizedPibtRobot
    reliable_type: type[ReliablePibtRobot] = SynchronizedPibtRobot
    robots: list[SynchronizedPibtRobot]  # type: ignore[assignment]
    steps_take_step_ticks = False

    _ended: dict[int, dict[int, int]]
    """Per step, the cell each robot that ended it ended on -> the cell it began on (:meth:`_record_steps`)."""

    def run(self) -> RunResult:
        """Begin every robot's step 1, then run as :meth:`RoundsSimulator.run <mrmp.sim.rounds.RoundsSimulator.run>`."""
        self._ended = {}
        self._place_bodies()
        for robot in self.robots:
            for item in robot.begin_step(1, (), self.tick):
                self._send(robot.index, item, self.tick)
        return super().run()

    def step(self) -> None:
        """One tick: timers and acts, deliveries, then the bodies of the robots whose step is done (module docstring)."""
        robots = self.robots
        send = self._send
        now = self.tick
        for robot in robots:
            for item in robot.on_tick(now):
                send(robot.index, item, now)
            for item in robot.act():
                send(robot.index, item, now)
        self._deliver_rounds(now)
        movers = self._movers()
        self._record_steps(movers)
        self._advance(moves=True, movers=set(movers))
        occupant = self._occupant
        for index in movers:
            robot = robots[index]
            occupant[robot.present] = index
            for item in robot.begin_step(robot.step + 1, (), self.tick):
                send(index, item, self.tick)
        self.step_count = max((robot.step for robot in robots), default=1) - 1  # the most steps a robot ended

    def _address(self, sender: int, item: Outgoing) -> tuple[int, ...]:
        """The recipients ``item`` names: a live brain names them all (no radio, whose bodies here move every tick)."""
        assert item.recipients is not None, "a live brain addresses every message by name"
        return item.recipients

    def _movers(self) -> list[int]:
        """The robots whose step is done and whose body can enter its cell now, the cells they leave emptied.

        A body enters a cell that holds none, or whose body leaves it in this
        tick for another cell (a chain that ends at an empty cell; never a swap).
        """
        robots = self.robots
        occupant = self._occupant
        decided: dict[int, int] = {}
        ready: dict[int, int] = {}
        for robot in robots:
            if robot.final and robot.target is not None:
                decided[robot.index] = robot.target
                if robot.step_done:
                    ready[robot.index] = robot.target
        self._audit(decided)
        wanted = Counter(target for index, target in ready.items() if target != robots[index].present)
        entering: dict[int, int] = {}  # occupied cell -> the ready robot that waits to enter it
        movers: list[int] = []
        for index, target in ready.items():
            if wanted[target] > 1:
                continue  # two bodies never enter one cell: both wait (the audit counted the conflict)
            other = occupant[target]
            if other in (NO_ROBOT, index):
                movers.append(index)
            else:
                entering[target] = index
        position = 0
        while position < len(movers):
            index = movers[position]
            position += 1
            left = robots[index].present
            follower = entering.pop(left, None) if ready[index] != left else None
            if follower is not None:
                movers.append(follower)
        for index in movers:
            here = robots[index].present
            if ready[index] != here:
                occupant[here] = NO_ROBOT  # its body leaves: step() puts it on its new cell after the move
        self.stats["body_waits"] += len(ready) - len(movers)
        return movers

    def _audit(self, decided: dict[int, int]) -> None:
        """Count a tick at which two robots decided for good, not yet moved, on one cell (staying on it
        included) or on each other's."""
        robots = self.robots
        occupant = self._occupant
        claimed: set[int] = set()
        for index, target in decided.items():
            here = robots[index].present
            other = occupant[target]
            swaps = target != here and other != NO_ROBOT and decided.get(other) == here
            if target in claimed or swaps:
                self.stats["conflicting_decisions"] += 1
                return
            claimed.add(target)

    def _record_steps(self, movers: list[int]) -> None:
        """Check, as the robots end their steps, that no two ended step ``k`` on one cell or trading cells.

        Every robot's step ``k`` goes from the cell it began on to the cell it
        ended on; over the robots that end step ``k`` (at whatever tick), those
        cells must be a move of central PIBT's kind: no cell entered or kept
        by two, no two robots trading cells (``conflicting_steps``).
        """
        robots = self.robots
        for index in movers:
            robot = robots[index]
            assert robot.target is not None
            step, here, there = robot.step, robot.present, robot.target
            ended = self._ended.setdefault(step, {})
            if there in ended or (here != there and ended.get(here) == there):
                self.stats["conflicting_steps"] += 1
            ended[there] = here  # the cell ended on -> the cell begun on
        slowest = min(robot.step for robot in robots)
        for step in [step for step in self._ended if step < slowest]:
            del self._ended[step]  # every robot has ended it: nothing more to check against

    def _result(self, stop_reason: str, wall_time: float) -> RunResult:
        result = super()._result(stop_reason, wall_time)
        counts = {name: sum(robot.stats[name] for robot in self.robots) for name in ROBOT_COUNTS}
        counts.update({name: self.stats[name] for name in SIMULATOR_COUNTS})
        result.network.update(counts)
        return result
