"""Authenticated envelopes: every rejection reason, and the replay window."""

import pytest

from mrmp.protocol.auth import MAX_DATAGRAM_BYTES, REPLAY_WINDOW, Opener, Sealer
from mrmp.protocol.messages import StateMessage

KEY = b"fleet-key-of-32-bytes-0123456789"


def message(seq, sender=0):
    return StateMessage(sender, seq, (0, 0), (1, 0))


def test_round_trip_and_counts():
    sealer, opener = Sealer(KEY, 9), Opener(KEY, 9, fleet_size=2)
    assert opener.open(sealer.seal(message(1))) == message(1)
    assert opener.accepted == 1 and not opener.rejected


@pytest.mark.parametrize(
    ("mangle", "reason"),
    [
        (lambda data: data[:10], "truncated"),
        (lambda data: data + bytes(MAX_DATAGRAM_BYTES), "oversized"),
        (lambda data: b"XX" + data[2:], "magic"),
        (lambda data: data[:-1] + bytes([data[-1] ^ 1]), "forged"),
        (lambda data: data[:12] + bytes([data[12] ^ 1]) + data[13:], "forged"),  # a flipped bit in the message
    ],
)
def test_tampering_is_rejected_by_reason(mangle, reason):
    opener = Opener(KEY, 9)
    assert opener.open(mangle(Sealer(KEY, 9).seal(message(1)))) is None
    assert opener.rejected == {reason: 1}


def test_other_session_other_key_and_unknown_sender():
    opener = Opener(KEY, 9, fleet_size=2)
    assert opener.open(Sealer(KEY, 8).seal(message(1))) is None
    assert opener.open(Sealer(b"another-key-0123456789abcdefghij", 9).seal(message(1))) is None
    assert opener.open(Sealer(KEY, 9).seal(message(1, sender=5))) is None
    assert opener.rejected == {"session": 1, "forged": 1, "malformed": 1}


def test_keyless_envelopes_only_match_keyless_openers():
    assert Opener(b"", 1).open(Sealer(b"", 1).seal(message(1))) is not None
    assert Opener(KEY, 1).open(Sealer(b"", 1).seal(message(1))) is None


def test_replay_window_accepts_reordering_and_rejects_replays_and_stale():
    sealer, opener = Sealer(KEY, 1), Opener(KEY, 1)
    datagrams = {seq: sealer.seal(message(seq)) for seq in (1, 2, 3, REPLAY_WINDOW + 5)}
    assert opener.open(datagrams[2]) is not None
    assert opener.open(datagrams[1]) is not None  # late but new: accepted
    assert opener.open(datagrams[2]) is None  # seen: replayed
    assert opener.open(datagrams[REPLAY_WINDOW + 5]) is not None
    assert opener.open(datagrams[3]) is None  # older than the window: stale
    assert opener.rejected == {"replayed": 1, "stale": 1}


def test_window_memory_stays_bounded():
    sealer, opener = Sealer(KEY, 1), Opener(KEY, 1)
    for seq in range(1, 10 * REPLAY_WINDOW):
        opener.open(sealer.seal(message(seq)))
    assert len(opener._windows[0].seen) <= 2 * REPLAY_WINDOW + 1
