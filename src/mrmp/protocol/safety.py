"""The safety layer: a robot enters a cell only when a majority of the fleet has registered it to that robot.

Every robot keeps a *registry*: for each cell, at most one owner. It owns its
own Present, the cell its body is entering, and the cell of its pending claim;
it records a peer as the owner of a cell when it grants that peer's claim (and,
at the start, every peer owns its start cell). A robot that wants to enter a
cell sends a :class:`~mrmp.protocol.messages.ClaimMessage` to every peer; each
peer grants the claim only if the cell has no other owner in its registry, and
refuses otherwise. The claimant starts moving only once a majority of the
fleet, itself included, has registered the cell to it.

Safety (no two robots ever cover one cell, whatever is lost, delayed, duplicated
or reordered): two majorities of one fleet share at least one robot, and that
robot registers a cell to at most one owner at a time, so two robots can never
both hold a majority for one cell at once. A registration is only dropped on
evidence from its owner itself: a state message sent *after* the claim (a larger
sequence number) that shows the owner neither covering the cell nor still
claiming it. A registration only ever moves forward (to a newer claim of the
same owner, never back to an older one), and a claim older than one already
seen from its sender is ignored. Until then the granting robot keeps the cell for its owner, even if
the owner is silent for ever (a crashed robot is an obstacle at its last cells),
so lost, late, duplicated or reordered messages can only delay a robot, never
let two robots into one cell. The full argument, and what it costs in messages,
is in ``docs/protocol.md``.

This module is sans-IO: it consumes messages and the driver's time, and returns
messages to send. Liveness needs a majority of the fleet alive and in touch; a
robot that cannot hear a majority cannot move.

Examples
--------
>>> layer = SafetyLayer(index=0, starts=[(0, 0), (0, 2), (4, 4)])
>>> layer.quorum
2
>>> layer.owner_of((0, 2)), layer.owner_of((1, 1))
(1, None)
>>> claim = layer.start_claim((0, 1), now=0.0)
>>> claim.cell, layer.may_enter((0, 1))
((0, 1), False)
>>> layer.handle_reply(ReplyMessage(sender=2, seq=1, claimant=0, claim=claim.claim, cell=(0, 1), granted=True), now=0.1)
>>> layer.may_enter((0, 1))
True
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from mrmp.core.cell import Cell
from mrmp.protocol.messages import ClaimMessage, ReplyMessage, StateMessage


@dataclass
class _Grant:
    """A cell this robot has registered to a peer, and the claim that asked for it."""

    owner: int
    claim: int
    claim_seq: int
    cell: Cell


@dataclass
class PendingClaim:
    """This robot's own claim in progress."""

    number: int
    cell: Cell
    started_at: float
    sent_at: float
    votes: set[int] = field(default_factory=set)
    refused: bool = False


@dataclass
class SafetyStats:
    """What the layer did: claims made, granted, refused, timed out; replies given."""

    claims: int = 0
    granted: int = 0
    refused: int = 0
    timed_out: int = 0
    grants_given: int = 0
    refusals_given: int = 0


class SafetyLayer:
    """One robot's side of the cell-registration protocol (see the module docstring).

    Parameters
    ----------
    index:
        This robot's index in the fleet.
    starts:
        Every robot's start cell, by index (registered to its robot at the start).
    claim_timeout:
        A claim without a majority after this long (driver's time units) is
        abandoned.
    retry_interval:
        A pending claim is sent again after this long without a majority.
    """

    def __init__(
        self,
        index: int,
        starts: Sequence[Cell],
        claim_timeout: float = 4.0,
        retry_interval: float = 1.0,
    ) -> None:
        self.index = index
        self.fleet_size = len(starts)
        self.quorum = self.fleet_size // 2 + 1
        self.claim_timeout = claim_timeout
        self.retry_interval = retry_interval
        self.present: Cell = starts[index]
        self.target: Cell | None = None
        self.pending: PendingClaim | None = None
        self.granted_claim: PendingClaim | None = None
        self.stats = SafetyStats()
        self._claim_numbers = 0
        self._grants: dict[Cell, _Grant] = {}
        self._newest_state: dict[int, tuple[int, int]] = {}
        self._highest_claim: dict[int, int] = {}
        for owner, cell in enumerate(starts):
            if owner != index:
                self._grants[cell] = _Grant(owner, 0, 0, cell)

    # -- the registry -----------------------------------------------------------------

    def owner_of(self, cell: Cell) -> int | None:
        """The robot this robot has registered ``cell`` to, or None."""
        if cell == self.present or cell == self.target:
            return self.index
        if self.pending is not None and cell == self.pending.cell:
            return self.index
        if self.granted_claim is not None and cell == self.granted_claim.cell:
            return self.index
        grant = self._grants.get(cell)
        return grant.owner if grant is not None else None

    # -- this robot's claims ----------------------------------------------------------

    def can_claim(self, cell: Cell) -> bool:
        """Whether ``cell`` is free in this robot's own registry (no peer owns it)."""
        owner = self.owner_of(cell)
        return owner is None or owner == self.index

    def start_claim(self, cell: Cell, now: float) -> ClaimMessage | None:
        """Begin claiming ``cell`` (abandoning any other pending claim); None if a peer owns it here.

        The returned message carries sequence number 0; the robot stamps it.
        """
        if not self.can_claim(cell):
            return None
        self._claim_numbers += 1
        self.pending = PendingClaim(self._claim_numbers, cell, now, now)
        self.stats.claims += 1
        return ClaimMessage(self.index, 0, self.pending.number, cell)

    def may_enter(self, cell: Cell) -> bool:
        """Whether a majority has registered ``cell`` to this robot for its pending claim."""
        pending = self.pending
        return (
            pending is not None
            and pending.cell == cell
            and not pending.refused
            and 1 + len(pending.votes) >= self.quorum
        )

    def begin_move(self, cell: Cell) -> None:
        """The body starts entering ``cell`` (which :meth:`may_enter` allowed, or any cell when unguarded)."""
        if self.pending is not None and self.pending.cell == cell:
            self.stats.granted += 1
            self.granted_claim = self.pending
        self.pending = None
        self.target = cell

    def end_move(self, cell: Cell) -> None:
        """The body stands on ``cell``: it is the new Present, and the move's claim is over."""
        self.present = cell
        self.target = None
        self.granted_claim = None

    def cancel_claim(self) -> None:
        """Abandon the pending claim (peers release it when they hear the next state)."""
        self.pending = None

    def expire(self, now: float) -> ClaimMessage | None:
        """Time out or resend the pending claim; returns a claim to send again, if any."""
        pending = self.pending
        if pending is None:
            return None
        if pending.refused:
            self.stats.refused += 1
            self.cancel_claim()
            return None
        if now - pending.started_at >= self.claim_timeout:
            self.stats.timed_out += 1
            self.cancel_claim()
            return None
        if now - pending.sent_at >= self.retry_interval and 1 + len(pending.votes) < self.quorum:
            pending.sent_at = now
            return ClaimMessage(self.index, 0, pending.number, pending.cell)
        return None

    def state_fields(self) -> dict[str, object]:
        """The safety part of this robot's state message: ``target``, ``claim``, ``claim_cell``."""
        claim = self.granted_claim or self.pending
        return {
            "target": self.target,
            "claim": claim.number if claim is not None else 0,
            "claim_cell": claim.cell if claim is not None else None,
        }

    # -- peers' messages ---------------------------------------------------------------

    def handle_state(self, message: StateMessage) -> None:
        """Drop registrations the sender's newer state shows it is done with."""
        sender = message.sender
        if message.seq <= self._newest_state.get(sender, (-1, 0))[0]:
            return
        self._newest_state[sender] = (message.seq, message.claim)
        self._highest_claim[sender] = max(self._highest_claim.get(sender, 0), message.claim)
        occupied = message.occupied
        for cell in [cell for cell, grant in self._grants.items() if grant.owner == sender]:
            grant = self._grants[cell]
            if message.seq <= grant.claim_seq or cell in occupied:
                continue
            if grant.claim and message.claim == grant.claim:
                continue
            del self._grants[cell]

    def handle_claim(self, message: ClaimMessage, claimant_outranks: bool) -> ReplyMessage | None:
        """Grant or refuse a peer's claim; None for a claim its sender has already given up.

        ``claimant_outranks`` says whether the claimant wins a contest with this
        robot's own pending claim on the same cell (this robot then abandons its
        claim and grants).
        The reply carries sequence number 0; the robot stamps it.
        """
        sender, cell = message.sender, message.cell
        newest_seq, newest_claim = self._newest_state.get(sender, (-1, 0))
        if message.seq < newest_seq and newest_claim != message.claim:
            return None  # a newer state of its sender shows it gave this claim up
        if message.claim < self._highest_claim.get(sender, 0):
            return None  # its sender has made a newer claim since: this one is over
        self._highest_claim[sender] = message.claim
        owner = self.owner_of(cell)
        pending_here = self.pending is not None and self.pending.cell == cell and cell != self.present
        if owner == self.index and pending_here and self.target != cell and claimant_outranks and self.granted_claim is None:
            self.pending = None
            owner = self.owner_of(cell)
        if owner is None or owner == sender:
            previous = self._grants.get(cell)
            claim_seq = message.seq if previous is None else max(previous.claim_seq, message.seq)
            self._grants[cell] = _Grant(sender, message.claim, claim_seq, cell)  # records only move forward
            self.stats.grants_given += 1
            return ReplyMessage(self.index, 0, sender, message.claim, cell, True)
        self.stats.refusals_given += 1
        return ReplyMessage(self.index, 0, sender, message.claim, cell, False)

    def handle_reply(self, message: ReplyMessage, now: float) -> None:
        """Count a peer's answer to this robot's pending claim (others are ignored)."""
        pending = self.pending
        if pending is None or message.claimant != self.index or message.claim != pending.number:
            return
        if message.granted:
            pending.votes.add(message.sender)
        else:
            pending.refused = True
