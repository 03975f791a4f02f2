"""The transport conformance suite: the same checks over every transport of the table, on loopback (127.0.0.1) only.

:class:`TransportConformance` holds the checks; its ``stack`` fixture says which
transport (and which layer on top of it, if any) they run on.
:class:`TestEveryTransport` runs them over every entry of
:data:`~mrmp.live.transport_table.TRANSPORTS` (read when the tests are
collected) and over every layer of :data:`~mrmp.live.transport_table.LAYERS`
on top of UDP. :class:`TestAToyTransport` adds an in-process queue transport
through the table alone, from this module, and runs the very same checks on it.

Where transports legitimately differ (a multicast robot hears itself, UDP cuts
oversized datagrams), the checks ask the entry's
:class:`~mrmp.live.transport_entry.Delivery`. Every wait follows progress,
bounded by :data:`polling.PATIENCE`: a loaded machine makes the tests slower,
not red.
"""

from __future__ import annotations

import queue
import threading
import time
import uuid
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import pytest
import typer
from polling import PATIENCE, receive_expected, receive_until, receive_while_closing, receive_within

from mrmp import cli
from mrmp.core.errors import InputError
from mrmp.live.launcher import check_hosting
from mrmp.live.process import check_key_policy
from mrmp.live.transport import ConnectedTransport, SeveralAtOnce, Transport
from mrmp.live.transport_entry import FleetLayout, TransportEntry, TransportLayer
from mrmp.live.transport_table import LAYERS, TRANSPORTS, TransportSpec
from mrmp.protocol.auth import MAX_DATAGRAM_BYTES, Opener, Sealer
from mrmp.protocol.messages import StateMessage

IDS = ("A", "B", "C")

BURST = 12
"""Datagrams sent back to back to one peer in :meth:`TransportConformance.test_a_burst_to_one_peer_arrives_whole`."""


@dataclass(frozen=True)
class Stack:
    """A transport of the table, with a layer on top or not."""

    entry: TransportEntry[Any]
    layer: TransportLayer[Any] | None = None

    def __str__(self) -> str:
        return self.entry.name if self.layer is None else f"{self.layer.name} over {self.entry.name}"


STACKS = [*(Stack(entry) for entry in TRANSPORTS), *(Stack(TRANSPORTS.entry("udp"), layer) for layer in LAYERS)]
"""What :class:`TestEveryTransport` checks: every transport, and every layer over UDP."""


class Fleet:
    """Robots of one fleet (a fresh name, fresh loopback ports) opened through the table; closed at the end."""

    def __init__(self, stack: Stack, size: int) -> None:
        self.stack = stack
        self.layout = FleetLayout.on_loopback(IDS[:size], fleet=f"mrmp-test/{uuid.uuid4().hex}")
        self.robots: list[Transport] = []

    def open(self) -> list[Transport]:
        """Open every robot, then wait until transports that connect have their peers."""
        name, size = self.stack.entry.name, self.layout.size
        opened = []
        for index in range(size):
            try:
                transport = TRANSPORTS.fleet_spec(name, self.layout, index).open(index, size)
            except OSError as error:
                pytest.skip(f"{name} cannot be opened on loopback here: {error}")
            opened.append(transport)
            layer = self.stack.layer
            self.robots.append(transport if layer is None else layer.wrap(transport, layer.harmless(), seed=index))
        for transport in opened:
            if isinstance(transport, ConnectedTransport):
                assert transport.wait_for_peers(size - 1, timeout=PATIENCE), f"{name}: robots did not connect"
        return self.robots

    def close(self) -> None:
        for robot in self.robots:
            robot.close()


class TransportConformance:
    """Every check a transport of the table passes; a subclass provides the ``stack`` fixture."""

    @pytest.fixture
    def fleet(self, stack):
        """A factory of open fleets of ``stack`` (three robots unless told), all closed at the end."""
        problem = stack.entry.unavailable()
        if problem is not None:
            pytest.skip(problem)
        fleets = []

        def make(size=3):
            fleets.append(Fleet(stack, size))
            return fleets[-1].open()

        yield make
        for made in fleets:
            made.close()

    # -- delivery ---------------------------------------------------------------------------------

    def test_a_broadcast_reaches_every_peer(self, stack, fleet):
        robots = fleet()
        robots[0].send(b"from 0 to all")
        receivers = stack.entry.delivery.receivers(0, None, len(robots))
        for index, robot in enumerate(robots):
            expected = [b"from 0 to all"] if index in receivers else []
            assert receive_expected(robot, expected) == Counter(expected), f"robot {index}"

    def test_an_addressed_datagram_reaches_its_recipient(self, stack, fleet):
        robots = fleet()
        robots[0].send(b"0 to 2", recipient=2)
        robots[2].send(b"2 to 1", recipient=1)
        delivery = stack.entry.delivery
        for index, robot in enumerate(robots):
            expected = [data for sender, recipient, data in ((0, 2, b"0 to 2"), (2, 1, b"2 to 1"))
                        if index in delivery.receivers(sender, recipient, len(robots))]
            assert receive_expected(robot, expected) == Counter(expected), f"robot {index}"

    def test_one_datagram_reaches_several_robots_where_the_entry_says_it_does(self, stack, fleet):
        """A transport that reaches several named robots with one datagram says so in its entry, and each named
        robot, and no other, takes it in; the others do not offer it (a live robot then sends one per robot)."""
        robots = fleet()
        several = stack.entry.delivery.reaches_several
        assert all(isinstance(robot, SeveralAtOnce) == several for robot in robots)
        if not several:
            return
        robots[1].send_together([(b"1 to 0 and 2", (0, 2)), (b"1 to 2", (2,))])
        for index, robot in enumerate(robots):
            expected = {0: [b"1 to 0 and 2"], 1: [], 2: [b"1 to 0 and 2", b"1 to 2"]}[index]
            assert receive_expected(robot, expected) == Counter(expected), f"robot {index}"

    def test_a_burst_to_one_peer_arrives_whole(self, stack, fleet):
        """A robot answers several messages at once: a dozen datagrams sent back to back to one peer all arrive."""
        a, b, _ = fleet()
        burst = [b"burst %d" % number + bytes(40) for number in range(BURST)]
        for data in burst:
            a.send(data, recipient=1)
        assert receive_expected(b, burst) == Counter(burst)

    def test_everyone_broadcasting_at_once(self, stack, fleet):
        robots = fleet()
        for index, robot in enumerate(robots):
            robot.send(b"hello from %d" % index)
        delivery = stack.entry.delivery
        for index, robot in enumerate(robots):
            expected = [b"hello from %d" % sender for sender in range(len(robots))
                        if index in delivery.receivers(sender, None, len(robots))]
            assert receive_expected(robot, expected) == Counter(expected), f"robot {index}"

    def test_a_sealed_message_arrives_and_opens(self, fleet):
        a, b, _ = fleet()
        a.send(Sealer(b"k" * 32, session=3).seal(StateMessage(0, 1, (2, 3), (2, 4))), recipient=1)
        message = Opener(b"k" * 32, session=3).open(receive_within(b))
        assert message is not None and message.present == (2, 3)

    # -- oversized and malformed datagrams ----------------------------------------------------------

    def test_an_oversized_datagram_arrives_whole_or_cut_and_the_opener_counts_it(self, stack, fleet):
        a, b, _ = fleet()
        oversized = bytes(range(256)) * ((MAX_DATAGRAM_BYTES + 500) // 256)
        assert len(oversized) > MAX_DATAGRAM_BYTES + 1
        a.send(oversized, recipient=1)
        longest = stack.entry.delivery.longest
        data = receive_within(b)
        assert data == (oversized if longest is None else oversized[:longest])
        opener = Opener(b"", session=1)
        assert opener.open(data) is None
        assert opener.rejected == Counter(oversized=1)

    def test_empty_and_malformed_datagrams_pass_through_for_the_opener_to_reject(self, fleet):
        a, b, _ = fleet()
        garbage = [b"", b"MR\x00", b"XX" + bytes(40)]
        for data in garbage:
            a.send(data, recipient=1)
        received = receive_expected(b, garbage)
        assert received == Counter(garbage)
        opener = Opener(b"k" * 32, session=1)
        assert [opener.open(data) for data in received.elements()] == [None] * 3
        assert opener.rejected == Counter(truncated=2, magic=1)

    # -- timeouts and closing -------------------------------------------------------------------------

    def test_receive_times_out_with_none(self, fleet):
        robot = fleet(2)[0]
        started = time.monotonic()
        assert robot.receive(0.2) is None
        assert 0.15 <= time.monotonic() - started < PATIENCE

    def test_close_wakes_a_blocked_receive(self, fleet):
        data, took, thread = receive_while_closing(fleet(2)[0], timeout=2 * PATIENCE)
        assert not thread.is_alive()
        assert data is None and took < PATIENCE  # woken by close, long before its timeout

    def test_after_close_receive_returns_none_at_once_and_nothing_fails(self, fleet):
        a, b, c = fleet()
        c.send(b"one", recipient=1)
        c.send(b"two, waiting when b closes", recipient=1)
        assert receive_within(b) in (b"one", b"two, waiting when b closes")
        b.close()
        started = time.monotonic()
        assert b.receive(2 * PATIENCE) is None
        assert time.monotonic() - started < PATIENCE  # at once, not after the timeout
        b.close()  # closing twice is harmless
        b.send(b"after close")  # a lost datagram, not an error
        b.send(b"after close", recipient=0)
        a.send(b"to a closed robot", recipient=1)  # a lost datagram, not an error
        a.send(b"to everyone, one of them closed")
        assert receive_until(c, b"to everyone, one of them closed")

    # -- what the rest of the system asks the entry ------------------------------------------------

    def test_the_entry_is_in_the_table_under_its_name(self, stack):
        assert stack.entry.name in TRANSPORTS.names
        assert TRANSPORTS.entry(stack.entry.name) is stack.entry
        assert stack.entry.summary

    def test_a_loopback_fleet_reaches_only_loopback_and_may_go_without_a_key(self, stack):
        layout = FleetLayout(IDS, (9001, 9002, 9003), 9004, "mrmp/1")
        warnings = []
        for index in range(layout.size):
            spec = TRANSPORTS.fleet_spec(stack.entry.name, layout, index)
            assert set(spec.hosts()) <= {"127.0.0.1"}
            assert check_key_policy(None, spec, warnings.append) == b""
        assert len(warnings) == layout.size and "NOT authenticated" in warnings[0]

    def test_a_fleet_elsewhere_names_its_hosts_and_needs_a_key(self, stack):
        layout = FleetLayout(IDS, (9001, 9002, 9003), 9004, "mrmp/1", host="10.201.7.2")
        for index in range(layout.size):
            spec = TRANSPORTS.fleet_spec(stack.entry.name, layout, index)
            hosts = spec.hosts()
            assert set(hosts) <= {"10.201.7.2"}
            assert check_key_policy(b"k" * 32, spec, pytest.fail) == b"k" * 32
            if hosts:  # a transport that reaches no host (in-process) needs no key
                with pytest.raises(InputError, match=r"refusing to talk to 10\.201\.7\.2"):
                    check_key_policy(None, spec, pytest.fail)

    def test_the_launchers_arguments_are_read_back_by_mrmp_agent(self, stack):
        layout = FleetLayout.on_loopback(IDS, fleet="mrmp/42")
        agent = typer.main.get_command(cli.app).commands["agent"]
        for index, robot in enumerate(IDS):
            spec = TRANSPORTS.fleet_spec(stack.entry.name, layout, index)
            arguments = spec.arguments(IDS)
            assert arguments[0] == f"--transport={stack.entry.name}"
            values = agent.make_context("agent", ["--scenario=fleet.yaml", f"--robot={robot}", *arguments]).params
            assert TRANSPORTS.parse(values["transport"], values, IDS, index) == spec


class TestEveryTransport(TransportConformance):
    """The checks over every transport of the table, and every layer over UDP."""

    @pytest.fixture(params=STACKS, ids=str)
    def stack(self, request):
        return request.param


# -- a toy transport, added through the table alone ----------------------------------------------------


class QueueTransport:
    """Robots of one process passing datagrams through in-memory queues; robots of a fleet find each other by its name."""

    fleets: ClassVar[dict[str, dict[int, QueueTransport]]] = {}
    _lock = threading.Lock()

    def __init__(self, fleet: str, index: int) -> None:
        self.fleet, self.index = fleet, index
        self.inbox: queue.SimpleQueue[bytes] = queue.SimpleQueue()
        self.closed = False
        with self._lock:
            self.fleets.setdefault(fleet, {})[index] = self

    def send(self, data: bytes, recipient: int | None = None) -> None:
        with self._lock:
            members = dict(self.fleets.get(self.fleet, {}))
        for index, member in members.items():
            if index != self.index and recipient in (None, index):
                member.inbox.put(data)

    def receive(self, timeout: float) -> bytes | None:
        if self.closed:
            return None
        try:
            data = self.inbox.get(timeout=max(timeout, 0.0))
        except queue.Empty:
            return None
        return None if self.closed else data

    def close(self) -> None:
        self.closed = True
        with self._lock:
            members = self.fleets.get(self.fleet, {})
            members.pop(self.index, None)
            if not members:
                self.fleets.pop(self.fleet, None)
        self.inbox.put(b"")  # wakes a blocked receive, which then sees the transport closed


@dataclass(frozen=True)
class QueueOptions:
    """The in-process queue transport: which fleet to join (``mrmp agent --fleet``)."""

    fleet: str = "mrmp"


class QueueEntry(TransportEntry[QueueOptions]):
    """The toy transport's table entry: all a transport needs to be a choice of the table."""

    name = "queue"
    summary = "in-process queues (a toy: robots of one process only)"

    def parse(self, values: Mapping[str, Any], ids: Sequence[str], index: int) -> QueueOptions:
        return QueueOptions(str(values["fleet"]))

    def hosts(self, options: QueueOptions) -> list[str]:
        return []  # it reaches no network

    def open(self, options: QueueOptions, index: int, fleet_size: int) -> Transport:
        return QueueTransport(options.fleet, index)

    def fleet_options(self, layout: FleetLayout, index: int) -> QueueOptions:
        return QueueOptions(layout.fleet)

    def arguments(self, options: QueueOptions, ids: Sequence[str]) -> list[str]:
        return [f"--fleet={options.fleet}"]


class TestAToyTransport(TransportConformance):
    """The same checks over a transport this module adds to the table (and takes out again)."""

    @pytest.fixture
    def stack(self):
        with TRANSPORTS.added(QueueEntry()) as entry:
            yield Stack(entry)
        assert not QueueTransport.fleets  # every robot closed


def test_a_transport_added_through_the_table_is_a_choice_until_it_is_taken_out():
    with TRANSPORTS.added(QueueEntry()):
        assert TRANSPORTS.names[-1] == "queue" and TRANSPORTS.listed().endswith(", zenoh or queue")
        spec = TRANSPORTS.parse("queue", {"fleet": "mrmp/5"}, IDS, 0)
        assert spec == TransportSpec("queue", QueueOptions("mrmp/5"))
        with pytest.raises(ValueError, match="already in the table"):
            TRANSPORTS.add(QueueEntry())
    assert "queue" not in TRANSPORTS
    with pytest.raises(InputError, match="unknown transport 'queue'; known: udp, multicast, zenoh"):
        TRANSPORTS.entry("queue")


def test_several_robots_to_a_process_are_refused_over_a_transport_that_carries_one():
    with TRANSPORTS.added(QueueEntry()):
        check_hosting(1, "queue", kill=False, ros2=False)
        with pytest.raises(InputError, match="--robots-per-process: one robot per process over queue"):
            check_hosting(2, "queue", kill=False, ros2=False)
