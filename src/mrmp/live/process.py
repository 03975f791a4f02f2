"""Running a robot, or the referee, as an OS process: transports, keys, signals, files.

:func:`run_agent` is what ``mrmp agent`` runs on each robot's computer;
:func:`run_referee` is what ``mrmp referee`` runs beside the fleet. Both write
their results to a folder as they go, and both stop cleanly on SIGINT or
SIGTERM, writing what they have. Both also stop when the process that started
them ends, however it ends (:mod:`mrmp.io.lifetime`).
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.errors import InputError, Problem
from mrmp.core.result import Collision
from mrmp.core.scenario import Scenario
from mrmp.core.seeds import Stream, derive_seed, stream_random
from mrmp.io.lifetime import STOP_SIGNALS, release_held_signals, watch_parent
from mrmp.io.live_files import TraceReader, TraceWriter, write_json
from mrmp.io.plans import read_share, read_share_dependents
from mrmp.live.action_referee import TurningActions
from mrmp.live.agent import Agent, AgentReport, AgentTiming
from mrmp.live.body import Body, OccupancyRecorder, OdometryLineBody, SimulatedBody
from mrmp.live.causal_agent import CausalAgent
from mrmp.live.diff_drive import body_geometry
from mrmp.live.host_loop import Hosted, Selectable, run_hosted
from mrmp.live.pibt_agent import PibtAgent
from mrmp.live.referee import IntervalReferee
from mrmp.live.ros2_driver import Ros2Driver, odometry_topic
from mrmp.live.ros2_topics import Ros2Publisher
from mrmp.live.transport import ConnectedTransport, LiveFaults, Transport, is_loopback
from mrmp.live.transport_table import FAULTS, TransportSpec
from mrmp.policies.plan_following import PlanFollowingPolicy
from mrmp.protocol.auth import Opener, Sealer
from mrmp.search.flat_map import FlatMap
from mrmp.sim.policy_table import policy_entry


def check_key_policy(key: bytes | None, spec: TransportSpec, warn: Callable[[str], None]) -> bytes:
    """The key to use; without one, refuse anything but loopback and warn loudly.

    The transport's table entry says which hosts it listens on and sends to;
    each must provably be loopback (:func:`~mrmp.live.transport.is_loopback`):
    an empty host (every interface), an address in another form, or a Zenoh
    endpoint whose reach is not just its host is refused.

    Raises
    ------
    InputError
        If there is no key and the transport reaches beyond loopback.

    >>> from mrmp.live.transport_table import TransportSpec, UdpOptions
    >>> check_key_policy(None, TransportSpec("udp", UdpOptions(("127.0.0.1", 9001))), warn=print)
    WARNING: no fleet key: messages are NOT authenticated; allowed on loopback only
    b''
    >>> check_key_policy(None, TransportSpec("udp", UdpOptions(("10.0.0.1", 9001))), warn=print)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: --key-file: no fleet key: refusing to talk to 10.0.0.1 (only loopback runs may go ...)
    """
    if key:
        return key
    outside = [host for host in spec.hosts() if not is_loopback(host)]
    if outside:
        hosts = ", ".join(host or repr(host) for host in sorted(set(outside)))
        only = "only loopback runs may go without a key; set MRMP_FLEET_KEY or --key-file"
        raise InputError(Problem("--key-file", f"no fleet key: refusing to talk to {hosts} ({only})"))
    warn("WARNING: no fleet key: messages are NOT authenticated; allowed on loopback only")
    return b""


CRASH_SILENCES = 2
"""A robot following a plan takes a peer it waits for for crashed after this many silence timeouts without news
(:mod:`mrmp.policies.plan_following`): a late process, starved of the CPU, is not taken for dead at once."""

PEER_WAIT_SECONDS = 10.0
"""How long a robot whose transport connects first waits for its peers before it starts anyway."""


START_WAIT_PER_ROBOT = 0.5
"""Seconds a robot process waits for its peers before it starts anyway, per robot of the fleet (at least
``AgentTiming.start_wait``): a fleet's processes started at once on one machine share its cores while
they start (each imports Python modules for a good part of a CPU second), so the last one is up long after
the first; a first robot that started without the last would take it for crashed."""


FLEET_STATES_PER_SECOND = 20.0
"""At most this many fleet-heartbeat datagrams a robot sends a second, whatever the fleet's size (and so at most
this many it receives): a fleet of more than this many robots and one spaces its fleet heartbeats further apart
(:func:`fleet_timing`). Sent to every peer once a second, they would cost each of ``N`` processes ``N - 1``
datagrams to receive a second, ``N**2`` in all: at 100 robot processes they alone filled two cores."""


def fleet_timing(timing: AgentTiming, robots: int) -> AgentTiming:
    """``timing`` fitted to a fleet of ``robots``: its start wait, fleet heartbeat and silences.

    * The start wait is at least :data:`START_WAIT_PER_ROBOT` seconds per robot.
    * The fleet heartbeat comes at most :data:`FLEET_STATES_PER_SECOND` times ``robots - 1`` a
      second: its period is at least ``(robots - 1) / FLEET_STATES_PER_SECOND`` seconds.
    * ``silence_timeout`` (a peer silent that long stands still for its peers' policies) and
      ``give_up_after`` (a peer silent that long is given up on; news older than that of a
      peer's arrival is too old to end the run on) stretch with the period, so that they
      still span as many fleet heartbeats: a far peer is heard only by them.

    >>> small, large = fleet_timing(AgentTiming(), 8), fleet_timing(AgentTiming(), 101)
    >>> small.start_wait, small.fleet_heartbeat, small.give_up_after
    (15.0, 1.0, 3.0)
    >>> large.start_wait, large.fleet_heartbeat, large.silence_timeout, large.give_up_after
    (50.5, 5.0, 7.5, 15.0)
    """
    period = max(timing.fleet_heartbeat, (robots - 1) / FLEET_STATES_PER_SECOND)
    stretch = period / timing.fleet_heartbeat
    return replace(
        timing,
        start_wait=max(timing.start_wait, START_WAIT_PER_ROBOT * robots),
        fleet_heartbeat=period,
        silence_timeout=timing.silence_timeout * stretch,
        give_up_after=timing.give_up_after * stretch,
    )


def stop_on_signals() -> threading.Event:
    """An event set by SIGINT or SIGTERM (from then on neither kills the process): install it before any slow work."""
    stop = threading.Event()
    _on_stop_signals(stop.set)
    return stop


def _on_stop_signals(action: Callable[[], None]) -> None:
    """Call ``action`` on SIGINT or SIGTERM, including one the launcher's start held until now (:mod:`mrmp.io.lifetime`)."""
    for signum in STOP_SIGNALS:
        signal.signal(signum, lambda *_: action())
    release_held_signals()


@dataclass(frozen=True)
class DriverOptions:
    """What a live driver takes besides its robot's scenario, transport, body and envelope."""

    timing: AgentTiming
    seed: int = 0
    guarded: bool = True
    flat: FlatMap | None = None
    """The map's distance tables, shared by the robots one process runs (None: each driver makes its own). They
    are a cache of what every robot computes alike from the public map, not any robot's state."""


@dataclass(frozen=True)
class AgentOptions:
    """Everything one robot process needs besides the scenario."""

    index: int
    transport: TransportSpec
    key: bytes
    session: int
    results: Path
    time_scale: float = 1.0
    faults: LiveFaults = field(default_factory=LiveFaults)
    jitter: float = 0.0
    miss_line: float = 0.0
    guarded: bool = True
    follow: bool = True
    """Whether a body that may be followed while it drives is (:attr:`mrmp.live.body.Body.follows`): False keeps
    a cell until the body has arrived elsewhere (a run that kills robots, whose bodies stop mid-drive)."""
    seed: int = 0
    timing: AgentTiming = field(default_factory=AgentTiming)
    plan: Path | None = None
    """This robot's share of a central plan (``mrmp.io.plans.write_share``)."""
    ros2_domain: int | None = None
    """Publish the robot's pose and state on ROS 2 topics in this domain (:mod:`mrmp.live.ros2_topics`); None: not."""
    drive: str = "simulated"
    """The body: ``simulated`` (:class:`~mrmp.live.body.SimulatedBody`), or ``ros2``: a robot's ROS 2 driver
    (:mod:`mrmp.live.ros2_driver`)."""
    drive_domain: int = 0
    """With ``drive="ros2"``: the ROS 2 domain of the robot's driver."""
    drive_wait: float = 30.0
    """With ``drive="ros2"``: seconds to wait for the driver's first odometry before giving up."""


def _per_robot_agent(
    scenario: Scenario,
    index: int,
    transport: Transport,
    body: Body,
    sealer: Sealer,
    opener: Opener,
    options: DriverOptions,
    policy: PlanFollowingPolicy | None,
) -> Agent:
    """The live driver of a per-robot policy (or of a central plan's share)."""
    return Agent(
        scenario, index, transport, body, sealer, opener,
        timing=options.timing, guarded=options.guarded, seed=options.seed, policy=policy,
    )  # fmt: skip


def _causal_agent(
    scenario: Scenario,
    index: int,
    transport: Transport,
    body: Body,
    sealer: Sealer,
    opener: Opener,
    options: DriverOptions,
    policy: PlanFollowingPolicy | None,
) -> CausalAgent:
    """The live driver of Causal-PIBT (always through the safety layer)."""
    return CausalAgent(
        scenario, index, transport, body, sealer, opener, timing=options.timing, seed=options.seed, flat=options.flat
    )


def _pibt_agent(
    scenario: Scenario,
    index: int,
    transport: Transport,
    body: Body,
    sealer: Sealer,
    opener: Opener,
    options: DriverOptions,
    policy: PlanFollowingPolicy | None,
) -> PibtAgent:
    """The live driver of ``pibt``: locally sequenced, in steps on a common clock, always through the safety layer."""
    return PibtAgent(
        scenario, index, transport, body, sealer, opener, timing=options.timing, seed=options.seed, flat=options.flat
    )


LiveDriver = Callable[
    [Scenario, int, Transport, Body, Sealer, Opener, "DriverOptions", "PlanFollowingPolicy | None"],
    "Agent | CausalAgent | PibtAgent",
]

LIVE_DRIVERS: dict[str, LiveDriver] = {"agent": _per_robot_agent, "causal": _causal_agent, "pibt": _pibt_agent}
"""The live drivers by the kind a policy-table entry names (:attr:`mrmp.sim.policy_table.PolicyEntry.live_driver`)."""


def driver_kind(scenario: Scenario, following_plan: bool) -> str:
    """The kind of :data:`LIVE_DRIVERS` entry that runs a robot of ``scenario``.

    A robot following its share of a central plan runs the per-robot driver
    whatever the scenario's policy: the plan replaces the policy.

    >>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
    >>> causal = Scenario(Grid(2, 2), (RobotSpec("A", (0, 0), (1, 1)),), policy=PolicyOptions(name="causal"))
    >>> driver_kind(causal, following_plan=False), driver_kind(causal, following_plan=True)
    ('causal', 'agent')
    """
    if following_plan:
        return "agent"
    return policy_entry(scenario.policy.name).live_driver or "agent"


def run_agent(scenario: Scenario, options: AgentOptions) -> AgentReport:
    """Run one robot until it is done, writing ``agent-<i>.json`` and ``trace-<i>.jsonl`` in ``options.results``."""
    return run_agents(scenario, [options])[0]


def run_agents(scenario: Scenario, robots: Sequence[AgentOptions]) -> list[AgentReport]:
    """Run the robots of ``robots`` in this process until each is done; each writes its report and trace as
    :func:`run_agent` does.

    Each hosted robot has what a robot process has: its own transport (its own
    socket), envelope, body and driver; none reads another's state, and they
    talk only through the network, as robots in processes of their own do. One
    robot runs as a robot process does (its receiving and client threads beside
    its main loop); several run in this thread, their main loops interleaved
    on the real clock (:func:`~mrmp.live.host_loop.run_hosted`). A stop signal,
    or the end of the process that started this one, stops them all.
    """
    with contextlib.ExitStack() as resources:
        hosted = [_HostedRobot.open(scenario, options, resources) for options in robots]

        def stop_all() -> None:
            for robot in hosted:
                robot.agent.request_stop()

        _on_stop_signals(stop_all)
        watch_parent(stop_all)
        for robot in hosted:
            if isinstance(robot.opened, ConnectedTransport):
                _wait_for_peers(robot.opened, len(scenario.robots) - 1, robot.agent.stop_requested)
        try:
            with profiled(robots[0].results / f"profile-{robots[0].index}.prof"):
                if len(hosted) == 1:
                    hosted[0].run()
                else:
                    run_hosted([robot.in_host_loop() for robot in hosted])
        finally:
            for robot in hosted:  # every report on disk, whatever ended the run
                write_json(robot.report_path, robot.agent.report.as_dict())
    return [robot.agent.report for robot in hosted]


@dataclass
class _HostedRobot:
    """One robot run by this process: its options, transport, driver and report file (:func:`run_agents`)."""

    options: AgentOptions
    opened: Transport
    """Its transport as opened (before faults are injected)."""
    agent: Agent | CausalAgent | PibtAgent
    report_path: Path

    @classmethod
    def open(cls, scenario: Scenario, options: AgentOptions, resources: contextlib.ExitStack) -> _HostedRobot:
        """Open the robot's trace, transport and body and make its driver; ``resources`` closes them."""
        options = replace(options, timing=fleet_timing(options.timing, len(scenario.robots)))
        index = options.index
        options.results.mkdir(parents=True, exist_ok=True)
        policy = None
        if options.plan is not None:
            moves, dependencies = read_share(options.plan, scenario.robots[index].id)
            dependents = read_share_dependents(options.plan, scenario.robots[index].id)
            crash_silence = CRASH_SILENCES * options.timing.silence_timeout
            policy = PlanFollowingPolicy(moves, dependencies, dependents, answer_all_pulls=True, crash_silence=crash_silence)
        spec = scenario.robots[index]
        trace = resources.enter_context(contextlib.closing(TraceWriter(options.results / f"trace-{index}.jsonl", index)))
        sink: OccupancySink = trace.write
        if options.ros2_domain is not None:
            ros2 = Ros2Publisher(spec.id, spec.start, spec.heading, domain=options.ros2_domain)
            resources.callback(ros2.close)
            sink = _both(trace.write, ros2.occupancy)
        opened = options.transport.open(index, len(scenario.robots))
        resources.callback(opened.close)  # closing is idempotent: the fault injector closes it too
        transport = FAULTS.wrap(opened, options.faults, seed=derive_seed(options.seed, Stream.LIVE_FAULTS, index))
        if transport is not opened:
            resources.callback(transport.close)  # its thread of late datagrams ends, then the socket closes
        body: Body
        if options.drive == "ros2":
            driver = Ros2Driver(spec.id, spec.start, spec.heading, domain=options.drive_domain, wheel_base=1.0)
            resources.callback(driver.close)
            body = _ros2_body(driver, scenario, index, options, OccupancyRecorder(sink))
        else:
            recorder = OccupancyRecorder(sink, heading_sink=trace.write_heading)
            body = simulated_body(
                scenario, index, recorder, options.time_scale, options.jitter, options.miss_line, options.seed, options.follow
            )
        sealer = Sealer(options.key, options.session)
        members = len(scenario.robots) + scenario.lifelong  # a lifelong fleet's task desk is one more member
        opener = Opener(options.key, options.session, fleet_size=members)
        agent = LIVE_DRIVERS[driver_kind(scenario, following_plan=policy is not None)](
            scenario, index, transport, body, sealer, opener, DriverOptions(options.timing, options.seed, options.guarded), policy
        )
        return cls(options, opened, agent, options.results / f"agent-{index}.json")

    def run(self) -> None:
        """Run the robot until it is done; what it gathered is kept, saying why it stopped, if it fails."""
        path = self.report_path
        try:
            self.agent.run(on_progress=lambda report: write_json(path, report.as_dict(), compact=True))
        except Exception as error:
            self.agent.report.stop_reason = f"crashed: {type(error).__name__}: {error}"
            write_json(path, self.agent.report.as_dict())
            raise

    def in_host_loop(self) -> Hosted:
        """The robot as :func:`~mrmp.live.host_loop.run_hosted` runs it: its socket watched, its report written as
        it goes."""
        if not isinstance(self.opened, Selectable):
            raise InputError(Problem("--robot", "several robots to a process need transports with a socket each"))
        path = self.report_path
        return Hosted(self.agent, self.opened, on_progress=lambda report: write_json(path, report.as_dict(), compact=True))


def simulated_body(
    scenario: Scenario,
    index: int,
    recorder: OccupancyRecorder,
    time_scale: float,
    jitter: float = 0.0,
    miss_line: float = 0.0,
    seed: int = 0,
    follow: bool = True,
) -> SimulatedBody:
    """Robot ``index``'s simulated body on its start cell, in the scenario's body model, its randomness from ``seed``
    (``follow``: :class:`~mrmp.live.body.SimulatedBody`'s)."""
    spec = scenario.robots[index]
    return SimulatedBody(
        spec.start,
        spec.heading,
        scenario.grid,
        scenario.timing,
        time_scale=time_scale,
        jitter=jitter,
        miss_line=miss_line,
        rng=stream_random(seed, Stream.BODY, index),
        recorder=recorder,
        model=body_model(scenario.policy.body),
        follow=follow,
    )


CELL_SIZE = 1.0
"""Metres per cell of a ROS 2 body (``docs/ros2.md``)."""
LINE_WIDTH = 0.1
"""Metres of a grid line under a ROS 2 body's sensor."""


def _ros2_body(
    driver: Ros2Driver, scenario: Scenario, index: int, options: AgentOptions, recorder: OccupancyRecorder
) -> OdometryLineBody:
    """A line-counting body (the thesis's, its turns ended by odometry) driven over ROS 2, at the scenario's timing."""
    spec = scenario.robots[index]
    cell_seconds = scenario.timing.cell_time / options.time_scale
    turn_seconds = scenario.timing.turn_time / options.time_scale
    speed, wheel_base, settle_seconds = body_geometry(cell_seconds, turn_seconds, CELL_SIZE, LINE_WIDTH)
    driver.wheel_base = wheel_base
    if not driver.wait_for_odometry(options.drive_wait):
        topic = odometry_topic(spec.id).removeprefix("rt")
        reason = f"no odometry on {topic} within {options.drive_wait:g} s: is the robot's ROS 2 driver running?"
        raise InputError(Problem("--drive", reason))
    return OdometryLineBody(driver, spec.start, spec.heading, speed, turn_seconds, settle_seconds, recorder)


OccupancySink = Callable[[str, Cell, float], None]
"""Where a body's ground-truth events go (:class:`~mrmp.live.body.OccupancyRecorder`)."""


def _both(first: OccupancySink, second: OccupancySink) -> OccupancySink:
    """An occupancy sink that hands every event to ``first``, then to ``second``."""

    def sink(event: str, cell: Cell, t: float) -> None:
        first(event, cell, t)
        second(event, cell, t)

    return sink


PROFILE_VARIABLE = "MRMP_PROFILE"
"""Set (to anything but empty) in a robot process's environment, it profiles the process's main thread (:func:`profiled`)."""


@contextlib.contextmanager
def profiled(path: Path, environment: Mapping[str, str] = os.environ) -> Iterator[None]:
    """Profile the CPU time of this thread over the block into ``path`` (``pstats`` format) when ``MRMP_PROFILE`` is set.

    The CPU time of the thread only (:func:`time.thread_time`): what the
    robot's main loop costs, not the time it sleeps. Read the file with
    ``python -m pstats``.

    >>> import pstats, tempfile
    >>> path = Path(tempfile.mkdtemp()) / "profile-0.prof"
    >>> with profiled(path, environment={}):
    ...     pass
    >>> path.exists()
    False
    >>> with profiled(path, environment={PROFILE_VARIABLE: "1"}):
    ...     _ = sorted(range(1000), key=str)
    >>> pstats.Stats(str(path)).total_calls > 0
    True
    """
    if not environment.get(PROFILE_VARIABLE):
        yield
        return
    import cProfile  # only when profiling: a robot process starts without it

    profile = cProfile.Profile(time.thread_time)
    profile.enable()
    try:
        yield
    finally:
        profile.disable()
        profile.dump_stats(str(path))


def _wait_for_peers(transport: ConnectedTransport, count: int, stop: threading.Event) -> None:
    """Wait up to :data:`PEER_WAIT_SECONDS` for ``count`` peers to connect, or until ``stop`` is set."""
    deadline = time.monotonic() + PEER_WAIT_SECONDS
    while not stop.is_set() and (remaining := deadline - time.monotonic()) > 0:
        if transport.wait_for_peers(count, timeout=min(remaining, 0.1)):
            return


REFEREE_PERIOD = 0.25
"""Seconds between two readings of the traces by a referee following a run."""

REFEREE_LAG = 1.0
"""How far behind the clock a referee following a run reports collisions: a collision at a moment at least this
long before a reading of every trace began is reported then (at most this and :data:`REFEREE_PERIOD` late); a
later one waits, since a robot's events of that moment may still be on their way to its trace."""


def run_referee(
    scenario: Scenario,
    results: Path,
    start_time: float | None,
    done_file: Path | None,
    report: Callable[[str], None],
    stop: threading.Event | None = None,
    clock: Callable[[], float] = time.monotonic,
) -> list:
    """Follow the fleet's traces until ``done_file`` appears (or a signal, or the end of its parent), reporting collisions.

    Without a ``done_file``, judge the traces as they are and stop. Without a
    ``start_time``, the run starts at the traces' first event (or now, when
    there is none). Writes ``referee.json``: the collisions and every robot's
    ground-truth intervals. Returns the collisions. ``stop``: the event of
    :func:`stop_on_signals`, when the caller installed it earlier (a signal
    that came meanwhile then finishes the verdict at once).

    While it follows a run, a collision is reported once it lies
    :data:`REFEREE_LAG` seconds before the ``clock`` reading taken as a
    reading of the traces began: the traces are read one after the other, and
    a robot writes an event a little after its moment, so a collision seen
    nearer the clock may be undone by an event of the same moment not read
    yet (a robot that had left the cell). What is left is reported once the
    run is over; ``referee.json`` is the verdict.
    """
    if stop is None:
        stop = stop_on_signals()
    if done_file is not None:  # following a run: it ends with its parent
        watch_parent(stop.set)
    ids, starts = [robot.id for robot in scenario.robots], [robot.start for robot in scenario.robots]
    readers = [TraceReader(results / f"trace-{index}.jsonl") for index in range(len(scenario.robots))]
    pending = [event for reader in readers for event in reader.read_new()]
    if start_time is None:
        start_time = min((t for _, _, _, t, _ in pending), default=time.monotonic())
    body = body_model(scenario.policy.body)
    referee = IntervalReferee(scenario.grid, ids, starts, start_time, follows=body.follows_while_driving)
    actions = None
    if body.turns_in_place:  # its actions are judged too
        actions = TurningActions(ids, starts, [robot.heading for robot in scenario.robots], start_time)
    reported: set[Collision] = set()
    finishing = False
    collisions = referee.collisions()
    while True:
        finishing = finishing or stop.is_set() or done_file is None or done_file.exists()
        read_at = clock()
        for reader in readers:
            pending.extend(reader.read_new())
        if pending:  # the collisions change only with new events: no new events, no new judgement
            for robot, event, cell, t, heading in pending:
                referee.feed(robot, event, cell, t)
                if actions is not None:
                    actions.feed(robot, event, cell, t, heading)
            pending = []
            collisions = referee.collisions()
            if actions is not None:
                collisions = sorted(collisions + actions.collisions(), key=lambda collision: collision.tick)
        judged_until = math.inf if finishing else (read_at - REFEREE_LAG - start_time) * 1000  # in ticks
        for collision in collisions:
            if collision.tick <= judged_until and collision not in reported:
                reported.add(collision)
                report(f"referee: {collision.describe()} (tick = milliseconds since the start)")
        if finishing:
            break
        stop.wait(REFEREE_PERIOD)
    write_json(
        results / "referee.json",
        {
            "start_time": start_time,
            "collisions": [
                {"kind": c.kind, "tick": c.tick, "robots": list(c.robots), "cells": [list(cell) for cell in c.cells]}
                for c in collisions
            ],
            "intervals": [
                {"robot": i.robot, "cell": list(i.cell), "start": i.start, "end": None if i.end == float("inf") else i.end}
                for i in referee.intervals
            ],
        },
    )
    return collisions


def warn(text: str) -> None:
    """Print a warning on standard error."""
    print(text, file=sys.stderr, flush=True)
