"""The codec's Causal-PIBT lock messages: round trips, size bounds, mutations, rejections."""

import pytest
from codec_checks import assert_exact_or_refused, assert_round_trip, mutated
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.protocol.codec import MAX_MESSAGE_BYTES, DecodeError, decode, encode
from mrmp.protocol.messages import (
    MAX_VISITED_CELLS,
    NO_CELL,
    LockAckMessage,
    LockGrantMessage,
    LockReleaseMessage,
    LockRequestMessage,
)

coordinates = st.integers(min_value=-(2**31), max_value=2**31 - 1)
cells = st.tuples(coordinates, coordinates)
wire_cells = cells.filter(lambda cell: cell != NO_CELL)
u32 = st.integers(0, 2**32 - 1)
visited_sets = st.lists(cells, max_size=MAX_VISITED_CELLS).map(tuple)


@st.composite
def grants(draw):
    mode = draw(st.integers(0, 2))
    return LockGrantMessage(
        sender=draw(u32),
        seq=draw(u32),
        locker=draw(u32),
        session=draw(u32),
        mode=mode,
        tail=draw(cells),
        head=None if mode == 0 else draw(wire_cells),
        urgent=draw(st.booleans()),
        reached=draw(u32),
        rank=draw(u32),
        visited=draw(visited_sets),
    )


messages = (
    st.builds(LockRequestMessage, sender=u32, seq=u32, session=u32)
    | grants()
    | st.builds(LockReleaseMessage, sender=u32, seq=u32, session=u32, operations=st.integers(0, 0x1F), visited=visited_sets)
    | st.builds(LockAckMessage, sender=u32, seq=u32, locker=u32, session=u32)
)


@settings(max_examples=400, derandomize=True)
@given(messages)
def test_round_trip_within_the_size_bound(message):
    assert_round_trip(message)


@settings(max_examples=400, derandomize=True)
@given(messages, st.data())
def test_mutations_decode_to_exact_messages_or_raise(message, data):
    assert_exact_or_refused(mutated(encode(message), data, most_extra=16))


def test_the_largest_grant_fits():
    grant = LockGrantMessage(1, 2, 3, 4, 2, (0, 0), (0, 1), True, 5, 6, tuple((i, i) for i in range(MAX_VISITED_CELLS)))
    assert len(encode(grant)) == 45 + 8 * MAX_VISITED_CELLS <= MAX_MESSAGE_BYTES
    assert len(encode(LockRequestMessage(1, 2, 3))) == 14
    assert len(encode(LockAckMessage(1, 2, 3, 4))) == 18


def test_too_many_visited_cells_are_refused_both_ways():
    too_many = tuple((i, 0) for i in range(MAX_VISITED_CELLS + 1))
    with pytest.raises(ValueError):
        encode(LockReleaseMessage(1, 2, 3, 0, too_many))
    data = bytearray(encode(LockReleaseMessage(1, 2, 3, 0, too_many[:1])))
    data[15] = MAX_VISITED_CELLS + 1  # the count byte
    with pytest.raises(DecodeError) as caught:
        decode(bytes(data) + bytes(8 * MAX_VISITED_CELLS))
    assert caught.value.reason == "malformed"


@pytest.mark.parametrize(
    "data",
    [
        encode(LockReleaseMessage(1, 2, 3, 0))[:14] + b"\x20" + b"\x00",  # unknown operation bit
        encode(LockGrantMessage(1, 2, 3, 4, 0, (0, 0), None, False, 0, 0))[:18] + b"\x03" + encode(
            LockGrantMessage(1, 2, 3, 4, 0, (0, 0), None, False, 0, 0)
        )[19:],  # mode 3
        encode(LockGrantMessage(1, 2, 3, 4, 0, (0, 0), None, False, 0, 0))[:19] + b"\x01" + encode(
            LockGrantMessage(1, 2, 3, 4, 0, (0, 0), None, False, 0, 0)
        )[20:],  # contracted, yet a head flag
    ],
)
def test_malformed_lock_messages(data):
    with pytest.raises(DecodeError) as caught:
        decode(data)
    assert caught.value.reason == "malformed"


def test_a_grant_whose_head_disagrees_with_its_mode_cannot_be_encoded():
    with pytest.raises(ValueError):
        encode(LockGrantMessage(1, 2, 3, 4, 1, (0, 0), None, False, 0, 0))
