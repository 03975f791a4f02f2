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
    InheritMessage,
    Message,
    PullMessage,
    ReplyMessage,
    ReserveMessage,
    StateMessage,
)

PROTOCOL_VERSION = 4
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
_STATE, _CLAIM, _REPLY, _BEACON, _INHERIT, _ANSWER, _RESERVE, _PULL = 1, 2, 3, 4, 5, 6, 7, 8
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
