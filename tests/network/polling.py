"""Receiving from a transport in tests: bounded polling, never a blind sleep.

Bounds are generous (:data:`PATIENCE`): a test waits for progress, and only a
transport that never delivers makes it wait that long.
"""

import threading
import time
from collections import Counter

PATIENCE = 30.0
"""Seconds a test waits at most for something that should happen (it goes on as soon as it does)."""

QUIET = 0.3
"""Seconds a test listens for datagrams that should not come, once the expected ones have."""


def receive_within(transport, timeout=PATIENCE, poll=0.05):
    """The next datagram, polling in short steps for at most ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        data = transport.receive(poll)
        if data is not None:
            return data
    return None


def drain(transport, duration):
    """Every datagram arriving during ``duration`` seconds."""
    received = []
    deadline = time.monotonic() + duration
    while (remaining := deadline - time.monotonic()) > 0:
        data = transport.receive(min(remaining, 0.05))
        if data is not None:
            received.append(data)
    return received


def receive_until(transport, wanted, patience=PATIENCE):
    """Whether ``wanted`` arrives within ``patience`` seconds (what comes before it is dropped)."""
    deadline = time.monotonic() + patience
    while time.monotonic() < deadline:
        if transport.receive(0.05) == wanted:
            return True
    return False


def receive_expected(transport, expected, patience=PATIENCE, quiet=QUIET):
    """Every datagram received until all of ``expected`` (a multiset) came, then during ``quiet`` seconds more.

    Returns a :class:`~collections.Counter` of what came, to compare with ``Counter(expected)``.
    """
    wanted = Counter(expected)
    received = Counter()
    deadline = time.monotonic() + patience
    while not wanted <= received and time.monotonic() < deadline:
        data = transport.receive(0.05)
        if data is not None:
            received[data] += 1
    received.update(drain(transport, quiet))
    return received


def receive_while_closing(transport, timeout, close_after=0.1, patience=PATIENCE):
    """Block in ``receive(timeout)`` in a thread, close the transport meanwhile; return (data, seconds, thread)."""
    outcome = {}
    entered = threading.Event()

    def receive():
        entered.set()
        started = time.monotonic()
        outcome["data"] = transport.receive(timeout)
        outcome["took"] = time.monotonic() - started

    thread = threading.Thread(target=receive)
    thread.start()
    entered.wait(patience)
    time.sleep(close_after)
    transport.close()
    thread.join(timeout=patience)
    return outcome.get("data"), outcome.get("took"), thread
