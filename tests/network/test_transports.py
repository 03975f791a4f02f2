"""What only UDP and the fault injector do, on loopback (127.0.0.1 only).

What every transport does (delivery, oversized and malformed datagrams,
timeouts, closing) is checked once for all of them in test_transport_conformance.py.
"""

import socket
import subprocess
import sys
import threading
import time
import types
from collections import Counter

import pytest
from polling import PATIENCE, drain, receive_expected, receive_within

from mrmp.live.multicast_wire import MAX_MULTICAST_DATAGRAM_BYTES, MAX_NAMED, read_head, read_sections
from mrmp.live.transport import (
    FaultyTransport,
    LiveFaults,
    SeveralAtOnce,
    UdpMulticastTransport,
    UdpTransport,
    with_faults,
)
from mrmp.live.transport_entry import free_ports

LOOPBACK = "127.0.0.1"


@pytest.fixture
def udp_fleet():
    """Three UDP transports on free loopback ports, each knowing the other two by index."""
    transports = [UdpTransport((LOOPBACK, 0), {}) for _ in range(3)]
    for index, transport in enumerate(transports):
        transport.peers = {other: peer.address for other, peer in enumerate(transports) if other != index}
    yield transports
    for transport in transports:
        transport.close()


class RecordingTransport:
    """An in-memory transport that records what it is asked to send."""

    def __init__(self):
        self.sent = []
        self.lock = threading.Lock()
        self.closed = False

    def send(self, data, recipient=None):
        with self.lock:
            self.sent.append((time.monotonic(), data, recipient))

    def receive(self, timeout):
        return None

    def close(self):
        self.closed = True


# -- UdpMulticastTransport ---------------------------------------------------------------------


def free_group():
    port = free_ports(1)[0]
    return (f"239.255.77.{1 + port % 250}", port)


class TakesEverything(UdpMulticastTransport):
    """Broken: takes in every message of the group, whoever it is headed for."""

    def receive(self, timeout):
        while not self._taken:
            data = self._receive_datagram(timeout, MAX_MULTICAST_DATAGRAM_BYTES + 1)
            if data is None:
                return None
            sections = read_sections(data, None)
            self._taken.extend([data[read_head(data, None)[1] :]] if sections is None else [message for _, message in sections])
        return self._taken.popleft()


@pytest.mark.parametrize("broken", [False, True])
def test_a_multicast_robot_takes_in_only_what_is_sent_to_it_or_to_every_robot(broken):
    """Every datagram reaches the whole group; one headed for other robots is dropped on receipt (a robot
    that took it in could take another's acknowledgement or answer for its own: ``docs/protocol.md``, "A
    multicast datagram says whom it is for")."""
    group = free_group()
    kind = TakesEverything if broken else UdpMulticastTransport
    robots = [kind(group, LOOPBACK, index, fleet_size=4) for index in range(4)]
    try:
        robots[0].send(b"0 to 2", recipient=2)
        robots[0].send_together([(b"0 to 1 and 3", (1, 3))])
        robots[0].send_together([(b"0 to 3", (3,)), (b"0 to 1 and 2", (1, 2))])  # one datagram, for all three
        robots[0].send(b"0 to all")
        received = [receive_expected(robot, [b"0 to all"]) for robot in robots[1:]]
    finally:
        for robot in robots:
            robot.close()
    if broken:
        assert received[0][b"0 to 2"] == 1 and received[0][b"0 to 3"] == 1
    else:
        assert received == [
            Counter([b"0 to 1 and 3", b"0 to 1 and 2", b"0 to all"]),
            Counter([b"0 to 2", b"0 to 1 and 2", b"0 to all"]),
            Counter([b"0 to 1 and 3", b"0 to 3", b"0 to all"]),
        ]


class OneDatagramEach(UdpMulticastTransport):
    """Broken: sends each message for each robot as a datagram of its own, as unicast does."""

    def send_together(self, messages):
        for data, recipients in messages:
            for recipient in recipients:
                self.send(data, recipient)


@pytest.mark.parametrize("broken", [False, True])
def test_multicast_messages_sent_together_are_one_datagram_on_the_wire(broken):
    """What a robot counts as one datagram (``AgentReport.datagrams_sent``) is one: a listener of the group
    that is no robot hears one datagram, whose sections name the robots of each message."""
    group = free_group()
    sender = (OneDatagramEach if broken else UdpMulticastTransport)(group, LOOPBACK, 0, fleet_size=3)
    listener = RawListener(group)
    try:
        sender.send_together([(b"to 1 and 2", (1, 2)), (b"to 2", (2,))])
        heard = [listener.receive(PATIENCE) for _ in range(3 if broken else 1)]
        assert listener.receive(0.2) is None
    finally:
        sender.close()
        listener.close()
    if broken:
        assert [read_head(data, None)[0] for data in heard] == [(1,), (2,), (2,)]
    else:
        assert read_sections(heard[0], 3) == [((1, 2), b"to 1 and 2"), ((2,), b"to 2")]


def test_a_multicast_message_for_more_robots_than_a_head_names_goes_in_as_few_datagrams_as_it_can():
    group = free_group()
    fleet = 2 * MAX_NAMED + 3
    sender = UdpMulticastTransport(group, LOOPBACK, 0, fleet_size=fleet)
    last = UdpMulticastTransport(group, LOOPBACK, fleet - 1, fleet_size=fleet)
    listener = RawListener(group)
    try:
        sender.send_together([(b"to everyone else", tuple(range(1, fleet)))])
        assert receive_expected(last, [b"to everyone else"]) == Counter([b"to everyone else"])
        heard = listener.receive(PATIENCE)
        assert listener.receive(0.2) is None
    finally:
        for transport in (sender, last, listener):
            transport.close()
    assert [named for named, _ in read_sections(heard, fleet)] == [  # one datagram: three heads
        tuple(range(1, MAX_NAMED + 1)), tuple(range(MAX_NAMED + 1, 2 * MAX_NAMED + 1)), (2 * MAX_NAMED + 1, 2 * MAX_NAMED + 2)
    ]


def test_multicast_messages_that_do_not_fit_in_one_datagram_go_in_more():
    group = free_group()
    sender = UdpMulticastTransport(group, LOOPBACK, 0, fleet_size=3)
    robot = UdpMulticastTransport(group, LOOPBACK, 1, fleet_size=3)
    listener = RawListener(group)
    long = [bytes([number]) * 500 for number in range(3)]
    try:
        sender.send_together([(data, (1,)) for data in long])
        assert receive_expected(robot, long) == Counter(long)
        heard = [listener.receive(PATIENCE) for _ in range(3)]
    finally:
        for transport in (sender, robot, listener):
            transport.close()
    assert all(len(data) <= MAX_MULTICAST_DATAGRAM_BYTES for data in heard)


class RawListener(UdpMulticastTransport):
    """A listener of the group that keeps each datagram as it came, heads and all."""

    def __init__(self, group):
        super().__init__(group, LOOPBACK)

    def receive(self, timeout):
        return self._receive_datagram(timeout, MAX_MULTICAST_DATAGRAM_BYTES + 1)


class ListenerOfHeads(RawListener):
    """A listener of the group that reads each datagram's head: the robots it names, and where its payload starts."""

    def receive(self, timeout):
        data = super().receive(timeout)
        return None if data is None else read_head(data, None)


def test_faults_on_multicast_give_each_named_robot_its_own_fate_and_still_send_one_datagram():
    group = free_group()
    inner = UdpMulticastTransport(group, LOOPBACK, 0, fleet_size=3)
    listener = ListenerOfHeads(group)
    faulty = with_faults(inner, LiveFaults(duplicate=1.0), seed=3)
    try:
        assert isinstance(faulty, SeveralAtOnce)
        faulty.send_together([(b"twice to 1 and 2", (1, 2))])
        heads = [listener.receive(PATIENCE) for _ in range(2)]
    finally:
        faulty.close()
        listener.close()
    assert [named for named, _ in heads] == [(1, 2), (1, 2)]  # two copies, each one datagram naming both
    assert (faulty.counts.sent, faulty.counts.duplicated) == (2, 2)  # a fate per named robot
    lossy = with_faults(UdpMulticastTransport(group, LOOPBACK, 0, fleet_size=3), LiveFaults(loss=1.0), seed=3)
    lossy.send_together([(b"lost", (1, 2))])
    assert (lossy.counts.sent, lossy.counts.lost) == (2, 2)
    lossy.close()
    assert not isinstance(with_faults(UdpTransport((LOOPBACK, 0), {}), LiveFaults(loss=0.5)), SeveralAtOnce)


# -- UdpTransport ----------------------------------------------------------------------------


def test_udp_ports_are_picked_on_loopback(udp_fleet):
    for transport in udp_fleet:
        host, port = transport.address
        assert host == LOOPBACK and port > 0
    assert len({transport.address for transport in udp_fleet}) == 3


def test_udp_send_to_an_unreachable_peer_is_a_lost_datagram():
    closed = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    closed.bind((LOOPBACK, 0))
    address = closed.getsockname()
    closed.close()
    transport = UdpTransport((LOOPBACK, 0), {1: address})
    for _ in range(3):  # the ICMP port-unreachable of one send makes the next one fail
        transport.send(b"nobody listens", recipient=1)
    transport.close()


# -- FaultyTransport ---------------------------------------------------------------------------


def test_faulty_total_loss_delivers_nothing(udp_fleet):
    a, b, c = udp_fleet
    faulty = FaultyTransport(a, LiveFaults(loss=1.0), seed=1)
    for number in range(20):
        faulty.send(b"lost %d" % number)
    faulty.send(b"lost too", recipient=1)
    assert drain(b, 0.3) == [] and drain(c, 0.05) == []
    assert (faulty.counts.sent, faulty.counts.lost, faulty.counts.delayed) == (21, 21, 0)
    faulty.close()


def test_faulty_duplication_delivers_two_copies(udp_fleet):
    a, b, c = udp_fleet
    faulty = FaultyTransport(a, LiveFaults(duplicate=1.0), seed=2)
    faulty.send(b"twice", recipient=1)
    faulty.send(b"twice to all")
    assert sorted(drain(b, 0.3)) == [b"twice", b"twice", b"twice to all", b"twice to all"]
    assert drain(c, 0.05) == [b"twice to all", b"twice to all"]
    assert (faulty.counts.sent, faulty.counts.duplicated, faulty.counts.lost) == (2, 2, 0)
    faulty.close()


def test_faulty_delay_holds_a_datagram_at_least_delay_min(udp_fleet):
    a, b, _ = udp_fleet
    faulty = FaultyTransport(a, LiveFaults(delay_min=0.2, delay_max=0.3), seed=3)
    started = time.monotonic()
    faulty.send(b"late", recipient=1)
    assert receive_within(b, poll=0.01) == b"late"
    assert time.monotonic() - started >= 0.2  # never sooner (later only as the machine's load makes it)
    assert (faulty.counts.sent, faulty.counts.delayed) == (1, 1)
    faulty.close()


def test_faulty_delayed_datagrams_all_arrive_and_close_closes_the_inner_transport():
    inner = RecordingTransport()
    faulty = FaultyTransport(inner, LiveFaults(delay_min=0.01, delay_max=0.05, reorder=0.5), seed=4)
    for number in range(30):
        faulty.send(b"%d" % number, recipient=number % 3)
    deadline = time.monotonic() + PATIENCE
    while len(inner.sent) < 30 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert sorted(data for _, data, _ in inner.sent) == sorted(b"%d" % number for number in range(30))
    assert {(data, recipient) for _, data, recipient in inner.sent} == {(b"%d" % n, n % 3) for n in range(30)}
    assert faulty.counts.delayed == 30 and 0 < faulty.counts.reordered < 30
    faulty.close()
    assert inner.closed


def lost_pattern(seed, count=200, loss=0.5):
    inner = RecordingTransport()
    faulty = FaultyTransport(inner, LiveFaults(loss=loss), seed=seed)
    for number in range(count):
        faulty.send(b"%d" % number)
    faulty.close()
    delivered = {int(data) for _, data, _ in inner.sent}
    assert faulty.counts.sent == count and faulty.counts.lost == count - len(delivered)
    return frozenset(set(range(count)) - delivered)


def test_faulty_loss_is_seeded():
    first, again, other = lost_pattern(seed=11), lost_pattern(seed=11), lost_pattern(seed=12)
    assert first == again  # the same seed loses the same datagrams
    assert first != other
    assert 60 < len(first) < 140  # about half of 200


def test_perfect_faults_pass_everything_through_at_once():
    inner = RecordingTransport()
    faulty = FaultyTransport(inner, LiveFaults(), seed=0)
    assert LiveFaults().is_perfect and not LiveFaults(loss=0.1).is_perfect
    faulty.send(b"a")
    faulty.send(b"b", recipient=2)
    assert [(data, recipient) for _, data, recipient in inner.sent] == [(b"a", None), (b"b", 2)]
    assert faulty.counts.sent == 2 and faulty.counts.lost == faulty.counts.delayed == 0
    faulty.close()


# -- the Zenoh transport without Zenoh ---------------------------------------------------------


def test_zenoh_transport_module_imports_without_zenoh_and_says_what_to_install():
    script = (
        "import sys; sys.modules['zenoh'] = None\n"
        "from mrmp.live import zenoh_transport\n"
        "try:\n"
        "    zenoh_transport.ZenohTransport(0, 'mrmp', 'tcp/127.0.0.1:1', [], 1)\n"
        "except RuntimeError as error:\n"
        "    print(error)\n"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=30, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "the zenoh transport needs the eclipse-zenoh package: in a checkout, .venv/bin/pip install -e '.[zenoh]'"


def test_without_zenoh_its_table_entry_is_still_there_and_says_how_to_install_it():
    script = (
        "import sys; sys.modules['zenoh'] = None\n"
        "from mrmp.live.transport_table import TRANSPORTS\n"
        "print('zenoh' in TRANSPORTS.names, TRANSPORTS.entry('zenoh').unavailable())\n"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=30, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "True zenoh needs the eclipse-zenoh package: in a checkout, .venv/bin/pip install -e '.[zenoh]'"


def test_zenoh_transport_refuses_a_zenoh_without_liveliness(monkeypatch):
    from mrmp.live.zenoh_transport import ZenohTransport

    class OldSession:  # eclipse-zenoh 1.0's Python Session has no liveliness()
        pass

    monkeypatch.setitem(sys.modules, "zenoh", types.SimpleNamespace(Session=OldSession))
    with pytest.raises(RuntimeError, match=r"1\.1 or later"):
        ZenohTransport(0, "mrmp", "tcp/127.0.0.1:1", [], 1)
