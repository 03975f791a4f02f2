"""Receiving from a transport in tests: bounded polling, never a blind sleep."""

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
