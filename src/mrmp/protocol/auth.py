"""Authenticated envelopes: a fleet key, a session, a MAC, and a replay window.

A stranger on the network must not be able to impersonate a robot or make one
move. Every datagram a robot sends is sealed::

    offset  size  field
    0       2     magic b"MR"
    2       4     session (unsigned): the run this datagram belongs to
    6       n     the message, as :mod:`mrmp.protocol.codec` encodes it
    6 + n   16    HMAC-SHA256(fleet key, bytes 0 .. 6 + n), first 16 bytes

(HMAC: Bellare, Canetti & Krawczyk, CRYPTO 1996; RFC 2104. Truncation to 128
bits follows RFC 2104 section 5.) The receiving :class:`Opener` checks, in
order: size, magic, MAC (constant-time comparison), session, message format, and
finally the sender's sequence number against a sliding window (as IPsec's
anti-replay window, RFC 4303 section 3.4.3): a sequence number seen before is a
replay, one older than the window is stale. Every rejected datagram is counted
by reason, never raised.

Without a key the MAC is computed with an empty key: it still catches corruption
but authenticates nothing, so keyless fleets are only allowed on loopback (the
live layer enforces it and says so loudly).

Examples
--------
>>> from mrmp.protocol.messages import StateMessage
>>> sealer, opener = Sealer(b"k" * 32, session=7), Opener(b"k" * 32, session=7)
>>> data = sealer.seal(StateMessage(1, 1, (0, 0), (1, 0)))
>>> opener.open(data).present
(0, 0)
>>> opener.open(data) is None, dict(opener.rejected)   # the same datagram again is a replay
(True, {'replayed': 1})
>>> Opener(b"x" * 32, session=7).open(data) is None    # another key: forged
True
"""

from __future__ import annotations

import hmac
import struct
from collections import Counter

from mrmp.protocol.codec import MAX_MESSAGE_BYTES, DecodeError, decode, encode
from mrmp.protocol.messages import Message

MAGIC = b"MR"
TAG_BYTES = 16
_PREFIX = struct.Struct("!2sI")
OVERHEAD = _PREFIX.size + TAG_BYTES
"""Bytes an envelope adds to a message."""
MAX_DATAGRAM_BYTES = MAX_MESSAGE_BYTES + OVERHEAD
"""The largest datagram a robot accepts."""
REPLAY_WINDOW = 1024
"""How far behind a sender's newest sequence number a datagram may still be accepted."""

REJECT_REASONS = (
    "oversized",
    "truncated",
    "magic",
    "forged",
    "session",
    "version",
    "type",
    "malformed",
    "replayed",
    "stale",
)
"""Why an :class:`Opener` drops a datagram."""


def _tag(key: bytes, body: bytes) -> bytes:
    return hmac.digest(key, body, "sha256")[:TAG_BYTES]  # the one-shot HMAC: OpenSSL's, no Python object per tag


class Sealer:
    """Seals messages for one session with the fleet key (``b""`` when the fleet has none)."""

    def __init__(self, key: bytes, session: int) -> None:
        self.key = key
        self.session = session

    def seal(self, message: Message) -> bytes:
        """Encode ``message`` and wrap it in an authenticated envelope."""
        body = _PREFIX.pack(MAGIC, self.session) + encode(message)
        return body + _tag(self.key, body)


class _Window:
    """Which sequence numbers of one sender have been accepted, within the window."""

    __slots__ = ("newest", "seen")

    def __init__(self) -> None:
        self.newest = 0
        self.seen: set[int] = set()

    def accept(self, seq: int) -> str | None:
        if seq + REPLAY_WINDOW <= self.newest:
            return "stale"
        if seq in self.seen:
            return "replayed"
        self.seen.add(seq)
        if seq > self.newest:
            self.newest = seq
            if len(self.seen) > 2 * REPLAY_WINDOW:
                floor = self.newest - REPLAY_WINDOW
                self.seen = {number for number in self.seen if number > floor}
        return None


class Opener:
    """Checks and opens envelopes for one session; counts every rejection by reason.

    Parameters
    ----------
    key:
        The fleet key (``b""`` when the fleet has none).
    session:
        The session of this run; datagrams of other sessions are rejected.
    fleet_size:
        When given, senders outside ``0 .. fleet_size - 1`` are rejected as malformed.
    """

    def __init__(self, key: bytes, session: int, fleet_size: int | None = None) -> None:
        self.key = key
        self.session = session
        self.fleet_size = fleet_size
        self.rejected: Counter[str] = Counter()
        self.accepted = 0
        self._windows: dict[int, _Window] = {}

    def open(self, data: bytes) -> Message | None:
        """The message inside ``data``, or None (and one more count in :attr:`rejected`)."""
        size = len(data)
        if size > MAX_DATAGRAM_BYTES:
            return self._reject("oversized")
        if size < OVERHEAD:
            return self._reject("truncated")
        body, tag = data[:-TAG_BYTES], data[-TAG_BYTES:]
        magic, session = _PREFIX.unpack_from(body)
        if magic != MAGIC:
            return self._reject("magic")
        if not hmac.compare_digest(tag, _tag(self.key, body)):
            return self._reject("forged")
        if session != self.session:
            return self._reject("session")
        try:
            message = decode(body[_PREFIX.size :])
        except DecodeError as error:
            return self._reject(error.reason)
        if self.fleet_size is not None and message.sender >= self.fleet_size:
            return self._reject("malformed")
        window = self._windows.setdefault(message.sender, _Window())
        verdict = window.accept(message.seq)
        if verdict is not None:
            return self._reject(verdict)
        self.accepted += 1
        return message

    def _reject(self, reason: str) -> Message | None:
        """Count a datagram rejected for ``reason``; :meth:`open` answers it with what this returns, None."""
        self.rejected[reason] += 1
        return None
