"""A compact, versioned, size-bounded binary codec for robot messages.

Wire layout (network byte order)::

    offset  size  field
    0       1     protocol version (PROTOCOL_VERSION)
    1       1     message type code
    2       4     sender index (unsigned)
    6       4     sequence number (unsigned)
    10      ...   body, fixed layout per type

Bodies (cells are two signed 32-bit integers)::

    1 state  present, next, target, claim cell (4 cells), heading (1 byte, 1..4),
             flags (1 byte: bit 0 arrived, bit 1 moving, bit 2 claiming), claim (u32),
             progress (u32)                                                             52 bytes in all
    2 claim  claim (u32), cell                                                          22 bytes in all
    3 reply  claimant (u32), claim (u32), cell, granted (1 byte, 0 or 1)                 27 bytes in all
    4 beacon step (u32), present, goal, elapsed (u32), tie (u32), heading (1 byte)      39 bytes in all
    5 inherit step (u32), cell                                                          22 bytes in all
    6 answer step (u32), moved (1 byte, 0 or 1)                                         15 bytes in all
    7 reserve step (u32), cell                                                          22 bytes in all
    8 pull   step (u32), cell                                                           22 bytes in all
    9 lock request   session (u32)                                                      14 bytes in all
   10 lock grant     locker (u32), session (u32), mode (1 byte, 0..2), flags (1 byte:
                     bit 0 has a head, bit 1 urgent), tail, head, reached (u32),
                     rank (u32), count (1 byte), count visited cells              45 + 8 * count bytes
   11 lock release   session (u32), operations (1 byte), count (1 byte),
                     count visited cells                                          16 + 8 * count bytes
   12 lock ack       locker (u32), session (u32)                                        18 bytes in all

Counts of visited cells are at most :data:`~mrmp.protocol.messages.MAX_VISITED_CELLS`.

Every datagram is at most :data:`MAX_MESSAGE_BYTES`. Authentication (a MAC
over these bytes) is a separate layer, :mod:`mrmp.protocol.auth`.

Decoding never trusts its input: anything that is not exactly a valid message
raises :class:`DecodeError` with a ``reason`` (``"oversized"``,
``"truncated"``, ``"version"``, ``"type"``, ``"malformed"``) so that a
receiver can drop it and count it per reason.

Examples
--------
>>> from mrmp.protocol.messages import StateMessage
>>> data = encode(StateMessage(sender=1, seq=3, present=(4, 2), next=(3, 2)))
>>> len(data)
52
>>> decode(data)
StateMessage(sender=1, seq=3, present=(4, 2), next=(3, 2), heading=<Heading.NORTH: 1>, arrived=False, target=None, claim=0, claim_cell=None, progress=0)
>>> decode(b"hello")
Traceback (most recent call last):
...
mrmp.protocol.codec.DecodeError: truncated: 5 bytes is shorter than the 10-byte header
"""

from __future__ import annotations

import struct

from mrmp.core.errors import MrmpError
from mrmp.core.heading import Heading
from mrmp.protocol.messages import (
    NO_CELL,
    AnswerMessage,
    BeaconMessage,
    ClaimMessage,
    MAX_VISITED_CELLS,
    RELEASE_OPERATIONS,
    InheritMessage,
    LockAckMessage,
    LockGrantMessage,
    LockReleaseMessage,
    LockRequestMessage,
    Message,
    PullMessage,
    ReplyMessage,
    ReserveMessage,
    StateMessage,
)

PROTOCOL_VERSION = 5
"""Version byte of every datagram; a receiver drops other versions."""
MAX_MESSAGE_BYTES = 512
"""Upper bound on the size of any encoded message."""

DECODE_REASONS = ("oversized", "truncated", "version", "type", "malformed")
"""Why a datagram can be rejected by :func:`decode`."""

_HEADER = struct.Struct("!BBII")
_STATE_BODY = struct.Struct("!iiiiiiiiBBII")
_CLAIM_BODY = struct.Struct("!Iii")
_REPLY_BODY = struct.Struct("!IIiiB")
_BEACON_BODY = struct.Struct("!IiiiiIIB")
_STEP_CELL_BODY = struct.Struct("!Iii")
_ANSWER_BODY = struct.Struct("!IB")
_LOCK_REQUEST_BODY = struct.Struct("!I")
_LOCK_GRANT_BODY = struct.Struct("!IIBBiiiiIIB")
_LOCK_RELEASE_BODY = struct.Struct("!IBB")
_LOCK_ACK_BODY = struct.Struct("!II")
_CELL = struct.Struct("!ii")
_STATE, _CLAIM, _REPLY, _BEACON, _INHERIT, _ANSWER, _RESERVE, _PULL = 1, 2, 3, 4, 5, 6, 7, 8
_LOCK_REQUEST, _LOCK_GRANT, _LOCK_RELEASE, _LOCK_ACK = 9, 10, 11, 12
_HAS_HEAD, _URGENT = 0x01, 0x02
_VARIABLE = frozenset({_LOCK_GRANT, _LOCK_RELEASE})
"""Types whose fixed body ends with a count of the visited cells that follow it."""
_ARRIVED, _MOVING, _CLAIMING = 0x01, 0x02, 0x04
_BODIES = {
    _STATE: _STATE_BODY,
    _CLAIM: _CLAIM_BODY,
    _REPLY: _REPLY_BODY,
    _BEACON: _BEACON_BODY,
    _INHERIT: _STEP_CELL_BODY,
    _ANSWER: _ANSWER_BODY,
    _RESERVE: _STEP_CELL_BODY,
    _PULL: _STEP_CELL_BODY,
    _LOCK_REQUEST: _LOCK_REQUEST_BODY,
    _LOCK_GRANT: _LOCK_GRANT_BODY,
    _LOCK_RELEASE: _LOCK_RELEASE_BODY,
    _LOCK_ACK: _LOCK_ACK_BODY,
}
_STEP_CELL_TYPES: dict[type, int] = {InheritMessage: _INHERIT, ReserveMessage: _RESERVE, PullMessage: _PULL}
_STEP_CELL_CLASSES = {code: cls for cls, code in _STEP_CELL_TYPES.items()}


class DecodeError(MrmpError):
    """A datagram that is not a valid message; ``reason`` is one of :data:`DECODE_REASONS`."""

    def __init__(self, reason: str, detail: str) -> None:
        self.reason = reason
        super().__init__(f"{reason}: {detail}")


def encode(message: Message) -> bytes:
    """Encode a message to bytes.

    Raises
    ------
    TypeError
        If ``message`` is not a message type the codec knows.
    struct.error
        If a field does not fit its wire size (for example a negative sender).
    """
    if isinstance(message, StateMessage):
        target = message.target if message.target is not None else NO_CELL
        claim_cell = message.claim_cell if message.claim and message.claim_cell is not None else NO_CELL
        flags = (
            (_ARRIVED if message.arrived else 0)
            | (_MOVING if message.target is not None else 0)
            | (_CLAIMING if message.claim else 0)
        )
        body = _STATE_BODY.pack(
            *message.present, *message.next, *target, *claim_cell, int(message.heading), flags, message.claim, message.progress
        )
        type_code = _STATE
    elif isinstance(message, ClaimMessage):
        body = _CLAIM_BODY.pack(message.claim, *message.cell)
        type_code = _CLAIM
    elif isinstance(message, ReplyMessage):
        body = _REPLY_BODY.pack(message.claimant, message.claim, *message.cell, 1 if message.granted else 0)
        type_code = _REPLY
    elif isinstance(message, BeaconMessage):
        body = _BEACON_BODY.pack(
            message.step, *message.present, *message.goal, message.elapsed, message.tie, int(message.heading)
        )
        type_code = _BEACON
    elif isinstance(message, AnswerMessage):
        body = _ANSWER_BODY.pack(message.step, 1 if message.moved else 0)
        type_code = _ANSWER
    elif isinstance(message, LockRequestMessage):
        body = _LOCK_REQUEST_BODY.pack(message.session)
        type_code = _LOCK_REQUEST
    elif isinstance(message, LockGrantMessage):
        if not 0 <= message.mode <= 2 or (message.head is None) != (message.mode == 0):
            raise ValueError(f"lock grant with mode {message.mode} and head {message.head}")
        head = message.head if message.head is not None else NO_CELL
        flags = (_HAS_HEAD if message.head is not None else 0) | (_URGENT if message.urgent else 0)
        body = _LOCK_GRANT_BODY.pack(
            message.locker, message.session, message.mode, flags, *message.tail, *head,
            message.reached, message.rank, len(message.visited),
        ) + _cells(message.visited)
        type_code = _LOCK_GRANT
    elif isinstance(message, LockReleaseMessage):
        body = _LOCK_RELEASE_BODY.pack(message.session, message.operations, len(message.visited)) + _cells(message.visited)
        type_code = _LOCK_RELEASE
    elif isinstance(message, LockAckMessage):
        body = _LOCK_ACK_BODY.pack(message.locker, message.session)
        type_code = _LOCK_ACK
    elif type(message) in _STEP_CELL_TYPES:
        body = _STEP_CELL_BODY.pack(message.step, *message.cell)  # type: ignore[union-attr]
        type_code = _STEP_CELL_TYPES[type(message)]
    else:
        raise TypeError(f"cannot encode {type(message).__name__}")
    return _HEADER.pack(PROTOCOL_VERSION, type_code, message.sender, message.seq) + body


def decode(data: bytes) -> Message:
    """Decode bytes produced by :func:`encode`.

    Raises
    ------
    DecodeError
        If the data is oversized, truncated, of another protocol version, of an
        unknown type, or has fields out of range.
    """
    size = len(data)
    if size > MAX_MESSAGE_BYTES:
        raise DecodeError("oversized", f"{size} bytes is more than the {MAX_MESSAGE_BYTES}-byte bound")
    if size < _HEADER.size:
        raise DecodeError("truncated", f"{size} bytes is shorter than the {_HEADER.size}-byte header")
    version, type_code, sender, seq = _HEADER.unpack_from(data)
    if version != PROTOCOL_VERSION:
        raise DecodeError("version", f"protocol version {version}, expected {PROTOCOL_VERSION}")
    body = _BODIES.get(type_code)
    if body is None:
        raise DecodeError("type", f"unknown message type {type_code}")
    expected = _HEADER.size + body.size
    if type_code in _VARIABLE and size >= expected:
        count = data[expected - 1]
        if count > MAX_VISITED_CELLS:
            raise DecodeError("malformed", f"{count} visited cells, at most {MAX_VISITED_CELLS}")
        expected += _CELL.size * count
    if size != expected:
        raise DecodeError("truncated" if size < expected else "malformed", f"{size} bytes, expected {expected}")
    fields = body.unpack_from(data, _HEADER.size)
    if type_code == _STATE:
        px, py, nx, ny, tx, ty, cx, cy, heading, flags, claim, progress = fields
        if not 1 <= heading <= 4:
            raise DecodeError("malformed", f"heading {heading} is not 1..4")
        if flags & ~(_ARRIVED | _MOVING | _CLAIMING):
            raise DecodeError("malformed", f"unknown flags {flags:#04x}")
        moving, claiming = bool(flags & _MOVING), bool(flags & _CLAIMING)
        if moving != ((tx, ty) != NO_CELL) or claiming != (claim != 0) or claiming != ((cx, cy) != NO_CELL):
            raise DecodeError("malformed", "flags disagree with the target and claim fields")
        return StateMessage(
            sender,
            seq,
            (px, py),
            (nx, ny),
            Heading(heading),
            bool(flags & _ARRIVED),
            (tx, ty) if moving else None,
            claim,
            (cx, cy) if claiming else None,
            progress,
        )
    if type_code == _BEACON:
        step, px, py, gx, gy, elapsed, tie, heading = fields
        if not 1 <= heading <= 4:
            raise DecodeError("malformed", f"heading {heading} is not 1..4")
        return BeaconMessage(sender, seq, step, (px, py), (gx, gy), elapsed, tie, Heading(heading))
    if type_code == _ANSWER:
        step, moved = fields
        if moved > 1:
            raise DecodeError("malformed", f"answer with moved={moved}")
        return AnswerMessage(sender, seq, step, bool(moved))
    if type_code in _VARIABLE:
        return _decode_lock(type_code, sender, seq, fields, data[_HEADER.size + body.size :])
    if type_code == _LOCK_REQUEST:
        (session,) = fields
        return LockRequestMessage(sender, seq, session)
    if type_code == _LOCK_ACK:
        locker, session = fields
        return LockAckMessage(sender, seq, locker, session)
    if type_code in _STEP_CELL_CLASSES:
        step, cx, cy = fields
        return _STEP_CELL_CLASSES[type_code](sender, seq, step, (cx, cy))  # type: ignore[no-any-return]
    if type_code == _CLAIM:
        claim, cx, cy = fields
        if claim == 0:
            raise DecodeError("malformed", "claim number 0")
        return ClaimMessage(sender, seq, claim, (cx, cy))
    claimant, claim, cx, cy, granted = fields
    if granted > 1 or claim == 0:
        raise DecodeError("malformed", f"reply with granted={granted}, claim={claim}")
    return ReplyMessage(sender, seq, claimant, claim, (cx, cy), bool(granted))


def _cells(cells: tuple[tuple[int, int], ...]) -> bytes:
    """The wire form of a visited set (at most :data:`MAX_VISITED_CELLS` cells)."""
    if len(cells) > MAX_VISITED_CELLS:
        raise ValueError(f"{len(cells)} visited cells, at most {MAX_VISITED_CELLS}")
    return b"".join(_CELL.pack(*cell) for cell in cells)


def _decode_lock(type_code: int, sender: int, seq: int, fields: tuple[int, ...], rest: bytes) -> Message:
    """Decode a lock grant or release whose fixed fields are ``fields`` and whose visited cells are ``rest``."""
    visited = tuple((x, y) for x, y in _CELL.iter_unpack(rest))
    if type_code == _LOCK_RELEASE:
        session, operations, _ = fields
        if operations & ~RELEASE_OPERATIONS:
            raise DecodeError("malformed", f"unknown release operations {operations:#04x}")
        return LockReleaseMessage(sender, seq, session, operations, visited)
    locker, session, mode, flags, tx, ty, hx, hy, reached, rank, _ = fields
    if mode > 2 or flags & ~(_HAS_HEAD | _URGENT):
        raise DecodeError("malformed", f"lock grant with mode {mode}, flags {flags:#04x}")
    has_head = bool(flags & _HAS_HEAD)
    if has_head != (mode != 0) or has_head != ((hx, hy) != NO_CELL):
        raise DecodeError("malformed", "lock grant whose head disagrees with its mode")
    head = (hx, hy) if has_head else None
    return LockGrantMessage(sender, seq, locker, session, mode, (tx, ty), head, bool(flags & _URGENT), reached, rank, visited)
