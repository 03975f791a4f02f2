"""Zenoh transport: a live robot's datagrams as Zenoh publications between peers.

:class:`ZenohTransport` implements :class:`mrmp.live.transport.Transport` on
top of `Zenoh <https://zenoh.io>`_: the ``eclipse-zenoh`` package, 1.1 or
later in 1.x (tested with 1.1.0, 1.2.0, 1.3.0, 1.5.0, 1.7.0 and 1.10.2).
Zenoh is imported lazily: this module imports without it, and the constructor
raises a clear :class:`RuntimeError` if it is missing (or too old).

Key expressions
---------------
Every robot of a fleet shares a key prefix ``{fleet}`` (e.g. ``mrmp/42``;
a Zenoh key is ``/``-separated non-empty chunks without ``* $ ? #``, see
https://zenoh.io/docs/manual/abstractions/). Robot ``i`` uses:

* ``{fleet}/robot/{i}``: its broadcasts (``send(data)``, for every peer);
* ``{fleet}/to/{j}``: datagrams it addresses to robot ``j`` (``send(data, j)``);
* ``{fleet}/alive/{i}``: a liveliness token, alive while its session is open.

It subscribes to ``{fleet}/robot/*`` (``*`` is exactly one chunk, so this is
every robot's broadcast key; its own is ignored) and to ``{fleet}/to/{i}``,
both restricted to remote publications (``allowed_origin=Locality.REMOTE``
where the installed Zenoh has it: 1.5 and later),
and to the liveliness of ``{fleet}/alive/*`` to know which peers are up.

Configuration, and why
----------------------
The options are documented in Zenoh's reference configuration,
``DEFAULT_CONFIG.json5`` (e.g. https://github.com/eclipse-zenoh/zenoh/blob/1.9.0/DEFAULT_CONFIG.json5),
and in the deployment guide (https://zenoh.io/docs/getting-started/deployment/):

* ``mode: "peer"``: robots talk to each other directly, with no router
  process to start or to lose.
* ``scouting/multicast/enabled: false`` and ``scouting/gossip/enabled: false``:
  robots find each other *only* through the explicit endpoints; a fleet does
  not join (or get joined by) any other Zenoh node that happens to be on the
  network, and the run's reachability is exactly what the launcher configured.
* ``listen/endpoints: [listen]`` and ``connect/endpoints: connect``: each
  robot listens on its own endpoint and dials the others'. Zenoh merges the
  two directions into one session per pair of peers.
* ``connect/timeout_ms: -1`` and ``connect/exit_on_failure: false`` (the
  documented defaults for peers, written out so the behaviour does not depend
  on them): opening a session does not fail when a peer is not up yet; Zenoh
  keeps retrying the endpoints it could not reach in the background. (With
  ``timeout_ms: 0`` it would try once and never again: checked with 1.10.)
* ``connect/retry``: ``period_init_ms: 100``, ``period_increase_factor: 1.5``,
  ``period_max_ms: 500`` instead of the default 1000/2/4000 ms: a robot
  started before its peers reaches them at most half a second after they come
  up (robots start within seconds of each other, and a connection attempt to
  a closed port costs almost nothing).
* ``scouting/delay: 100`` instead of 500 ms: "in peer mode, the period
  dedicated to scouting remote peers before attempting other operations";
  with scouting off it only bounds how long opening the session waits for the
  connections to peers that are not up yet. Readiness is checked explicitly
  with :meth:`ZenohTransport.wait_for_peers` instead.

Publications use ``congestion_control=DROP`` (a datagram that cannot be sent
now is lost, as on UDP; the protocol layer tolerates loss) and
``express=True`` (sent at once, not batched with later ones).

``transport/link/tx/queue/size/data: 16`` instead of 2 (the most the
reference configuration allows): an express publication closes its batch, and
a publication that finds the link's queue full waits ``wait_before_drop``
(1 ms) and is then dropped. A robot sends several datagrams to one peer at
once (it answers several messages in one act); with 2 batches, on a machine
whose two cores four busy loops kept loaded, one of three to a dozen
datagrams sent back to back was lost in 7 of 13 runs of the conformance
checks that send them (0 of 14 with 16 batches). Batches are allocated when
first used (``allocation/mode: lazy``, the default).

Several robots to a process
---------------------------
Zenoh hands each sample to a callback on one of its own threads, which queues
it. A process that hosts several robots in one thread
(:func:`mrmp.live.host_loop.run_hosted`) watches a socket per robot with one
selector; :meth:`ZenohTransport.fileno` gives it one: the read end of a local
socket pair to which the callback writes a byte after queueing a sample.
:meth:`ZenohTransport.receive` empties that socket before it takes from the
queue, so a sample queued while it looks is announced by a byte still unread
(a wake-up at worst spurious, never missed). Each hosted robot opens a session
of its own; a process's sessions share Zenoh's runtime threads.

Readiness
---------
A peer robot counts as *connected* (:meth:`ZenohTransport.peers`,
:meth:`ZenohTransport.wait_for_peers`) once its liveliness token is seen. A
robot declares its token after its subscribers, and declarations travel in
order on a session, so a connected peer is one whose subscriptions are already
known here: a datagram sent to it from then on is routed to it.
(``session.info.peers_zid()`` only says that a Zenoh session exists.)

Example
-------
Two robots on loopback (needs the network, so not run as a doctest):

>>> from mrmp.live.zenoh_transport import ZenohTransport
>>> a = ZenohTransport(0, "mrmp/1", "tcp/127.0.0.1:7447", ["tcp/127.0.0.1:7448"], 2)  # doctest: +SKIP
>>> b = ZenohTransport(1, "mrmp/1", "tcp/127.0.0.1:7448", ["tcp/127.0.0.1:7447"], 2)  # doctest: +SKIP
>>> a.wait_for_peers(1, timeout=5.0) and b.wait_for_peers(1, timeout=5.0)  # doctest: +SKIP
True
>>> a.send(b"hello")  # doctest: +SKIP
>>> b.receive(timeout=1.0)  # doctest: +SKIP
b'hello'
>>> a.close(); b.close()  # doctest: +SKIP
"""

from __future__ import annotations

import contextlib
import json
import socket
import threading
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Self

if TYPE_CHECKING:  # pragma: no cover - typing only
    import zenoh

MISSING_ZENOH = "the zenoh transport needs the eclipse-zenoh package: in a checkout, .venv/bin/pip install -e '.[zenoh]'"
"""The message of the :class:`RuntimeError` raised when Zenoh is not installed."""

TOO_OLD_ZENOH = "the zenoh transport needs eclipse-zenoh 1.1 or later: in a checkout, .venv/bin/pip install -U -e '.[zenoh]'"
"""The message of the :class:`RuntimeError` raised when the installed Zenoh has no liveliness API."""

DEFAULT_QUEUE_LIMIT = 10_000
"""How many received datagrams are kept waiting for :meth:`ZenohTransport.receive` at most."""

CONNECT_RETRY = {"period_init_ms": 100, "period_max_ms": 500, "period_increase_factor": 1.5}
"""How often a robot retries the endpoints of peers that are not up yet (see the module docstring)."""

SCOUTING_DELAY_MS = 100
"""How long opening a session waits for the connections to peers, at most (see the module docstring)."""

DATA_QUEUE_BATCHES = 16
"""Batches the transmission queue of a link holds for data publications (see the module docstring)."""

_FORBIDDEN_IN_KEYS = set("*$?#")


ENDPOINT_FORM = "<protocol>/<address>[?<metadata>][#<config>]"
"""Zenoh's form of an endpoint (the message of its own parser)."""

IP_PROTOCOLS = ("tcp", "udp")
"""The Zenoh protocols whose address is ``HOST:PORT`` on an IP network, which the no-key check can read."""


@dataclass(frozen=True)
class ZenohEndpoint:
    """A Zenoh endpoint split as Zenoh itself splits it: ``<protocol>/<address>[?<metadata>][#<config>]``.

    The grammar is Zenoh's (``commons/zenoh-protocol/src/core/endpoint.rs``,
    functions ``protocol``, ``address``, ``metadata``, ``config`` and
    ``EndPoint::try_from``): the protocol ends at the first ``/``; the address
    runs from there to the first ``?`` or ``#``; the metadata from ``?`` to
    ``#``; the configuration after ``#``. So ``tcp/0.0.0.0:7447?x=/`` has the
    address ``0.0.0.0:7447``, whatever its metadata holds.

    >>> ZenohEndpoint.parse("tcp/0.0.0.0:17450?x=/")
    ZenohEndpoint(protocol='tcp', address='0.0.0.0:17450', metadata='x=/', config='')
    >>> ZenohEndpoint.parse("tcp/0.0.0.0:17450#a/b").address, ZenohEndpoint.parse("tcp/[::1]:7447").host
    ('0.0.0.0:17450', '::1')
    >>> ZenohEndpoint.parse("tcp127.0.0.1:7447")
    Traceback (most recent call last):
    ...
    ValueError: expected a Zenoh endpoint <protocol>/<address>[?<metadata>][#<config>], got 'tcp127.0.0.1:7447'
    """

    protocol: str
    address: str
    metadata: str = ""
    config: str = ""

    @classmethod
    def parse(cls, text: str) -> ZenohEndpoint:
        """Split ``text`` by Zenoh's grammar.

        Raises
        ------
        ValueError
            Where Zenoh's own parser refuses the text: no ``/`` with a protocol
            before it and something after it; an empty ``?`` metadata or ``#``
            configuration, or one before the ``/`` (or ``#`` before ``?``).
        """
        wrong = ValueError(f"expected a Zenoh endpoint {ENDPOINT_FORM}, got {text!r}")
        slash = text.find("/")
        if slash <= 0 or slash == len(text) - 1:
            raise wrong
        question, hash_sign = text.find("?"), text.find("#")
        end_of_address = min(index for index in (question, hash_sign, len(text)) if index >= 0)
        metadata = config = ""
        if question >= 0:
            metadata = text[question + 1 : hash_sign if hash_sign >= 0 else len(text)]
            if question < slash or not metadata or 0 <= hash_sign < question:
                raise wrong
        if hash_sign >= 0:
            config = text[hash_sign + 1 :]
            if hash_sign < slash or not config:
                raise wrong
        return cls(text[:slash], text[slash + 1 : end_of_address], metadata, config)

    @property
    def host(self) -> str | None:
        """The host of an IP endpoint (:data:`IP_PROTOCOLS`, address ``HOST:PORT``), brackets removed; else None.

        >>> ZenohEndpoint("tcp", "127.0.0.1:7447").host, ZenohEndpoint("unixsock-stream", "/tmp/s").host
        ('127.0.0.1', None)
        """
        host, separator, port = self.address.rpartition(":")
        if self.protocol not in IP_PROTOCOLS or not separator or not port.isdigit():
            return None
        return host.removeprefix("[").removesuffix("]")

    def sole_host(self) -> str | None:
        """The host, when it is all this endpoint reaches: an IP endpoint with no metadata and no configuration.

        Zenoh's ``#config`` can choose the interface or the source address of a
        link, so an endpoint with one (or with metadata) is not known to stay
        on its host; None then.

        >>> ZenohEndpoint.parse("tcp/127.0.0.1:7447").sole_host()
        '127.0.0.1'
        >>> ZenohEndpoint.parse("tcp/127.0.0.1:7447#iface=eth0").sole_host() is None
        True
        """
        return self.host if not self.metadata and not self.config else None


def fleet_keys(fleet: str, index: int) -> dict[str, str]:
    """The key expressions robot ``index`` of ``fleet`` publishes on and subscribes to.

    Parameters
    ----------
    fleet:
        The fleet's key prefix.
    index:
        The robot's index in the scenario.

    Returns
    -------
    dict
        ``broadcast`` (where it publishes broadcasts), ``broadcasts`` (every
        robot's broadcasts), ``inbox`` (datagrams addressed to it), ``alive``
        (its liveliness token) and ``everyone_alive`` (every robot's token).

    Raises
    ------
    ValueError
        If ``fleet`` is not a valid Zenoh key (empty chunks, wildcards).

    >>> keys = fleet_keys("mrmp/7", 2)
    >>> keys["broadcast"], keys["broadcasts"], keys["inbox"], keys["alive"]
    ('mrmp/7/robot/2', 'mrmp/7/robot/*', 'mrmp/7/to/2', 'mrmp/7/alive/2')
    >>> fleet_keys("mrmp/*", 0)
    Traceback (most recent call last):
    ...
    ValueError: the fleet prefix must be a Zenoh key ('/'-separated non-empty chunks without * $ ? #), got 'mrmp/*'
    """
    if not fleet or any(not chunk for chunk in fleet.split("/")) or _FORBIDDEN_IN_KEYS & set(fleet):
        raise ValueError(
            f"the fleet prefix must be a Zenoh key ('/'-separated non-empty chunks without * $ ? #), got {fleet!r}"
        )
    return {
        "broadcast": f"{fleet}/robot/{index}",
        "broadcasts": f"{fleet}/robot/*",
        "inbox": f"{fleet}/to/{index}",
        "alive": f"{fleet}/alive/{index}",
        "everyone_alive": f"{fleet}/alive/*",
    }


def addressed_key(fleet: str, recipient: int) -> str:
    """The key expression of datagrams addressed to robot ``recipient``.

    >>> addressed_key("mrmp/7", 3)
    'mrmp/7/to/3'
    """
    return f"{fleet}/to/{recipient}"


def session_config(listen: str, connect: Sequence[str]) -> dict[str, Any]:
    """The Zenoh configuration entries of a robot (key path to value), as explained in the module docstring.

    >>> config = session_config("tcp/127.0.0.1:7447", ["tcp/127.0.0.1:7448"])
    >>> config["mode"], config["scouting/multicast/enabled"], config["connect/endpoints"]
    ('peer', False, ['tcp/127.0.0.1:7448'])
    """
    return {
        "mode": "peer",
        "scouting/multicast/enabled": False,
        "scouting/gossip/enabled": False,
        "scouting/delay": SCOUTING_DELAY_MS,
        "listen/endpoints": [listen],
        "connect/endpoints": list(connect),
        "connect/timeout_ms": -1,
        "connect/exit_on_failure": False,
        "connect/retry": dict(CONNECT_RETRY),
        "transport/link/tx/queue/size/data": DATA_QUEUE_BATCHES,
    }


def _last_chunk_index(key: str) -> int | None:
    _, _, last = key.rpartition("/")
    return int(last) if last.isdigit() else None


class ZenohTransport:
    """One robot's Zenoh peer session: broadcasts and addressed datagrams as publications.

    Parameters
    ----------
    index:
        This robot's index, ``0 <= index < fleet_size``.
    fleet:
        The fleet's key prefix, shared by its robots (e.g. ``"mrmp/42"``).
    listen:
        This robot's Zenoh endpoint, e.g. ``"tcp/127.0.0.1:7447"``.
    connect:
        The other robots' endpoints. Peers that are not up yet are retried in
        the background.
    fleet_size:
        How many robots the fleet has.
    queue_limit:
        How many received datagrams wait for :meth:`receive` at most; beyond
        that the oldest is dropped and counted in :attr:`dropped`.

    Attributes
    ----------
    dropped:
        Received datagrams dropped because the queue was full.
    received:
        Datagrams received from peers (including dropped ones).

    Raises
    ------
    RuntimeError
        If the ``eclipse-zenoh`` package is not installed, or older than 1.1.
    ValueError
        If ``index`` is not in ``range(fleet_size)`` or ``fleet`` is not a Zenoh key.
    zenoh.ZError
        If the session cannot be opened (e.g. ``listen`` is taken or malformed).

    Notes
    -----
    Payloads are passed through unchanged whatever their size (the protocol
    layer's opener counts oversized datagrams). Own broadcasts are not
    received.

    Examples
    --------
    See the module docstring; in short (needs the network)::

        transport = ZenohTransport(0, "mrmp/1", "tcp/127.0.0.1:7447", ["tcp/127.0.0.1:7448"], 2)
        transport.wait_for_peers(1, timeout=10.0)
        transport.send(b"to everyone")
        transport.send(b"to robot 1", recipient=1)
        data = transport.receive(timeout=0.05)
        transport.close()
    """

    def __init__(
        self,
        index: int,
        fleet: str,
        listen: str,
        connect: Sequence[str],
        fleet_size: int,
        *,
        queue_limit: int = DEFAULT_QUEUE_LIMIT,
    ) -> None:
        try:
            import zenoh
        except ImportError as error:
            raise RuntimeError(MISSING_ZENOH) from error
        if not hasattr(zenoh.Session, "liveliness"):
            raise RuntimeError(TOO_OLD_ZENOH)
        if not 0 <= index < fleet_size:
            raise ValueError(f"robot index {index} is not in 0..{fleet_size - 1}")
        if queue_limit < 1:
            raise ValueError(f"queue_limit must be positive, got {queue_limit}")
        self.index = index
        self.fleet = fleet
        self.fleet_size = fleet_size
        self.listen = listen
        self.connect = list(connect)
        self.queue_limit = queue_limit
        self.dropped = 0
        self.received = 0
        keys = fleet_keys(fleet, index)
        self._own_broadcast = keys["broadcast"]
        self._queue: deque[bytes] = deque()
        self._ready = threading.Condition()
        self._alive: set[int] = set()
        self._closed = False
        self._close_lock = threading.Lock()
        self._wake: tuple[socket.socket, socket.socket] | None = None  # (read end, write end), once fileno is asked

        config = zenoh.Config()
        for path, value in session_config(listen, self.connect).items():
            config.insert_json5(path, json.dumps(value))
        self._zenoh = zenoh
        self._session: zenoh.Session = zenoh.open(config)
        entities: list[Any] = []
        try:
            # Only remote publications where Zenoh can say so (1.5 and later); the own-key check in
            # _on_sample covers older versions.
            origin = {"allowed_origin": zenoh.Locality.REMOTE} if hasattr(zenoh, "Locality") else {}
            for key in (keys["broadcasts"], keys["inbox"]):
                entities.append(self._session.declare_subscriber(key, self._on_sample, **origin))
            liveliness = self._session.liveliness()
            entities.append(liveliness.declare_subscriber(keys["everyone_alive"], self._on_liveliness, history=True))

            def publisher(key: str) -> zenoh.Publisher:
                return self._session.declare_publisher(key, congestion_control=zenoh.CongestionControl.DROP, express=True)

            self._broadcast = publisher(keys["broadcast"])
            entities.append(self._broadcast)
            self._addressed = {
                other: publisher(addressed_key(fleet, other))
                for other in range(fleet_size)
                if other != index
            }
            entities.extend(self._addressed.values())
            # Declared last: a peer that sees this token already knows the subscribers above.
            entities.append(liveliness.declare_token(keys["alive"]))
        except BaseException:
            self._session.close()
            raise
        self._entities = entities

    # -- Zenoh callbacks (run on Zenoh's threads) --------------------------------------

    def _on_sample(self, sample: zenoh.Sample) -> None:
        if str(sample.key_expr) == self._own_broadcast:
            return
        data = sample.payload.to_bytes()
        with self._ready:
            if self._closed:
                return
            self.received += 1
            if len(self._queue) >= self.queue_limit:
                self._queue.popleft()
                self.dropped += 1
            self._queue.append(data)
            self._ready.notify()
            if self._wake is not None:
                with contextlib.suppress(BlockingIOError):  # full: bytes unread already announce the queue
                    self._wake[1].send(b"\0")

    def _on_liveliness(self, sample: zenoh.Sample) -> None:
        robot = _last_chunk_index(str(sample.key_expr))
        if robot is None or robot == self.index or not 0 <= robot < self.fleet_size:
            return
        with self._ready:
            if sample.kind == self._zenoh.SampleKind.PUT:
                self._alive.add(robot)
            else:
                self._alive.discard(robot)
            self._ready.notify_all()

    # -- the Transport protocol --------------------------------------------------------

    def send(self, data: bytes, recipient: int | None = None) -> None:
        """Publish ``data`` to every peer (``recipient`` None) or to robot ``recipient``.

        Sending is fire-and-forget: a datagram no peer is subscribed to, or one
        sent after :meth:`close`, is lost, as on UDP.

        Raises
        ------
        ValueError
            If ``recipient`` is not another robot of the fleet.
        """
        if recipient is None:
            publisher = self._broadcast
        else:
            try:
                publisher = self._addressed[recipient]
            except KeyError:
                raise ValueError(f"robot {self.index} has no peer {recipient} (fleet of {self.fleet_size})") from None
        if self._closed:
            return
        with contextlib.suppress(self._zenoh.ZError):  # closed concurrently, or refused: a lost datagram
            publisher.put(data)

    def receive(self, timeout: float) -> bytes | None:
        """The next datagram from a peer, or None after ``timeout`` seconds (at once once closed)."""
        deadline = time.monotonic() + max(timeout, 0.0)
        self._empty_wake_socket()
        with self._ready:
            while not self._queue and not self._closed:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return None
                self._ready.wait(remaining)
            if self._closed:
                return None
            return self._queue.popleft()

    def close(self) -> None:
        """Undeclare everything and close the session; :meth:`receive` then returns None. Idempotent."""
        with self._close_lock:
            with self._ready:
                if self._closed:
                    return
                self._closed = True
                self._queue.clear()
                self._ready.notify_all()
            for entity in reversed(self._entities):
                with contextlib.suppress(self._zenoh.ZError):
                    entity.undeclare()
            with contextlib.suppress(self._zenoh.ZError):
                self._session.close()
            with self._ready:
                wake, self._wake = self._wake, None
            for end in wake or ():
                end.close()

    # -- a socket to watch -------------------------------------------------------------

    def fileno(self) -> int:
        """A socket that is readable while a received datagram may wait for :meth:`receive` (module docstring,
        "Several robots to a process"): for a selector that watches several robots' transports.

        Raises
        ------
        ValueError
            Once closed.
        """
        with self._ready:
            if self._closed:
                raise ValueError("the transport is closed")
            if self._wake is None:
                read_end, write_end = socket.socketpair()
                read_end.setblocking(False)
                write_end.setblocking(False)
                self._wake = (read_end, write_end)
                if self._queue:  # queued before anyone watched
                    write_end.send(b"\0")
            return self._wake[0].fileno()

    def _empty_wake_socket(self) -> None:
        """Read every byte the callback wrote to the watched socket (before the queue is looked at)."""
        wake = self._wake
        if wake is None:
            return
        with contextlib.suppress(BlockingIOError, OSError):
            while wake[0].recv(4096):
                pass

    # -- readiness ---------------------------------------------------------------------

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` was called."""
        return self._closed

    def peers(self) -> frozenset[int]:
        """The other robots of the fleet currently connected (their liveliness token is seen)."""
        with self._ready:
            return frozenset(self._alive)

    def wait_for_peers(self, count: int, timeout: float) -> bool:
        """Wait until at least ``count`` other robots are connected, for at most ``timeout`` seconds.

        Returns
        -------
        bool
            Whether they are (False also once closed).
        """
        deadline = time.monotonic() + max(timeout, 0.0)
        with self._ready:
            while len(self._alive) < count and not self._closed:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._ready.wait(remaining)
            return not self._closed and len(self._alive) >= count

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self._closed else f"{len(self.peers())} peers"
        return f"ZenohTransport(robot {self.index} of {self.fleet_size}, {self.fleet!r}, {self.listen}, {state})"
