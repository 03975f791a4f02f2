"""A compact, versioned, size-bounded binary codec for robot messages.

Wire layout (network byte order)::

    offset  size  field
    0       1     protocol version (PROTOCOL_VERSION)
    1       1     message type code
    2       4     sender index (unsigned)
    6       4     sequence number (unsigned)
    10      ...   body, fixed layout per type

The bodies, one layout per message type, are declared once each in the message
table (:mod:`mrmp.protocol.wire`); :mod:`mrmp.protocol.formats` holds the
project's own and lists their layouts. Counts of visited cells are at most
:data:`~mrmp.protocol.messages.MAX_VISITED_CELLS`.

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
mrmp.protocol.wire.DecodeError: truncated: 5 bytes is shorter than the 10-byte header
"""  # noqa: E501

from __future__ import annotations

from mrmp.protocol import formats  # noqa: F401  (registers the project's message types)
from mrmp.protocol.messages import Message
from mrmp.protocol.wire import (
    DECODE_REASONS,
    HEADER,
    DecodeError,
    WireFormat,
    fixed_sizes,
    format_for_code,
    format_of,
    register,
    unregister,
)

__all__ = [
    "DECODE_REASONS",
    "MAX_MESSAGE_BYTES",
    "PROTOCOL_VERSION",
    "DecodeError",
    "WireFormat",
    "decode",
    "encode",
    "fixed_sizes",
    "register",
    "unregister",
]

PROTOCOL_VERSION = 7
"""Version byte of every datagram; a receiver drops other versions."""
MAX_MESSAGE_BYTES = 512
"""Upper bound on the size of any encoded message."""


def encode(message: Message) -> bytes:
    """Encode a message to bytes, through its type's entry in the message table.

    Raises
    ------
    TypeError
        If ``message`` is not a message type the codec knows.
    struct.error
        If a field does not fit its wire size (for example a negative sender).
    """
    wire_format = format_of(message)
    body = wire_format.encode_body(message)
    return HEADER.pack(PROTOCOL_VERSION, wire_format.code, message.sender, message.seq) + body


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
    if size < HEADER.size:
        raise DecodeError("truncated", f"{size} bytes is shorter than the {HEADER.size}-byte header")
    version, type_code, sender, seq = HEADER.unpack_from(data)
    if version != PROTOCOL_VERSION:
        raise DecodeError("version", f"protocol version {version}, expected {PROTOCOL_VERSION}")
    wire_format = format_for_code(type_code)
    if wire_format is None:
        raise DecodeError("type", f"unknown message type {type_code}")
    expected = wire_format.expected_size(data)
    if size != expected:
        raise DecodeError("truncated" if size < expected else "malformed", f"{size} bytes, expected {expected}")
    return wire_format.decode_body(sender, seq, data)
