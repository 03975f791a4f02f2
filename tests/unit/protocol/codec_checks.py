"""Checks of the codec tests: round trips, mutations of valid encodings, and that what decodes is exact or refused."""

from hypothesis import strategies as st

from mrmp.protocol.codec import MAX_MESSAGE_BYTES, PROTOCOL_VERSION, DecodeError, decode, encode
from mrmp.protocol.messages import Message

DECODE_REASONS = ("oversized", "truncated", "version", "type", "malformed")
"""The reasons a :class:`~mrmp.protocol.codec.DecodeError` may give."""


def assert_round_trip(message: Message) -> None:
    """``message`` encodes within :data:`MAX_MESSAGE_BYTES`, with the protocol version first, and decodes back to itself."""
    data = encode(message)
    assert data[0] == PROTOCOL_VERSION
    assert len(data) <= MAX_MESSAGE_BYTES
    assert decode(data) == message


def mutated(encoded: bytes, data: st.DataObject, most_extra: int) -> bytes:
    """``encoded`` with one byte flipped, cut short, or extended by 1 to ``most_extra`` bytes, as ``data`` draws."""
    mutation = bytearray(encoded)
    how = data.draw(st.sampled_from(["flip", "cut", "extend"]))
    if how == "flip":
        position = data.draw(st.integers(0, len(mutation) - 1))
        mutation[position] ^= data.draw(st.integers(1, 255))
    elif how == "cut":
        mutation = mutation[: data.draw(st.integers(0, len(mutation) - 1))]
    else:
        mutation += data.draw(st.binary(min_size=1, max_size=most_extra))
    return bytes(mutation)


def assert_exact_or_refused(data: bytes) -> None:
    """``data`` decodes to a message that encodes back to exactly ``data``, or raises a typed :class:`DecodeError`."""
    try:
        message = decode(data)
    except DecodeError as error:
        assert error.reason in DECODE_REASONS
    else:
        assert encode(message) == data  # anything accepted is exactly a valid encoding
