"""The message table: a message type added from outside the package, round-tripped and taken out again."""

from dataclasses import dataclass

import pytest

from mrmp.protocol.codec import DecodeError, WireFormat, decode, encode, fixed_sizes, register, unregister
from mrmp.protocol.messages import ClaimMessage, Message, StateMessage
from mrmp.protocol.wire import format_for_code


@dataclass(frozen=True, slots=True)
class HopMessage(Message):
    """A toy message: how many hops it has travelled, and where it started."""

    sender: int
    seq: int
    hops: int
    origin: tuple[int, int]


def _unpack_hop(sender, seq, fields, cells):
    hops, x, y = fields
    if hops == 0:
        raise DecodeError("malformed", "zero hops")
    return HopMessage(sender, seq, hops, (x, y))


@pytest.fixture
def hop_format():
    wire_format = register(WireFormat(250, HopMessage, "!Iii", lambda m: (m.hops, *m.origin), _unpack_hop))
    yield wire_format
    unregister(wire_format)


def test_a_registered_message_round_trips_and_is_gone_once_unregistered(hop_format):
    message = HopMessage(3, 9, 2, (-1, 4))
    data = encode(message)
    assert len(data) == 22 == fixed_sizes()[HopMessage]
    assert decode(data) == message
    with pytest.raises(DecodeError) as caught:
        decode(data[:10] + bytes(12))
    assert caught.value.reason == "malformed"
    unregister(hop_format)
    with pytest.raises(TypeError):
        encode(message)
    with pytest.raises(DecodeError) as caught:
        decode(data)
    assert caught.value.reason == "type"


def test_codes_and_types_are_unique_in_the_table(hop_format):
    with pytest.raises(ValueError, match="taken"):
        register(WireFormat(1, HopMessage, "!I", lambda m: (m.hops,), _unpack_hop))
    with pytest.raises(ValueError, match="already"):
        register(WireFormat(251, HopMessage, "!I", lambda m: (m.hops,), _unpack_hop))
    assert format_for_code(1).kind is StateMessage and format_for_code(2).kind is ClaimMessage
