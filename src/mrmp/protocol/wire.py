"""The message table: every message type's type code and binary layout, declared once.

A :class:`WireFormat` says how one message type crosses the wire: its type
code, the fixed layout of its body (a :class:`struct.Struct` in network byte
order, after the header of :mod:`mrmp.protocol.codec`), how a message becomes
the body's fields and how fields become a message again (checking them, and
raising :class:`DecodeError` for anything out of range). A type may end its
body with a count byte followed by that many cells (``cells`` names where the
message keeps them). :func:`register` adds a format to the table,
:func:`unregister` takes it out again; the codec encodes and decodes through
the table alone, so a new message type is one class and one registration,
from any module.

Examples
--------
>>> from dataclasses import dataclass
>>> from mrmp.protocol.messages import Message
>>> @dataclass(frozen=True, slots=True)
... class PingMessage(Message):
...     sender: int
...     seq: int
...     hops: int
>>> ping = register(WireFormat(200, PingMessage, "!I", lambda m: (m.hops,), lambda s, q, f, c: PingMessage(s, q, *f)))
>>> format_of(PingMessage(0, 1, 3)).size
14
>>> unregister(ping)
>>> format_of(PingMessage(0, 1, 3))
Traceback (most recent call last):
...
TypeError: cannot encode PingMessage
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Generic, TypeVar

from mrmp.core.cell import Cell
from mrmp.core.errors import MrmpError
from mrmp.protocol.messages import MAX_VISITED_CELLS, Message

__all__ = [
    "CELL",
    "DECODE_REASONS",
    "HEADER",
    "DecodeError",
    "WireFormat",
    "fixed_sizes",
    "format_for_code",
    "format_of",
    "register",
    "unregister",
]

M = TypeVar("M", bound=Message)

HEADER = struct.Struct("!BBII")
"""Protocol version, type code, sender, sequence number: the first bytes of every message."""
CELL = struct.Struct("!ii")
"""A cell on the wire: two signed 32-bit integers."""

DECODE_REASONS = ("oversized", "truncated", "version", "type", "malformed")
"""Why a datagram can be rejected by :func:`mrmp.protocol.codec.decode`."""


class DecodeError(MrmpError):
    """A datagram that is not a valid message; ``reason`` is one of :data:`DECODE_REASONS`."""

    def __init__(self, reason: str, detail: str) -> None:
        self.reason = reason
        super().__init__(f"{reason}: {detail}")


@dataclass(frozen=True)
class WireFormat(Generic[M]):
    """How messages of type ``kind`` cross the wire (see the module docstring).

    Attributes
    ----------
    code:
        The type code (1 to 255), unique in the table.
    kind:
        The message class.
    layout:
        The body's fixed layout, as :mod:`struct` characters in network byte
        order (``"!Iii"``); with ``cells``, its last field is the count byte
        of the cells that follow.
    pack:
        The body's fixed fields of a message (without the count).
    unpack:
        ``(sender, seq, fields, cells)`` to the message; raises
        :class:`DecodeError` (reason ``"malformed"``) for fields out of range.
    cells:
        Where a message keeps the cells that end its body, or None when the body is fixed.
    """

    code: int
    kind: type[M]
    layout: str
    pack: Callable[[M], tuple[int, ...]]
    unpack: Callable[[int, int, tuple[Any, ...], tuple[Cell, ...]], M]
    cells: Callable[[M], tuple[Cell, ...]] | None = None
    body: struct.Struct = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not 1 <= self.code <= 255:
            raise ValueError(f"type code {self.code} is not 1..255")
        object.__setattr__(self, "body", struct.Struct(self.layout))

    @property
    def size(self) -> int:
        """Bytes of a message of this type with no trailing cells, header included."""
        return HEADER.size + self.body.size

    def encode_body(self, message: M) -> bytes:
        """The body of ``message``: its fixed fields, then its cells when the layout has them.

        Raises
        ------
        struct.error
            If a field does not fit its wire size.
        ValueError
            If there are more than :data:`~mrmp.protocol.messages.MAX_VISITED_CELLS` cells.
        """
        if self.cells is None:
            return self.body.pack(*self.pack(message))
        cells = self.cells(message)
        fixed = self.body.pack(*self.pack(message), len(cells))
        if len(cells) > MAX_VISITED_CELLS:
            raise ValueError(f"{len(cells)} visited cells, at most {MAX_VISITED_CELLS}")
        return fixed + b"".join(CELL.pack(*cell) for cell in cells)

    def expected_size(self, data: bytes) -> int:
        """How long ``data`` must be to hold a message of this type (its count byte read when it has cells).

        Raises
        ------
        DecodeError
            If the count byte says more than :data:`~mrmp.protocol.messages.MAX_VISITED_CELLS` cells.
        """
        expected = self.size
        if self.cells is not None and len(data) >= expected:
            count = data[expected - 1]
            if count > MAX_VISITED_CELLS:
                raise DecodeError("malformed", f"{count} visited cells, at most {MAX_VISITED_CELLS}")
            expected += CELL.size * count
        return expected

    def decode_body(self, sender: int, seq: int, data: bytes) -> M:
        """The message whose header said ``sender`` and ``seq`` and whose body is the rest of ``data`` (of the expected size)."""
        fields = self.body.unpack_from(data, HEADER.size)
        if self.cells is None:
            return self.unpack(sender, seq, fields, ())
        cells = tuple((x, y) for x, y in CELL.iter_unpack(data[self.size :]))
        return self.unpack(sender, seq, fields[:-1], cells)


_BY_CODE: dict[int, WireFormat[Any]] = {}
_BY_KIND: dict[type, WireFormat[Any]] = {}


def register(wire_format: WireFormat[M]) -> WireFormat[M]:
    """Add ``wire_format`` to the table and return it; its code and its type must be new to the table."""
    if wire_format.code in _BY_CODE:
        raise ValueError(f"type code {wire_format.code} is taken by {_BY_CODE[wire_format.code].kind.__name__}")
    if wire_format.kind in _BY_KIND:
        raise ValueError(f"{wire_format.kind.__name__} already has type code {_BY_KIND[wire_format.kind].code}")
    _BY_CODE[wire_format.code] = wire_format
    _BY_KIND[wire_format.kind] = wire_format
    return wire_format


def unregister(wire_format: WireFormat[Any]) -> None:
    """Take ``wire_format`` out of the table (messages of its type no longer encode or decode)."""
    if _BY_CODE.get(wire_format.code) is wire_format:
        del _BY_CODE[wire_format.code]
        del _BY_KIND[wire_format.kind]


def format_of(message: Message) -> WireFormat[Any]:
    """The wire format of ``message``'s type.

    Raises
    ------
    TypeError
        If the table has no format for that type.
    """
    wire_format = _BY_KIND.get(type(message))
    if wire_format is None:
        raise TypeError(f"cannot encode {type(message).__name__}")
    return wire_format


def format_for_code(code: int) -> WireFormat[Any] | None:
    """The wire format of type code ``code``, or None when the table has none."""
    return _BY_CODE.get(code)


def fixed_sizes() -> dict[type, int]:
    """The encoded size of every message type in the table whose messages all have one size."""
    return {kind: wire_format.size for kind, wire_format in _BY_KIND.items() if wire_format.cells is None}
