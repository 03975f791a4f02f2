"""The binary codec: round trips, bounds, and garbage."""

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.core.heading import Heading
from mrmp.protocol.codec import MAX_MESSAGE_BYTES, PROTOCOL_VERSION, DecodeError, decode, encode
from mrmp.protocol.messages import StateMessage

coordinates = st.integers(min_value=-(2**31), max_value=2**31 - 1)
cells = st.tuples(coordinates, coordinates)
states = st.builds(
    StateMessage,
    sender=st.integers(0, 2**32 - 1),
    seq=st.integers(0, 2**32 - 1),
    present=cells,
    next=cells,
    heading=st.sampled_from(list(Heading)),
    arrived=st.booleans(),
)


@settings(max_examples=300, derandomize=True)
@given(states)
def test_round_trip(message):
    data = encode(message)
    assert data[0] == PROTOCOL_VERSION
    assert len(data) <= MAX_MESSAGE_BYTES
    assert decode(data) == message


@settings(max_examples=500, derandomize=True)
@given(st.binary(max_size=2 * MAX_MESSAGE_BYTES))
def test_garbage_raises_only_decode_error(data):
    try:
        message = decode(data)
    except DecodeError as error:
        assert error.reason in ("oversized", "truncated", "version", "type", "malformed")
    else:
        assert encode(message) == data  # anything accepted is exactly a valid encoding


def _valid():
    return encode(StateMessage(3, 9, (1, 2), (2, 2), Heading.EAST, True))


@pytest.mark.parametrize(
    ("data", "reason"),
    [
        (b"", "truncated"),
        (_valid()[:-1], "truncated"),
        (_valid() + b"\x00", "malformed"),
        (bytes([PROTOCOL_VERSION + 1]) + _valid()[1:], "version"),
        (_valid()[:1] + b"\x63" + _valid()[2:], "type"),
        (_valid()[:-2] + b"\x07\x00", "malformed"),  # heading 7
        (_valid()[:-1] + b"\x80", "malformed"),  # unknown flag
        (b"\x01" * (MAX_MESSAGE_BYTES + 1), "oversized"),
    ],
)
def test_each_rejection_reason(data, reason):
    with pytest.raises(DecodeError) as caught:
        decode(data)
    assert caught.value.reason == reason


def test_fields_that_do_not_fit_are_refused_at_encoding():
    with pytest.raises(struct.error):
        encode(StateMessage(-1, 0, (0, 0), (0, 0)))
