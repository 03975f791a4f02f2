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
Only a perfect network is run: the one-round provisional reservation rests on
every round's messages arriving in that round (a lossy or slow network is
refused with a one-line error; ``pibt``'s default, sequenced driver,
:mod:`mrmp.sim.rounds`, runs those).

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

from mrmp.core.errors import InputError
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.protocol.codec import decode, encode
from mrmp.protocol.messages import Message
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_local import LocalPibtRobot
from mrmp.sim.rounds import NO_ROBOT, RoundsSimulator
from mrmp.sim.ticking import TickObserver, link_faults, run_result, scenario_network

__all__ = ["LocalRoundsSimulator"]

ROBOT_COUNTS = ("waits", "withdrawn", "refused", "passed_busy", "abandoned")
"""What the robots count themselves, reported in the result's ``network``."""


class LocalRoundsSimulator(RoundsSimulator):
    """Runs a scenario with robots that sequence their PIBT calls themselves (module docstring).

    Parameters are those of :class:`~mrmp.sim.rounds.RoundsSimulator`.

    Raises
    ------
    InputError
        If the scenario's network is not perfect.
    """

    robot_type = LocalPibtRobot
    robots: list[LocalPibtRobot]  # type: ignore[assignment]

    def __init__(
        self,
        scenario: Scenario,
        random_ties: bool = True,
        on_tick: TickObserver | None = None,
        tie_penalties: bool | None = None,
    ) -> None:
        if not scenario.network.is_perfect or link_faults(scenario):
            raise InputError("network: local sequencing of pibt runs over a perfect network only")
        super().__init__(scenario, random_ties, on_tick, tie_penalties)
        self.network = scenario_network(scenario)
        self._everyone = range(len(self.robots))

    def step(self) -> None:
        """One PIBT step: beacons, rounds until nothing is due and no timer is set, then the moves."""
        self.step_count += 1
        step = self.step_count
        robots = self.robots
        occupant = self._occupant = [NO_ROBOT] * len(self.flat.neighbours)
        for robot in robots:
            occupant[robot.present] = robot.index
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
            decoded: dict[int, Message] = {}
            for _, recipient, payload in batch:
                message = decoded.get(id(payload))
                if message is None:
                    message = decoded[id(payload)] = decode(payload)
                if receivers[recipient](message):
                    acting[recipient] = None
            woken = []
            for index in acting:
                robot = robots[index]
                for item in robot.act():
                    send(index, item, now)
                if robot.wake:
                    woken.append(index)
        self.stats["rounds"] += rounds
        self._advance(moves=True)

    def _send(self, sender: int, item: Outgoing, now: int) -> None:
        """Hand ``item`` to the network: to its named recipients, or by radio to the bodies within its radius."""
        recipients = item.recipients
        if recipients is None:
            assert item.radius is not None, "a PIBT robot broadcasts within a radius"
            occupant = self._occupant
            cells = self._within(self.robots[sender].present, item.radius)
            recipients = tuple(other for cell in cells if (other := occupant[cell]) != NO_ROBOT)
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
