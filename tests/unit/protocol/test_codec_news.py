"""The live brain's beacon with news: round trips, size bound, mutations, rejections."""

import struct

import pytest
from codec_checks import assert_exact_or_refused, assert_round_trip, mutated
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.core.heading import Heading
from mrmp.protocol.codec import MAX_MESSAGE_BYTES, DecodeError, decode, encode
from mrmp.protocol.pibt_local import MAX_NEWS, NewsBeaconMessage

coordinates = st.integers(min_value=-(2**31), max_value=2**31 - 1)
cells = st.tuples(coordinates, coordinates)
u32 = st.integers(0, 2**32 - 1)
i32_natural = st.integers(0, 2**31 - 1)
news = st.lists(st.tuples(i32_natural, cells, i32_natural), max_size=MAX_NEWS).map(tuple)
beacons = st.builds(
    NewsBeaconMessage,
    sender=u32,
    seq=u32,
    step=u32,
    present=cells,
    goal=cells,
    elapsed=u32,
    tie=u32,
    heading=st.sampled_from(list(Heading)),
    news=news,
    asks=st.booleans(),
)


@settings(max_examples=300, derandomize=True)
@given(beacons)
def test_round_trip_within_the_size_bound(message):
    assert_round_trip(message)


@settings(max_examples=300, derandomize=True)
@given(beacons, st.data())
def test_mutations_decode_to_exact_messages_or_raise(message, data):
    assert_exact_or_refused(mutated(encode(message), data, most_extra=24))


def test_the_fullest_beacon_fits_and_one_more_entry_is_refused():
    entries = tuple((peer, (peer, -peer), 7) for peer in range(MAX_NEWS))
    full = NewsBeaconMessage(1, 2, 7, (0, 0), (3, 3), 4, 5, news=entries)
    assert len(encode(full)) == 41 + 16 * MAX_NEWS <= MAX_MESSAGE_BYTES
    assert len(encode(NewsBeaconMessage(1, 2, 7, (0, 0), (3, 3), 4, 5))) == 41
    with pytest.raises(ValueError, match="news entries"):
        encode(NewsBeaconMessage(1, 2, 7, (0, 0), (3, 3), 4, 5, news=(*entries, (99, (1, 1), 7))))


def test_an_odd_cell_a_negative_robot_or_an_asks_beyond_one_is_malformed():
    data = encode(NewsBeaconMessage(1, 2, 7, (0, 0), (3, 3), 4, 5, news=((9, (1, 1), 6),)))
    odd = data[:40] + bytes([1]) + data[41:49]  # one cell, not a pair
    negative = data[:41] + struct.pack("!ii", -9, 6) + data[49:]
    asks_two = data[:39] + bytes([2]) + data[40:]
    for garbage in (odd, negative, asks_two):
        with pytest.raises(DecodeError) as caught:
            decode(garbage)
        assert caught.value.reason == "malformed"
