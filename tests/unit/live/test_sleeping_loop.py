"""The live driver's main loop sleeps until something is due instead of polling: fewer turns, the same messages.

The driver runs on a clock of the test's own (:class:`FakeClock`) and its
mailbox's wait moves that clock on instead of sleeping, so the loop's turns
are counted, not timed. A driver that polls every ``poll`` seconds whatever
happens (the loop as it was, :class:`PollingAgent`) is the reference: the
sleeping loop must send the same messages in the same order, in far fewer turns.
"""

from __future__ import annotations

import threading
import time

from mrmp.core import Grid, RobotSpec, Scenario, Timing
from mrmp.core.heading import Heading
from mrmp.live.agent import Agent
from mrmp.live.body import SimulatedBody
from mrmp.live.driver import AgentTiming, Mailbox
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.messages import HelloMessage, StateMessage

KEY = b"k" * 32
TIMING = AgentTiming(start_wait=1.0, timeout=30.0, poll=0.004)


class FakeClock:
    """A clock that only moves when told."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


class CountingMailbox(Mailbox):
    """A mailbox whose wait moves the fake clock on by its timeout (at least a microsecond) and counts the waits."""

    def __init__(self, clock: FakeClock) -> None:
        super().__init__()
        self.clock = clock
        self.waits = 0

    def wait(self, timeout: float) -> bool:
        self.waits += 1
        self.clock.now += max(timeout, 1e-6)
        return super().wait(0.0)


class Recording:
    """Keeps every datagram sent; receives nothing."""

    def __init__(self) -> None:
        self.sent: list[tuple[bytes, int | None]] = []
        self.lock = threading.Lock()

    def send(self, data: bytes, recipient: int | None = None) -> None:
        with self.lock:
            self.sent.append((data, recipient))

    def receive(self, timeout: float) -> bytes | None:
        time.sleep(min(timeout, 0.005))
        return None

    def close(self) -> None:
        pass


class PollingAgent(Agent):
    """The loop as it was: whatever is due, sleep ``poll`` seconds between two turns."""

    def _sleep(self, until: float, timers: bool = True) -> None:
        self._inbox.wait(self.timing.poll)


def on_fake_clock(agent: Agent, mailbox: CountingMailbox) -> None:
    """Make ``agent`` sleep on the fake clock: through ``mailbox``, a poll's sleep too."""
    agent._inbox = mailbox
    agent._nap = lambda seconds: mailbox.wait(seconds) and None  # type: ignore[method-assign]


def scenario(goal: tuple[int, int] = (0, 0), silent_peer: bool = True) -> Scenario:
    """Robot A (the one run), and B, a peer that never speaks."""
    robots = (RobotSpec("A", (0, 0), goal, Heading.NORTH), RobotSpec("B", (3, 3), (3, 3)))
    return Scenario(Grid(4, 4), robots if silent_peer else robots[:1], timing=Timing(cell_time=0.4, turn_time=0.2))


def run(kind: type[Agent], scene: Scenario) -> tuple[int, list[tuple[str, int | None]], str, list]:
    """Run robot A on the fake clock: the loop's turns, what it sent (message kind and recipient), why it stopped,
    and the cells its body entered and left (ground truth)."""
    clock = FakeClock()
    transport = Recording()
    spec = scene.robots[0]
    body = SimulatedBody(spec.start, spec.heading, scene.grid, scene.timing)
    agent = kind(scene, 0, transport, body, Sealer(KEY, 1), Opener(KEY, 1), timing=TIMING, clock=clock)
    mailbox = CountingMailbox(clock)
    on_fake_clock(agent, mailbox)
    report = agent.run()
    opener = Opener(KEY, 1)
    sent = []
    for data, recipient in transport.sent:
        message = opener.open(data)
        assert message is not None
        sent.append((type(message).__name__, recipient))
    return mailbox.waits, sent, report.stop_reason, [(event, cell) for event, cell, _ in body.recorder.events]


def test_an_arrived_robot_waiting_for_a_silent_peer_sends_the_same_messages_in_far_fewer_turns():
    polled_turns, polled_sent, polled_stop, _ = run(PollingAgent, scenario())
    turns, sent, stop, _ = run(Agent, scenario())
    assert stop == polled_stop == "arrived; peers silent"
    assert sent == polled_sent
    assert sent and {kind for kind, _ in sent} == {StateMessage.__name__, HelloMessage.__name__}
    assert all(recipient == 1 for kind, recipient in sent if kind == HelloMessage.__name__)  # to B, never heard
    assert polled_turns > 400  # 1 s of fleet wait and 1.2 s of linger, every 4 ms
    assert turns * 10 < polled_turns


def test_a_moving_robot_makes_the_same_moves_and_sends_the_same_messages_in_fewer_turns():
    polled_turns, polled_sent, _, polled_moves = run(PollingAgent, scenario(goal=(2, 3), silent_peer=False))
    turns, sent, stop, moves = run(Agent, scenario(goal=(2, 3), silent_peer=False))
    assert stop == "all arrived"
    assert len(moves) == 2 * 5 and moves == polled_moves
    assert sent == polled_sent
    assert turns * 3 < polled_turns


def test_a_message_wakes_the_mailbox_and_a_stop_request_wakes_the_loop():
    mailbox = Mailbox()
    threading.Thread(target=mailbox.put, args=("state",)).start()
    assert mailbox.wait(60.0) is True
    assert mailbox.take() == ["state"]
    assert mailbox.wait(0.0) is False
    mailbox.wake()
    assert mailbox.wait(60.0) is True
    assert mailbox.take() == []


class InjectingMailbox(CountingMailbox):
    """A counting mailbox that receives ``message`` at its ``at``-th wait."""

    def __init__(self, clock: FakeClock, message: StateMessage, at: int) -> None:
        super().__init__(clock)
        self.message, self.at = message, at

    def wait(self, timeout: float) -> bool:
        if self.waits + 1 == self.at:
            self.put(self.message)
        return super().wait(timeout)


def fleet_wait(heard_at_wait: int) -> list[tuple[float, int | None, str]]:
    """Robot A waits for B and C (C never speaks; B's state comes at A's ``heard_at_wait``-th wait):
    when A sent its state, and to whom (None: every peer)."""
    robots = (RobotSpec("A", (0, 0), (0, 0)), RobotSpec("B", (3, 3), (3, 3)), RobotSpec("C", (0, 3), (0, 3)))
    scene = Scenario(Grid(4, 4), robots)
    clock, transport = FakeClock(), Recording()
    spec = scene.robots[0]
    body = SimulatedBody(spec.start, spec.heading, scene.grid, scene.timing)
    timing = AgentTiming(start_wait=2.5, heartbeat=0.2, fleet_heartbeat=1.0)
    agent = Agent(scene, 0, transport, body, Sealer(KEY, 1), Opener(KEY, 1), timing=timing, clock=clock)
    sent: list[tuple[float, int | None, str]] = []
    openers: dict[int | None, Opener] = {}  # each recipient opens what it gets

    def record(data: bytes, recipient: int | None) -> None:
        message = openers.setdefault(recipient, Opener(KEY, 1)).open(data)
        assert message is not None  # every datagram, hellos too, stamped with a fresh sequence number
        sent.append((round(clock.now - 100.0, 3), recipient, type(message).__name__))

    agent._client.send = record  # type: ignore[method-assign]
    on_fake_clock(agent, InjectingMailbox(clock, StateMessage(1, 1, (3, 3), (3, 3)), at=heard_at_wait))
    agent._wait_for_fleet()
    assert agent._peers_heard() == 1  # C never spoke: the wait ended at start_wait
    return sent


def test_waiting_for_the_fleet_a_robot_asks_unheard_peers_at_doubling_gaps_and_tells_everyone_every_fleet_heartbeat():
    sent = fleet_wait(heard_at_wait=3)  # B's state comes during the third wait: it is heard at 0.8 s
    state, hello = StateMessage.__name__, HelloMessage.__name__
    assert sent == [
        (0.0, None, state),  # every peer
        (0.2, 1, hello), (0.2, 2, hello),  # the peers not heard from are asked for their state a heartbeat later,
        (0.4, 1, hello), (0.4, 2, hello),  # then at gaps doubling from a heartbeat (0.2 s)
        (0.8, 1, state),  # B, heard for the first time, is answered at once
        (0.8, 2, hello),
        (1.0, None, state),  # every peer every fleet heartbeat
        (1.6, 2, hello),  # C: the gap has reached the fleet heartbeat (1 s)
        (2.0, None, state),
    ]  # fmt: skip


def answers_to_a_hello(heard: bool) -> list[tuple[str, tuple[int, ...] | None]]:
    """What robot A sends when B's hello comes (B heard from before, or not)."""
    scene = scenario()
    spec = scene.robots[0]
    body = SimulatedBody(spec.start, spec.heading, scene.grid, scene.timing)
    agent = Agent(scene, 0, Recording(), body, Sealer(KEY, 1), Opener(KEY, 1), timing=TIMING, clock=FakeClock())
    sent: list[tuple[str, tuple[int, ...] | None]] = []
    agent._send = lambda outgoing: sent.extend((type(o.message).__name__, o.recipients) for o in outgoing)  # type: ignore[method-assign]
    if heard:
        agent.robot.receive(StateMessage(1, 1, (3, 3), (3, 3)), 100.0)
    agent._inbox.put(HelloMessage(1, 7))
    agent._drain_inbox(100.0)
    assert set(agent.robot.belief.peers) == ({1} if heard else set())  # the brain never sees the hello
    return sent


def test_a_hello_is_answered_with_the_state_at_once_and_with_a_hello_when_its_sender_is_unheard():
    """A peer's hello says it has not heard this robot: the state goes to it alone; a sender not heard from is asked
    for its state in turn (it is up, and its own state to this robot may have been lost)."""
    state, hello = StateMessage.__name__, HelloMessage.__name__
    assert answers_to_a_hello(heard=True) == [(state, (1,))]
    assert answers_to_a_hello(heard=False) == [(state, (1,)), (hello, (1,))]


def test_the_end_of_the_run_is_seen_as_by_a_scan_of_every_peer():
    """The end check asks first the peer that kept it open: its answers are those of a scan of every peer."""
    robots = tuple(RobotSpec(name, (0, index), (0, index)) for index, name in enumerate("ABCD"))
    scene = Scenario(Grid(1, 4), robots)
    spec = scene.robots[0]
    body = SimulatedBody(spec.start, spec.heading, scene.grid, scene.timing)
    agent = Agent(scene, 0, Recording(), body, Sealer(KEY, 1), Opener(KEY, 1), timing=AgentTiming(give_up_after=3.0))
    news: dict[int, tuple[float, bool] | None] = {}
    agent._peer_news = news.get  # type: ignore[method-assign]
    now = 10.0
    running, done, silent = (now - 1.0, False), (now - 1.0, True), (now - 5.0, False)
    steps = [
        ({1: done, 2: running, 3: running}, False, None),
        ({1: done, 2: done, 3: running}, False, None),  # the peer that kept it open is done: the others are asked
        ({1: done, 2: done, 3: silent}, True, [3]),
        ({1: running, 2: done, 3: silent}, False, None),
        ({1: done, 2: done, 3: None}, True, [3]),  # never heard: silent
    ]
    for peers, finished, silent_peers in steps:
        news.clear()
        news.update(peers)
        assert agent._everyone_done(now) is finished
        if finished:
            assert agent.report.silent_peers == silent_peers
