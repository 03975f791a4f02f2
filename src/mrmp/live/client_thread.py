"""The thesis's client thread: a live robot's datagrams are sent by a thread of their own, fed by a queue.

Thesis, section 3.5: every robot runs a server, a thread that receives
continuously, and a client, a thread that "becomes active when the robot
updates its coordinate value and send[s] this information to the other robot
instantly". A live driver (:class:`~mrmp.live.driver.LiveDriver`) has its
receiving thread; :class:`ClientThread` is its client: the main loop seals each
message and puts the datagram on a queue, and the client thread alone calls
the transport's ``send``, in queue order. The main loop, where the sans-IO brain
runs, never waits on a socket; a transport that blocks (a full socket buffer, a
Zenoh session that is slow to accept a put) delays only the client thread.

Closing the client sends what is still queued, then ends the thread. A
transport that raises stops the client, and the error is raised again in the
main loop at its next :meth:`ClientThread.send` or at :meth:`ClientThread.close`,
so a broken transport still ends the run as it did when the main loop sent.

Examples
--------
>>> class Recording:
...     def __init__(self):
...         self.sent = []
...     def send(self, data, recipient=None):
...         self.sent.append((data, recipient))
>>> transport = Recording()
>>> client = ClientThread(transport, name="robot-0-client")
>>> client.start()
>>> client.send(b"present", None); client.send(b"claim", 2)
>>> client.close()
>>> transport.sent
[(b'present', None), (b'claim', 2)]
"""

from __future__ import annotations

import functools
import queue
import threading
from collections.abc import Callable, Sequence
from typing import Protocol

from mrmp.live.multicast_wire import Addressed
from mrmp.live.transport import SeveralAtOnce


class Sending(Protocol):
    """The part of a :class:`~mrmp.live.transport.Transport` the client thread uses."""

    def send(self, data: bytes, recipient: int | None = None) -> None:
        """Send ``data`` to one peer, or to every peer when ``recipient`` is None."""
        ...


class ClientThread:
    """Sends the datagrams queued by :meth:`send` from a thread of its own, in order.

    Parameters
    ----------
    transport:
        Where the datagrams go (its ``send`` is only ever called from the client thread).
    name:
        The thread's name.
    """

    def __init__(self, transport: Sending, name: str) -> None:
        self.transport = transport
        self._several = transport if isinstance(transport, SeveralAtOnce) else None
        self._queue: queue.SimpleQueue[Callable[[], None] | None] = queue.SimpleQueue()
        """The sendings queued, in order; None ends the thread."""
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._failure: Exception | None = None
        self._closed = False

    @property
    def name(self) -> str:
        """The thread's name."""
        return self._thread.name

    @property
    def reaches_several(self) -> bool:
        """Whether one datagram reaches several peers (:meth:`send_together`): the transport's can."""
        return self._several is not None

    def start(self) -> None:
        """Start the client thread; datagrams queued before are sent first."""
        self._thread.start()

    def send(self, data: bytes, recipient: int | None) -> None:
        """Queue ``data`` for ``recipient`` (every peer when None) and return at once.

        Raises
        ------
        Exception
            The error the transport raised in the client thread, if it did.
        RuntimeError
            If the client is closed.
        """
        self._queue_sending(functools.partial(self.transport.send, data, recipient))

    def send_together(self, messages: Sequence[Addressed]) -> None:
        """Queue ``messages``, each for the peers it names, to go together (only when :attr:`reaches_several`)."""
        if self._several is None:
            raise TypeError(f"{self.name}'s transport does not reach several peers with one datagram")
        self._queue_sending(functools.partial(self._several.send_together, list(messages)))

    def _queue_sending(self, sending: Callable[[], None]) -> None:
        self._raise_failure()
        if self._closed:
            raise RuntimeError(f"{self.name} is closed")
        self._queue.put(sending)

    def close(self, timeout: float = 2.0) -> None:
        """Send what is queued, end the thread (waiting at most ``timeout`` seconds), and raise its error if any."""
        if not self._closed:
            self._closed = True
            self._queue.put(None)  # the end: after everything queued before it
            if self._thread.is_alive():
                self._thread.join(timeout)
        self._raise_failure()

    def _raise_failure(self) -> None:
        failure, self._failure = self._failure, None
        if failure is not None:
            raise failure

    def _run(self) -> None:
        while True:
            sending = self._queue.get()
            if sending is None:
                return
            try:
                sending()
            except Exception as error:  # handed to the main loop, which ends the run with it
                self._failure = error
                return
