"""The neighbour-lock protocol that makes a Causal-PIBT activation atomic, as a sans-IO state machine.

Causal-PIBT (K. Okumura, Y. Tamura, X. Défago, "Time-Independent Planning for
Multiple Moving Agents", AAAI 2021) assumes that each activation of a robot
runs atomically on the states of its neighbours. Over messages, a robot makes
it so by *locking* them first (``docs/protocol.md``, "Atomicity by locks"):

1. An activation (:meth:`NeighbourLocks.begin`) gets the next session number
   and takes the locks of its members, itself included, **in index order**, one
   at a time: a peer's by :class:`~mrmp.protocol.messages.LockRequestMessage`
   answered by :class:`~mrmp.protocol.messages.LockGrantMessage`, its own when
   no peer holds it. Locks taken in one global order cannot form a cycle of
   waits (ordered resource acquisition: J. W. Havender, "Avoiding deadlock in
   multitasking systems", IBM Systems Journal 7(2), 1968).
2. A robot's lock has at most one holder. A request it cannot grant waits in a
   first-come line (the robot's own activation included), served when the lock
   is given back.
3. Holding every lock, the robot runs its transition on the grants and
   :meth:`~NeighbourLocks.release` sends each locked peer a
   :class:`~mrmp.protocol.messages.LockReleaseMessage` with what it wrote into
   it, answered by :class:`~mrmp.protocol.messages.LockAckMessage`; the
   activation is over when every release is acknowledged.
4. Requests and releases are sent again every ``retry_interval`` until
   answered; an activation that got no new lock for ``lock_timeout`` is
   abandoned (released everywhere it asked, writing nothing back). Every message
   names its session, so copies get the same answer again and stale messages
   are dropped and counted (``dropped``).

Limits: a lock has no lease. A locker that crashes while holding a peer's lock
leaves that peer locked (its own activations and other lockers wait; those
time out); a peer that crashes before acknowledging a release keeps the
locker's activation releasing until the peer answers again (a restarted peer
acknowledges any release).

The machine has two parts, in the manner of h11's per-role connection states:
the robot's own activation (:class:`ActivationState`) and the robot's lock as
others see it (:class:`LockState`). Each moves only along its table
(:data:`ACTIVATION_TRANSITIONS`, :data:`LOCK_TRANSITIONS`); a move the table
does not allow raises :class:`LockProtocolError`, a fault of the caller. What
the network does (losses, copies, reordering, late messages) never raises: such
messages are dropped and counted. The machine is sans-IO: it takes messages
and the time and returns :class:`~mrmp.robot.messaging.Outgoing` messages with
sequence number 0, for the robot to number and send in the order given.

Examples
--------
Robot 0 locks itself and robot 1, which grants, and releases it:

>>> from mrmp.protocol.messages import LockGrantMessage
>>> def grant_of(index):
...     return lambda locker, session: LockGrantMessage(index, 0, locker, session, 0, (0, index), None, True, 0, index)
>>> locker, peer = NeighbourLocks(0, grant_of(0)), NeighbourLocks(1, grant_of(1))
>>> (request,) = locker.begin([1], now=0)
>>> locker.activation, locker.lock, request.recipients
(<ActivationState.ACQUIRING: 'acquiring'>, <LockState.HELD_BY_SELF: 'held by self'>, (1,))
>>> (grant,) = peer.take_request(request.message)
>>> peer.lock, peer.holder
(<LockState.HELD_BY_PEER: 'held by peer'>, (0, 1))
>>> locker.take_grant(grant.message, now=1), locker.activation
([], <ActivationState.HOLDING: 'holding'>)
>>> (release,) = locker.release({1: (0, ())}, now=1)
>>> ack, applies = peer.take_release(release.message)
>>> applies, peer.lock
(True, <LockState.FREE: 'free'>)
>>> locker.take_ack(ack.message)
>>> locker.activation, locker.lock
(<ActivationState.IDLE: 'idle'>, <LockState.FREE: 'free'>)
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from enum import Enum

from mrmp.core.cell import Cell
from mrmp.protocol.messages import LockAckMessage, LockGrantMessage, LockReleaseMessage, LockRequestMessage
from mrmp.robot.messaging import Outgoing

__all__ = [
    "ACTIVATION_TRANSITIONS",
    "LOCK_TRANSITIONS",
    "ActivationEvent",
    "ActivationState",
    "LockEvent",
    "LockProtocolError",
    "LockSession",
    "LockState",
    "NeighbourLocks",
]


class ActivationState(Enum):
    """Where this robot's own activation stands."""

    IDLE = "idle"
    """No activation under way."""
    ACQUIRING = "acquiring"
    """Taking the locks of its members, in index order."""
    HOLDING = "holding"
    """Every lock held: the transition runs."""
    RELEASING = "releasing"
    """Releases sent; waiting for their acknowledgements."""


class ActivationEvent(Enum):
    """What moves an activation from one state to another."""

    BEGIN = "begin"
    ALL_LOCKED = "take the last lock"
    RELEASE = "release with write-backs"
    ABANDON = "abandon"
    ALL_ACKNOWLEDGED = "take the last acknowledgement"


class LockState(Enum):
    """Who holds this robot's lock."""

    FREE = "free"
    HELD_BY_SELF = "held by self"
    HELD_BY_PEER = "held by peer"


class LockEvent(Enum):
    """What moves this robot's lock from one state to another."""

    TAKE_OWN = "take its own lock"
    GIVE_BACK_OWN = "give its own lock back"
    GRANT = "grant a peer"
    RELEASED = "be released by its holder"


ACTIVATION_TRANSITIONS: dict[ActivationState, dict[ActivationEvent, ActivationState]] = {
    ActivationState.IDLE: {ActivationEvent.BEGIN: ActivationState.ACQUIRING},
    ActivationState.ACQUIRING: {
        ActivationEvent.ALL_LOCKED: ActivationState.HOLDING,
        ActivationEvent.ABANDON: ActivationState.RELEASING,
    },
    ActivationState.HOLDING: {ActivationEvent.RELEASE: ActivationState.RELEASING},
    ActivationState.RELEASING: {ActivationEvent.ALL_ACKNOWLEDGED: ActivationState.IDLE},
}
"""The allowed moves of an activation: state -> event -> next state."""

LOCK_TRANSITIONS: dict[LockState, dict[LockEvent, LockState]] = {
    LockState.FREE: {LockEvent.TAKE_OWN: LockState.HELD_BY_SELF, LockEvent.GRANT: LockState.HELD_BY_PEER},
    LockState.HELD_BY_SELF: {LockEvent.GIVE_BACK_OWN: LockState.FREE},
    LockState.HELD_BY_PEER: {LockEvent.RELEASED: LockState.FREE},
}
"""The allowed moves of a robot's lock: state -> event -> next state."""


class LockProtocolError(RuntimeError):
    """A move that the transition tables do not allow (a fault of the caller, never of the network).

    >>> NeighbourLocks(4, grant=print).release({}, now=0)
    Traceback (most recent call last):
    ...
    mrmp.robot.neighbour_locks.LockProtocolError: robot 4's activation cannot release with write-backs when idle (allowed: begin)
    """


@dataclass
class LockSession:
    """One activation in progress: its members in index order, how far it got, the grants and the releases."""

    number: int
    order: tuple[int, ...]
    started_at: float
    sent_at: float = -1.0
    """When a request or the releases were last sent."""
    progress_at: float = -1.0
    """When the last grant arrived."""
    position: int = 0
    """The member whose lock is taken next."""
    grants: dict[int, LockGrantMessage] = field(default_factory=dict)
    releases: dict[int, LockReleaseMessage] = field(default_factory=dict)
    """The releases not yet acknowledged."""


class NeighbourLocks:
    """One robot's side of the neighbour-lock protocol (see the module docstring).

    Parameters
    ----------
    index:
        The robot's index in the fleet.
    grant:
        Builds this robot's grant to ``(locker, session)`` from its current state (sequence number 0).
    retry_interval:
        Requests and releases are sent again after this long (driver's time units).
    lock_timeout:
        An activation that got no new lock for this long is abandoned.
    stats, dropped:
        Counters of what happened and of the messages dropped, by reason (shared with the robot's).
    """

    def __init__(
        self,
        index: int,
        grant: Callable[[int, int], LockGrantMessage],
        retry_interval: float = 1.0,
        lock_timeout: float = 20.0,
        stats: Counter[str] | None = None,
        dropped: Counter[str] | None = None,
    ) -> None:
        self.index = index
        self._grant_message = grant
        self.retry_interval = retry_interval
        self.lock_timeout = lock_timeout
        self.stats: Counter[str] = stats if stats is not None else Counter()
        self.dropped: Counter[str] = dropped if dropped is not None else Counter()
        self.activation = ActivationState.IDLE
        self.session: LockSession | None = None
        self.sessions = 0
        """Activations begun so far (the last session number)."""
        self.lock = LockState.FREE
        self.holder: tuple[int, int] | None = None
        """``(locker, session)`` holding this robot's lock."""
        self._released: dict[int, int] = {}
        """The newest session of each locker that released (or abandoned) this robot."""
        self._waiting: dict[int, int] = {}
        """The line for this robot's lock, first come first: locker -> its newest session asking."""

    # -- moves along the tables ----------------------------------------------------------------

    def _move_activation(self, event: ActivationEvent) -> None:
        allowed = ACTIVATION_TRANSITIONS[self.activation]
        if event not in allowed:
            raise self._refusal("activation", event.value, self.activation.value, [known.value for known in allowed])
        self.activation = allowed[event]

    def _move_lock(self, event: LockEvent, holder: tuple[int, int] | None) -> None:
        allowed = LOCK_TRANSITIONS[self.lock]
        if event not in allowed:
            raise self._refusal("lock", event.value, self.lock.value, [known.value for known in allowed])
        self.lock = allowed[event]
        self.holder = holder

    def _refusal(self, part: str, event: str, state: str, allowed: list[str]) -> LockProtocolError:
        return LockProtocolError(f"robot {self.index}'s {part} cannot {event} when {state} (allowed: {', '.join(allowed)})")

    # -- this robot's activation ---------------------------------------------------------------

    @property
    def idle(self) -> bool:
        """Whether no activation of this robot is under way."""
        return self.activation is ActivationState.IDLE

    @property
    def all_locked(self) -> bool:
        """Whether the activation holds every lock: time to run the transition and :meth:`release`."""
        return self.activation is ActivationState.HOLDING

    @property
    def grants(self) -> list[LockGrantMessage]:
        """The grants of the activation, in the order they arrived (index order)."""
        return list(self.session.grants.values()) if self.session is not None else []

    def begin(self, members: Iterable[int], now: float) -> list[Outgoing]:
        """Start an activation that locks ``members`` (this robot is added); ask the first lock."""
        self._move_activation(ActivationEvent.BEGIN)
        self.sessions += 1
        self.session = LockSession(self.sessions, tuple(sorted({*members, self.index})), now)
        return self._advance(now)

    def _current(self) -> LockSession:
        session = self.session
        assert session is not None, "no activation under way"
        return session

    def _advance(self, now: float) -> list[Outgoing]:
        """Take the next lock in order: this robot's own when free, or ask the next peer."""
        session = self._current()
        while session.position < len(session.order):
            member = session.order[session.position]
            if member != self.index:
                session.sent_at = now
                return [Outgoing(LockRequestMessage(self.index, 0, session.number), (member,))]
            if self.lock is LockState.HELD_BY_PEER:
                self._waiting.setdefault(self.index, session.number)
                return []  # locked by a peer: wait in line for its release
            self._waiting.pop(self.index, None)
            self._move_lock(LockEvent.TAKE_OWN, (self.index, session.number))
            session.position += 1
        self._move_activation(ActivationEvent.ALL_LOCKED)
        return []

    def release(self, write_backs: Mapping[int, tuple[int, tuple[Cell, ...]]], now: float) -> list[Outgoing]:
        """The transition ran: give this robot's lock back, serve its line, and release every locked peer.

        ``write_backs`` maps a locked peer to the operations and visited set of its release (none: nothing written).
        """
        self._move_activation(ActivationEvent.RELEASE)
        session = self._current()
        self._move_lock(LockEvent.GIVE_BACK_OWN, None)
        sent = self.serve_line(now)  # the grant carries this robot's new state
        session.releases = {
            member: LockReleaseMessage(self.index, 0, session.number, *write_backs.get(member, (0, ())))
            for member in session.grants
        }
        return sent + self._start_releasing(session, now)

    def _abandon(self, now: float) -> list[Outgoing]:
        """Give the activation up: release every robot asked so far, writing nothing back."""
        self._move_activation(ActivationEvent.ABANDON)
        session = self._current()
        self.stats["abandoned"] += 1
        sent: list[Outgoing] = []
        self._waiting.pop(self.index, None)
        if self.holder == (self.index, session.number):
            self._move_lock(LockEvent.GIVE_BACK_OWN, None)
            sent = self.serve_line(now)
        session.releases = {
            member: LockReleaseMessage(self.index, 0, session.number)
            for member in session.order[: session.position + 1]
            if member != self.index
        }
        return sent + self._start_releasing(session, now)

    def _start_releasing(self, session: LockSession, now: float) -> list[Outgoing]:
        """Send the releases of ``session``; with none to send, the activation is over."""
        if not session.releases:
            self._end_activation()
            return []
        return self._send_releases(session, now)

    def _send_releases(self, session: LockSession, now: float) -> list[Outgoing]:
        """Send (again) every release of ``session`` not yet acknowledged."""
        session.sent_at = now
        return [Outgoing(release, (member,)) for member, release in session.releases.items()]

    def _end_activation(self) -> None:
        self._move_activation(ActivationEvent.ALL_ACKNOWLEDGED)
        self.session = None

    def expire(self, now: float) -> list[Outgoing]:
        """Resend an unanswered request or releases after ``retry_interval``; abandon an activation stuck ``lock_timeout``."""
        session = self.session
        if session is None or not now - session.sent_at >= self.retry_interval:
            return []
        if self.activation is ActivationState.RELEASING:
            sent = self._send_releases(session, now)
            self.stats["resent"] += len(session.releases)
            return sent
        if self.activation is not ActivationState.ACQUIRING:
            return []  # holding: the transition is running
        if now - max(session.started_at, session.progress_at) >= self.lock_timeout:
            return self._abandon(now)
        sent = self._advance(now)
        self.stats["resent"] += 1
        return sent

    # -- messages in -----------------------------------------------------------------------------

    def take_request(self, message: LockRequestMessage) -> list[Outgoing]:
        """A peer asks for this robot's lock: grant it, grant it again (a copy), or queue it (busy)."""
        locker, number = message.sender, message.session
        if number <= self._released.get(locker, 0):
            self.dropped["stale_lock_request"] += 1
            return []
        if self.holder == (locker, number):
            return [self._grant(locker, number)]  # a copy, or the grant was lost: grant again
        if self.holder is not None:
            self.stats["busy"] += 1
            self._waiting[locker] = max(self._waiting.get(locker, 0), number)
            return []  # granted when this robot is released (or asked again later)
        self._move_lock(LockEvent.GRANT, (locker, number))
        return [self._grant(locker, number)]

    def _grant(self, locker: int, session: int) -> Outgoing:
        return Outgoing(self._grant_message(locker, session), (locker,))

    def serve_line(self, now: float) -> list[Outgoing]:
        """The lock is free: give it to the first in line whose activation is still on (this robot's own included)."""
        while self._waiting and self.holder is None:
            locker = next(iter(self._waiting))
            number = self._waiting.pop(locker)
            if locker == self.index:
                session = self.session
                if session is not None and session.number == number and self.activation is ActivationState.ACQUIRING:
                    return self._advance(now)
            elif number > self._released.get(locker, 0):
                self._move_lock(LockEvent.GRANT, (locker, number))
                return [self._grant(locker, number)]
        return []

    def take_grant(self, message: LockGrantMessage, now: float) -> list[Outgoing]:
        """The peer asked last grants its lock: ask the next (a grant of anything else is dropped)."""
        session = self.session
        if (
            session is None
            or self.activation is not ActivationState.ACQUIRING
            or message.locker != self.index
            or message.session != session.number
            or session.position >= len(session.order)
            or session.order[session.position] != message.sender
        ):
            self.dropped["stale_grant"] += 1
            return []
        session.grants[message.sender] = message
        session.position += 1
        session.progress_at = now
        return self._advance(now)

    def take_release(self, message: LockReleaseMessage) -> tuple[Outgoing, bool]:
        """A locker ends its session: the acknowledgement, and whether the release is of the lock's holder.

        When it is, the lock is free: the robot applies the release's write-backs, then calls :meth:`serve_line`.
        """
        locker, number = message.sender, message.session
        ack = Outgoing(LockAckMessage(self.index, 0, locker, number), (locker,))
        holds = self.holder == (locker, number)
        if holds:
            self._move_lock(LockEvent.RELEASED, None)
        elif number <= self._released.get(locker, 0):
            self.dropped["duplicate_release"] += 1
        self._released[locker] = max(self._released.get(locker, 0), number)
        return ack, holds

    def take_ack(self, message: LockAckMessage) -> None:
        """A peer took in this activation's release; the last acknowledgement ends the activation."""
        session = self.session
        if (
            session is None
            or self.activation is not ActivationState.RELEASING
            or message.locker != self.index
            or message.session != session.number
        ):
            self.dropped["stale_ack"] += 1
            return
        if session.releases.pop(message.sender, None) is None:
            self.dropped["duplicate_ack"] += 1
        if not session.releases:
            self._end_activation()
