"""What only the Zenoh transport does: three robots in a full mesh of explicit loopback TCP endpoints.

What every transport does is checked once for all of them in test_transport_conformance.py.
"""

import select
import socket
import time
import uuid

import pytest

zenoh = pytest.importorskip("zenoh")

from polling import PATIENCE, drain, receive_within  # noqa: E402 (after the skip when Zenoh is missing)
from test_orphans import wait_for  # noqa: E402

from mrmp.live.zenoh_transport import ZenohTransport, session_config  # noqa: E402

LOOPBACK = "127.0.0.1"


def free_ports(count):
    """``count`` distinct TCP ports free on loopback right now (bound together, then released)."""
    sockets = []
    try:
        for _ in range(count):
            sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            sock.bind((LOOPBACK, 0))
            sockets.append(sock)
        return [sock.getsockname()[1] for sock in sockets]
    finally:
        for sock in sockets:
            sock.close()


def endpoint(port):
    return f"tcp/{LOOPBACK}:{port}"


class Fleet:
    """Opens robots of one fleet (a fresh key prefix) on fresh ports; closes them all at the end."""

    def __init__(self, size):
        self.size = size
        self.name = f"mrmp-test/{uuid.uuid4().hex}"
        self.ports = free_ports(size)
        self.robots = {}

    def start(self, index, connect=None, **options):
        if connect is None:
            connect = [endpoint(port) for other, port in enumerate(self.ports) if other != index]
        robot = ZenohTransport(index, self.name, endpoint(self.ports[index]), connect, self.size, **options)
        self.robots[index] = robot
        return robot

    def close(self):
        for robot in self.robots.values():
            robot.close()


@pytest.fixture
def fleet():
    fleets = []

    def make(size=3):
        fleets.append(Fleet(size))
        return fleets[-1]

    yield make
    for made in fleets:
        made.close()


@pytest.fixture
def mesh(fleet):
    """Three connected robots."""
    three = fleet(3)
    robots = [three.start(index) for index in range(3)]
    assert all(robot.wait_for_peers(2, timeout=PATIENCE) for robot in robots)
    return robots



def test_configuration_is_peer_mode_with_explicit_endpoints_only():
    config = session_config(endpoint(7447), [endpoint(7448), endpoint(7449)])
    assert config["mode"] == "peer"
    assert config["scouting/multicast/enabled"] is False and config["scouting/gossip/enabled"] is False
    assert config["listen/endpoints"] == ["tcp/127.0.0.1:7447"]
    assert config["connect/endpoints"] == ["tcp/127.0.0.1:7448", "tcp/127.0.0.1:7449"]
    assert config["connect/exit_on_failure"] is False and config["connect/timeout_ms"] == -1
    assert config["connect/retry"]["period_max_ms"] <= 500  # a peer that comes up later is dialled again soon


def test_connected_peers_are_the_others(mesh):
    a, b, c = mesh
    assert a.peers() == {1, 2} and b.peers() == {0, 2} and c.peers() == {0, 1}


def test_a_robot_started_before_its_peers_still_connects(fleet):
    three = fleet(3)
    first = three.start(0)
    assert not first.wait_for_peers(1, timeout=0.5)  # nobody there yet
    others = [three.start(1), three.start(2)]
    assert all(robot.wait_for_peers(2, timeout=PATIENCE) for robot in (first, *others))
    first.send(b"first to all")
    others[1].send(b"third to first", recipient=0)
    assert [receive_within(robot) for robot in others] == [b"first to all"] * 2
    assert receive_within(first) == b"third to first"


def test_a_peer_that_comes_up_later_is_dialled_again(fleet):
    two = fleet(2)
    dialler = two.start(0)  # dials robot 1, which is not up
    time.sleep(0.5)
    listener = two.start(1, connect=[])  # never dials: the link can only come from robot 0's retries
    assert dialler.wait_for_peers(1, timeout=PATIENCE) and listener.wait_for_peers(1, timeout=PATIENCE)
    listener.send(b"you found me")
    assert receive_within(dialler) == b"you found me"


def test_robots_find_each_other_only_through_explicit_endpoints(fleet):
    two = fleet(2)
    a = two.start(0, connect=[])
    b = two.start(1, connect=[])
    assert not a.wait_for_peers(1, timeout=1.0)  # no scouting: same fleet, same host, never connected
    assert b.peers() == set()


def test_fleets_do_not_hear_each_other(fleet):
    ours, theirs = fleet(2), fleet(2)
    a0, a1 = ours.start(0), ours.start(1)
    stranger = theirs.start(0, connect=[endpoint(ours.ports[0])])  # same Zenoh network, other fleet prefix
    assert a0.wait_for_peers(1, timeout=PATIENCE) and a1.wait_for_peers(1, timeout=PATIENCE)
    stranger.send(b"wrong fleet")
    stranger.send(b"wrong fleet to 1", recipient=1)
    assert drain(a0, 0.3) == [] and drain(a1, 0.05) == []
    assert stranger.peers() == set() and a0.peers() == {1}


def test_close_is_prompt_and_peers_see_it(mesh):
    a, b, c = mesh
    for robot in (c, b):
        robot.close()
        assert robot.closed and robot.receive(5.0) is None
    deadline = time.monotonic() + PATIENCE
    while a.peers() and time.monotonic() < deadline:
        time.sleep(0.02)
    assert a.peers() == set()
    b.close()  # closing twice is harmless
    b.send(b"after close")  # a lost datagram, not an error
    a.close()
    assert a.closed


def test_the_queue_is_capped_dropping_the_oldest(fleet):
    """Of the datagrams that reach an unread receiver, it keeps the newest five, in order.

    Zenoh itself may drop a datagram on a busy machine (its congestion control
    drops rather than blocks), so the sender sends until 20 have arrived and the
    test counts what arrived, not what was sent.
    """
    two = fleet(2)
    sender = two.start(0)
    receiver = two.start(1, queue_limit=5)
    assert sender.wait_for_peers(1, timeout=PATIENCE) and receiver.wait_for_peers(1, timeout=PATIENCE)
    sent = 0
    deadline = time.monotonic() + PATIENCE
    while receiver.received < 20 and time.monotonic() < deadline:
        sender.send(b"%d" % sent)
        sent += 1
        time.sleep(0.002)
    settled = -1
    while settled != receiver.received:  # what is still in flight arrives
        settled = receiver.received
        time.sleep(0.2)
    assert receiver.received >= 20 and receiver.dropped == receiver.received - 5
    kept = [int(data) for data in drain(receiver, 0.1)]
    assert len(kept) == 5 and kept == sorted(set(kept)) and kept[-1] < sent


def test_bad_arguments_are_refused(mesh):
    with pytest.raises(ValueError, match="no peer 3"):
        mesh[0].send(b"x", recipient=3)
    with pytest.raises(ValueError, match="no peer 0"):
        mesh[0].send(b"x", recipient=0)
    port = free_ports(1)[0]
    with pytest.raises(ValueError, match=r"not in 0\.\.2"):
        ZenohTransport(3, "mrmp/x", endpoint(port), [], 3)
    with pytest.raises(ValueError, match="Zenoh key"):
        ZenohTransport(0, "mrmp/*", endpoint(port), [], 3)
    with pytest.raises(ValueError, match="Zenoh key"):
        ZenohTransport(0, "mrmp//x", endpoint(port), [], 3)


def test_a_taken_listen_endpoint_fails_to_open(mesh):
    taken = mesh[0].listen
    with pytest.raises(zenoh.ZError):
        ZenohTransport(0, "mrmp/other", taken, [], 2)


def readable(transport, timeout):
    """Whether ``transport``'s watched socket becomes readable within ``timeout`` seconds."""
    ready, _, _ = select.select([transport.fileno()], [], [], timeout)
    return bool(ready)


def test_its_socket_is_readable_exactly_while_a_datagram_waits(mesh):
    """What a process hosting several robots watches: readable once a datagram is queued, quiet once it is taken."""
    a, b, _ = mesh
    assert not readable(b, 0.0)
    a.send(b"wake", recipient=1)
    assert readable(b, PATIENCE)
    assert b.receive(0.0) == b"wake"
    assert b.receive(0.0) is None and not readable(b, 0.0)


def test_a_datagram_queued_before_the_socket_was_asked_for_makes_it_readable(mesh):
    a, b, _ = mesh
    a.send(b"early", recipient=1)
    assert wait_for(lambda: b.received >= 1)  # queued, not taken
    assert readable(b, 0.0)
    assert b.receive(0.0) == b"early"
    b.close()
    with pytest.raises(ValueError, match="closed"):
        b.fileno()
