"""The live driver of one robot: the thesis's server and client threads around the sans-IO brain.

As in the thesis (section 3.5), a *receiving thread* keeps reading the
transport for the whole run (the thesis stops receiving at the destination, but
a robot that arrived still occupies its cell, so it keeps answering), and the
robot sends on every update of its state. The brain itself runs in the main
thread only, fed with the messages the receiving thread queued and with the
clock:

* announce Present and Next; listen for ``listen_time``; decide (and, guarded,
  claim the chosen cell); start the body's move once allowed;
* when the body reports the new cell, announce at once (the client thread
  "sends the updated information as soon as it is updated");
* send the state at least every ``heartbeat`` seconds, so that lost messages
  are repaired and silent robots are noticed;
* run the safety layer's timers (resend or abandon a claim).

Before its first step a robot waits (at most ``start_wait`` seconds) until it
has heard from every peer, so that a fleet whose processes start one by one
begins together; its clock starts then.

The run ends when this robot and every peer have arrived (and a short linger
has passed so that late claims are still answered), when every peer that has
not arrived has been silent for ``give_up_after`` seconds, on timeout, or on a
stop request (a signal). The driver writes its report (and, through the body,
ground truth) to the results folder, including on interruption.
"""

from __future__ import annotations

import queue
import random
import threading
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

from mrmp.core.cell import Cell
from mrmp.core.scenario import Scenario
from mrmp.live.body import Body
from mrmp.live.transport import FaultyTransport, Transport
from mrmp.policies.base import Policy
from mrmp.policies.registry import make_policy
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.messages import Message
from mrmp.robot.robot import Outgoing, Robot


class Phase(Enum):
    """Where a live robot is in its step (module docstring)."""

    LISTEN = "announced Next; listening before deciding"
    CLAIM = "decided; waiting for the safety layer to allow the move"
    MOVING = "the body is moving"
    PAUSE = "stays this step; announces again after a pause"


@dataclass(frozen=True)
class AgentTiming:
    """Real-time settings of a live robot, in seconds of wall-clock time."""

    listen_time: float = 0.05
    heartbeat: float = 0.2
    claim_retry: float = 0.15
    claim_timeout: float = 1.0
    silence_timeout: float = 1.5
    give_up_after: float = 3.0
    linger: float = 0.6
    poll: float = 0.004
    timeout: float = 120.0
    start_wait: float = 15.0


@dataclass
class AgentReport:
    """What one robot did in a live run (written to ``agent-<index>.json``)."""

    robot: str
    index: int
    start: Cell
    goal: Cell
    arrived: bool = False
    arrival_time: float | None = None
    stop_reason: str = "running"
    started_at: float = 0.0
    ended_at: float = 0.0
    believed_path: list[tuple[float, Cell]] = field(default_factory=list)
    turns: int = 0
    steps: int = 0
    messages_sent: int = 0
    bytes_sent: int = 0
    datagrams_sent: int = 0
    messages_received: int = 0
    rejected: dict[str, int] = field(default_factory=dict)
    faults: dict[str, int] = field(default_factory=dict)
    safety: dict[str, int] = field(default_factory=dict)
    decision_latency: list[float] = field(default_factory=list)
    silent_peers: list[int] = field(default_factory=list)
    missed_lines: int = 0

    def as_dict(self) -> dict[str, Any]:
        """A JSON-ready copy."""
        data = dict(self.__dict__)
        data["start"], data["goal"] = list(self.start), list(self.goal)
        data["believed_path"] = [[t, list(cell)] for t, cell in self.believed_path]
        return data


class Agent:
    """Runs one robot in real time (see the module docstring).

    Parameters
    ----------
    scenario:
        The whole scenario (every robot loads the same one).
    index:
        Which robot this process is.
    transport:
        Its transport, already connected.
    body:
        Its body, standing on the robot's start cell.
    sealer, opener:
        Its authenticated envelope, for sending and receiving.
    timing:
        Real-time settings.
    guarded:
        Whether the safety layer guards every move.
    seed:
        Seed of the driver's own randomness (pauses that break symmetry).
    clock:
        The clock (``time.monotonic``; shared by every process on a machine).
    policy:
        The robot's policy, when not the scenario's (for example its share of a central plan).
    """

    def __init__(
        self,
        scenario: Scenario,
        index: int,
        transport: Transport,
        body: Body,
        sealer: Sealer,
        opener: Opener,
        timing: AgentTiming = AgentTiming(),
        guarded: bool = True,
        seed: int = 0,
        clock: Callable[[], float] = time.monotonic,
        policy: Policy | None = None,
    ) -> None:
        spec = scenario.robots[index]
        self.scenario = scenario
        self.index = index
        self.transport = transport
        self.body = body
        self.sealer = sealer
        self.opener = opener
        self.timing = timing
        self.clock = clock
        self.random = random.Random(seed * 1_000_003 + index)
        self.robot = Robot(
            spec,
            index,
            scenario.grid,
            policy if policy is not None else make_policy(scenario.policy, scenario.timing),
            [robot.start for robot in scenario.robots],
            guarded=guarded,
            claim_timeout=timing.claim_timeout,
            retry_interval=timing.claim_retry,
            silence_timeout=timing.silence_timeout,
        )
        self.report = AgentReport(spec.id, index, spec.start, spec.goal)
        self.stop_requested = threading.Event()
        self._inbox: queue.SimpleQueue[Message] = queue.SimpleQueue()
        self._receiving = threading.Event()
        self._lock = threading.Lock()
        self._peers = len(scenario.robots) - 1

    # -- the receiving thread ----------------------------------------------------------

    def _receive_loop(self) -> None:
        while self._receiving.is_set():
            data = self.transport.receive(0.05)
            if data is None:
                continue
            with self._lock:
                message = self.opener.open(data)
            if message is not None:
                self._inbox.put(message)

    def _drain_inbox(self, now: float) -> None:
        """Hand the brain every message the receiving thread queued, and send its answers."""
        while True:
            try:
                message = self._inbox.get_nowait()
            except queue.Empty:
                return
            self.report.messages_received += 1
            self._send(self.robot.receive(message, now))

    # -- sending ---------------------------------------------------------------------------

    def _send(self, outgoing: list[Outgoing]) -> None:
        report = self.report
        for item in outgoing:
            data = self.sealer.seal(item.message)
            if item.recipients is None:
                self.transport.send(data, None)
                report.messages_sent += self._peers
                report.bytes_sent += len(data) * self._peers
                report.datagrams_sent += 1
            else:
                for recipient in item.recipients:
                    self.transport.send(data, recipient)
                    report.messages_sent += 1
                    report.bytes_sent += len(data)
                    report.datagrams_sent += 1

    # -- the main loop ---------------------------------------------------------------------

    def run(self, on_progress: Callable[[AgentReport], None] | None = None, progress_every: float = 1.0) -> AgentReport:
        """Run until done, timed out or stopped; returns (and keeps in :attr:`report`) the report."""
        robot, body, timing, report = self.robot, self.body, self.timing, self.report
        clock = self.clock
        self._receiving.set()
        receiver = threading.Thread(target=self._receive_loop, name=f"robot-{self.index}-server", daemon=True)
        receiver.start()
        self._wait_for_fleet()
        started = clock()
        report.started_at = started
        report.believed_path.append((started, robot.present))
        self._send(robot.announce(started))
        last_state = started
        next_decision = started + timing.listen_time
        phase = Phase.LISTEN
        decided_at = started
        everyone_done_since: float | None = None
        last_progress = started
        try:
            while not self.stop_requested.is_set():
                now = clock()
                if now - started > timing.timeout:
                    report.stop_reason = "timeout"
                    break
                self._drain_inbox(now)
                if body.moving:
                    if body.poll(now):
                        robot.arrived_at(body.cell, body.heading)
                        report.steps += 1
                        report.believed_path.append((now, body.cell))
                        self._send(robot.announce(now))
                        last_state = now
                        phase, next_decision = Phase.LISTEN, now + timing.listen_time
                        if robot.arrived and report.arrival_time is None:
                            report.arrival_time = now - started
                        elif not robot.arrived:
                            report.arrival_time = None
                elif phase is Phase.LISTEN and now >= next_decision:
                    self._send(robot.decide(now))
                    phase, decided_at = Phase.CLAIM, now
                if phase is Phase.CLAIM and not body.moving:
                    target = robot.motion(now)
                    if target is not None:
                        body.start_move(target, now)
                        report.decision_latency.append(now - decided_at)
                        phase = Phase.MOVING
                    elif robot.wanted is None and robot.safety.pending is None:
                        pause = timing.heartbeat if robot.arrived else timing.listen_time * (1 + self.random.random())
                        phase, next_decision = Phase.PAUSE, now + pause
                if phase is Phase.PAUSE and now >= next_decision:
                    self._send(robot.announce(now))
                    last_state = now
                    phase, next_decision = Phase.LISTEN, now + timing.listen_time
                self._send(robot.expire(now))
                if now - last_state >= timing.heartbeat:
                    self._send(robot.announce(now))
                    last_state = now
                if self._everyone_done(now):
                    everyone_done_since = everyone_done_since if everyone_done_since is not None else now
                    if now - everyone_done_since >= timing.linger:
                        report.stop_reason = "all arrived" if not report.silent_peers else "arrived; peers silent"
                        break
                else:
                    everyone_done_since = None
                if on_progress is not None and now - last_progress >= progress_every:
                    last_progress = now
                    self._fill_report(now)
                    on_progress(report)
                time.sleep(timing.poll)
            else:
                report.stop_reason = "interrupted"
        finally:
            self._receiving.clear()
            receiver.join(timeout=1.0)
            self._fill_report(clock())
        return report

    def _wait_for_fleet(self) -> None:
        """Announce every heartbeat, and answer, until every peer has been heard (or ``start_wait`` passes)."""
        robot, clock = self.robot, self.clock
        deadline = clock() + self.timing.start_wait
        last_state = -float("inf")
        while not self.stop_requested.is_set() and len(robot.belief.peers) < self._peers and clock() < deadline:
            now = clock()
            self._drain_inbox(now)
            if now - last_state >= self.timing.heartbeat:
                self._send([Outgoing(robot.state_message())])
                last_state = now
            time.sleep(self.timing.poll)

    def _everyone_done(self, now: float) -> bool:
        robot = self.robot
        if not robot.arrived:
            return False
        horizon = now - self.timing.give_up_after
        silent = []
        for index in range(len(self.scenario.robots)):
            if index == self.index:
                continue
            peer = robot.belief.peers.get(index)
            if peer is not None and peer.arrived and peer.heard_at >= now - 2 * self.timing.silence_timeout:
                continue
            if peer is None or peer.heard_at < horizon:
                silent.append(index)
                continue
            return False
        self.report.silent_peers = silent
        return True

    def _fill_report(self, now: float) -> None:
        report, robot = self.report, self.robot
        report.ended_at = now
        report.arrived = robot.arrived
        report.turns = getattr(self.body, "turns", 0)
        report.missed_lines = getattr(self.body, "missed_lines", 0)
        with self._lock:
            rejected = Counter(self.opener.rejected)
        rejected.update(robot.dropped)
        report.rejected = dict(rejected)
        if isinstance(self.transport, FaultyTransport):
            report.faults = dict(self.transport.counts.__dict__)
        report.safety = dict(robot.safety.stats.__dict__)
        report.safety["stale_states"] = robot.belief.stale_messages
