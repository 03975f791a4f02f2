"""The messages of PIBT sequenced by the robots themselves (``pibt`` with local sequencing).

:class:`~mrmp.robot.pibt_local.LocalPibtRobot` runs several PIBT calls at
once, one per *root* (a robot that starts a call on its own), so its
reservations and inheritance requests say which call they belong to and with
what priority: the root's index and priority ``(elapsed, tie)``. A reservation
is first *provisional*, then *final* (the robot will not change its mind this
step). Beacons, answers and pulls are those of :mod:`mrmp.protocol.messages`.

Over a network that loses messages every message but an acknowledgement is
acknowledged (:class:`CallAckMessage`), and the acknowledgement carries the
acknowledging robot's own reservation, so that two calls claiming one cell
hear of it before either claim is confirmed.

A robot that senses no body (the live brain, :mod:`mrmp.robot.pibt_live`)
sends :class:`NewsBeaconMessage`: a beacon that also says where the sender
last heard some peers stood, so that its neighbours learn of the robots around
it without hearing each of them, and whether it *asks* for the recipient's
beacon (a copy sent again to a peer whose beacon it still waits for). Such a
beacon is not acknowledged: the robot that waits for a beacon asks for it.

A call of higher priority that meets a robot busy in a call of lower
priority takes it over (wound-wait): :class:`CallWoundMessage` asks the
lower call to give up, and every robot of it that gives up says so to the
robots around it (:class:`CallAbortMessage`).

Registered in the message table (:mod:`mrmp.protocol.wire`) under codes 40 to 45.

Examples
--------
>>> from mrmp.protocol.codec import decode, encode
>>> claim = CallReserveMessage(3, 9, 12, (4, 5), root=7, root_elapsed=2, root_tie=30, final=True)
>>> decode(encode(claim)) == claim, len(encode(claim))
(True, 35)
>>> decode(encode(CallInheritMessage(3, 10, 12, (4, 6), 7, 2, 30))).root
7
>>> decode(encode(CallAckMessage(4, 1, 12, 9, NO_CLAIM, 0, 0, 0))).claim
(-1, -1)
>>> decode(encode(CallAbortMessage(5, 12, 12, root=7))), len(encode(CallWoundMessage(6, 13, 12)))
(CallAbortMessage(sender=5, seq=12, step=12, root=7), 14)
>>> beacon = NewsBeaconMessage(3, 11, 12, (4, 5), (9, 9), 2, 30, news=((7, (4, 8), 11), (8, (2, 5), 12)))
>>> decode(encode(beacon)) == beacon, len(encode(beacon))
(True, 73)
>>> decode(encode(NewsBeaconMessage(3, 11, 12, (4, 5), (9, 9), 2, 30, asks=True))).asks
True
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from mrmp.core.cell import Cell
from mrmp.protocol.formats import BEACON  # the project's own types first, so codes never clash silently
from mrmp.protocol.messages import MAX_VISITED_CELLS, BeaconMessage, PibtMessage
from mrmp.protocol.wire import DecodeError, WireFormat, register

__all__ = [
    "MAX_NEWS",
    "NO_CLAIM",
    "CallAbortMessage",
    "CallAckMessage",
    "CallInheritMessage",
    "CallReserveMessage",
    "CallWoundMessage",
    "News",
    "NewsBeaconMessage",
]

NO_CLAIM = (-1, -1)
"""The ``claim`` of an acknowledgement from a robot that holds no reservation."""


@dataclass(frozen=True, slots=True)
class CallReserveMessage(PibtMessage):
    """The sender reserved ``cell`` for the end of step ``step`` within the PIBT call of robot ``root``.

    ``final``: the sender has decided and will not change its mind this step
    (otherwise the reservation is provisional: it may be withdrawn when a call
    of higher priority reserved the same cell in the same round, or replaced
    after backtracking).
    """

    sender: int
    seq: int
    step: int
    cell: Cell
    root: int
    root_elapsed: int
    root_tie: int
    final: bool = False

    @property
    def rank(self) -> tuple[int, int, int]:
        """The priority of the call: ``(elapsed, tie, -root)``, larger first."""
        return (self.root_elapsed, self.root_tie, -self.root)


@dataclass(frozen=True, slots=True)
class CallInheritMessage(PibtMessage):
    """Priority inheritance within the call of ``root``: the sender reserved ``cell``, the recipient's cell."""

    sender: int
    seq: int
    step: int
    cell: Cell
    root: int
    root_elapsed: int
    root_tie: int

    @property
    def rank(self) -> tuple[int, int, int]:
        """The priority of the call: ``(elapsed, tie, -root)``, larger first."""
        return (self.root_elapsed, self.root_tie, -self.root)


@dataclass(frozen=True, slots=True)
class CallAckMessage(PibtMessage):
    """The sender received message ``acked`` (a sequence number) of this step; it holds reservation ``claim``.

    ``claim`` is :data:`NO_CLAIM` when the sender holds none; otherwise the
    claim belongs to the call of ``root`` with priority ``(root_elapsed, root_tie)``,
    and ``settled`` says whether it is no longer provisional.
    """

    sender: int
    seq: int
    step: int
    acked: int
    claim: Cell
    root: int
    root_elapsed: int
    root_tie: int
    settled: bool = False

    @property
    def rank(self) -> tuple[int, int, int]:
        """The priority of the call of the claim: ``(elapsed, tie, -root)``, larger first."""
        return (self.root_elapsed, self.root_tie, -self.root)


@dataclass(frozen=True, slots=True)
class CallWoundMessage(PibtMessage):
    """From a robot to the robot it asked in its call: a call of higher priority wants a robot of this call.

    The recipient gives the call up (:class:`CallAbortMessage`) if it has not
    decided for good; if it is itself waiting for the answer of the robot it
    asked, it passes the message on to that robot first.
    """

    sender: int
    seq: int
    step: int


@dataclass(frozen=True, slots=True)
class CallAbortMessage(PibtMessage):
    """The sender gave up the call of robot ``root`` this step: its provisional reservation is void; it is free again."""

    sender: int
    seq: int
    step: int
    root: int


News = tuple[int, Cell, int]
"""``(peer, cell, step)``: robot ``peer`` stood on ``cell`` at the start of step ``step``."""

MAX_NEWS = MAX_VISITED_CELLS // 2
"""Most entries a :class:`NewsBeaconMessage` carries (each takes two cells on the wire)."""


@dataclass(frozen=True, slots=True)
class NewsBeaconMessage(BeaconMessage):
    """A beacon (:class:`~mrmp.protocol.messages.BeaconMessage`) that also tells ``news``: where peers stood.

    Every entry is a fact its sender learnt first hand or was told:
    ``(peer, cell, step)``, robot ``peer`` stood on ``cell`` at the start of
    step ``step``; at most :data:`MAX_NEWS` of them. On the wire each entry
    is two cells: ``(peer, step)``, then ``cell``. ``asks``: the sender
    still waits for this step's beacon of the recipient, which answers with
    it.
    """

    news: tuple[News, ...] = ()
    asks: bool = False


def _news_cells(message: NewsBeaconMessage) -> tuple[Cell, ...]:
    if len(message.news) > MAX_NEWS:
        raise ValueError(f"{len(message.news)} news entries, at most {MAX_NEWS}")
    return tuple(cell for peer, place, step in message.news for cell in ((peer, step), place))


def _unpack_news_beacon(sender: int, seq: int, fields: Any, cells: tuple[Cell, ...]) -> NewsBeaconMessage:
    if len(cells) % 2:
        raise DecodeError("malformed", f"news beacon with {len(cells)} cells, not pairs")
    news = tuple((peer, place, step) for (peer, step), place in zip(cells[::2], cells[1::2], strict=True))
    if any(peer < 0 or step < 0 for peer, _, step in news):
        raise DecodeError("malformed", "news of a negative robot or step")
    *fixed, asks = fields
    if asks > 1:
        raise DecodeError("malformed", f"news beacon with asks={asks}")
    beacon = BEACON.unpack(sender, seq, tuple(fixed), ())
    return NewsBeaconMessage(
        sender, seq, beacon.step, beacon.present, beacon.goal, beacon.elapsed, beacon.tie, beacon.heading, news,
        bool(asks),
    )  # fmt: skip


def _unpack_reserve(sender: int, seq: int, fields: Any, _: tuple[Cell, ...]) -> CallReserveMessage:
    step, x, y, root, elapsed, tie, final = fields
    if final > 1:
        raise DecodeError("malformed", f"reservation with final={final}")
    return CallReserveMessage(sender, seq, step, (x, y), root, elapsed, tie, bool(final))


def _unpack_ack(sender: int, seq: int, fields: Any, _: tuple[Cell, ...]) -> CallAckMessage:
    step, acked, x, y, root, elapsed, tie, settled = fields
    if settled > 1:
        raise DecodeError("malformed", f"acknowledgement with settled={settled}")
    return CallAckMessage(sender, seq, step, acked, (x, y), root, elapsed, tie, bool(settled))


CALL_RESERVE = register(
    WireFormat(
        40,
        CallReserveMessage,
        "!IiiIIIB",
        lambda m: (m.step, *m.cell, m.root, m.root_elapsed, m.root_tie, int(m.final)),
        _unpack_reserve,
    )
)
CALL_INHERIT = register(
    WireFormat(
        41,
        CallInheritMessage,
        "!IiiIII",
        lambda m: (m.step, *m.cell, m.root, m.root_elapsed, m.root_tie),
        lambda sender, seq, f, _: CallInheritMessage(sender, seq, f[0], (f[1], f[2]), f[3], f[4], f[5]),
    )
)
CALL_ACK = register(
    WireFormat(
        42,
        CallAckMessage,
        "!IIiiIIIB",
        lambda m: (m.step, m.acked, *m.claim, m.root, m.root_elapsed, m.root_tie, int(m.settled)),
        _unpack_ack,
    )
)
NEWS_BEACON = register(
    WireFormat(
        43,
        NewsBeaconMessage,
        BEACON.layout + "BB",  # the beacon's fields, asks, the count of news cells
        lambda m: (*BEACON.pack(m), int(m.asks)),
        _unpack_news_beacon,
        cells=_news_cells,
    )
)
CALL_WOUND = register(
    WireFormat(44, CallWoundMessage, "!I", lambda m: (m.step,), lambda sender, seq, f, _: CallWoundMessage(sender, seq, *f))
)
CALL_ABORT = register(
    WireFormat(
        45, CallAbortMessage, "!II", lambda m: (m.step, m.root), lambda sender, seq, f, _: CallAbortMessage(sender, seq, *f)
    )
)
