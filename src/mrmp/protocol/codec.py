"""A compact, versioned, size-bounded binary codec for robot messages.

Wire layout (network byte order)::

    offset  size  field
    0       1     protocol version (PROTOCOL_VERSION)
    1       1     message type code
    2       4     sender index (unsigned)
    6       4     sequence number (unsigned)
    10      ...   body, fixed layout per type

:class:`~mrmp.protocol.messages.StateMessage` (type 1) has a 18-byte body:
present x, present y, next x, next y (signed 32-bit each), heading (1..4) and
flags (bit 0: arrived), 28 bytes in all. Every datagram is at most
:data:`MAX_MESSAGE_BYTES`.

Decoding never trusts its input: anything that is not exactly a valid message
raises :class:`DecodeError` with a ``reason`` (``"oversized"``,
``"truncated"``, ``"version"``, ``"type"``, ``"malformed"``) so that a
receiver can drop it and count it per reason.

Examples
--------
>>> from mrmp.protocol.messages import StateMessage
>>> data = encode(StateMessage(sender=1, seq=3, present=(4, 2), next=(3, 2)))
>>> len(data)
28
>>> decode(data)
StateMessage(sender=1, seq=3, present=(4, 2), next=(3, 2), heading=<Heading.NORTH: 1>, arrived=False)
>>> decode(b"hello")
Traceback (most recent call last):
...
mrmp.protocol.codec.DecodeError: truncated: 5 bytes is shorter than the 10-byte header
"""

from __future__ import annotations

import struct

from mrmp.core.errors import MrmpError
from mrmp.core.heading import Heading
from mrmp.protocol.messages import Message, StateMessage

PROTOCOL_VERSION = 1
"""Version byte of every datagram; a receiver drops other versions."""
MAX_MESSAGE_BYTES = 512
"""Upper bound on the size of any encoded message."""

DECODE_REASONS = ("oversized", "truncated", "version", "type", "malformed")
"""Why a datagram can be rejected by :func:`decode`."""

_HEADER = struct.Struct("!BBII")
_STATE_BODY = struct.Struct("!iiiiBB")
_STATE_TYPE = 1
_ARRIVED = 0x01


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
        flags = _ARRIVED if message.arrived else 0
        return _HEADER.pack(PROTOCOL_VERSION, _STATE_TYPE, message.sender, message.seq) + _STATE_BODY.pack(
            message.present[0], message.present[1], message.next[0], message.next[1], int(message.heading), flags
        )
    raise TypeError(f"cannot encode {type(message).__name__}")


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
    if type_code == _STATE_TYPE:
        expected = _HEADER.size + _STATE_BODY.size
        if size != expected:
            reason = "truncated" if size < expected else "malformed"
            raise DecodeError(reason, f"state message of {size} bytes, expected {expected}")
        px, py, nx, ny, heading, flags = _STATE_BODY.unpack_from(data, _HEADER.size)
        if not 1 <= heading <= 4:
            raise DecodeError("malformed", f"heading {heading} is not 1..4")
        if flags & ~_ARRIVED:
            raise DecodeError("malformed", f"unknown flags {flags:#04x}")
        return StateMessage(sender, seq, (px, py), (nx, ny), Heading(heading), bool(flags & _ARRIVED))
    raise DecodeError("type", f"unknown message type {type_code}")
