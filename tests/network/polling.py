"""Receiving from a transport in tests: bounded polling, never a blind sleep."""

import threading
import time


def receive_within(transport, timeout=2.0, poll=0.05):
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


def receive_while_closing(transport, timeout, close_after=0.1):
    """Block in ``receive(timeout)`` in a thread, close the transport meanwhile; return (data, seconds, thread)."""
    outcome = {}

    def receive():
        started = time.monotonic()
        outcome["data"] = transport.receive(timeout)
        outcome["took"] = time.monotonic() - started

    thread = threading.Thread(target=receive)
    thread.start()
    time.sleep(close_after)
    transport.close()
    thread.join(timeout=2.0)
    return outcome.get("data"), outcome.get("took"), thread
