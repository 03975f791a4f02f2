"""What a multicast datagram looks like: the robots it is for, then the message, or several of these together.

Every robot of a multicast group hears every datagram, so each datagram says
whom it is for (``docs/protocol.md``, "A multicast datagram says whom it is
for"): a *head*, the count of robots it names (0: every robot) then each
index, two bytes each, and after it the sealed message. A robot takes in
what names it or every robot, and drops the rest.

Several messages sent in one turn of a robot's main loop, each for its own
robots, go *together* (:func:`datagrams_together`): one datagram headed by
:data:`TOGETHER`, a count no head has, then each message as a *section*: its
head, its length (two bytes), and the message. Every robot the sections name
hears the datagram once and takes in the sections that name it. A message
for more than :data:`MAX_NAMED` robots is several sections, and sections
that do not fit in :data:`MAX_MULTICAST_DATAGRAM_BYTES` go in the next
datagram; a datagram of one section is the plain one (head, then message).

Nothing here opens a message: a datagram whose head or sections name no
robot of the fleet, or whose sections do not add up, is handed on whole
(:func:`payloads_for`), for the opener to reject and count, as it rejects
a stranger's datagram on any transport.

Examples
--------
>>> sent = datagrams_together([(b"ack", (2,)), (b"beacon", (1, 2)), (b"claim", (3,))])
>>> [named for _, named in sent]
[(2, 1, 3)]
>>> [payloads_for(sent[0][0], robot, fleet_size=4) for robot in (1, 2, 3)]
[[b'beacon'], [b'ack', b'beacon'], [b'claim']]
>>> [payloads_for(data, 1, fleet_size=4) for data, _ in datagrams_together([(b"alone", (1,))])]
[[b'alone']]
"""

from __future__ import annotations

import struct
from collections.abc import Sequence

from mrmp.protocol.auth import MAX_DATAGRAM_BYTES

__all__ = [
    "COUNT",
    "LENGTH",
    "MAX_MULTICAST_DATAGRAM_BYTES",
    "MAX_NAMED",
    "TOGETHER",
    "Addressed",
    "count_together",
    "datagrams_together",
    "groups_together",
    "payloads_for",
    "read_head",
    "read_sections",
    "recipients_head",
]

COUNT = struct.Struct("!H")
"""The head of every multicast datagram starts with how many robots it names (0: it is for every robot)."""
LENGTH = struct.Struct("!H")
"""A section's length, after its head, in a datagram of several messages."""
MAX_NAMED = 128
"""The most robots one head names: a message for more goes as several heads (sections or datagrams)."""
MAX_MULTICAST_DATAGRAM_BYTES = COUNT.size * (1 + MAX_NAMED) + MAX_DATAGRAM_BYTES
"""The longest multicast datagram a robot sends: the longest head, then the longest sealed message; messages
sent together fill a datagram up to this too."""
TOGETHER = 0xFFFF
"""The count that heads a datagram of several messages: no head names so many robots."""

Addressed = tuple[bytes, tuple[int, ...]]
"""A sealed message and the robots it is for (one or more, named)."""


def recipients_head(recipients: tuple[int, ...]) -> bytes:
    """The head of a multicast datagram for ``recipients`` (none: every robot): their count, then each index.

    >>> recipients_head(()).hex(), recipients_head((2, 5)).hex()
    ('0000', '000200020005')
    """
    return struct.pack(f"!H{len(recipients)}H", len(recipients), *recipients)


def read_head(data: bytes, fleet_size: int | None, start: int = 0) -> tuple[tuple[int, ...], int] | None:
    """The robots the head at ``start`` names (none: every robot) and where what follows it starts; None if it
    names no robot of the fleet (too short, more robots than the fleet has, or an index outside it).

    >>> read_head(recipients_head((1, 3)) + b"payload", 4)
    ((1, 3), 6)
    >>> read_head(b"hello", 4) is None     # a stranger's datagram: "he" would name 26,725 robots
    True
    """
    if len(data) < start + COUNT.size:
        return None
    (count,) = COUNT.unpack_from(data, start)
    end = start + COUNT.size * (1 + count)
    if len(data) < end or (fleet_size is not None and count > fleet_size):
        return None
    named = struct.unpack_from(f"!{count}H", data, start + COUNT.size)
    if fleet_size is not None and any(index >= fleet_size for index in named):
        return None
    return named, end


def datagrams_together(messages: Sequence[Addressed]) -> list[tuple[bytes, tuple[int, ...]]]:
    """The multicast datagrams that carry ``messages``, in order, each with the robots its heads name (module
    docstring): as many sections to a datagram as fit.

    A message listed twice, for some robots and for others, is one section naming all of them.

    Raises
    ------
    ValueError
        If a message names no robot (a message for every robot goes on its own, headed so).

    >>> [(data.hex(), named) for data, named in datagrams_together([(b"A", (1,)), (b"B", (2,)), (b"A", (3,))])]
    [('ffff00020001000300014100010002000142', (1, 3, 2))]
    """
    datagrams = []
    for group in groups_together(messages):
        if len(group) == 1:
            data, named = group[0]
            datagrams.append((recipients_head(named) + data, named))
            continue
        sections = b"".join(recipients_head(named) + LENGTH.pack(len(data)) + data for data, named in group)
        union = tuple(dict.fromkeys(robot for _, named in group for robot in named))
        datagrams.append((COUNT.pack(TOGETHER) + sections, union))
    return datagrams


def count_together(messages: Sequence[Addressed]) -> int:
    """How many datagrams :func:`datagrams_together` puts ``messages`` in (without making them).

    >>> count_together([(b"x" * 500, (1,)), (b"y" * 500, (2,)), (b"z", (3,))])
    2
    """
    return len(groups_together(messages))


def groups_together(messages: Sequence[Addressed]) -> list[list[Addressed]]:
    """What each datagram of :func:`datagrams_together` carries: its sections, each a message and its robots.

    >>> groups_together([(b"x" * 500, (1,)), (b"y" * 500, (2,)), (b"x" * 500, (3,))])[0][0][1]
    (1, 3)
    """
    return _groups(_sections(messages))


def payloads_for(data: bytes, robot: int | None, fleet_size: int | None) -> list[bytes]:
    """The messages of a multicast datagram that ``robot`` takes in: those for it or for every robot (every
    message when ``robot`` is None, as for a listener that is no robot).

    A datagram that names no robot of the fleet (:func:`read_head`), or one
    of several messages whose sections do not add up, is handed on whole: the
    opener rejects it and counts it. A message is cut one byte past the
    longest sealed message, as a unicast read cuts a datagram, so an
    oversized one still shows.

    >>> payloads_for(recipients_head((2,)) + b"for 2", 1, 4), payloads_for(recipients_head(()) + b"for all", 1, 4)
    ([], [b'for all'])
    >>> payloads_for(b"hello", 1, 4)     # a stranger's datagram
    [b'hello']
    """
    if _is_together(data):
        sections = read_sections(data, fleet_size)
        if sections is None:
            return [data]
        return [payload[: MAX_DATAGRAM_BYTES + 1] for named, payload in sections if not named or robot is None or robot in named]
    head = read_head(data, fleet_size)
    if head is None:
        return [data]
    named, start = head
    if named and robot is not None and robot not in named:
        return []
    return [data[start : start + MAX_DATAGRAM_BYTES + 1]]


def _sections(messages: Sequence[Addressed]) -> list[Addressed]:
    """``messages`` as sections: one per distinct message, naming its robots, at most :data:`MAX_NAMED` a section."""
    robots_of: dict[bytes, dict[int, None]] = {}
    for data, recipients in messages:
        if not recipients:
            raise ValueError("a message sent together with others names the robots it is for")
        robots_of.setdefault(data, {}).update(dict.fromkeys(recipients))
    sections: list[Addressed] = []
    for data, robots in robots_of.items():
        named = tuple(robots)
        sections.extend((data, named[first : first + MAX_NAMED]) for first in range(0, len(named), MAX_NAMED))
    return sections


def _groups(sections: list[Addressed]) -> list[list[Addressed]]:
    """``sections`` in order, cut into datagrams of as many as fit in :data:`MAX_MULTICAST_DATAGRAM_BYTES`."""
    groups: list[list[Addressed]] = []
    size = 0
    for data, named in sections:
        cost = COUNT.size * (1 + len(named)) + LENGTH.size + len(data)
        if groups and size + cost <= MAX_MULTICAST_DATAGRAM_BYTES:
            groups[-1].append((data, named))
            size += cost
        else:
            groups.append([(data, named)])
            size = COUNT.size + cost
    return groups


def read_sections(data: bytes, fleet_size: int | None) -> list[tuple[tuple[int, ...], bytes]] | None:
    """The sections of a datagram of several messages: each one's robots and message; None if they do not add up
    (or if the datagram is not one of several messages).

    >>> read_sections(datagrams_together([(b"a", (1,)), (b"b", (2, 3))])[0][0], fleet_size=4)
    [((1,), b'a'), ((2, 3), b'b')]
    >>> read_sections(recipients_head((1,)) + b"a", fleet_size=4) is None
    True
    """
    if not _is_together(data):
        return None
    sections = []
    offset = COUNT.size
    while offset < len(data):
        head = read_head(data, fleet_size, offset)
        if head is None or len(data) < head[1] + LENGTH.size:
            return None
        named, start = head
        (length,) = LENGTH.unpack_from(data, start)
        start += LENGTH.size
        if len(data) < start + length:
            return None
        sections.append((named, data[start : start + length]))
        offset = start + length
    return sections or None


def _is_together(data: bytes) -> bool:
    """Whether ``data`` starts as a datagram of several messages does (:data:`TOGETHER`)."""
    return len(data) >= COUNT.size and COUNT.unpack_from(data)[0] == TOGETHER
