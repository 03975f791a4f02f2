"""The binary codec: round trips, bounds, and garbage."""

import struct

import pytest
from codec_checks import assert_exact_or_refused, assert_round_trip, mutated
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.core.heading import Heading
from mrmp.protocol.codec import MAX_MESSAGE_BYTES, PROTOCOL_VERSION, DecodeError, decode, encode
from mrmp.protocol.messages import ClaimMessage, FarewellMessage, ReplyMessage, StateMessage

coordinates = st.integers(min_value=-(2**31), max_value=2**31 - 1)
cells = st.tuples(coordinates, coordinates)
wire_cells = cells.filter(lambda cell: cell != (-(2**31), -(2**31)))
u32 = st.integers(0, 2**32 - 1)
claims = st.integers(1, 2**32 - 1)


@st.composite
def states(draw):
    claim = draw(st.sampled_from([0, 1, 2**32 - 1]) | claims)
    return StateMessage(
        sender=draw(u32),
        seq=draw(u32),
        present=draw(cells),
        next=draw(cells),
        heading=draw(st.sampled_from(list(Heading))),
        arrived=draw(st.booleans()),
        target=draw(st.none() | wire_cells),
        claim=claim,
        claim_cell=draw(wire_cells) if claim else None,
        progress=draw(u32),
    )


messages = (
    states()
    | st.builds(ClaimMessage, sender=u32, seq=u32, claim=claims, cell=cells)
    | st.builds(ReplyMessage, sender=u32, seq=u32, claimant=u32, claim=claims, cell=cells, granted=st.booleans())
    | st.builds(FarewellMessage, sender=u32, seq=u32, cell=cells)
)


@pytest.mark.slow
@settings(max_examples=500, derandomize=True)
@given(messages)
def test_round_trip(message):
    assert_round_trip(message)


@pytest.mark.slow
@settings(max_examples=500, derandomize=True)
@given(st.binary(max_size=2 * MAX_MESSAGE_BYTES))
def test_garbage_raises_only_decode_error(data):
    assert_exact_or_refused(data)


@pytest.mark.slow
@settings(max_examples=500, derandomize=True)
@given(messages, st.data())
def test_mutations_of_valid_messages_decode_to_valid_messages_or_raise(message, data):
    """Flip, cut or extend a valid encoding: the result is a typed error or a message that encodes back exactly."""
    assert_exact_or_refused(mutated(encode(message), data, most_extra=8))


def _valid():
    return encode(StateMessage(3, 9, (1, 2), (2, 2), Heading.EAST, True))


HEADING_AT, FLAGS_AT = 10 + 32, 10 + 33


@pytest.mark.parametrize(
    ("data", "reason"),
    [
        (b"", "truncated"),
        (_valid()[:-1], "truncated"),
        (_valid() + b"\x00", "malformed"),
        (bytes([PROTOCOL_VERSION + 1]) + _valid()[1:], "version"),
        (_valid()[:1] + b"\x63" + _valid()[2:], "type"),
        (_valid()[:HEADING_AT] + b"\x07" + _valid()[HEADING_AT + 1 :], "malformed"),  # heading 7
        (_valid()[:FLAGS_AT] + b"\x81" + _valid()[FLAGS_AT + 1 :], "malformed"),  # unknown flag
        (_valid()[:FLAGS_AT] + b"\x03" + _valid()[FLAGS_AT + 1 :], "malformed"),  # moving without a target
        (encode(ClaimMessage(1, 2, 3, (0, 0)))[:10] + bytes(12), "malformed"),  # claim number 0
        (encode(ReplyMessage(1, 2, 3, 4, (0, 0), True))[:-1] + b"\x02", "malformed"),  # granted = 2
        (b"\x01" * (MAX_MESSAGE_BYTES + 1), "oversized"),
    ],
)
def test_each_rejection_reason(data, reason):
    with pytest.raises(DecodeError) as caught:
        decode(data)
    assert caught.value.reason == reason


def test_sizes_stay_small():
    assert len(_valid()) == 52
    assert len(encode(ClaimMessage(1, 2, 3, (4, 5)))) == 22
    assert len(encode(ReplyMessage(1, 2, 3, 4, (5, 6), False))) == 27
    assert len(encode(FarewellMessage(1, 2, (3, 4)))) == 18


def test_fields_that_do_not_fit_are_refused_at_encoding():
    with pytest.raises(struct.error):
        encode(StateMessage(-1, 0, (0, 0), (0, 0)))
