"""The transport table: every live transport as one entry, and the layers that wrap any of them.

:data:`TRANSPORTS` holds one :class:`~mrmp.live.transport_entry.TransportEntry`
per transport: UDP unicast (the thesis's design, section 3.5), UDP multicast,
and Zenoh (optional: imported only when opened; without ``eclipse-zenoh`` the
entry is still listed and says how to install it). :data:`LAYERS` holds the
layers that wrap any transport: :data:`FAULTS`, the fault injector.

Everything outside asks the table: ``mrmp agent`` parses its options through
it (:meth:`TransportTable.parse`), the robot process opens what it returns
(:meth:`TransportSpec.open`), the no-key check asks it for the hosts
(:meth:`TransportSpec.hosts`), and ``mrmp run --live`` asks it for each
robot's arguments (:meth:`TransportTable.fleet_spec`, :meth:`TransportSpec.arguments`).

>>> TRANSPORTS.names
('udp', 'multicast', 'zenoh')
>>> spec = TRANSPORTS.fleet_spec("udp", FleetLayout(("A", "B"), (9001, 9002), 9003, "mrmp/7"), 0)
>>> spec.arguments(("A", "B"))
['--transport=udp', '--bind=127.0.0.1:9001', '--peer=B=127.0.0.1:9002']
>>> spec.hosts()
['127.0.0.1', '127.0.0.1']
"""

from __future__ import annotations

import importlib.util
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from mrmp.core.errors import InputError, Problem
from mrmp.live.transport import (
    Address,
    LiveFaults,
    Transport,
    UdpMulticastTransport,
    UdpTransport,
    ipv4_interface,
    multicast_group,
    parse_address,
    with_faults,
)
from mrmp.live.transport_entry import Delivery, FleetLayout, TransportEntry, TransportLayer
from mrmp.live.zenoh_transport import ZenohEndpoint, fleet_keys
from mrmp.protocol.auth import MAX_DATAGRAM_BYTES


def _address(values: Mapping[str, Any], name: str) -> Address:
    try:
        return parse_address(str(values[name]))
    except ValueError as error:
        raise InputError(Problem(f"--{name}", str(error))) from None


def _text(address: Address) -> str:
    return f"{address[0]}:{address[1]}"


# -- UDP unicast --------------------------------------------------------------------------------


@dataclass(frozen=True)
class UdpOptions:
    """UDP unicast: the address to receive on, every peer's address by robot index, and a lifelong run's task
    desk's (None: no desk)."""

    bind: Address = ("127.0.0.1", 0)
    peers: Mapping[int, Address] = field(default_factory=dict)
    desk: Address | None = None


class UdpEntry(TransportEntry[UdpOptions]):
    """UDP unicast to every peer's address (:class:`~mrmp.live.transport.UdpTransport`).

    >>> UdpEntry().parse({"bind": "127.0.0.1:9001", "peer": ["B=127.0.0.1:9002"]}, ["A", "B"], 0)
    UdpOptions(bind=('127.0.0.1', 9001), peers={1: ('127.0.0.1', 9002)}, desk=None)
    >>> UdpEntry().parse({"bind": "127.0.0.1:9001", "peer": []}, ["A", "B"], 0)
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: --peer: no address for B: give --peer ID=HOST:PORT for every other robot
    """

    name = "udp"
    summary = "UDP unicast to every peer's address"
    delivery = Delivery(longest=MAX_DATAGRAM_BYTES + 1)
    reaches_desk = True

    def parse(self, values: Mapping[str, Any], ids: Sequence[str], index: int) -> UdpOptions:
        peers: dict[int, Address] = {}
        for item in values.get("peer") or ():
            name, separator, address = item.partition("=")
            if not separator or name not in ids:
                raise InputError(Problem("--peer", f"expected ID=HOST:PORT with a robot id of the scenario, got {item!r}"))
            try:
                peers[ids.index(name)] = parse_address(address)
            except ValueError as error:
                raise InputError(Problem("--peer", str(error))) from None
        missing = [ids[other] for other in range(len(ids)) if other != index and other not in peers]
        if missing:
            give = "give --peer ID=HOST:PORT for every other robot"
            raise InputError(Problem("--peer", f"no address for {', '.join(missing)}: {give}"))
        desk = _address(values, "task_desk") if values.get("task_desk") else None
        return UdpOptions(_address(values, "bind"), peers, desk)

    def hosts(self, options: UdpOptions) -> list[str]:
        desk = [] if options.desk is None else [options.desk[0]]
        return [options.bind[0], *(address[0] for address in options.peers.values()), *desk]

    def open(self, options: UdpOptions, index: int, fleet_size: int) -> Transport:
        """The robot's socket; the desk, if any, is reached as index ``fleet_size`` (one past the last robot)."""
        return UdpTransport(options.bind, options.peers, {} if options.desk is None else {fleet_size: options.desk})

    def fleet_options(self, layout: FleetLayout, index: int) -> UdpOptions:
        host = layout.host
        return UdpOptions((host, layout.ports[index]), {other: (host, port) for other, port in layout.others(index)}, layout.desk)

    def arguments(self, options: UdpOptions, ids: Sequence[str]) -> list[str]:
        peers = [f"--peer={ids[other]}={_text(address)}" for other, address in options.peers.items()]
        return [f"--bind={_text(options.bind)}", *peers, *_desk_arguments(options.desk)]

    hosts_several = True

    def hosting(self, values: Mapping[str, Any], ids: Sequence[str], robots: Sequence[str]) -> list[Mapping[str, Any]]:
        """Each hosted robot binds the address its own ``--peer`` gives and sends to the others'.

        >>> UdpEntry().hosting({"peer": ["A=127.0.0.1:9001", "B=127.0.0.1:9002"]}, ["A", "B"], ["B", "A"])
        [{'peer': ['A=127.0.0.1:9001'], 'bind': '127.0.0.1:9002'}, {'peer': ['B=127.0.0.1:9002'], 'bind': '127.0.0.1:9001'}]
        """
        entries = [str(item) for item in values.get("peer") or ()]
        addresses = {name: address for name, _, address in (item.partition("=") for item in entries)}
        hosted: list[Mapping[str, Any]] = []
        for robot in robots:
            if robot not in addresses:
                reason = f"no address for {robot}: each robot of a process that hosts several binds its own --peer address"
                raise InputError(Problem("--peer", reason))
            others = [item for item in entries if item.partition("=")[0] != robot]
            hosted.append({**values, "peer": others, "bind": addresses[robot]})
        return hosted

    def hosting_arguments(self, layout: FleetLayout, indices: Sequence[int]) -> list[str]:
        """Every robot's address as a ``--peer``, the hosted ones' included.

        >>> UdpEntry().hosting_arguments(FleetLayout(("A", "B"), (9001, 9002), 9003, "mrmp/7"), [1])
        ['--peer=A=127.0.0.1:9001', '--peer=B=127.0.0.1:9002']
        """
        peers = [f"--peer={robot}={layout.host}:{port}" for robot, port in zip(layout.ids, layout.ports, strict=True)]
        return peers + _desk_arguments(layout.desk)


def _desk_arguments(desk: Address | None) -> list[str]:
    """``mrmp agent``'s argument for a lifelong run's task desk at ``desk`` (none without a desk)."""
    return [] if desk is None else [f"--task-desk={_text(desk)}"]


# -- UDP multicast ------------------------------------------------------------------------------


@dataclass(frozen=True)
class MulticastOptions:
    """UDP multicast: the fleet's group, and the IPv4 address of the interface to use."""

    group: Address = ("239.255.77.1", 47000)
    interface: str = "127.0.0.1"


class MulticastEntry(TransportEntry[MulticastOptions]):
    """One UDP multicast group for the fleet (:class:`~mrmp.live.transport.UdpMulticastTransport`).

    >>> entry = MulticastEntry()
    >>> options = entry.fleet_options(FleetLayout(("A", "B"), (9001, 9002), 47003, "mrmp/7"), 1)
    >>> entry.arguments(options, ("A", "B")), entry.hosts(options)
    (['--group=239.255.77.4:47003', '--interface=127.0.0.1'], ['127.0.0.1'])
    """

    name = "multicast"
    summary = "one UDP multicast group for the fleet, on an explicit interface"
    delivery = Delivery(echoes=True, longest=MAX_DATAGRAM_BYTES + 1, reaches_several=True)

    def parse(self, values: Mapping[str, Any], ids: Sequence[str], index: int) -> MulticastOptions:
        try:
            group = multicast_group(str(values["group"]))
        except ValueError as error:
            raise InputError(Problem("--group", str(error))) from None
        try:
            interface = ipv4_interface(str(values["interface"]))
        except ValueError as error:
            raise InputError(Problem("--interface", str(error))) from None
        return MulticastOptions(group, interface)

    def hosts(self, options: MulticastOptions) -> list[str]:
        return [options.interface]

    def open(self, options: MulticastOptions, index: int, fleet_size: int) -> Transport:
        return UdpMulticastTransport(options.group, options.interface, index, fleet_size)

    def fleet_options(self, layout: FleetLayout, index: int) -> MulticastOptions:
        return MulticastOptions((f"239.255.77.{1 + layout.group_port % 250}", layout.group_port), layout.host)

    def arguments(self, options: MulticastOptions, ids: Sequence[str]) -> list[str]:
        return [f"--group={_text(options.group)}", f"--interface={options.interface}"]

    hosts_several = True

    def hosting(self, values: Mapping[str, Any], ids: Sequence[str], robots: Sequence[str]) -> list[Mapping[str, Any]]:
        """Every hosted robot joins the group with a socket of its own."""
        return [values for _ in robots]

    def hosting_arguments(self, layout: FleetLayout, indices: Sequence[int]) -> list[str]:
        return self.arguments(self.fleet_options(layout, indices[0]), layout.ids)


# -- Zenoh --------------------------------------------------------------------------------------

MISSING_ZENOH_PACKAGE = "zenoh needs the eclipse-zenoh package: in a checkout, .venv/bin/pip install -e '.[zenoh]'"
"""What the Zenoh entry answers when ``eclipse-zenoh`` is not installed."""


@dataclass(frozen=True)
class ZenohOptions:
    """Zenoh: this robot's endpoint, the other robots' endpoints, and the fleet's key prefix."""

    listen: str = ""
    connect: tuple[str, ...] = ()
    fleet: str = "mrmp"


class ZenohEntry(TransportEntry[ZenohOptions]):
    """Zenoh peer sessions over explicit endpoints (:class:`~mrmp.live.zenoh_transport.ZenohTransport`).

    >>> entry = ZenohEntry()
    >>> options = entry.fleet_options(FleetLayout(("A", "B"), (7447, 7448), 7449, "mrmp/7"), 0)
    >>> entry.arguments(options, ("A", "B"))
    ['--listen=tcp/127.0.0.1:7447', '--connect=tcp/127.0.0.1:7448', '--fleet=mrmp/7']
    >>> entry.hosts(options)
    ['127.0.0.1', '127.0.0.1']

    Endpoints are read with Zenoh's own grammar (:class:`ZenohEndpoint`); one
    whose reach is not just its host (metadata, ``#config``, a protocol other
    than TCP or UDP) is named whole by :meth:`hosts`, so that the no-key check
    refuses it:

    >>> entry.hosts(ZenohOptions("tcp/0.0.0.0:17450?x=/", ("tcp/127.0.0.1:7448#iface=eth0",)))
    ['tcp/0.0.0.0:17450?x=/', 'tcp/127.0.0.1:7448#iface=eth0']
    >>> entry.parse({"listen": "", "connect": [], "fleet": "mrmp"}, ["A", "B"], 0)
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: --listen: the zenoh transport needs this robot's endpoint, e.g. tcp/127.0.0.1:7447
    """

    name = "zenoh"
    summary = "Zenoh peer sessions over explicit endpoints (needs eclipse-zenoh)"

    def parse(self, values: Mapping[str, Any], ids: Sequence[str], index: int) -> ZenohOptions:
        listen, connect, fleet = str(values.get("listen") or ""), tuple(values.get("connect") or ()), str(values["fleet"])
        if not listen:
            raise InputError(Problem("--listen", "the zenoh transport needs this robot's endpoint, e.g. tcp/127.0.0.1:7447"))
        for option, endpoint in (("--listen", listen), *(("--connect", endpoint) for endpoint in connect)):
            try:
                ZenohEndpoint.parse(endpoint)
            except ValueError as error:
                raise InputError(Problem(option, str(error))) from None
        try:
            fleet_keys(fleet, index)
        except ValueError as error:
            raise InputError(Problem("--fleet", str(error))) from None
        return ZenohOptions(listen, connect, fleet)

    def hosts(self, options: ZenohOptions) -> list[str]:
        hosts = []
        for text in (options.listen, *options.connect):
            try:
                host = ZenohEndpoint.parse(text).sole_host()
            except ValueError:
                host = None
            hosts.append(text if host is None else host)
        return hosts

    def open(self, options: ZenohOptions, index: int, fleet_size: int) -> Transport:
        import zenoh

        from mrmp.live.zenoh_transport import ZenohTransport

        try:
            return ZenohTransport(index, options.fleet, options.listen, list(options.connect), fleet_size)
        except zenoh.ZError as error:  # e.g. the endpoint is taken, or Zenoh cannot use it
            first_line = str(error).splitlines()[0] if str(error) else type(error).__name__
            raise OSError(first_line.split(" at /", 1)[0]) from None  # without the source location of Zenoh's Rust code

    def fleet_options(self, layout: FleetLayout, index: int) -> ZenohOptions:
        connect = tuple(f"tcp/{layout.host}:{port}" for _, port in layout.others(index))
        return ZenohOptions(f"tcp/{layout.host}:{layout.ports[index]}", connect, layout.fleet)

    def arguments(self, options: ZenohOptions, ids: Sequence[str]) -> list[str]:
        connects = [f"--connect={endpoint}" for endpoint in options.connect]
        return [f"--listen={options.listen}", *connects, f"--fleet={options.fleet}"]

    hosts_several = True

    def hosting(self, values: Mapping[str, Any], ids: Sequence[str], robots: Sequence[str]) -> list[Mapping[str, Any]]:
        """Every robot's endpoint is a ``--connect``, in the fleet's order; each hosted robot listens on its own
        and dials the others' (a session of its own), so ``--listen`` is not given.

        >>> for own in ZenohEntry().hosting({"connect": ["tcp/127.0.0.1:7447", "tcp/127.0.0.1:7448"]}, "AB", "BA"):
        ...     print(own)
        {'connect': ['tcp/127.0.0.1:7447'], 'listen': 'tcp/127.0.0.1:7448'}
        {'connect': ['tcp/127.0.0.1:7448'], 'listen': 'tcp/127.0.0.1:7447'}
        >>> ZenohEntry().hosting({"connect": ["tcp/127.0.0.1:7447"]}, ["A", "B"], ["B", "A"])  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        mrmp.core.errors.InputError: --connect: a process hosting several robots gives every robot's endpoint, ...
        """
        if values.get("listen"):
            reason = "a process hosting several robots takes each one's endpoint from --connect (every robot's, in order)"
            raise InputError(Problem("--listen", reason))
        endpoints = [str(item) for item in values.get("connect") or ()]
        if len(endpoints) != len(ids):
            reason = f"{len(ids)} robots, {len(endpoints)} --connect"
            every = "a process hosting several robots gives every robot's endpoint, in the scenario's order"
            raise InputError(Problem("--connect", f"{every}: {reason}"))
        hosted: list[Mapping[str, Any]] = []
        for robot in robots:
            own = ids.index(robot)
            others = [endpoint for index, endpoint in enumerate(endpoints) if index != own]
            hosted.append({**values, "connect": others, "listen": endpoints[own]})
        return hosted

    def hosting_arguments(self, layout: FleetLayout, indices: Sequence[int]) -> list[str]:
        """Every robot's endpoint as a ``--connect``, in the fleet's order, the hosted ones' included.

        >>> ZenohEntry().hosting_arguments(FleetLayout(("A", "B"), (7447, 7448), 7449, "mrmp/7"), [0, 1])
        ['--connect=tcp/127.0.0.1:7447', '--connect=tcp/127.0.0.1:7448', '--fleet=mrmp/7']
        """
        return [*(f"--connect=tcp/{layout.host}:{port}" for port in layout.ports), f"--fleet={layout.fleet}"]

    def unavailable(self) -> str | None:
        return MISSING_ZENOH_PACKAGE if importlib.util.find_spec("zenoh") is None else None


# -- the table ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class TransportSpec:
    """Which transport one robot uses (``kind``, a name in :data:`TRANSPORTS`) and its options for it.

    >>> spec = TransportSpec("multicast", MulticastOptions(("239.255.77.9", 47000), "10.0.0.5"))
    >>> spec.hosts(), spec.entry.name
    (['10.0.0.5'], 'multicast')
    """

    kind: str
    options: Any

    @property
    def entry(self) -> TransportEntry[Any]:
        """The table's entry for ``kind``."""
        return TRANSPORTS.entry(self.kind)

    def hosts(self) -> list[str]:
        """Every host this transport listens on or sends to (the no-key check inspects them)."""
        return self.entry.hosts(self.options)

    def open(self, index: int, fleet_size: int) -> Transport:
        """Open the transport, for robot ``index`` of a fleet of ``fleet_size``.

        Raises
        ------
        InputError
            If the transport cannot be opened with these options (an address
            taken or not on this host, a group that cannot be joined), naming
            ``--transport`` and the reason.
        """
        try:
            return self.entry.open(self.options, index, fleet_size)
        except (OSError, ValueError) as error:
            reason = error.strerror if isinstance(error, OSError) and error.strerror else str(error)
            raise InputError(Problem(f"--transport={self.kind}", f"cannot open the transport: {reason}")) from None

    def arguments(self, ids: Sequence[str]) -> list[str]:
        """The ``mrmp agent`` arguments that select this transport with these options."""
        return [f"--transport={self.kind}", *self.entry.arguments(self.options, ids)]


class TransportTable:
    """The transports by name, in the order they were added (the order the CLI lists them in).

    >>> table = TransportTable(UdpEntry(), MulticastEntry())
    >>> table.names, table.listed()
    (('udp', 'multicast'), 'udp or multicast')
    >>> table.entry("carrier pigeon")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: --transport: unknown transport 'carrier pigeon'; known: udp, multicast
    """

    def __init__(self, *entries: TransportEntry[Any]) -> None:
        self._entries: dict[str, TransportEntry[Any]] = {}
        for entry in entries:
            self.add(entry)

    @property
    def names(self) -> tuple[str, ...]:
        """Every transport's name."""
        return tuple(self._entries)

    def listed(self) -> str:
        """The names for a sentence, e.g. ``udp, multicast or zenoh``."""
        *first, last = self.names
        return f"{', '.join(first)} or {last}" if first else last

    def __iter__(self) -> Iterator[TransportEntry[Any]]:
        return iter(list(self._entries.values()))

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def entry(self, name: str) -> TransportEntry[Any]:
        """The entry called ``name``.

        Raises
        ------
        InputError
            If there is none (the problem names ``--transport`` and lists the known ones).
        """
        try:
            return self._entries[name]
        except KeyError:
            raise InputError(Problem("--transport", f"unknown transport {name!r}; known: {', '.join(self.names)}")) from None

    def add(self, entry: TransportEntry[Any]) -> None:
        """Add ``entry`` after the others.

        Raises
        ------
        ValueError
            If a transport of that name is already in the table.
        """
        if entry.name in self._entries:
            raise ValueError(f"a transport called {entry.name!r} is already in the table")
        self._entries[entry.name] = entry

    def remove(self, name: str) -> None:
        """Take the transport called ``name`` out of the table (no error if it is not there)."""
        self._entries.pop(name, None)

    @contextmanager
    def added(self, entry: TransportEntry[Any]) -> Iterator[TransportEntry[Any]]:
        """``entry`` in the table for the duration of a ``with`` block.

        >>> table = TransportTable(UdpEntry())
        >>> with table.added(MulticastEntry()):
        ...     table.names
        ('udp', 'multicast')
        >>> table.names
        ('udp',)
        """
        self.add(entry)
        try:
            yield entry
        finally:
            self.remove(entry.name)

    def parse(self, name: str, values: Mapping[str, Any], ids: Sequence[str], index: int) -> TransportSpec:
        """The transport ``name`` with its options read from ``mrmp agent``'s option values.

        Raises
        ------
        InputError
            For an unknown transport, or option values its entry cannot use.
        """
        return TransportSpec(name, self.entry(name).parse(values, ids, index))

    def hosted(self, name: str, values: Mapping[str, Any], ids: Sequence[str], robots: Sequence[str]) -> list[TransportSpec]:
        """The transport ``name`` of each of several ``robots`` one ``mrmp agent`` hosts (one: as :meth:`parse`).

        Raises
        ------
        InputError
            For a transport that carries one robot per process, or option values its entry cannot use.
        """
        entry = self.entry(name)
        hosted = [values] if len(robots) == 1 else entry.hosting(values, ids, robots)
        return [TransportSpec(name, entry.parse(own, ids, ids.index(robot))) for robot, own in zip(robots, hosted, strict=True)]

    def fleet_spec(self, name: str, layout: FleetLayout, index: int) -> TransportSpec:
        """The transport ``name`` as robot ``index`` of a laid-out fleet uses it."""
        return TransportSpec(name, self.entry(name).fleet_options(layout, index))


TRANSPORTS = TransportTable(UdpEntry(), MulticastEntry(), ZenohEntry())
"""Every live transport, by name."""


# -- layers -------------------------------------------------------------------------------------


class FaultLayer(TransportLayer[LiveFaults]):
    """Loss, delay, duplication and reordering of sent datagrams (:class:`~mrmp.live.transport.FaultyTransport`).

    >>> FAULTS.arguments(LiveFaults(loss=0.1, delay_min=0.02, delay_max=0.08))
    ['--loss=0.1', '--delay-ms=20..80', '--duplicate=0.0', '--reorder=0.0']
    """

    name = "faults"
    summary = "injected loss, delay, duplication and reordering of sent datagrams (seeded)"

    def wrap(self, transport: Transport, options: LiveFaults, seed: int) -> Transport:
        return transport if options.is_perfect else with_faults(transport, options, seed=seed)

    def arguments(self, options: LiveFaults) -> list[str]:
        return [
            f"--loss={options.loss}",
            f"--delay-ms={options.delay_min * 1000:g}..{options.delay_max * 1000:g}",
            f"--duplicate={options.duplicate}",
            f"--reorder={options.reorder}",
        ]

    def harmless(self) -> LiveFaults:
        return LiveFaults(delay_min=0.0, delay_max=0.005)


FAULTS = FaultLayer()
"""The fault injector, as a layer."""

LAYERS: tuple[TransportLayer[Any], ...] = (FAULTS,)
"""Every layer that wraps a transport."""
