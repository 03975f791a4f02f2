"""The live fleet on a virtual clock: every robot's live driver, brain, safety layer and body, unchanged, in one process.

Two cores cannot host hundreds of robot processes, so what a live fleet of 200
or 1,000 robots does cannot be measured with processes here. This module runs
the very objects a robot process runs (:data:`mrmp.live.process.LIVE_DRIVERS`:
the driver, its sans-IO brain and safety layer, a
:class:`~mrmp.live.body.SimulatedBody`, the sealed and authenticated envelope)
with the clock they are given reading a virtual time instead of the wall
clock, and the datagrams they send crossing a simulated network instead of
sockets. The main loop of each driver is the one a process runs
(:meth:`~mrmp.live.driver.LiveDriver.fleet_wait_turn`,
:meth:`~mrmp.live.driver.LiveDriver.turn`), and it sleeps by the same rule
(:meth:`~mrmp.live.driver.LiveDriver.wake_rule`): until its next timer, or
until a message arrives when its timers are idle.

What the harness adds is what a real fleet has and a single process does not:

* **a network** (:class:`VirtualNetwork`): each datagram arrives after a
  ``latency`` plus a delay drawn from the faults' range, is lost or duplicated
  with the faults' probabilities (seeded), and goes to one peer or every peer,
  or (with ``multicast``, as a multicast group) to several named peers at once,
  each of whom misses it or not on its own; over multicast the datagrams are
  those of :class:`~mrmp.live.transport.UdpMulticastTransport`, heads and
  all (:mod:`mrmp.live.multicast_wire`), and each robot takes in what they
  carry for it as that transport does;
* **a computer per robot**: a turn of a robot's main loop takes
  ``costs.turn`` seconds plus ``costs.datagram`` per datagram it took in or sent
  (:class:`ProcessingCosts`); its datagrams leave when the turn ends, and the
  robot's next turn starts no sooner. Each robot has its own processor, as
  each real robot has; nothing is shared but the network.

A lifelong run's task desk (:mod:`mrmp.live.task_desk`) is a member of the
network too, one past the last robot, answering at once what reaches it.

The run writes what a live run writes (``agent-<i>.json``, ``trace-<i>.jsonl``,
``referee.json``, and ``tasks.json`` with a desk) and is judged by the same referee and result builder
(:func:`mrmp.live.process.run_referee`, :func:`mrmp.live.results.live_result`),
its times in virtual seconds; its ``wall_time_s`` is the CPU time the
harness spent, and its ``network`` counts the turns run (``virtual_turns``)
and the datagrams taken in or sent (``virtual_datagrams``), and those that
reached a robot whose process had ended (``virtual_to_ended``). It is
deterministic for a seed: one thread, one seeded network, seeded bodies and
drivers (the fleet key and session only change the bytes, not their fate).

Examples
--------
>>> import tempfile
>>> from pathlib import Path
>>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario, Timing
>>> robots = (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2)))
>>> swap = Scenario(Grid(5, 5), robots, timing=Timing(1.0, 0.5), policy=PolicyOptions(name="pibt"))
>>> result = run_virtual(swap, VirtualOptions(results=Path(tempfile.mkdtemp()), time_scale=10))
>>> result.success, result.collisions, result.mode
(True, [], 'live')
"""

from __future__ import annotations

import heapq
import itertools
import math
import os
import random
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from mrmp.core.errors import InputError, Problem
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.core.seeds import Stream, derive_seed
from mrmp.io.lifetime import interrupted_once
from mrmp.io.live_files import TraceWriter, read_json, write_json
from mrmp.live.body import OccupancyRecorder
from mrmp.live.driver import AgentTiming, LiveDriver
from mrmp.live.launcher import check_tasks, run_timeout, with_desk
from mrmp.live.multicast_wire import Addressed, datagrams_together, payloads_for, recipients_head
from mrmp.live.process import LIVE_DRIVERS, DriverOptions, driver_kind, fleet_timing, run_referee, simulated_body
from mrmp.live.results import live_result
from mrmp.live.task_desk import TaskDesk
from mrmp.live.transport import FaultCounts, LiveFaults
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.tasks import TaskReportMessage
from mrmp.search.flat_map import FlatMap
from mrmp.sim.policy_table import body_problem

__all__ = ["ProcessingCosts", "VirtualNetwork", "VirtualOptions", "run_virtual"]


@dataclass(frozen=True)
class ProcessingCosts:
    """Seconds of a robot's processor: per turn of its main loop, and per datagram it takes in or sends.

    The defaults are of the order this machine's robot processes spend
    (``bench/live_virtual.py`` measures the harness's own cost per turn and per
    datagram, which is the same code). A turn must cost some time: a driver
    whose timers are due turns again at once, as a process does, and only the
    turn's cost moves its clock on.

    >>> ProcessingCosts(turn=0.0)
    Traceback (most recent call last):
    ...
    ValueError: processing costs: a turn must take some time and a datagram none or more, got 0.0, 3e-05
    """

    turn: float = 50e-6
    datagram: float = 30e-6

    def __post_init__(self) -> None:
        if not self.turn > 0 or not self.datagram >= 0:
            raise ValueError(
                f"processing costs: a turn must take some time and a datagram none or more, got {self.turn}, {self.datagram}"
            )  # a driver whose timers are due polls again at once: with no cost, virtual time would stand still


@dataclass(frozen=True)
class VirtualOptions:
    """How a fleet runs on the virtual clock (module docstring); the live run's options where they are the same."""

    results: Path
    time_scale: float = 1.0
    faults: LiveFaults = field(default_factory=LiveFaults)
    jitter: float = 0.0
    seed: int = 0
    latency: float = 200e-6
    """Seconds a datagram takes on a perfect network (loopback is about 50 microseconds, a wireless LAN a few ms)."""
    multicast: bool = False
    """Whether one datagram reaches several named peers, as over multicast (the robots then send the messages of
    a turn for named peers together, where unicast sends one datagram per message and peer:
    :attr:`~mrmp.live.driver.AgentReport.datagrams_sent`)."""
    costs: ProcessingCosts = field(default_factory=ProcessingCosts)
    timing: AgentTiming = field(default_factory=AgentTiming)
    timeout: float | None = None
    """Virtual seconds before every robot stops (None: as a live run's launcher chooses)."""


class VirtualNetwork:
    """The simulated network of a virtual fleet: datagrams with a latency, seeded loss, delay and duplication.

    >>> network = VirtualNetwork(3, LiveFaults(), latency=0.001, seed=0)
    >>> network.post(0, b"hello", None, at=1.0)
    >>> network.next_arrival(), [(recipient, data) for _, recipient, data in network.take_due(2.0)]
    (1.001, [(1, b'hello'), (2, b'hello')])
    """

    def __init__(self, robots: int, faults: LiveFaults, latency: float, seed: int, services: int = 0) -> None:
        self.robots = robots
        """The robots, members ``0 .. robots - 1``: a datagram to every peer reaches them."""
        self.faults = faults
        self.latency = latency
        self.random = random.Random(seed)
        self.counts = [FaultCounts() for _ in range(robots + services)]
        """Per member (the robots, then ``services`` more reached by their index only, as a task desk is)."""
        self._queue: list[tuple[float, int, int, bytes]] = []
        self._order = itertools.count()

    def post(self, sender: int, data: bytes, recipient: int | tuple[int, ...] | None, at: float) -> None:
        """``sender`` sends ``data`` at time ``at`` to ``recipient`` (several, when a tuple), or to every other
        robot when None; each recipient's copy meets its own fate."""
        recipients = range(self.robots) if recipient is None else recipient if isinstance(recipient, tuple) else (recipient,)
        faults, rng, counts = self.faults, self.random, self.counts[sender]
        for peer in recipients:
            if peer == sender:
                continue
            counts.sent += 1
            if faults.loss and rng.random() < faults.loss:
                counts.lost += 1
                continue
            copies = 1
            if faults.duplicate and rng.random() < faults.duplicate:
                counts.duplicated += 1
                copies = 2
            for _ in range(copies):
                delay = self.latency
                if faults.delay_max > 0:
                    delay += rng.uniform(faults.delay_min, faults.delay_max)
                    counts.delayed += 1
                heapq.heappush(self._queue, (at + delay, next(self._order), peer, data))

    def next_arrival(self) -> float:
        """When the next datagram arrives (``inf``: none is on its way)."""
        return self._queue[0][0] if self._queue else math.inf

    def take_due(self, now: float) -> Iterator[tuple[float, int, bytes]]:
        """The datagrams that have arrived by ``now``, in order of arrival: ``(time, recipient, data)``."""
        queue = self._queue
        while queue and queue[0][0] <= now:
            arrival, _, recipient, data = heapq.heappop(queue)
            yield arrival, recipient, data


class _Outbox:
    """A virtual robot's datagrams of one turn, held until the turn's processing ends (:class:`~mrmp.live.driver.Sending`).

    Over multicast, each is the datagram the multicast transport would send, its head and all.
    """

    def __init__(self, multicast: bool) -> None:
        self.datagrams: list[tuple[bytes, int | tuple[int, ...] | None]] = []
        """Each datagram, and whom it reaches: one robot, several, or every one (None)."""
        self.multicast = multicast

    @property
    def reaches_several(self) -> bool:
        return self.multicast

    def start(self) -> None:
        """Nothing to start: the harness sends."""

    def send(self, data: bytes, recipient: int | None) -> None:
        if self.multicast:
            data = recipients_head(() if recipient is None else (recipient,)) + data
        self.datagrams.append((data, recipient))

    def send_together(self, messages: Sequence[Addressed]) -> None:
        if not self.multicast:
            raise TypeError("a unicast network does not reach several peers with one datagram")
        self.datagrams.extend(datagrams_together(messages))

    def close(self) -> None:
        """Nothing to flush: the harness sends after every turn."""


@dataclass
class _Robot:
    """One robot of the virtual fleet: its driver, where its main loop stands, and when it next runs."""

    driver: LiveDriver
    outbox: _Outbox
    trace: TraceWriter
    done: bool = False
    wake_at: float = 0.0
    woken_by_messages: bool = True
    busy_until: float = 0.0
    version: int = 0
    """Bumped whenever ``wake_at`` changes: a queued wake-up of another version is stale."""


class _VirtualFleet:
    """The robots, the network and the clock of one virtual run (module docstring)."""

    def __init__(self, scenario: Scenario, options: VirtualOptions) -> None:
        self.scenario = scenario
        self.options = options
        self.now = 0.0
        robots = len(scenario.robots)
        desk = scenario.tasks is not None
        network_seed = derive_seed(options.seed, Stream.LIVE_FAULTS, 0)
        self.network = VirtualNetwork(robots, options.faults, options.latency, network_seed, services=desk)
        key, session = os.urandom(32), random.Random(options.seed).randrange(1, 2**31)
        timing = fleet_timing(options.timing, robots)
        self.timing = replace(timing, timeout=options.timeout or run_timeout(scenario, options.time_scale))
        kind = LIVE_DRIVERS[driver_kind(scenario, following_plan=False)]
        shared = DriverOptions(self.timing, options.seed, flat=FlatMap(scenario.grid))  # one copy of the map's tables
        self.robots: list[_Robot] = []
        for index in range(robots):
            trace = TraceWriter(options.results / f"trace-{index}.jsonl", index)
            recorder = OccupancyRecorder(trace.write, heading_sink=trace.write_heading)
            body = simulated_body(scenario, index, recorder, options.time_scale, options.jitter, seed=options.seed)
            sealer, opener = Sealer(key, session), Opener(key, session, fleet_size=robots + desk)
            driver = kind(scenario, index, _NoSockets(), body, sealer, opener, shared, None)
            driver.clock = self.clock
            outbox = _Outbox(options.multicast)
            driver.send_through(outbox)
            self.robots.append(_Robot(driver, outbox, trace))
        self._wakes: list[tuple[float, int, int]] = [(0.0, index, 0) for index in range(robots)]
        self.desk: TaskDesk | None = None
        if scenario.tasks is not None and scenario.max_ticks is not None:
            starts = [spec.start for spec in scenario.robots]
            self.desk = TaskDesk(scenario.tasks, scenario.grid, starts, scenario.max_ticks, flat=shared.flat)
            self._desk_envelope = Sealer(key, session), Opener(key, session, fleet_size=robots)
            self._desk_version = 0
            self._wake_desk(0.0)
        self.turns = 0
        """Turns of the robots' main loops run."""
        self.datagrams = 0
        """Datagrams the robots took in or sent."""
        self.to_ended = 0
        """Datagrams that reached a robot whose process had ended (lost on it)."""
        self.stopped = 0
        """Robots whose run is over."""

    def clock(self) -> float:
        """The virtual time: what every driver's clock reads."""
        return self.now

    def run(self, writing: Callable[[], None] = lambda: None) -> None:
        """Run every robot until each has stopped, the virtual timeout passes, or Ctrl-C (what was done is kept);
        ``writing`` is called once the loop is over (the reports are filled in from then on)."""
        for robot in self.robots:
            robot.driver.begin_fleet_wait(0.0)
        end = self.timing.timeout + self.timing.start_wait + 1.0
        network = self.network
        unfinished = "timeout"
        try:
            while self.stopped < len(self.robots) and (self._wakes or network.next_arrival() < math.inf):
                next_robot = self._wakes[0][0] if self._wakes else math.inf
                self.now = min(next_robot, network.next_arrival())
                if self.now > end:
                    break
                if network.next_arrival() <= next_robot:
                    for arrival, recipient, data in network.take_due(self.now):
                        self._deliver(recipient, data, arrival)
                    continue
                _, index, version = heapq.heappop(self._wakes)
                if index == len(self.robots):
                    if version == self._desk_version:
                        self._desk_turn()
                    continue
                robot = self.robots[index]
                if version == robot.version and not robot.done:
                    self._turn(index, robot)
        except KeyboardInterrupt:
            unfinished = "interrupted"
        writing()
        for robot in self.robots:
            if not robot.done:
                robot.driver.report.stop_reason = unfinished
                robot.driver.fill_report(self.now)
                robot.done = True

    def _deliver(self, recipient: int, data: bytes, arrival: float) -> None:
        if recipient == len(self.robots):
            self._desk_takes(data, arrival)
            return
        robot = self.robots[recipient]
        if robot.done:
            self.to_ended += 1
            return  # its process has ended
        if self.options.multicast:
            for message in payloads_for(data, recipient, len(self.robots)):
                robot.driver.take_datagram(message)
        else:
            robot.driver.take_datagram(data)
        if robot.woken_by_messages and robot.wake_at > arrival:
            self._schedule(recipient, robot, max(arrival, robot.busy_until), woken_by_messages=False)

    def _turn(self, index: int, robot: _Robot) -> None:
        """One turn of the robot's main loop at the current time; its datagrams leave when its processing ends."""
        driver, report, now = robot.driver, robot.driver.report, self.now
        taken_in, sent = report.messages_received, report.datagrams_sent
        wake = driver.main_turn(now)
        datagrams = report.messages_received - taken_in + report.datagrams_sent - sent
        self.turns += 1
        self.datagrams += datagrams
        costs = self.options.costs
        robot.busy_until = now + costs.turn + costs.datagram * datagrams
        for data, recipient in robot.outbox.datagrams:
            self.network.post(index, data, recipient, at=robot.busy_until)
        robot.outbox.datagrams.clear()
        if wake is None:
            robot.done = True
            self.stopped += 1
            driver.fill_report(now)
            return
        at, woken_by_messages = driver.wake_rule(now, wake, timers=driver.running)
        self._schedule(index, robot, max(at, robot.busy_until), woken_by_messages)

    def _desk_takes(self, data: bytes, arrival: float) -> None:
        """The desk answers what reached it at once (a datagram not a task report is counted by its opener)."""
        assert self.desk is not None
        sealer, opener = self._desk_envelope
        report = opener.open(data)
        if isinstance(report, TaskReportMessage):
            self.network.post(self.desk.index, sealer.seal(self.desk.take(report)), report.sender, at=arrival)
            self._wake_desk(arrival)  # a task finished may have given others a task to tell

    def _desk_turn(self) -> None:
        """The desk tells the robots the tasks they have not named yet; it wakes again for the next."""
        assert self.desk is not None
        sealer = self._desk_envelope[0]
        for robot, message in self.desk.due(self.now):
            self.network.post(self.desk.index, sealer.seal(message), robot, at=self.now)
        self._wake_desk(self.desk.next_due())

    def _wake_desk(self, at: float) -> None:
        """Wake the desk at ``at`` (at once if that is past; never when ``inf``), instead of when it was to wake."""
        if at < math.inf:
            self._desk_version += 1
            heapq.heappush(self._wakes, (max(at, self.now), len(self.robots), self._desk_version))

    def _schedule(self, index: int, robot: _Robot, at: float, woken_by_messages: bool) -> None:
        robot.version += 1
        robot.wake_at, robot.woken_by_messages = at, woken_by_messages
        heapq.heappush(self._wakes, (at, index, robot.version))

    def finish(self) -> list[dict]:
        """Every robot's report, written as a live robot writes it (its injected faults included)."""
        reports = []
        for index, robot in enumerate(self.robots):
            robot.trace.close()
            report = robot.driver.report
            report.faults = dict(self.network.counts[index].__dict__)
            written = report.as_dict()
            write_json(self.options.results / f"agent-{index}.json", written)
            reports.append(written)
        return reports


class _NoSockets:
    """The transport of a virtual robot: it has none (its driver sends through the harness, which delivers)."""

    def send(self, data: bytes, recipient: int | None = None) -> None:
        raise RuntimeError("a virtual robot sends through its harness")

    def receive(self, timeout: float) -> bytes | None:
        return None

    def close(self) -> None:
        """Nothing to release."""


def run_virtual(scenario: Scenario, options: VirtualOptions) -> RunResult:
    """Run ``scenario``'s live fleet on a virtual clock (module docstring); return the judged result.

    Raises
    ------
    InputError
        If the scenario's robots cannot run live in its body model, or the
        results folder cannot be made.
    """
    body_issue = body_problem(scenario, live=True)
    if body_issue is not None:
        raise InputError(body_issue)
    check_tasks(scenario, "multicast" if options.multicast else "udp", planned=False)
    try:
        options.results.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise InputError(Problem("--results", f"cannot make {options.results}: {error.strerror}")) from None
    for stale in (*options.results.glob("agent-*.json"), *options.results.glob("trace-*.jsonl"), options.results / "tasks.json"):
        stale.unlink(missing_ok=True)
    with interrupted_once() as writing:  # a second stop signal does not cut the writing of what was done short
        return _run_and_judge(scenario, options, writing)


def _run_and_judge(scenario: Scenario, options: VirtualOptions, writing: Callable[[], None]) -> RunResult:
    """:func:`run_virtual` from the fleet's start: run it, then (``writing`` called: no longer interruptible) write
    every report, have the referee judge and return the result."""
    started = time.process_time()
    fleet = _VirtualFleet(scenario, options)
    fleet.run(writing)
    reports = fleet.finish()
    start_time = min(float(report["started_at"]) for report in reports)
    run_referee(scenario, options.results, start_time, None, lambda text: None, stop=threading.Event())
    verdict = read_json(options.results / "referee.json")
    stop_reasons = {str(report["stop_reason"]) for report in reports}
    stop_reason = "all arrived" if stop_reasons <= {"all arrived", "arrived; peers silent"} else ", ".join(sorted(stop_reasons))
    result = live_result(
        scenario,
        reports,
        verdict,
        stop_reason=stop_reason,
        wall_time_s=time.process_time() - started,
        tick_seconds=scenario.timing.cell_time / options.time_scale / 4,
        time_scale=options.time_scale,
    )
    harness = {"virtual_turns": fleet.turns, "virtual_datagrams": fleet.datagrams, "virtual_to_ended": fleet.to_ended}
    result = replace(result, network={**result.network, **harness})
    if fleet.desk is None:
        return result
    write_json(options.results / "tasks.json", fleet.desk.summary())
    return with_desk(result, fleet.desk, verdict)

