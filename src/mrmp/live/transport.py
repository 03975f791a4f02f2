"""Transports: how a live robot's datagrams reach its peers.

A transport moves opaque byte strings; sealing and opening them is the
protocol layer's job (:mod:`mrmp.protocol.auth`). Three implementations:

* :class:`UdpTransport`: UDP unicast to a list of peers (the thesis's design,
  section 3.5: "Server and Client are implemented using the UDP Protocol");
* :class:`UdpMulticastTransport`: one UDP multicast group for the fleet, with
  the sending interface always set explicitly (``IP_MULTICAST_IF``);
* ``ZenohTransport`` in :mod:`mrmp.live.zenoh_transport`.

:class:`FaultyTransport` wraps any of them to inject loss, delay, duplication
and reordering into a live run. A transport whose peers must connect before
they can be reached says so by being a :class:`ConnectedTransport`.

Each of them is one entry of :data:`mrmp.live.transport_table.TRANSPORTS`,
which says how to configure, open and launch it.
"""

from __future__ import annotations

import contextlib
import functools
import heapq
import ipaddress
import random
import socket
import struct
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from mrmp.core.faults import message_fates
from mrmp.live.multicast_wire import (
    MAX_MULTICAST_DATAGRAM_BYTES,
    Addressed,
    datagrams_together,
    groups_together,
    payloads_for,
    recipients_head,
)
from mrmp.protocol.auth import MAX_DATAGRAM_BYTES

Address = tuple[str, int]


class Transport(Protocol):
    """Sends datagrams to peers by robot index and receives datagrams addressed to this robot."""

    def send(self, data: bytes, recipient: int | None = None) -> None:
        """Send ``data`` to one peer, or to every peer when ``recipient`` is None."""
        ...

    def receive(self, timeout: float) -> bytes | None:
        """The next datagram, or None after ``timeout`` seconds (or once closed)."""
        ...

    def close(self) -> None:
        """Release the transport's sockets; ``receive`` then returns None."""
        ...


@runtime_checkable
class SeveralAtOnce(Protocol):
    """A transport that reaches several named peers with one datagram (multicast: every robot of the group
    hears it, and each named robot takes it in); a unicast transport sends one datagram per peer instead."""

    def send_together(self, messages: Sequence[Addressed]) -> None:
        """Send ``messages``, each to the peers it names, in as few datagrams as they fit in
        (:func:`~mrmp.live.multicast_wire.datagrams_together`): one, unless they are long or name very many."""
        ...


@runtime_checkable
class ConnectedTransport(Transport, Protocol):
    """A transport whose peers connect before datagrams reach them (Zenoh): it can wait for them.

    Connectionless transports (UDP, multicast) are not: a datagram sent to a
    peer that is up reaches it.
    """

    def wait_for_peers(self, count: int, timeout: float) -> bool:
        """Wait until ``count`` other robots are connected, for at most ``timeout`` seconds; whether they are."""
        ...


def parse_address(text: str) -> Address:
    """Read ``HOST:PORT``.

    Raises
    ------
    ValueError
        If the text is not ``HOST:PORT`` with a port in 0..65535.

    >>> parse_address("127.0.0.1:9001")
    ('127.0.0.1', 9001)
    """
    host, separator, port = text.rpartition(":")
    if not separator or not host or not port.isdigit() or not 0 <= int(port) <= 65535:
        raise ValueError(f"expected HOST:PORT, got {text!r}")
    return host.strip("[]"), int(port)


def is_loopback(host: str) -> bool:
    """Whether ``host`` provably names a loopback address: ``localhost``, or an address of 127.0.0.0/8 or ``::1``.

    Only the strict forms count (:mod:`ipaddress`): ``127.1``, ``0x7f.1`` or
    ``"127.0.0.1 x"``, which the C library's ``inet_aton`` would read as
    127.0.0.1, are not loopback here, nor is an empty host (which means every
    interface to ``bind``).

    >>> is_loopback("127.0.0.1"), is_loopback("localhost"), is_loopback("::1"), is_loopback("[::1]")
    (True, True, True, True)
    >>> is_loopback("10.0.0.1"), is_loopback("0.0.0.0"), is_loopback(""), is_loopback("127.1"), is_loopback("127.0.0.1 x")
    (False, False, False, False, False)
    """
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.removeprefix("[").removesuffix("]")).is_loopback
    except ValueError:
        return False


def multicast_group(text: str) -> Address:
    """Read ``GROUP:PORT`` with an IPv4 multicast group (224.0.0.0/4).

    Raises
    ------
    ValueError
        If the text is not ``HOST:PORT``, or the host is not an IPv4 multicast address.

    >>> multicast_group("239.255.77.1:47000")
    ('239.255.77.1', 47000)
    >>> multicast_group("127.0.0.2:47000")
    Traceback (most recent call last):
    ...
    ValueError: 127.0.0.2 is not an IPv4 multicast group (224.0.0.0 to 239.255.255.255)
    """
    host, port = parse_address(text)
    try:
        multicast = ipaddress.IPv4Address(host).is_multicast
    except ValueError:
        multicast = False
    if not multicast:
        raise ValueError(f"{host} is not an IPv4 multicast group (224.0.0.0 to 239.255.255.255)")
    return host, port


def ipv4_interface(text: str) -> str:
    """Read the IPv4 address of an interface, e.g. ``127.0.0.1``.

    Raises
    ------
    ValueError
        If it is not an IPv4 address in dotted form.

    >>> ipv4_interface("127.0.0.1")
    '127.0.0.1'
    >>> ipv4_interface("lo")
    Traceback (most recent call last):
    ...
    ValueError: expected the IPv4 address of an interface, e.g. 127.0.0.1, got 'lo'
    """
    try:
        return str(ipaddress.IPv4Address(text))
    except ValueError:
        raise ValueError(f"expected the IPv4 address of an interface, e.g. 127.0.0.1, got {text!r}") from None


class _UdpSocket:
    """Receiving and closing, shared by the UDP transports."""

    _socket: socket.socket
    _closed: bool

    def receive(self, timeout: float) -> bytes | None:
        """The next datagram (read up to one byte past the bound, so oversized ones show), or None."""
        return self._receive_datagram(timeout, MAX_DATAGRAM_BYTES + 1)

    def _receive_datagram(self, timeout: float, size: int) -> bytes | None:
        """The next datagram on the socket, read up to ``size`` bytes, or None."""
        if self._closed:
            return None
        try:
            self._socket.settimeout(timeout)
            data, _ = self._socket.recvfrom(size)
        except (TimeoutError, OSError):
            return None
        return None if self._closed else data

    def fileno(self) -> int:
        """The socket's file descriptor (a selector can watch it: :mod:`mrmp.live.host_loop`)."""
        return self._socket.fileno()

    def close(self) -> None:
        """Close the socket, waking a ``receive`` blocked in another thread; ``receive`` returns None from now on."""
        self._closed = True
        with contextlib.suppress(OSError):
            self._socket.shutdown(socket.SHUT_RDWR)  # wakes a blocked recvfrom on Linux
        self._socket.close()


class UdpTransport(_UdpSocket):
    """UDP unicast: one socket bound to ``bind``, datagrams sent to each peer's address.

    Parameters
    ----------
    bind:
        Local address to receive on (port 0 picks a free port; see :attr:`address`).
    peers:
        Each peer's address, by robot index.
    services:
        Addresses reached by an index too, but never by a datagram to every peer (a lifelong run's task desk).
    """

    def __init__(self, bind: Address, peers: Mapping[int, Address], services: Mapping[int, Address] | None = None) -> None:
        self.peers = dict(peers)
        self.services = dict(services or {})
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._socket.bind(bind)
        except BaseException:
            self._socket.close()
            raise
        self.address: Address = self._socket.getsockname()
        self._closed = False

    def send(self, data: bytes, recipient: int | None = None) -> None:
        if recipient is None:
            targets = list(self.peers.values())
        else:
            address = self.peers.get(recipient, self.services.get(recipient))
            targets = [address] if address is not None else []  # no address: lost, as on any network
        for address in targets:
            with contextlib.suppress(OSError):  # an unreachable peer is a lost datagram, as on any network
                self._socket.sendto(data, address)


IP_MULTICAST_ALL = getattr(socket, "IP_MULTICAST_ALL", 49)
"""Linux's socket option (``<linux/in.h>``) that, set to 0, limits a socket to the groups it joined itself."""


class UdpMulticastTransport(_UdpSocket):
    """UDP multicast: every robot joins one group; every datagram goes to all of them.

    The sending and receiving interface is always set explicitly
    (``IP_MULTICAST_IF`` and the membership's interface), never left to the
    routing table. Datagrams addressed to some robots are sent to the group too,
    headed by the robots they are for (:func:`recipients_head`), and a receiver
    drops those that do not name it: as over unicast, a robot takes in only what
    was sent to it or to every robot (it also hears its own datagrams to every
    robot, and drops them). Without it, a robot would take a message meant for
    another (an acknowledgement of a sequence number that happens to be one of
    its own, a request to leave another robot's cell) for its own. Messages
    for several robots, sent together (:meth:`send_together`), are one datagram
    naming them all, where unicast sends one per message and robot
    (:mod:`mrmp.live.multicast_wire`).

    The socket is bound to the group's address, not to every address: on Linux
    it then receives only datagrams sent to the group, never one sent to any
    address of the host (ip(7), "bind"); and with ``IP_MULTICAST_ALL`` off it
    receives only the group it joined, on the interface it joined it on
    (ip(7), ``IP_MULTICAST_ALL``). A robot on the loopback interface is
    therefore unreachable from any other host.

    Parameters
    ----------
    group:
        Multicast group and port, e.g. ``("239.255.77.1", 47000)``.
    interface:
        IPv4 address of the interface to use (``"127.0.0.1"`` on loopback).
    index:
        The robot's index: datagrams headed for another robot are dropped
        (None: none is, as for a listener that is no robot).
    fleet_size:
        How many robots the fleet has: a datagram whose head names none of
        them is no robot's, and is handed on whole, for the opener to reject
        and count (None: every head names a robot).
    """

    def __init__(self, group: Address, interface: str, index: int | None = None, fleet_size: int | None = None) -> None:
        self.group = group
        self.interface = interface
        self.index = index
        self.fleet_size = fleet_size
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if hasattr(socket, "SO_REUSEPORT"):
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
            sock.bind(group)
            if sys.platform.startswith("linux"):
                sock.setsockopt(socket.IPPROTO_IP, IP_MULTICAST_ALL, 0)
            interface_bytes = socket.inet_aton(interface)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, interface_bytes)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            membership = struct.pack("4s4s", socket.inet_aton(group[0]), interface_bytes)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
        except BaseException:
            sock.close()
            raise
        self._socket = sock
        self._closed = False
        self._taken: deque[bytes] = deque()
        """Messages of a datagram received, not returned yet (a datagram may carry several for this robot)."""

    def send(self, data: bytes, recipient: int | None = None) -> None:
        self._send_datagram(recipients_head(() if recipient is None else (recipient,)) + data)

    def send_together(self, messages: Sequence[Addressed]) -> None:
        for datagram, _ in datagrams_together(messages):
            self._send_datagram(datagram)

    def _send_datagram(self, datagram: bytes) -> None:
        with contextlib.suppress(OSError):
            self._socket.sendto(datagram, self.group)

    def receive(self, timeout: float) -> bytes | None:
        """The next message for this robot or for every robot, its head removed, or None.

        A datagram's messages for other robots of the fleet are dropped (they
        take them in, or reject and count them), and when a datagram brings this
        robot nothing, what else waits is looked at without waiting further
        (None when nothing does). A datagram that names no robot of the fleet
        is no robot's: it is handed on whole, and the opener rejects it and
        counts it (:func:`~mrmp.live.multicast_wire.payloads_for`).
        """
        while not self._taken:
            data = self._receive_datagram(timeout, MAX_MULTICAST_DATAGRAM_BYTES + 1)  # one byte more: oversized shows
            if data is None:
                return None
            self._taken.extend(payloads_for(data, self.index, self.fleet_size))
            timeout = 0.0
        return self._taken.popleft()


@dataclass(frozen=True)
class LiveFaults:
    """Faults injected into a live transport: probabilities, and a delay range in seconds."""

    loss: float = 0.0
    delay_min: float = 0.0
    delay_max: float = 0.0
    duplicate: float = 0.0
    reorder: float = 0.0

    @property
    def is_perfect(self) -> bool:
        """Whether nothing is injected."""
        return self == LiveFaults()


@dataclass
class FaultCounts:
    """What a :class:`FaultyTransport` did to the datagrams it was given."""

    sent: int = 0
    lost: int = 0
    duplicated: int = 0
    delayed: int = 0
    reordered: int = 0


class FaultyTransport:
    """Wraps a transport to lose, delay, duplicate and reorder outgoing datagrams (seeded).

    Delayed datagrams are sent by a background thread at their due time; a
    reordered datagram is held back an extra random time so that later ones
    overtake it.
    """

    def __init__(self, inner: Transport, faults: LiveFaults, seed: int = 0) -> None:
        self.inner = inner
        self.faults = faults
        self.counts = FaultCounts()
        self._random = random.Random(seed)
        self._queue: list[tuple[float, int, Callable[[], None]]] = []
        """Sendings held back: when each is due, its order (ties keep it), and the sending."""
        self._order = 0
        self._wake = threading.Condition()
        self._closed = False
        self._thread = threading.Thread(target=self._deliver_late, name="faulty-transport", daemon=True)
        self._thread.start()

    def send(self, data: bytes, recipient: int | None = None) -> None:
        for delay in self._fates():
            if delay <= 0:
                self.inner.send(data, recipient)
            else:
                self._send_later(functools.partial(self.inner.send, data, recipient), delay)

    def _fates(self) -> list[float]:
        """Draw one datagram's fate: the delays of the copies delivered (none if it is lost), each counted."""
        faults = self.faults
        rng = self._random
        self.counts.sent += 1
        fates = message_fates(
            rng,
            faults.loss,
            faults.duplicate,
            faults.reorder,
            (lambda: rng.uniform(faults.delay_min, faults.delay_max)) if faults.delay_max else (lambda: 0.0),
        )
        self.counts.duplicated += fates.duplicated
        self.counts.lost += fates.lost
        delays = []
        for copy in fates.delivered:
            delay = copy.delay
            if copy.reordered:
                self.counts.reordered += 1
                delay += copy.hold * max(faults.delay_max, 0.02)  # held back so that later ones overtake it
            if delay > 0:
                self.counts.delayed += 1
            delays.append(delay)
        return delays

    def _send_later(self, sending: Callable[[], None], delay: float) -> None:
        """Call ``sending`` from the background thread ``delay`` seconds from now."""
        with self._wake:
            self._order += 1
            heapq.heappush(self._queue, (time.monotonic() + delay, self._order, sending))
            self._wake.notify()

    def _deliver_late(self) -> None:
        with self._wake:
            while not self._closed:
                if not self._queue:
                    self._wake.wait()
                    continue
                due = self._queue[0][0] - time.monotonic()
                if due > 0:
                    self._wake.wait(due)
                    continue
                _, _, sending = heapq.heappop(self._queue)
                sending()

    def receive(self, timeout: float) -> bytes | None:
        return self.inner.receive(timeout)

    def close(self) -> None:
        with self._wake:
            self._closed = True
            self._wake.notify()
        self._thread.join(timeout=1.0)
        self.inner.close()


class FaultySeveralTransport(FaultyTransport):
    """A :class:`FaultyTransport` around a transport that reaches several peers with one datagram (multicast).

    Each named peer's copy of a datagram meets its own fate, as each receiver
    of a multicast datagram misses it or not on its own: the copies due at
    once go as one datagram naming their peers, with what it carries for them,
    and delayed ones each on its own.
    """

    def __init__(self, inner: Transport, faults: LiveFaults, seed: int = 0) -> None:
        if not isinstance(inner, SeveralAtOnce):
            raise TypeError(f"{type(inner).__name__} does not reach several peers with one datagram")
        super().__init__(inner, faults, seed)
        self.several: SeveralAtOnce = inner

    def send_together(self, messages: Sequence[Addressed]) -> None:
        for datagram in groups_together(messages):
            due_now: dict[int, list[int]] = {}  # by copy (duplication makes a second): the robots it is due to at once
            for recipient in dict.fromkeys(robot for _, named in datagram for robot in named):
                for copy, delay in enumerate(self._fates()):
                    if delay <= 0:
                        due_now.setdefault(copy, []).append(recipient)
                    else:
                        self._send_later(functools.partial(self.several.send_together, only_for(datagram, {recipient})), delay)
            for robots in due_now.values():
                self.several.send_together(only_for(datagram, set(robots)))


def only_for(messages: Sequence[Addressed], robots: set[int]) -> list[Addressed]:
    """What of ``messages`` is for ``robots``: each message for any of them, naming only them.

    >>> only_for([(b"a", (1, 2)), (b"b", (3,))], {2})
    [(b'a', (2,))]
    """
    kept = ((data, tuple(robot for robot in named if robot in robots)) for data, named in messages)
    return [(data, named) for data, named in kept if named]


def with_faults(transport: Transport, faults: LiveFaults, seed: int = 0) -> FaultyTransport:
    """``transport`` wrapped to inject ``faults``, still reaching several peers at once if it did.

    >>> faulty = with_faults(UdpTransport(("127.0.0.1", 0), {}), LiveFaults(loss=0.1))
    >>> type(faulty).__name__, isinstance(faulty, SeveralAtOnce)
    ('FaultyTransport', False)
    >>> faulty.close()
    """
    if isinstance(transport, SeveralAtOnce):
        return FaultySeveralTransport(transport, faults, seed)
    return FaultyTransport(transport, faults, seed)
