"""What every live robot driver shares: the receiving and client threads, the fleet wait, the run loop, the report.

A live driver runs one sans-IO robot brain in real time (thesis, section 3.5):
a *receiving thread* (the thesis's server) keeps reading the transport for the
whole run and queues what it opens, a *client thread*
(:class:`~mrmp.live.client_thread.ClientThread`, the thesis's client) sends
every datagram the main loop queues, and the brain runs in the main thread
only, fed with those messages and with the clock. :class:`LiveDriver` holds that machinery; a
policy's driver (:class:`mrmp.live.agent.Agent`,
:class:`mrmp.live.causal_agent.CausalAgent`) supplies its brain and its step.

Every turn of the loop hands the brain the queued messages (queueing its
answers for the client thread), runs the policy's step, runs the brain's timers, and sends the state
when nothing was sent for ``heartbeat`` seconds. While the brain's own timers may
be due (resending a claim, a lock request), turns come every ``poll`` seconds.
A brain whose timers are idle (no claim pending, no release unacknowledged) is
not polled: the main thread sleeps until the first of a message arriving (the
receiving thread wakes it, :class:`Mailbox`), the next thing the step or the
body has scheduled (``_due``), a heartbeat, the progress report or the end of
the linger. A robot waiting, arrived or not, therefore costs little CPU time:
dozens of robot processes share a few cores. UDP unicast has no radio, so a
radius broadcast (an :class:`~mrmp.robot.messaging.Outgoing` with ``radius``)
goes to the peers the brain believes within the radius; over multicast, the
messages of one turn for named peers go together in one datagram (:meth:`LiveDriver._send`); for discovery, the
state goes to every peer once every ``fleet_heartbeat`` seconds. A peer is
believed within the radius when its last known cell is, widened by the cells it
can have driven since it was heard (:func:`believed_near`), so a robot coming
near is addressed before it is within the interaction radius
(``docs/protocol.md``, "Neighbourhoods"). Before its first step a robot
waits (at most ``start_wait`` seconds) until it has heard from every peer, so
that a fleet whose processes start one by one begins together; its clock starts
then. While it waits it sends its state every fleet heartbeat to every peer and
at once to a peer it hears from for the first time, and asks the peers it has
not heard from for their state with a :class:`~mrmp.protocol.messages.HelloMessage`,
a heartbeat after it began waiting, then at gaps doubling up to a fleet
heartbeat. A robot answers every hello with its state, waiting or running (and
with a hello of its own to a sender it has not heard from): a waiting robot
whose first answer from a peer was lost hears it at its next hello, not a fleet
heartbeat later (with 48 robots that is 2.35 s, and one robot starting that late
holds up every robot that waits for it). The run
ends when this robot and every peer have arrived (and a short linger has
passed so that late requests are still answered, at least a fleet heartbeat,
so that a far peer that has left its goal again is heard of; the robot then
sends every peer its state, or what its policy's driver sends instead: a live
``pibt`` robot its farewell), when every peer that has not arrived has been
silent for ``give_up_after`` seconds, on timeout, or on a stop request.
"""

from __future__ import annotations

import contextlib
import functools
import math
import queue
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, Concatenate, ParamSpec, Protocol, TypeVar

from mrmp.core.cell import Cell
from mrmp.core.errors import MrmpError
from mrmp.core.heading import Heading
from mrmp.core.scenario import Scenario
from mrmp.core.seeds import Stream, stream_random
from mrmp.live.body import Body, TurnsInPlace
from mrmp.live.client_thread import ClientThread
from mrmp.live.multicast_wire import Addressed, count_together
from mrmp.live.transport import FaultyTransport, Transport
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.messages import HelloMessage, Message
from mrmp.robot.robot import Outgoing

_Arguments = ParamSpec("_Arguments")
_Returned = TypeVar("_Returned")


def _one_turn(
    method: Callable[Concatenate[LiveDriver, _Arguments], _Returned],
) -> Callable[Concatenate[LiveDriver, _Arguments], _Returned]:
    """A turn of a driver's main loop: its messages for named peers go together at its end (:meth:`LiveDriver._send`)."""

    @functools.wraps(method)
    def turn(driver: LiveDriver, *arguments: _Arguments.args, **keywords: _Arguments.kwargs) -> _Returned:
        with driver._messages_together():
            return method(driver, *arguments, **keywords)

    return turn


@dataclass(frozen=True)
class AgentTiming:
    """Real-time settings of a live robot, in seconds of wall-clock time."""

    listen_time: float = 0.05
    heartbeat: float = 0.2
    fleet_heartbeat: float = 1.0
    claim_retry: float = 0.05
    claim_timeout: float = 1.0
    silence_timeout: float = 1.5
    give_up_after: float = 3.0
    linger: float = 0.6
    poll: float = 0.004
    """The longest sleep of the main loop while the brain's timers may be due (they run at most this late)."""
    timeout: float = 120.0
    start_wait: float = 15.0


SENSOR_POLL = 0.004
"""Seconds between two polls of a moving body that cannot tell when it next changes (a line sensor to read)."""


LIVE_SLACK = 2
"""Cells added to a live robot's interaction radius: a body between two cells, a state in flight."""


def live_state_radius(interaction: int) -> int:
    """The radius (cells) of a live robot's states: its interaction radius plus :data:`LIVE_SLACK`.

    A policy whose decisions read no peer's cells (radius 0: a robot following a
    plan, which hears by name from the robots it waits for) gets no slack: its
    states go to the peers it names and to nobody by radius.

    >>> live_state_radius(2), live_state_radius(0)
    (4, 0)
    """
    return interaction + LIVE_SLACK if interaction > 0 else 0


def believed_near(
    peers: Iterable[tuple[int, Cell, float]], here: Cell, radius: int, now: float, cell_seconds: float
) -> list[int]:
    """The peers to address with a radius broadcast: each ``(index, last known cell, heard at)`` whose cell is
    within ``radius`` cells of ``here`` plus the cells it can have driven since it was heard.

    A peer within ``radius`` now was, when last heard ``age`` seconds ago, at most
    ``ceil(age / cell_seconds)`` cells further: so it is addressed, and a peer
    known freshly is addressed only when it is near.

    >>> believed_near([(1, (0, 6), 9.9), (2, (0, 6), 8.0), (3, (0, 20), 8.0)], (0, 0), 4, now=10.0, cell_seconds=0.5)
    [2]
    """
    x, y = here
    return [
        index
        for index, (cx, cy), heard_at in peers
        if abs(cx - x) + abs(cy - y) <= radius + math.ceil(max(0.0, now - heard_at) / cell_seconds)
    ]


class Mailbox:
    """The messages the receiving thread opened, queued for the main loop, which can sleep until one arrives.

    >>> mailbox = Mailbox()
    >>> mailbox.wait(0.0), mailbox.take()
    (False, [])
    >>> mailbox.put("a"); mailbox.put("b")
    >>> mailbox.wait(10.0), mailbox.take(), mailbox.wait(0.0)
    (True, ['a', 'b'], False)
    """

    def __init__(self) -> None:
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._arrived = threading.Event()

    def put(self, message: Any) -> None:
        """Queue ``message`` and wake a :meth:`wait` (from any thread)."""
        self._queue.put(message)
        if not self._arrived.is_set():  # set and not yet cleared: the waiter clears it before it takes, so takes this
            self._arrived.set()

    def wake(self) -> None:
        """End a :meth:`wait` at once, with nothing queued (a stop request)."""
        self._arrived.set()

    def wait(self, timeout: float) -> bool:
        """Sleep until something was put (or :meth:`wake`) since the last wait, for at most ``timeout`` seconds.

        Whether anything came. What comes after this returns wakes the next
        wait: the event is cleared before :meth:`take` empties the queue.
        """
        arrived = self._arrived.wait(timeout) if timeout > 0 else self._arrived.is_set()
        self._arrived.clear()
        return arrived

    def take(self) -> list[Any]:
        """Everything queued, oldest first."""
        taken = []
        while True:
            try:
                taken.append(self._queue.get_nowait())
            except queue.Empty:
                return taken


class HelloSchedule:
    """When a robot waiting for its fleet asks each peer not heard from for its state (:class:`LiveDriver`).

    A peer is asked ``first`` seconds after the wait begins, then at gaps
    doubling from ``first`` up to ``longest``; :meth:`restart` (a hello came
    from it: it is up) starts its gaps again.

    >>> schedule = HelloSchedule([1, 2], now=0.0, first=0.2, longest=1.0)
    >>> schedule.take_due([1, 2], 0.1), schedule.take_due([1, 2], 0.2), schedule.next_due([1, 2])
    ((), (1, 2), 0.4)
    >>> schedule.take_due([1], 0.4), schedule.next_due([1])   # the gap doubles: next at 0.8
    ((1,), 0.8)
    >>> schedule.restart(1, now=0.5); schedule.next_due([1])
    0.7
    """

    def __init__(self, peers: Iterable[int], now: float, first: float, longest: float) -> None:
        self.first, self.longest = first, longest
        self._due = dict.fromkeys(peers, now + first)
        self._gap = dict.fromkeys(self._due, first)

    def take_due(self, peers: Iterable[int], now: float) -> tuple[int, ...]:
        """Those of ``peers`` to ask now; each is then due again one gap later, its next gap doubled."""
        due = tuple(peer for peer in peers if self._due.get(peer, math.inf) <= now)
        for peer in due:
            self._due[peer] = now + self._gap[peer]
            self._gap[peer] = min(2 * self._gap[peer], self.longest)
        return due

    def next_due(self, peers: Iterable[int]) -> float:
        """When the first of ``peers`` is to be asked next (``inf``: none)."""
        return min((self._due.get(peer, math.inf) for peer in peers), default=math.inf)

    def restart(self, peer: int, now: float) -> None:
        """``peer`` is up: ask it again ``first`` seconds from ``now``, its gaps doubling again from there."""
        if peer in self._due:
            self._due[peer], self._gap[peer] = now + self.first, self.first


@dataclass
class _FleetWait:
    """Where a robot's wait for its fleet stands (:meth:`LiveDriver.fleet_wait_turn`)."""

    deadline: float
    last_fleet_state: float
    unheard: tuple[int, ...]


@dataclass
class _RunTimes:
    """When the main loop last did what it does now and then (:meth:`LiveDriver.turn`)."""

    started: float
    last_state: float
    last_fleet_state: float
    last_progress: float
    linger: float
    on_progress: Callable[[AgentReport], None] | None
    progress_every: float
    everyone_done_since: float | None = None


class Sending(Protocol):
    """Where a driver's sealed datagrams go: its client thread, or a virtual network (:mod:`mrmp.live.virtual_time`)."""

    def start(self) -> None:
        """Begin sending."""
        ...

    @property
    def reaches_several(self) -> bool:
        """Whether one datagram reaches several named peers (multicast), and :meth:`send_together` may be called."""
        ...

    def send(self, data: bytes, recipient: int | None) -> None:
        """Send ``data`` to ``recipient`` (every peer when None)."""
        ...

    def send_together(self, messages: Sequence[Addressed]) -> None:
        """Send ``messages``, each to the peers it names, in as few datagrams as they fit in
        (:func:`~mrmp.live.multicast_wire.count_together` says how many)."""
        ...

    def close(self) -> None:
        """Send what is queued, then stop."""
        ...


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
    """Messages sent, counted per recipient (a message to every peer counts once per peer): the datagrams a
    unicast transport (UDP, Zenoh) puts on the wire, and the figure of "messages per move"."""
    sent_by_kind: dict[str, int] = field(default_factory=dict)
    """Messages sent (per recipient) by message type (``StateMessage``, ``ClaimMessage``...)."""
    bytes_sent: int = 0
    datagrams_sent: int = 0
    """Datagrams the robot put on the wire: one per recipient over unicast (as :attr:`messages_sent`); over
    multicast, one per message to every peer, and one for the messages of a turn to named peers, which go
    together (as many more as they need when they do not fit in one)."""
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


class Brain(Protocol):
    """What the driver needs of a sans-IO robot brain (:class:`~mrmp.robot.robot.Robot`, ``CausalRobot``)."""

    dropped: Counter[str]

    def next_seq(self) -> int:
        """Its next sequence number (the driver stamps its hellos with it)."""
        ...

    def receive(self, message: Message, now: float) -> list[Outgoing]:
        """Take in one decoded message; return the answers to send."""
        ...

    def expire(self, now: float) -> list[Outgoing]:
        """Run the brain's timers; return what to resend."""
        ...


class LiveDriver:
    """The machinery of a live robot driver around a brain (see the module docstring).

    A subclass sets :attr:`robot` (its brain) in its constructor and supplies
    the hooks below: the policy's step and what it reads of its brain.

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
    seed:
        Seed of the driver's own randomness.
    clock:
        The clock (``time.monotonic``; shared by every process on a machine).
    """

    robot: Brain

    wakes_while_polling = False
    """Whether a message arriving wakes the loop while it polls for the brain's timers too (:meth:`wake_rule`);
    False: it waits for the next poll, a datagram costing no wake of its own."""

    def __init__(
        self,
        scenario: Scenario,
        index: int,
        transport: Transport,
        body: Body,
        sealer: Sealer,
        opener: Opener,
        timing: AgentTiming,
        seed: int,
        clock: Callable[[], float],
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
        self.random = stream_random(seed, Stream.SCHEDULE, index)
        self.report = AgentReport(spec.id, index, spec.start, spec.goal)
        self.stop_requested = threading.Event()
        self.running = False
        """Whether the wait for the fleet is over and the run begun (:meth:`main_turn`)."""
        self._inbox = Mailbox()
        self._receiving = threading.Event()
        self._lock = threading.Lock()
        self._peers = len(scenario.robots) - 1
        self._waiting_on: int | None = None
        """The peer that kept :meth:`_everyone_done` False last time (asked first next time)."""
        self._client: Sending = ClientThread(transport, name=f"robot-{index}-client")
        self.cell_seconds = scenario.timing.cell_time / getattr(body, "time_scale", 1.0)
        """Seconds the body takes for a cell (a body without a time scale runs in real time)."""
        self._hellos = HelloSchedule((), 0.0, timing.heartbeat, timing.fleet_heartbeat)
        """While waiting for the fleet: when each peer not heard from is asked for its state."""
        self._turning = False  # the body's action in progress is a turn in place, not a move
        self._together: list[Addressed] = []
        """Over multicast, the messages for named peers sent in this turn so far: they go together at its end."""
        self._turns_open = 0
        """How many of :meth:`begin_run`, :meth:`turn` and :meth:`fleet_wait_turn` are running (one calls another)."""

    # -- what a policy's driver supplies ----------------------------------------------------

    def _present(self) -> Cell:
        """The cell the brain stands on."""
        raise NotImplementedError

    def _arrived(self) -> bool:
        """Whether the brain stands on its goal (the report's ``arrived``)."""
        raise NotImplementedError

    def _settled(self) -> bool:
        """Whether this robot is done, as far as it is concerned (by default: it arrived)."""
        return self._arrived()

    def _peers_heard(self) -> int:
        """How many peers the brain has heard from."""
        raise NotImplementedError

    def _peer_news(self, index: int) -> tuple[float, bool] | None:
        """When peer ``index`` was last heard and whether it said it arrived (``None``: never heard)."""
        raise NotImplementedError

    def _state_messages(self, now: float) -> list[Outgoing]:
        """The state to send at the start and on every heartbeat of the run."""
        raise NotImplementedError

    def _fleet_wait_messages(self) -> list[Outgoing]:
        """The state to send every heartbeat while waiting for the fleet."""
        raise NotImplementedError

    def _fleet_heartbeat(self, now: float) -> list[Outgoing]:
        """What to send every ``fleet_heartbeat`` seconds of the run: by default the state, to every peer."""
        return fleet_wide(self._state_messages(now))

    def _farewell_messages(self, now: float) -> list[Outgoing]:
        """What to send every peer as the run ends: by default the state, so that every peer's last news of this
        robot is fresh."""
        return fleet_wide(self._state_messages(now))

    def _believed_within(self, radius: int) -> list[int]:
        """The peers the brain believes within ``radius`` cells of itself (where a radius broadcast goes)."""
        raise NotImplementedError

    def _begin(self, started: float) -> None:
        """Set up the policy's step at the start of the run (the clock reads ``started``)."""
        raise NotImplementedError

    def _step(self, now: float, started: float) -> bool:
        """One poll of the policy's step; returns whether it sent the state (which defers the heartbeat)."""
        raise NotImplementedError

    def _safety_counts(self) -> dict[str, int]:
        """The report's ``safety`` counts."""
        raise NotImplementedError

    def _due(self) -> float:
        """When the step next has something to do by the clock alone, besides the brain's timers (``inf``: nothing).

        By default: when the moving body next enters a cell or ends its move
        (a body that cannot tell is polled every :data:`SENSOR_POLL` seconds). A driver with
        timers of its own (a pause, the next activation) adds them.
        """
        body = self.body
        if not body.moving:
            return math.inf
        event = body.next_event()
        return self.clock() + SENSOR_POLL if event is None else event

    def _timers_idle(self) -> bool:
        """Whether the brain's timers have nothing to do until a message comes (then the loop need not wake every ``poll``).

        By default False: the brain may have a timer due at any moment.
        """
        return False

    def send_through(self, client: Sending) -> None:
        """Send through ``client`` instead of the client thread (a driver run on a virtual clock, which sends as it
        goes, from the one thread that runs every robot: :mod:`mrmp.live.virtual_time`)."""
        self._client = client

    def request_stop(self) -> None:
        """Ask the run to stop (from a signal handler or another thread); the main loop wakes at once."""
        self.stop_requested.set()
        self._inbox.wake()

    def _start_turn_in_place(self, heading: Heading, now: float) -> None:
        """Start the body's quarter turn in place to ``heading``; :meth:`_ended_a_turn` tells its end from a move's.

        Raises
        ------
        MrmpError
            If the body does not turn in place.
        """
        if not isinstance(self.body, TurnsInPlace):
            raise MrmpError(f"robot {self.index}: its brain turns in place, its body cannot")
        self.body.start_turn(heading, now)
        self._turning = True

    def _ended_a_turn(self) -> bool:
        """Whether the body's action that has just ended was a turn in place (not a move)."""
        turning, self._turning = self._turning, False
        return turning

    def _record_move(self, now: float, started: float, on_goal: bool) -> None:
        """The body ended a move, on the goal or not: count it, log the cell, keep the arrival time."""
        report = self.report
        report.steps += 1
        report.believed_path.append((now, self.body.cell))
        if not on_goal:
            report.arrival_time = None
        elif report.arrival_time is None:
            report.arrival_time = now - started

    # -- the receiving thread ----------------------------------------------------------

    def _receive_loop(self) -> None:
        while self._receiving.is_set():
            data = self.transport.receive(0.05)
            if data is not None:
                self.take_datagram(data)

    def take_datagram(self, data: bytes) -> None:
        """Open a datagram that arrived and queue its message for the main loop (dropped and counted if it is bad)."""
        with self._lock:
            message = self.opener.open(data)
        if message is not None:
            self._inbox.put(message)

    def _drain_inbox(self, now: float) -> None:
        """Hand the brain every message the receiving thread queued, and send its answers; answer a hello with the
        state, and with a hello too when its sender has not been heard from (module docstring)."""
        for message in self._inbox.take():
            self.report.messages_received += 1
            if not isinstance(message, HelloMessage):
                self._send(self.robot.receive(message, now))
                continue
            sender = (message.sender,)
            self._send(self._fleet_wait_to(sender))
            if self._peer_news(message.sender) is None:
                self._send(self._hellos_to(sender))
                self._hellos.restart(message.sender, now)  # it is up: ask it again soon, not at a long gap

    def _hellos_to(self, peers: tuple[int, ...]) -> list[Outgoing]:
        """A hello to ``peers``, asking each for its state."""
        return [Outgoing(HelloMessage(self.index, self.robot.next_seq()), peers)]

    def _sleep(self, until: float, timers: bool = True) -> None:
        """Sleep until the clock reads ``until`` (or a stop is requested), waking for the brain's timers.

        While the brain's ``timers`` may be due (they are not idle,
        :meth:`_timers_idle`), the loop polls as it always did: it sleeps at
        most ``poll`` seconds, and what arrives meanwhile waits for the next
        turn, unless the driver :attr:`wakes_while_polling`. Otherwise it
        sleeps until ``until``, and the first message to arrive wakes it at once.
        """
        now = self.clock()
        wake, woken_by_messages = self.wake_rule(now, until, timers)
        if woken_by_messages:
            self._inbox.wait(max(0.0, wake - now))
        else:
            self._nap(max(0.0, wake - now))

    def wake_rule(self, now: float, until: float, timers: bool = True) -> tuple[float, bool]:
        """When the main loop, about to sleep at ``now`` until ``until``, wakes at the latest, and whether a
        message arriving earlier wakes it (:meth:`_sleep`; a driver on a virtual clock follows the same rule)."""
        if timers and not self._timers_idle():
            return min(until, now + self.timing.poll), self.wakes_while_polling
        return until, True

    def _nap(self, seconds: float) -> None:
        """Sleep ``seconds`` whatever arrives (a poll's sleep)."""
        time.sleep(seconds)

    # -- sending ---------------------------------------------------------------------------

    def _send(self, outgoing: list[Outgoing]) -> None:
        """Seal each message and queue it for the client thread, counting it as sent.

        Over a transport that reaches several peers with one datagram
        (multicast), the messages for named peers wait for the end of the
        turn and go together (:meth:`_send_together`); a message to every
        peer goes at once, after those that wait, so that the order of
        sending stays the order of the brain's messages.
        """
        report, client = self.report, self._client
        by_kind = report.sent_by_kind
        for item in outgoing:
            data = self.sealer.seal(item.message)
            kind = type(item.message).__name__
            if item.radius:  # a radius of 0 reaches no peer but those named
                near = self._believed_within(item.radius)
                item = item._replace(recipients=(*near, *(peer for peer in item.recipients or () if peer not in near)))
            if item.recipients is None:
                self._send_together()
                client.send(data, None)
                messages = self._peers
                report.datagrams_sent += 1 if client.reaches_several else messages
            elif client.reaches_several:
                messages = len(item.recipients)
                if messages:
                    self._together.append((data, item.recipients))
            else:
                for recipient in item.recipients:
                    client.send(data, recipient)
                messages = len(item.recipients)
                report.datagrams_sent += messages
            report.messages_sent += messages
            by_kind[kind] = by_kind.get(kind, 0) + messages
            report.bytes_sent += len(data) * messages
        if not self._turns_open:
            self._send_together()

    def _send_together(self) -> None:
        """Send the messages waiting to go together (:meth:`_send`), counting their datagrams."""
        if self._together:
            together, self._together = self._together, []
            self._client.send_together(together)
            self.report.datagrams_sent += count_together(together)

    @contextlib.contextmanager
    def _messages_together(self) -> Iterator[None]:
        """While this is open, messages for named peers wait (:meth:`_send`); they go when the outermost closes."""
        self._turns_open += 1
        try:
            yield
        finally:
            self._turns_open -= 1
            if not self._turns_open:
                self._send_together()

    # -- the main loop ---------------------------------------------------------------------

    def run(self, on_progress: Callable[[AgentReport], None] | None = None, progress_every: float = 1.0) -> AgentReport:
        """Run until done, timed out or stopped; returns (and keeps in :attr:`report`) the report.

        The receiving and client threads run beside the main loop; the main
        loop waits for the fleet, then runs :meth:`turn` and sleeps until what
        it returns (or a message wakes it: :meth:`wake_rule`).
        """
        clock = self.clock
        self._receiving.set()
        receiver = threading.Thread(target=self._receive_loop, name=f"robot-{self.index}-server", daemon=True)
        receiver.start()
        self._client.start()
        try:
            self._wait_for_fleet()
            self.begin_run(clock(), on_progress, progress_every)
            while not self.stop_requested.is_set():
                wake = self.turn(clock())
                if wake is None:
                    break
                self._sleep(wake)
            else:
                self.report.stop_reason = "interrupted"
        finally:
            try:
                self._client.close()  # what is queued still goes out, while the receiving thread answers
            finally:
                self._receiving.clear()
                receiver.join(timeout=1.0)
                self.fill_report(clock())
        return self.report

    @_one_turn
    def begin_run(
        self, now: float, on_progress: Callable[[AgentReport], None] | None = None, progress_every: float = 1.0
    ) -> None:
        """Start the run at ``now`` (the fleet has been waited for): tell every peer, and begin the first step."""
        report = self.report
        report.started_at = now
        report.believed_path.append((now, self._present()))
        if self._present() == self.scenario.robots[self.index].goal:
            report.arrival_time = 0.0  # there from the start: it arrives at once, unless it moves away
        if on_progress is not None:  # the launcher learns at once when this robot's run began
            self.fill_report(now)
            on_progress(report)
        self._send(fleet_wide(self._state_messages(now)))
        linger = max(self.timing.linger, self.timing.fleet_heartbeat + self.timing.heartbeat)  # a far peer's news
        self._loop = _RunTimes(now, now, now, now, linger, on_progress, progress_every)
        self._begin(now)

    @_one_turn
    def turn(self, now: float) -> float | None:
        """One turn of the main loop at ``now``; when to wake for the next (:meth:`wake_rule`), or None: the run is over.

        Hand the brain what arrived, run the policy's step and the brain's
        timers, send the heartbeats due, end the run when this robot and every
        peer are done (after a linger) or at the timeout, and report progress.
        """
        loop, timing, report = self._loop, self.timing, self.report
        if now - loop.started > timing.timeout:
            report.stop_reason = "timeout"
            return None
        self._drain_inbox(now)
        if self._step(now, loop.started):
            loop.last_state = now
        self._send(self.robot.expire(now))
        if now - loop.last_fleet_state >= timing.fleet_heartbeat:
            self._send(self._fleet_heartbeat(now))
            loop.last_state = loop.last_fleet_state = now
        elif now - loop.last_state >= timing.heartbeat:
            self._send(self._state_messages(now))
            loop.last_state = now
        if self._everyone_done(now):
            if loop.everyone_done_since is None:
                loop.everyone_done_since = now
            if now - loop.everyone_done_since >= loop.linger:
                report.stop_reason = "all arrived" if not report.silent_peers else "arrived; peers silent"
                self._send(self._farewell_messages(now))
                return None
        else:
            loop.everyone_done_since = None
        if loop.on_progress is not None and now - loop.last_progress >= loop.progress_every:
            loop.last_progress = now
            self.fill_report(now)
            loop.on_progress(report)
        return min(
            self._due(),
            loop.last_state + timing.heartbeat,
            loop.last_fleet_state + timing.fleet_heartbeat,
            loop.started + timing.timeout,
            math.inf if loop.everyone_done_since is None else loop.everyone_done_since + loop.linger,
            math.inf if loop.on_progress is None else loop.last_progress + loop.progress_every,
        )

    def _wait_for_fleet(self) -> None:
        """Wait for the fleet in real time: :meth:`fleet_wait_turn` until it is over, sleeping between turns."""
        self.begin_fleet_wait(self.clock())
        while not self.stop_requested.is_set():
            wake = self.fleet_wait_turn(self.clock())
            if wake is None:
                return
            self._sleep(wake, timers=False)  # no brain timers run before the start

    def main_turn(self, now: float, on_progress: Callable[[AgentReport], None] | None = None) -> float | None:
        """One turn of the main loop of a driver run by a loop of someone else's (a virtual clock, a process hosting
        several robots): a turn of the wait for the fleet (:meth:`begin_fleet_wait` first) and, once it is over,
        the run begun and its first turn, then a turn of the run. When to wake next (:meth:`wake_rule`, with timers
        once :attr:`running`), or None: the run is over."""
        if not self.running:
            wake = self.fleet_wait_turn(now)
            if wake is not None:
                return wake
            self.running = True
            self.begin_run(now, on_progress)
        return self.turn(now)

    def begin_fleet_wait(self, now: float) -> None:
        """Start waiting for the fleet at ``now`` (:meth:`fleet_wait_turn`)."""
        unheard = self._unheard_peers()
        self._fleet_wait = _FleetWait(now + self.timing.start_wait, -math.inf, unheard)
        self._hellos = HelloSchedule(unheard, now, self.timing.heartbeat, self.timing.fleet_heartbeat)

    @_one_turn
    def fleet_wait_turn(self, now: float) -> float | None:
        """One turn of the wait for the fleet: send the state, and answer, until every peer has been heard (or
        ``start_wait`` passes); when to wake for the next turn, or None: the wait is over.

        The state goes every fleet heartbeat to every peer, and at once to a
        peer heard from for the first time (it is up: now it hears this robot
        too). A peer not heard from yet gets a hello, which it answers with its
        state (its answer to this robot's state may have been lost): a heartbeat
        after the start, then at gaps doubling from a heartbeat up to a fleet
        heartbeat, so that a fleet whose processes start one by one does not
        flood with hellos the robots already up, nor the addresses of those not up yet;
        a hello from a peer not heard from (it is up) starts its gaps again from a heartbeat.
        """
        wait, timing, hellos = self._fleet_wait, self.timing, self._hellos
        if self._peers_heard() >= self._peers or now >= wait.deadline:
            return None
        self._drain_inbox(now)
        still_unheard = self._unheard_peers()
        newly_heard = tuple(sorted(set(wait.unheard) - set(still_unheard)))
        wait.unheard = still_unheard
        if newly_heard and now - wait.last_fleet_state < timing.fleet_heartbeat:  # answered at once
            self._send(self._fleet_wait_to(newly_heard))
        if now - wait.last_fleet_state >= timing.fleet_heartbeat:
            self._send(fleet_wide(self._fleet_wait_messages()))
            wait.last_fleet_state = now
        due = hellos.take_due(wait.unheard, now)
        if due:
            self._send(self._hellos_to(due))
        return min(hellos.next_due(wait.unheard), wait.last_fleet_state + timing.fleet_heartbeat, wait.deadline)

    def _fleet_wait_to(self, peers: tuple[int, ...]) -> list[Outgoing]:
        """The fleet-wait state addressed to ``peers`` only."""
        return [item._replace(recipients=peers, radius=None) for item in self._fleet_wait_messages()]

    def _unheard_peers(self) -> tuple[int, ...]:
        """The peers not heard from yet."""
        fleet = range(len(self.scenario.robots))
        return tuple(index for index in fleet if index != self.index and self._peer_news(index) is None)

    def _everyone_done(self, now: float) -> bool:
        """This robot and every peer arrived (peers silent for ``give_up_after`` are given up on).

        The peer that kept the answer False last time is asked first: while it
        still does, one peer is looked at, not the whole fleet.
        """
        if not self._settled():
            return False
        waiting_on = self._waiting_on
        if waiting_on is not None and self._peer_state(waiting_on, now) == "running":
            return False
        silent = []
        for index in range(len(self.scenario.robots)):
            if index == self.index:
                continue
            state = self._peer_state(index, now)
            if state == "silent":
                silent.append(index)
            elif state == "running":
                self._waiting_on = index
                return False
        self._waiting_on = None
        self.report.silent_peers = silent
        return True

    def _peer_state(self, index: int, now: float) -> str:
        """``"done"`` (arrived, heard within ``give_up_after``), ``"silent"`` (not heard that long) or ``"running"``."""
        news = self._peer_news(index)
        if news is not None and news[1] and news[0] >= now - self.timing.give_up_after:
            return "done"
        if news is None or news[0] < now - self.timing.give_up_after:
            return "silent"
        return "running"

    def fill_report(self, now: float) -> None:
        """Bring :attr:`report` up to ``now``: end time, arrival, turns, rejections, faults and the safety counts."""
        report, robot = self.report, self.robot
        report.ended_at = now
        report.arrived = self._arrived()
        report.turns = getattr(self.body, "turns", 0)
        report.missed_lines = getattr(self.body, "missed_lines", 0)
        with self._lock:
            rejected = Counter(self.opener.rejected)
        rejected.update(robot.dropped)
        report.rejected = dict(rejected)
        if isinstance(self.transport, FaultyTransport):
            report.faults = dict(self.transport.counts.__dict__)
        report.safety = self._safety_counts()


def fleet_wide(outgoing: list[Outgoing]) -> list[Outgoing]:
    """``outgoing`` addressed to every peer (the fleet heartbeat).

    >>> from mrmp.protocol.messages import StateMessage
    >>> fleet_wide([Outgoing(StateMessage(0, 1, (0, 0), (0, 1)), (2,), 3)])[0].fleet_wide
    True
    """
    return [item._replace(recipients=None, radius=None) for item in outgoing]
