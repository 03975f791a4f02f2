"""Several robots' main loops in one thread (``mrmp.live.host_loop``): turns on time, datagrams through each one's
own socket, a failing robot stopped alone."""

from __future__ import annotations

import contextlib
import socket
import threading

import pytest

from mrmp.live.driver import AgentReport
from mrmp.live.host_loop import Hosted, run_hosted


class Datagrams:
    """A robot's own socket, one end of a datagram socket pair: what it sends arrives at the other end, the peer's."""

    def __init__(self, own: socket.socket) -> None:
        self.own = own
        own.setblocking(False)

    def fileno(self) -> int:
        return self.own.fileno()

    def receive(self, timeout: float) -> bytes | None:
        try:
            return self.own.recv(2048)
        except BlockingIOError:
            return None

    def send(self, data: bytes, recipient: int | None = None) -> None:
        with contextlib.suppress(BlockingIOError):  # the peer's buffer is full (it stopped reading): lost, as over UDP
            self.own.send(data)


class CountingDriver:
    """A driver that waits for the fleet for one turn, then sends ``turns`` datagrams, one a turn, 0.01 s apart,
    and ends once it has also taken ``expect`` datagrams; it fails at turn ``fail_at`` if given."""

    def __init__(self, transport: Datagrams, turns: int, expect: int, fail_at: int | None = None) -> None:
        self.transport = transport
        self.turns, self.expect, self.fail_at = turns, expect, fail_at
        self.sent = self.taken = self.turned = 0
        self.stop_requested = threading.Event()
        self.running = False
        self.report = AgentReport(robot="r", index=0, start=(0, 0), goal=(0, 0))
        self.client = None

    def send_through(self, client) -> None:
        self.client = client

    def begin_fleet_wait(self, now: float) -> None:
        pass

    def main_turn(self, now: float, on_progress=None) -> float | None:
        if not self.running:  # its fleet is there at once
            self.running = True
            self.report.started_at = now
        return self.turn(now)

    def turn(self, now: float) -> float | None:
        self.turned += 1
        if self.turned == self.fail_at:
            raise RuntimeError("a broken brain")
        if self.sent < self.turns:
            self.client.send(b"x", 1)
            self.sent += 1
        if self.sent == self.turns and self.taken >= self.expect:
            self.report.stop_reason = "all arrived"
            return None
        return now + (0.01 if self.sent < self.turns else 5.0)  # then only a datagram wakes it

    def wake_rule(self, now: float, until: float, timers: bool = True) -> tuple[float, bool]:
        return until, True

    def take_datagram(self, data: bytes) -> None:
        self.taken += 1

    def fill_report(self, now: float) -> None:
        self.report.ended_at = now


def pair(turns=(5, 5), fail_at=(None, None)):
    first, second = socket.socketpair(socket.AF_UNIX, socket.SOCK_DGRAM)
    a = CountingDriver(Datagrams(first), turns[0], turns[1], fail_at[0])
    b = CountingDriver(Datagrams(second), turns[1], turns[0], fail_at[1])
    return a, b


def test_two_robots_in_one_thread_exchange_datagrams_through_their_own_sockets_and_end():
    a, b = pair(turns=(5, 3))
    run_hosted([Hosted(a, a.transport), Hosted(b, b.transport)])
    assert (a.sent, a.taken, b.sent, b.taken) == (5, 3, 3, 5)
    assert a.report.stop_reason == b.report.stop_reason == "all arrived"


def test_a_robot_that_fails_stops_alone_and_its_failure_is_raised_once_the_others_are_done():
    a, b = pair(turns=(3, 3), fail_at=(2, None))
    b.expect = 1  # a sends one datagram before it fails
    with pytest.raises(RuntimeError, match="a broken brain"):
        run_hosted([Hosted(a, a.transport), Hosted(b, b.transport)])
    assert a.report.stop_reason == "crashed: RuntimeError: a broken brain"
    assert b.report.stop_reason == "all arrived" and b.sent == 3


def test_a_stop_request_ends_the_robot_it_reaches_before_or_during_its_run():
    a, b = pair(turns=(1000, 1000))
    a.stop_requested.set()  # before its first turn
    threading.Timer(0.1, b.stop_requested.set).start()  # during its run: alone, it sends every 0.01 s for 10 s
    run_hosted([Hosted(a, a.transport), Hosted(b, b.transport)])
    assert a.report.stop_reason == b.report.stop_reason == "interrupted"
    assert a.sent == 0 and 0 < b.sent < 1000
