"""The shape of a transport table entry: what the rest of the system asks about a transport.

A live robot reaches its peers through a :class:`~mrmp.live.transport.Transport`.
Everything else the system needs to know about one kind of transport is
answered by its :class:`TransportEntry` (the table of them is
:data:`mrmp.live.transport_table.TRANSPORTS`):

* :meth:`~TransportEntry.parse`: ``mrmp agent``'s options, as given, turned
  into the entry's options (a frozen dataclass of its own);
* :meth:`~TransportEntry.hosts`: the hosts those options listen on or send
  to, which the no-key check inspects (a keyless run stays on loopback);
* :meth:`~TransportEntry.open`: the robot process opening the transport;
* :meth:`~TransportEntry.fleet_options` and :meth:`~TransportEntry.arguments`:
  ``mrmp run --live`` giving each robot of a fleet its options, and passing
  them to ``mrmp agent`` as command-line arguments;
* :meth:`~TransportEntry.unavailable`: whether the transport can be used here
  (one may need an optional package);
* :attr:`~TransportEntry.delivery`: who receives what, where transports
  legitimately differ (the transport conformance suite checks it).

A :class:`TransportLayer` wraps any transport (the fault injector is one).
:class:`FleetLayout` is what the launcher decides for a fleet before it starts
the robots: their ids, ports and fleet name.
"""

from __future__ import annotations

import socket
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Generic, TypeVar

from mrmp.core.errors import InputError, Problem
from mrmp.live.transport import Transport

LOOPBACK = "127.0.0.1"
"""The host of every fleet the launcher starts on this machine."""

OptionsT = TypeVar("OptionsT")


def free_ports(count: int) -> list[int]:
    """``count`` distinct ports free for both UDP and TCP on loopback (bound and released together).

    >>> ports = free_ports(3)
    >>> len(set(ports)) == 3 and all(0 < port < 65536 for port in ports)
    True
    """
    sockets: list[socket.socket] = []
    ports: list[int] = []
    try:
        while len(ports) < count:
            tcp = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            tcp.bind((LOOPBACK, 0))
            sockets.append(tcp)
            port = tcp.getsockname()[1]
            udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            sockets.append(udp)
            try:
                udp.bind((LOOPBACK, port))
            except OSError:
                continue  # taken for UDP: keep the TCP socket bound so it is not offered again, try another
            ports.append(port)
        return ports
    finally:
        for sock in sockets:
            sock.close()


@dataclass(frozen=True)
class FleetLayout:
    """Where the robots of one fleet listen: what the launcher decides before starting them.

    ``ports`` has one port per robot (by index), free for UDP and TCP on
    ``host``; ``group_port`` is one more, for a transport that uses one group
    for the whole fleet; ``fleet`` names this fleet (unique per run);
    ``desk_port``, where a lifelong run's task desk listens (None: no desk).

    >>> layout = FleetLayout(("A", "B"), (9001, 9002), 9003, "mrmp/7")
    >>> layout.size, layout.host, layout.others(0)
    (2, '127.0.0.1', [(1, 9002)])
    """

    ids: tuple[str, ...]
    ports: tuple[int, ...]
    group_port: int
    fleet: str
    host: str = LOOPBACK
    desk_port: int | None = None

    @classmethod
    def on_loopback(cls, ids: Sequence[str], fleet: str, desk: bool = False) -> FleetLayout:
        """A layout on loopback with ports free right now (:func:`free_ports`), and one for a task desk if ``desk``.

        >>> layout = FleetLayout.on_loopback(["A", "B", "C"], "mrmp/1", desk=True)
        >>> len(set(layout.ports) | {layout.group_port, layout.desk_port}), layout.fleet
        (5, 'mrmp/1')
        """
        ports = free_ports(len(ids) + 1 + desk)
        return cls(tuple(ids), tuple(ports[: len(ids)]), ports[len(ids)], fleet, desk_port=ports[-1] if desk else None)

    @property
    def desk(self) -> tuple[str, int] | None:
        """The task desk's address, or None without one."""
        return None if self.desk_port is None else (self.host, self.desk_port)

    @property
    def size(self) -> int:
        """How many robots the fleet has."""
        return len(self.ids)

    def others(self, index: int) -> list[tuple[int, int]]:
        """Every other robot's index and port, by index."""
        return [(other, port) for other, port in enumerate(self.ports) if other != index]


@dataclass(frozen=True)
class Delivery:
    """Who receives what: the ways transports legitimately differ beyond the Transport protocol.

    Attributes
    ----------
    echoes:
        Whether a robot receives the datagrams it sends itself.
    addressed_to_all:
        Whether a datagram addressed to one robot reaches every robot (which
        drop what is not for them) instead of that robot only.
    longest:
        The longest datagram ``receive`` returns; longer ones arrive cut to
        this length (the opener then rejects them as oversized). None: every
        datagram arrives whole, whatever its size.
    reaches_several:
        Whether one datagram reaches several named robots (the transport is a
        :class:`~mrmp.live.transport.SeveralAtOnce`), where unicast sends one
        per robot: what a live robot counts as a datagram on the wire, and how
        the virtual clock's network delivers (:mod:`mrmp.live.virtual_time`).

    >>> Delivery()
    Delivery(echoes=False, addressed_to_all=False, longest=None, reaches_several=False)
    """

    echoes: bool = False
    addressed_to_all: bool = False
    longest: int | None = None
    reaches_several: bool = False

    def receivers(self, sender: int, recipient: int | None, fleet_size: int) -> set[int]:
        """The robots that receive what ``sender`` sends to ``recipient`` (None: to every peer).

        >>> Delivery().receivers(0, None, 3), Delivery().receivers(0, 2, 3)
        ({1, 2}, {2})
        >>> Delivery(echoes=True, addressed_to_all=True).receivers(0, 2, 3)
        {0, 1, 2}
        """
        if recipient is not None and not self.addressed_to_all:
            return {recipient}
        return {robot for robot in range(fleet_size) if robot != sender or self.echoes}


class TransportEntry(ABC, Generic[OptionsT]):
    """One kind of transport: its name, its options, and everything the system asks about it.

    A subclass sets :attr:`name`, :attr:`summary` (and :attr:`delivery` where
    it differs from the default) and implements the five abstract methods for
    its own options type. Registering an instance in
    :data:`mrmp.live.transport_table.TRANSPORTS` makes it a choice of
    ``mrmp agent --transport`` and ``mrmp run --live --transport``.
    """

    name: ClassVar[str]
    """The ``--transport`` value that selects this transport."""
    hosts_several: ClassVar[bool] = False
    """Whether one ``mrmp agent`` can host several robots over it, each with a transport of its own (:meth:`hosting`)."""
    reaches_desk: ClassVar[bool] = False
    """Whether its robots reach a lifelong run's task desk (``--task-desk``; :mod:`mrmp.live.task_desk`)."""

    summary: ClassVar[str]
    """One line on what it is."""

    delivery: ClassVar[Delivery] = Delivery()
    """Who receives what (see :class:`Delivery`)."""

    @abstractmethod
    def parse(self, values: Mapping[str, Any], ids: Sequence[str], index: int) -> OptionsT:
        """This transport's options for robot ``index`` from ``mrmp agent``'s option values (by parameter name).

        Raises
        ------
        InputError
            For an option value it cannot use (naming the option).
        """

    @abstractmethod
    def hosts(self, options: OptionsT) -> list[str]:
        """Every host these options listen on or send to (the no-key check refuses any but loopback)."""

    @abstractmethod
    def open(self, options: OptionsT, index: int, fleet_size: int) -> Transport:
        """Open the transport for robot ``index`` of a fleet of ``fleet_size``."""

    @abstractmethod
    def fleet_options(self, layout: FleetLayout, index: int) -> OptionsT:
        """The options of robot ``index`` of a fleet the launcher laid out."""

    @abstractmethod
    def arguments(self, options: OptionsT, ids: Sequence[str]) -> list[str]:
        """``options`` as ``mrmp agent`` arguments (``--option=value``, no ``--transport``); :meth:`parse` reads them back."""

    def unavailable(self) -> str | None:
        """Why this transport cannot be used here and how to fix it, or None when it can."""
        return None

    def hosting(self, values: Mapping[str, Any], ids: Sequence[str], robots: Sequence[str]) -> list[Mapping[str, Any]]:
        """The option values (as :meth:`parse` reads them) of each of several ``robots`` (of the fleet's ``ids``)
        one ``mrmp agent`` hosts, each with a transport of its own, from the values its command line gave.

        Raises
        ------
        InputError
            By default: this transport carries one robot per process.
        """
        raise InputError(Problem("--robot", f"one robot per process over {self.name}"))

    def hosting_arguments(self, layout: FleetLayout, indices: Sequence[int]) -> list[str]:
        """The ``mrmp agent`` arguments of one process hosting robots ``indices`` of a laid-out fleet (:meth:`hosting`
        reads them back)."""
        raise InputError(Problem("--robots-per-process", f"one robot per process over {self.name}"))


class TransportLayer(ABC, Generic[OptionsT]):
    """Something that wraps any transport, e.g. to inject faults; its options travel with the robot's.

    A subclass sets :attr:`name` and :attr:`summary` and implements
    :meth:`wrap`, :meth:`arguments` and :meth:`harmless`.
    """

    name: ClassVar[str]
    """What the layer is called (in test ids and messages)."""

    summary: ClassVar[str]
    """One line on what it does."""

    @abstractmethod
    def wrap(self, transport: Transport, options: OptionsT, seed: int) -> Transport:
        """``transport`` with this layer on top (or ``transport`` itself when the options ask for nothing)."""

    @abstractmethod
    def arguments(self, options: OptionsT) -> list[str]:
        """``options`` as ``mrmp agent`` arguments."""

    @abstractmethod
    def harmless(self) -> OptionsT:
        """Options under which the layer loses no datagram (it may delay them): what the conformance suite wraps with."""
