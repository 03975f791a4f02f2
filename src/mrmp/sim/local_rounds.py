"""Synchronous rounds without a sequencer: the simulator of ``pibt`` with local sequencing.

The robots are :class:`~mrmp.robot.pibt_local.LocalPibtRobot` brains, which
decide among themselves whose PIBT call runs when. This driver is only a
radio, a network and a clock:

* the *radio* turns a broadcast of radius ``r`` into datagrams to the robots
  whose bodies stand within ``r`` cells (Manhattan) of the sender's body (the
  physical world, read from the bodies' cells, never from a brain);
* every message is encoded (:func:`mrmp.protocol.codec.encode`) and crosses
  the scenario's seeded :class:`~mrmp.sim.network.SimulatedNetwork`, as for
  the other policies, and is decoded by its recipient;
* the *clock*: a message of delay 0 arrives within the tick it was sent, in
  the next round. A round delivers everything due, then every robot that got
  something to act on, or asked for the round (its one-round timer,
  :attr:`~mrmp.robot.pibt_local.LocalPibtRobot.wake`), acts. When nothing is
  due and no timer is set, the tick ends; every robot moves if it decided for
  good, else stays (and counts an abandoned step itself).

Nobody sorts the robots, finds their groups or waits for them to finish: the
order of calls is the robots' own (``docs/protocol.md``, "Local sequencing").

Over a network that loses, delays, duplicates or reorders, the one-round
provisional reservation no longer holds (a round's messages may not arrive in
that round), so the robots are :class:`~mrmp.robot.pibt_reliable.ReliablePibtRobot`
brains, which acknowledge and retransmit themselves; the clock then gives every
step ``step_ticks`` ticks (by default :data:`STEP_RETRIES` retry intervals of
``2 * delay_max + 1`` ticks), after which the robots that decided for good move
(``docs/protocol.md``, "Over a faulty network").

Deterministic for a seed.

Examples
--------
>>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
>>> swap = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))),
...                 policy=PolicyOptions(name="pibt"))
>>> result = LocalRoundsSimulator(swap).run()
>>> result.success, result.makespan, result.sum_of_costs, result.lower_bound
(True, 7, 11, 8)
>>> result.network["abandoned"], result.network["sent"] == result.network["delivered"]
(0, True)
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any

from mrmp.core.errors import InputError
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.protocol.codec import decode, encode
from mrmp.protocol.messages import BeaconMessage, Message, PibtMessage
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_local import LocalPibtRobot
from mrmp.robot.pibt_reliable import ReliablePibtRobot
from mrmp.robot.pibt_robot import RESERVE_RADIUS
from mrmp.sim.metrics import default_max_ticks
from mrmp.sim.rounds import NO_ROBOT, RoundsSimulator
from mrmp.sim.ticking import TickObserver, run_result, scenario_network

__all__ = ["STEP_RETRIES", "LocalRoundsSimulator"]

STEP_RETRIES = 8
"""Over a faulty network a step lasts this many retry intervals (``2 * delay_max + 1`` ticks each) by default."""

ROBOT_COUNTS = (
    "waits", "withdrawn", "refused", "passed_busy", "settled_at_once", "abandoned", "acks", "retransmissions",
    "aborted", "blocked",
)  # fmt: skip
"""What the robots count themselves, reported in the result's ``network``."""


def _take_in(batch: list[tuple[int, int, bytes]], receivers: Sequence[Callable[[Any], bool]], acting: dict[int, None]) -> None:
    """Decode every datagram of ``batch`` (once per payload) and hand it to its recipient's receiver.

    The recipients whose receiver asks to act (returns True) are added to ``acting``, in order.
    """
    decoded: dict[int, Message] = {}
    for _, recipient, payload in batch:
        message = decoded.get(id(payload))
        if message is None:
            message = decoded[id(payload)] = decode(payload)
            assert isinstance(message, PibtMessage), "a PIBT robot sends PIBT messages"
        if receivers[recipient](message):
            acting[recipient] = None


class LocalRoundsSimulator(RoundsSimulator):
    """Runs a scenario with robots that sequence their PIBT calls themselves (module docstring).

    Parameters are those of :class:`~mrmp.sim.rounds.RoundsSimulator`.

    ``step_ticks`` (faulty networks only; None for the default) is the length
    of a step in ticks. A scenario with a task stream (a League of Robot
    Runners problem) lasts ``max_ticks`` steps, that is ``max_ticks x
    step_ticks`` ticks, since its limit counts the competition's steps.

    Raises
    ------
    InputError
        If ``step_ticks`` is below 1.
    """

    robot_type = LocalPibtRobot
    """The brain over a perfect network."""
    reliable_type: type[ReliablePibtRobot] = ReliablePibtRobot
    """The brain over a faulty network."""
    robots: list[LocalPibtRobot]  # type: ignore[assignment]
    steps_take_step_ticks = True
    """Whether every step lasts ``step_ticks`` ticks (a simulator whose robots end their own steps says no)."""

    def __init__(
        self,
        scenario: Scenario,
        random_ties: bool = True,
        on_tick: TickObserver | None = None,
        tie_penalties: bool | None = None,
        step_ticks: int | None = None,
    ) -> None:
        self.perfect = scenario.perfect_network
        worst = scenario.worst_faults()
        self.retry = 2 * worst.delay_max + 1
        if step_ticks is None:
            step_ticks = 1 if self.perfect else STEP_RETRIES * self.retry
        if step_ticks < 1:
            raise InputError(f"step_ticks: must be at least 1, got {step_ticks}")
        self.step_ticks = step_ticks
        if not self.perfect:
            self.robot_type = self.reliable_type
        super().__init__(scenario, random_ties, on_tick, tie_penalties)
        if scenario.tasks is not None and scenario.max_ticks is not None and self.steps_take_step_ticks:
            self.max_ticks = scenario.max_ticks * step_ticks  # a task stream's run (LoRR's) lasts its steps
        for robot in self.robots:
            if isinstance(robot, ReliablePibtRobot):
                robot.retry = self.retry
        self.network = scenario_network(scenario)
        self._everyone = range(len(self.robots))
        self._hearers: dict[tuple[int, int], tuple[int, ...]] = {}

    def _default_max_ticks(self) -> int:
        """Room for PIBT's steps (:func:`~mrmp.sim.metrics.default_max_ticks`) of ``step_ticks`` each; twice that when faulty."""
        ticks = default_max_ticks(self.scenario.with_changes(safety=False), self.lengths) * self.step_ticks
        return ticks if self.perfect else 2 * ticks

    encode_perfect = False
    """Send every message through the codec and the network on a perfect network too (slower; same decisions)."""

    def step(self) -> None:
        """One PIBT step: beacons, rounds until nothing is due and no timer is set, then the moves."""
        if not self.perfect:
            self._timed_step()
            return
        self.step_count += 1
        step = self.step_count
        robots = self.robots
        self._place_bodies()
        if self.encode_perfect:
            self._encoded_rounds(step)
            return
        receivers = self._receivers  # a perfect network: every message once, in the next round, unchanged
        address = self._address
        results = self._results
        sizes = self._sizes
        sent = sent_bytes = 0
        due: list[tuple[tuple[int, ...], Message]] = []
        for robot in robots:
            index = robot.index
            for item in robot.begin_step(step):
                hearers = address(index, item)
                count = len(hearers)
                size = sizes[type(item.message)] * count
                results[index].messages_sent += count
                results[index].bytes_sent += size
                sent += count
                sent_bytes += size
                if hearers:
                    due.append((hearers, item.message))
        if due and all(type(message) is BeaconMessage for _, message in due):
            heard: list[list[BeaconMessage]] = [[] for _ in robots]  # the beacon round, one call per recipient
            for hearers, message in due:
                for recipient in hearers:
                    heard[recipient].append(message)  # type: ignore[arg-type]
            for robot, beacons in zip(robots, heard):
                if beacons:
                    robot.receive_beacons(beacons)
            due = []
        woken = [robot.index for robot in robots if robot.wake]
        rounds = 0
        while due or woken:
            rounds += 1
            acting = dict.fromkeys(woken)
            for hearers, message in due:
                for recipient in hearers:
                    if receivers[recipient](message):
                        acting[recipient] = None
            due = []
            woken = []
            for index in acting:
                robot = robots[index]
                out = robot.act()
                if out:
                    result = results[index]
                    for item in out:
                        hearers = address(index, item)
                        count = len(hearers)
                        size = sizes[type(item.message)] * count
                        result.messages_sent += count
                        result.bytes_sent += size
                        sent += count
                        sent_bytes += size
                        if hearers:
                            due.append((hearers, item.message))
                if robot.wake:
                    woken.append(index)
        stats = self.network.stats
        stats.sent += sent
        stats.delivered += sent
        stats.bytes_sent += sent_bytes
        stats.bytes_delivered += sent_bytes
        self.stats["rounds"] += rounds
        self._advance(moves=True)

    def _place_bodies(self) -> None:
        """Note which robot's body stands on every cell this step (the radio's physical world)."""
        occupant = self._occupant = [NO_ROBOT] * len(self.flat.neighbours)
        self._hearers = {}
        for robot in self.robots:
            occupant[robot.present] = robot.index

    def _encoded_rounds(self, step: int) -> None:
        """:meth:`step` with every message encoded, sent through the network and decoded by its recipient."""
        robots = self.robots
        now = self.tick
        send = self._send
        for robot in robots:
            for item in robot.begin_step(step):
                send(robot.index, item, now)
        woken = [robot.index for robot in robots if robot.wake]
        network = self.network
        receivers = self._receivers  # a perfect network: every datagram once, in its step
        rounds = 0
        while True:
            batch = network.deliver(now)
            if not batch and not woken:
                break
            rounds += 1
            acting = dict.fromkeys(woken)
            _take_in(batch, receivers, acting)
            woken = []
            for index in acting:
                robot = robots[index]
                for item in robot.act():
                    send(index, item, now)
                if robot.wake:
                    woken.append(index)
        self.stats["rounds"] += rounds
        self._advance(moves=True)

    def _timed_step(self) -> None:
        """One step over a faulty network: ``step_ticks`` ticks of deliveries, timers and rounds, then the moves."""
        self.step_count += 1
        step = self.step_count
        robots = self.robots
        self._place_bodies()
        occupant = self._occupant
        send = self._send
        within = self._within
        reliable = [robot for robot in robots if isinstance(robot, ReliablePibtRobot)]
        for brain in reliable:
            sensed = [cell for cell in within(brain.present, RESERVE_RADIUS) if occupant[cell] != NO_ROBOT]
            for item in brain.begin_step(step, sensed, self.tick):
                send(brain.index, item, self.tick)
        for tick_of_step in range(self.step_ticks):
            now = self.tick
            if tick_of_step:
                for brain in reliable:
                    for item in brain.on_tick(now):
                        send(brain.index, item, now)
            for robot in robots:
                for item in robot.act():
                    send(robot.index, item, now)
            self._deliver_rounds(now)
            if self.tick >= self.max_ticks:
                return
            self._advance(moves=tick_of_step == self.step_ticks - 1)

    def _deliver_rounds(self, now: int) -> None:
        """Deliver what is due at ``now`` and let the recipients act, until nothing more is due this tick."""
        robots = self.robots
        network = self.network
        send = self._send
        receivers = [robot.receive for robot in robots]  # checks for stale messages and second copies
        while True:
            batch = network.deliver(now)
            if not batch:
                return
            self.stats["rounds"] += 1
            acting: dict[int, None] = {}
            _take_in(batch, receivers, acting)
            for index in acting:
                for item in robots[index].act():
                    send(index, item, now)

    def _address(self, sender: int, item: Outgoing) -> tuple[int, ...]:
        """The recipients of ``item``: its named ones, or by radio the bodies within its radius of the sender's."""
        recipients = item.recipients
        if recipients is not None:
            return recipients
        assert item.radius is not None, "a PIBT robot broadcasts within a radius"
        key = (sender, item.radius)
        hearers = self._hearers.get(key)
        if hearers is None:  # the bodies stand still during a step: who hears whom is found once
            occupant = self._occupant
            cells = self._within(self.robots[sender].present, item.radius)
            hearers = self._hearers[key] = tuple(other for cell in cells if (other := occupant[cell]) != NO_ROBOT)
        return hearers

    def _send(self, sender: int, item: Outgoing, now: int) -> None:
        """Hand ``item``, encoded, to the network for its recipients (:meth:`_address`)."""
        recipients = self._address(sender, item)
        payload = encode(item.message)
        network_send = self.network.send
        for recipient in recipients:
            network_send(sender, recipient, payload, now)
        result = self._results[sender]
        result.messages_sent += len(recipients)
        result.bytes_sent += len(payload) * len(recipients)

    def _result(self, stop_reason: str, wall_time: float) -> RunResult:
        for index, result in enumerate(self._results):
            result.time_s = sum(self._durations[index][: result.cost])
        counts: Counter[str] = Counter()
        for robot in self.robots:
            counts.update(robot.stats)
        network = {name: int(value) for name, value in sorted(self.stats.items())}
        network.update(self.network.stats.as_dict())
        network.update({name: counts[name] for name in ROBOT_COUNTS})
        network["steps"] = self.step_count
        network["messages"] = sum(result.messages_sent for result in self._results)
        network["dropped_by_robots"] = sum(sum(robot.dropped.values()) for robot in self.robots)
        network["distance_tables"] = self.flat.tables_computed
        return run_result(self, self._results, "pibt", stop_reason, wall_time, network, planning_time_s=self.flat.table_seconds)
