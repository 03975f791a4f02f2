"""Several live robots in one thread: each with its own socket, driver, brain and body, on the real clock.

:func:`run_hosted` runs the main loops of the drivers it is given as their
robot processes would (:meth:`~mrmp.live.driver.LiveDriver.main_turn`, and each driver's own
:meth:`~mrmp.live.driver.LiveDriver.wake_rule` for when its next turn comes),
interleaved in one thread: a driver's turn runs when its wake time comes or,
when its rule says a message wakes it, as soon as a datagram reaches its
socket. One selector watches every robot's socket; a datagram is handed to
the driver whose socket it reached (:meth:`~mrmp.live.driver.LiveDriver.take_datagram`),
and what a turn sends leaves at once through that robot's own transport. So a
robot costs no receiving or client thread of its own, and no robot reads
another's state: they share the thread and the clock, as robots share the
air. It is what the virtual clock does (:mod:`mrmp.live.virtual_time`), with
the real clock and real sockets instead of a simulated network.

A stop request to any driver (a signal, the launcher's end) is seen within
:data:`STOP_LATENCY` seconds. A driver that fails is stopped, its report
saying why; the others run on, and the first failure is raised when they are done.
"""

from __future__ import annotations

import math
import selectors
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

from mrmp.live.driver import AgentReport, LiveDriver
from mrmp.live.multicast_wire import Addressed
from mrmp.live.transport import SeveralAtOnce, Transport

__all__ = ["STOP_LATENCY", "Hosted", "Selectable", "run_hosted"]

STOP_LATENCY = 0.1
"""Seconds the loop waits on the sockets at most, so that a stop request is seen that soon."""


@runtime_checkable
class Selectable(Protocol):
    """A transport whose datagrams arrive on one socket that a selector can watch."""

    def fileno(self) -> int:
        """The socket's file descriptor."""
        ...


@dataclass
class Hosted:
    """One robot of :func:`run_hosted`: its driver, its transport as opened (the socket to watch), and what to call
    with its report now and then (its progress, written to disk by a robot process)."""

    driver: LiveDriver
    socket: Selectable
    on_progress: Callable[[AgentReport], None] | None = None
    done: bool = False
    wake_at: float = 0.0
    woken_by_messages: bool = True
    failure: Exception | None = field(default=None, repr=False)


class _Direct:
    """A driver's sending straight through its transport, from the loop's thread (:class:`~mrmp.live.driver.Sending`)."""

    def __init__(self, transport: Transport) -> None:
        self.transport = transport
        self._several = transport if isinstance(transport, SeveralAtOnce) else None

    @property
    def reaches_several(self) -> bool:
        return self._several is not None

    def start(self) -> None:
        """Nothing to start: each send goes out at once."""

    def send(self, data: bytes, recipient: int | None) -> None:
        self.transport.send(data, recipient)

    def send_together(self, messages: Sequence[Addressed]) -> None:
        if self._several is None:
            raise TypeError(f"{type(self.transport).__name__} does not reach several peers with one datagram")
        self._several.send_together(messages)

    def close(self) -> None:
        """Nothing queued."""


def run_hosted(robots: Sequence[Hosted], clock: Callable[[], float] = time.monotonic) -> None:
    """Run every robot of ``robots`` until each is done, stopped or failed (module docstring).

    Raises
    ------
    Exception
        The first failure of a driver, once every other robot is done.
    """
    selector = selectors.DefaultSelector()
    try:
        start = clock()
        for robot in robots:
            robot.driver.send_through(_Direct(robot.driver.transport))
            robot.driver.begin_fleet_wait(start)
            robot.wake_at = start
            selector.register(robot.socket.fileno(), selectors.EVENT_READ, robot)
        while not all(robot.done for robot in robots):
            for robot in robots:
                if not robot.done and (robot.wake_at <= clock() or robot.driver.stop_requested.is_set()):
                    _turn(robot, clock())
                    if robot.done:  # its process would have ended: what reaches its socket from now on is lost
                        selector.unregister(robot.socket.fileno())
            waiting = [robot.wake_at for robot in robots if not robot.done]
            timeout = min(STOP_LATENCY, max(0.0, min(waiting, default=math.inf) - clock()))
            for key, _ in selector.select(timeout):
                _take_datagrams(key.data, clock())
    finally:
        selector.close()
    for robot in robots:
        if robot.failure is not None:
            raise robot.failure


def _turn(robot: Hosted, now: float) -> None:
    """One turn of the robot's main loop: its wait for the fleet, or its run; when its next turn comes."""
    driver = robot.driver
    try:
        if driver.stop_requested.is_set():
            driver.report.stop_reason = "interrupted"
            wake = None
        else:
            wake = driver.main_turn(now, robot.on_progress)
    except Exception as error:  # the robot stops, saying why; the others run on
        driver.report.stop_reason = f"crashed: {type(error).__name__}: {error}"
        robot.failure, wake = error, None
    if wake is None:
        robot.done = True
        driver.fill_report(now)
        return
    robot.wake_at, robot.woken_by_messages = driver.wake_rule(now, wake, timers=driver.running)


def _take_datagrams(robot: Hosted, now: float) -> None:
    """Hand the robot every datagram waiting on its socket; its turn comes now if its rule says a message wakes it."""
    transport = robot.driver.transport
    while (data := transport.receive(0.0)) is not None:
        robot.driver.take_datagram(data)
        if robot.woken_by_messages:
            robot.wake_at = min(robot.wake_at, now)
