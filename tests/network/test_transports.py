"""The UDP transports and the fault injector, on loopback (127.0.0.1 only)."""

import os
import random
import socket
import subprocess
import sys
import threading
import time
import types

import pytest

from mrmp.live.transport import (
    FaultyTransport,
    LiveFaults,
    UdpMulticastTransport,
    UdpTransport,
)
from mrmp.protocol.auth import MAX_DATAGRAM_BYTES, Opener, Sealer
from mrmp.protocol.messages import StateMessage
from polling import drain, receive_while_closing, receive_within

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


# -- UdpTransport ----------------------------------------------------------------------------


def test_udp_ports_are_picked_on_loopback(udp_fleet):
    for transport in udp_fleet:
        host, port = transport.address
        assert host == LOOPBACK and port > 0
    assert len({transport.address for transport in udp_fleet}) == 3


def test_udp_unicast_reaches_only_the_recipient(udp_fleet):
    a, b, c = udp_fleet
    a.send(b"for b only", recipient=1)
    assert receive_within(b) == b"for b only"
    assert drain(c, 0.2) == [] and drain(a, 0.05) == []


def test_udp_broadcast_reaches_every_peer(udp_fleet):
    a, b, c = udp_fleet
    a.send(b"to everyone")
    assert receive_within(b) == b"to everyone"
    assert receive_within(c) == b"to everyone"
    assert drain(a, 0.1) == []  # a robot is not its own peer


def test_udp_oversized_datagram_arrives_truncated_and_the_opener_counts_it(udp_fleet):
    a, b, _ = udp_fleet
    a.send(bytes(range(256)) * ((MAX_DATAGRAM_BYTES + 300) // 256 + 1), recipient=1)
    data = receive_within(b)
    assert data is not None and len(data) == MAX_DATAGRAM_BYTES + 1
    opener = Opener(b"", session=1)
    assert opener.open(data) is None
    assert opener.rejected["oversized"] == 1


def test_udp_carries_a_sealed_message(udp_fleet):
    a, b, _ = udp_fleet
    a.send(Sealer(b"k" * 32, session=3).seal(StateMessage(0, 1, (2, 3), (2, 4))), recipient=1)
    message = Opener(b"k" * 32, session=3).open(receive_within(b))
    assert message is not None and message.present == (2, 3)


def test_udp_receive_times_out_with_none(udp_fleet):
    started = time.monotonic()
    assert udp_fleet[0].receive(0.2) is None
    assert 0.15 <= time.monotonic() - started < 1.0


def test_udp_receive_after_close_returns_none_at_once():
    transport = UdpTransport((LOOPBACK, 0), {})
    peer = UdpTransport((LOOPBACK, 0), {0: transport.address})
    peer.send(b"queued before close")
    time.sleep(0.05)
    transport.close()
    started = time.monotonic()
    assert transport.receive(5.0) is None
    assert time.monotonic() - started < 0.1
    peer.send(b"to a closed transport")  # not an error: a lost datagram
    peer.close()


def test_udp_send_to_an_unreachable_peer_is_a_lost_datagram():
    closed = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    closed.bind((LOOPBACK, 0))
    address = closed.getsockname()
    closed.close()
    transport = UdpTransport((LOOPBACK, 0), {1: address})
    for _ in range(3):  # the ICMP port-unreachable of one send makes the next one fail
        transport.send(b"nobody listens", recipient=1)
    transport.close()


def test_udp_close_wakes_a_blocked_receive():
    data, took, _ = receive_while_closing(UdpTransport((LOOPBACK, 0), {}), timeout=1.0)
    assert data is None and took < 0.5


# -- UdpMulticastTransport ---------------------------------------------------------------------


def test_multicast_on_loopback_reaches_every_member():
    rng = random.Random(os.getpid() ^ time.time_ns())
    group = (f"239.255.77.{rng.randint(1, 254)}", rng.randint(40_000, 59_999))
    try:
        a = UdpMulticastTransport(group, LOOPBACK)
        b = UdpMulticastTransport(group, LOOPBACK)
    except OSError as error:
        pytest.skip(f"the kernel refuses multicast on loopback ({group[0]}:{group[1]} via {LOOPBACK}): {error}")
    try:
        nonce = f"hello {rng.getrandbits(64):x}".encode()
        a.send(nonce)
        heard = {}
        for name, transport in (("a", a), ("b", b)):
            deadline = time.monotonic() + 2.0
            while time.monotonic() < deadline and name not in heard:
                if transport.receive(0.05) == nonce:
                    heard[name] = True
        if not heard:
            pytest.skip(f"multicast on loopback is not delivered here ({group[0]}:{group[1]})")
        assert heard == {"a": True, "b": True}  # the sender hears itself too (IP_MULTICAST_LOOP)
        a.send(b"x", recipient=1)  # addressed datagrams go to the group as well
        assert receive_within(b) == b"x"
    finally:
        a.close()
        b.close()
    assert a.receive(1.0) is None


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
    assert receive_within(b, timeout=2.0, poll=0.01) == b"late"
    took = time.monotonic() - started
    assert 0.2 <= took < 1.0
    assert (faulty.counts.sent, faulty.counts.delayed) == (1, 1)
    faulty.close()


def test_faulty_delayed_datagrams_all_arrive_and_close_closes_the_inner_transport():
    inner = RecordingTransport()
    faulty = FaultyTransport(inner, LiveFaults(delay_min=0.01, delay_max=0.05, reorder=0.5), seed=4)
    for number in range(30):
        faulty.send(b"%d" % number, recipient=number % 3)
    deadline = time.monotonic() + 2.0
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
    assert result.stdout.strip() == "the zenoh transport needs the eclipse-zenoh package: pip install eclipse-zenoh"


def test_zenoh_transport_refuses_a_zenoh_without_liveliness(monkeypatch):
    from mrmp.live.zenoh_transport import ZenohTransport

    class OldSession:  # eclipse-zenoh 1.0's Python Session has no liveliness()
        pass

    monkeypatch.setitem(sys.modules, "zenoh", types.SimpleNamespace(Session=OldSession))
    with pytest.raises(RuntimeError, match="1.1 or later"):
        ZenohTransport(0, "mrmp", "tcp/127.0.0.1:1", [], 1)
