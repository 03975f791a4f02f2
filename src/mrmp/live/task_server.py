"""The task desk on the network: a thread of the launcher that answers the robots' task reports over UDP.

:class:`TaskServer` runs a :class:`~mrmp.live.task_desk.TaskDesk` behind a
transport of its own (the desk's address, every robot's address; the run's
fault injector on top, so that the desk's datagrams are lost, late or doubled
as the robots' are), sealed and opened with the fleet's key. It answers every
report, and tells a robot a task it gave it until the robot names it
(:meth:`~mrmp.live.task_desk.TaskDesk.due`). A datagram that is not a sealed
task report is dropped and counted. What the desk knows is
written to ``tasks.json`` as it changes (at most every :data:`WRITE_EVERY_S`)
and when the server stops, so that a run killed midway keeps its tasks.

It is the one central part of a live lifelong run, as the world's task
manager is in the League of Robot Runners: it gives robots errands and
nothing else (:mod:`mrmp.live.task_desk`).
"""

from __future__ import annotations

import threading
import time
from collections import Counter
from pathlib import Path

from mrmp.io.live_files import write_json
from mrmp.live.task_desk import TaskDesk
from mrmp.live.transport import Transport
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.tasks import TaskReportMessage

__all__ = ["WRITE_EVERY_S", "TaskServer"]

WRITE_EVERY_S = 0.25
"""Least seconds between two writes of ``tasks.json`` while the run goes on."""
POLL_S = 0.05
"""Most seconds the server waits for a datagram before it looks at its timers and its running flag again."""


class TaskServer:
    """Serves ``desk`` through ``transport`` in a thread (module docstring); ``path``: its ``tasks.json``.

    >>> import tempfile
    >>> from mrmp.core.grid import Grid
    >>> from mrmp.core.tasks import TaskStream
    >>> from mrmp.live.transport import UdpTransport
    >>> robot = UdpTransport(("127.0.0.1", 0), {})
    >>> server_transport = UdpTransport(("127.0.0.1", 0), {0: robot.address})
    >>> robot.peers[1] = server_transport.address
    >>> desk = TaskDesk(TaskStream(errands=(((0, 3),),), reveal=1), Grid(1, 4), [(0, 0)], steps=10)
    >>> path = Path(tempfile.mkdtemp()) / "tasks.json"
    >>> server = TaskServer(desk, server_transport, Sealer(b"k", 1), Opener(b"k", 1, fleet_size=1), path)
    >>> server.start()
    >>> answer = Opener(b"k", 1, fleet_size=2).open(robot.receive(5.0))   # told at once
    >>> server.stop(); robot.close()
    >>> answer.task, answer.errands, path.exists()
    (0, ((0, 3),), True)
    """

    def __init__(self, desk: TaskDesk, transport: Transport, sealer: Sealer, opener: Opener, path: Path) -> None:
        self.desk = desk
        self.transport = transport
        self.sealer = sealer
        self.opener = opener
        self.path = path
        self.dropped: Counter[str] = Counter()
        self.answers = 0
        self._running = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="task-desk", daemon=True)
        self._written = -1

    def start(self) -> None:
        """Start answering (the book is on disk from now on)."""
        self._write()
        self._running.set()
        self._thread.start()

    def stop(self) -> None:
        """Stop answering, close the transport and write the book a last time."""
        self._running.clear()
        if self._thread.is_alive():
            self._thread.join(timeout=5.0)
        self.transport.close()
        self._write()

    def _serve(self) -> None:
        desk = self.desk
        written_at = time.monotonic()
        while self._running.is_set():
            now = time.monotonic()
            for robot, message in desk.due(now):
                self.transport.send(self.sealer.seal(message), robot)
            data = self.transport.receive(min(POLL_S, max(0.0, desk.next_due() - now)))
            if data is not None:
                self._answer(data)
            if desk.changes != self._written and time.monotonic() - written_at >= WRITE_EVERY_S:
                self._write()
                written_at = time.monotonic()

    def _answer(self, data: bytes) -> None:
        message = self.opener.open(data)
        if message is None:
            return  # counted by the opener, by reason
        if not isinstance(message, TaskReportMessage):
            self.dropped["not a report"] += 1
            return
        self.transport.send(self.sealer.seal(self.desk.take(message)), message.sender)
        self.answers += 1

    def _write(self) -> None:
        self._written = self.desk.changes
        dropped = {**self.opener.rejected, **self.dropped}
        write_json(self.path, {**self.desk.summary(), "answers": self.answers, "dropped": dropped})
