"""What every robot brain does with messages alike: numbering what it sends, answering claims, decoding.

What every brain sends is a list of :class:`Outgoing`: a message, and to
whom (named robots, every robot within a radio radius of the sender, both, or
every peer). The driver interprets the address: the simulators deliver a radius
broadcast to the robots whose bodies stand within the radius
(:mod:`mrmp.sim.spatial`), a live driver to the peers it believes there.
Every brain takes in what it receives through a :class:`Handlers` table, from
message type to the method that takes messages of that type in. Every message a robot
sends carries the next number of the robot's sequence (``seq``), so that
receivers can tell newer states from older ones; its state message carries the
safety layer's part (:meth:`~mrmp.protocol.safety.SafetyLayer.state_fields`).
A peer's claim of a cell is answered by the safety layer, which yields to the
claimant when it outranks this robot (:func:`~mrmp.policies.priority.outranks`).
A datagram that does not decode is dropped and counted by the reason the codec
gives (:class:`~mrmp.protocol.codec.DecodeError`).

Examples
--------
>>> from collections import Counter
>>> class Silent(MessageEndpoint):
...     def __init__(self):
...         self.index, self.seq, self.dropped = 0, 0, Counter()
...     def receive(self, message, now):
...         return []
>>> robot = Silent()
>>> robot.receive_datagram(b"", now=0.0), dict(robot.dropped)
([], {'truncated': 1})
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable
from typing import Any, NamedTuple, TypeVar

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.policies.priority import outranks
from mrmp.protocol.codec import DecodeError, decode
from mrmp.protocol.messages import ClaimMessage, Message, ReleaseMessage, StateMessage
from mrmp.protocol.safety import SafetyLayer

M = TypeVar("M", bound=Message)
F = TypeVar("F", bound=Callable[..., Any])


class Outgoing(NamedTuple):
    """A message to send: to the robots named in ``recipients`` and to every robot within ``radius`` cells.

    ``radius`` is Manhattan, around the sender's cell; with both None the
    message goes to every peer (fleet-wide).

    >>> Outgoing(ClaimMessage(0, 1, 1, (0, 1)), (2,)).recipients
    (2,)
    >>> Outgoing(ClaimMessage(0, 1, 1, (0, 1)), (2,), 3).fleet_wide, Outgoing(ClaimMessage(0, 1, 1, (0, 1))).fleet_wide
    (False, True)
    """

    message: Message
    recipients: tuple[int, ...] | None = None
    radius: int | None = None

    @property
    def fleet_wide(self) -> bool:
        """Whether the message goes to every peer (neither named recipients nor a radius)."""
        return self.recipients is None and self.radius is None


class Handlers:
    """A brain's table from message type to the method that takes messages of that type in.

    >>> class Echo:
    ...     handlers = Handlers()
    ...     @handlers.on(ClaimMessage)
    ...     def _take_claim(self, message, now):
    ...         return [Outgoing(message, (message.sender,))]
    >>> handler = Echo.handlers.get(ClaimMessage(3, 1, 1, (0, 1)))
    >>> [sent.recipients for sent in handler(Echo(), ClaimMessage(3, 1, 1, (0, 1)), 0.0)]
    [(3,)]
    >>> Echo.handlers.get(StateMessage(3, 1, (0, 0), (0, 0))) is None
    True
    """

    __slots__ = ("_table",)

    def __init__(self) -> None:
        self._table: dict[type, Callable[..., Any]] = {}

    def on(self, *kinds: type[Message]) -> Callable[[F], F]:
        """Decorate the method that takes in messages of the types ``kinds``."""

        def register(method: F) -> F:
            for kind in kinds:
                self._table[kind] = method
            return method

        return register

    def get(self, message: Message) -> Callable[..., Any] | None:
        """The method (unbound) that takes in ``message``, or None when the brain has none for its type."""
        return self._table.get(type(message))

    def table(self) -> dict[type, Callable[..., Any]]:
        """The table itself, from message type to method (unbound), for a brain that looks types up on every message.

        >>> class Echo:
        ...     handlers = Handlers()
        ...     @handlers.on(ClaimMessage)
        ...     def _take_claim(self, message, now):
        ...         return []
        >>> [kind.__name__ for kind in Echo.handlers.table()]
        ['ClaimMessage']
        """
        return self._table

    def copy(self) -> Handlers:
        """A copy of the table, for a subclass whose brain takes some types of message in its own way.

        >>> class Echo:
        ...     handlers = Handlers()
        ...     @handlers.on(ClaimMessage)
        ...     def _take_claim(self, message, now):
        ...         return [Outgoing(message, (message.sender,))]
        >>> class Quiet(Echo):
        ...     handlers = Echo.handlers.copy()
        ...     @handlers.on(ClaimMessage)
        ...     def _ignore_claim(self, message, now):
        ...         return []
        >>> claim = ClaimMessage(3, 1, 1, (0, 1))
        >>> len(Quiet.handlers.get(claim)(Quiet(), claim, 0.0)), len(Echo.handlers.get(claim)(Echo(), claim, 0.0))
        (0, 1)
        """
        copied = Handlers()
        copied._table.update(self._table)
        return copied


class MessageEndpoint:
    """Numbering, state messages and datagram decoding of a robot brain (see the module docstring).

    A subclass sets ``index``, ``seq`` (0 at first), ``dropped`` and, for
    state messages, ``safety``, and takes in decoded messages in :meth:`receive`.
    """

    index: int
    seq: int
    dropped: Counter[str]
    safety: SafetyLayer

    def next_seq(self) -> int:
        """This robot's next sequence number (every message it sends has a fresh one: the receivers' replay window)."""
        self.seq += 1
        return self.seq

    def _stamp(self, message: M) -> M:
        """``message`` with this robot's next sequence number."""
        return message.with_seq(self.next_seq())

    def _stamped(self, sends: Iterable[tuple[Message, tuple[int, ...]]]) -> list[Outgoing]:
        """The safety layer's ``(message, recipients)`` pairs, each message with this robot's next sequence number."""
        return [Outgoing(self._stamp(message), recipients) for message, recipients in sends]

    def _state(self, present: Cell, next: Cell, heading: Heading, arrived: bool, progress: int = 0) -> StateMessage:
        """A fresh state message with the next sequence number and the safety layer's state."""
        self.seq += 1
        return StateMessage(
            self.index,
            self.seq,
            present,
            next,
            heading,
            arrived,
            progress=progress,
            **self.safety.state_fields(),  # type: ignore[arg-type]
        )

    def _answer_claim(self, message: ClaimMessage, claimant_present: Cell, present: Cell) -> list[Outgoing]:
        """The safety layer's reply to a peer's claim, for the claimant alone (none to a stale claim, counted).

        ``claimant_present`` is where the claimant is believed to stand, ``present`` where this robot stands.
        """
        claimant_outranks = outranks(claimant_present, message.sender, present, self.index)
        reply = self.safety.handle_claim(message, claimant_outranks)
        if reply is None:
            self.dropped["stale_claim"] += 1
            return []
        return [Outgoing(self._stamp(reply), (message.sender,))]

    def _answer_release(self, message: ReleaseMessage) -> list[Outgoing]:
        """The safety layer's acknowledgement of a peer's release, for that peer alone."""
        return [Outgoing(self._stamp(self.safety.handle_release(message)), (message.sender,))]

    def receive(self, message: Message, now: float) -> list[Outgoing]:
        """Take in one decoded message; return the answers to send."""
        raise NotImplementedError

    def receive_datagram(self, data: bytes, now: float) -> list[Outgoing]:
        """Decode and take in a datagram; malformed data is dropped and counted by reason."""
        try:
            message = decode(data)
        except DecodeError as error:
            self.dropped[error.reason] += 1
            return []
        return self.receive(message, now)
