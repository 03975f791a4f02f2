"""The safety layer: a robot enters a cell only when a majority of the cell's replicas registered it to that robot.

Each cell has a *replica set* of at most three robots, the same for every
robot (:mod:`mrmp.protocol.replicas`). Each robot keeps a *registry* for the
cells it is a replica of: for each, at most one owner. A robot owns its own
Present, the cell its body is entering and the cell of its pending claim; it
records a peer as the owner of a cell when it grants that peer's claim (and, at
the start, every robot owns its start cell in the registries of that cell's
replicas). A robot that wants to enter a cell sends a
:class:`~mrmp.protocol.messages.ClaimMessage` to the cell's replicas; each
grants the claim only if the cell has no other owner in its registry, and
refuses otherwise. The claimant starts moving only once a majority of the
cell's replicas (itself among them if it is one) has registered the cell to it.

A registration is dropped only on a :class:`~mrmp.protocol.messages.ReleaseMessage`
from its owner naming the cell and a claim at least as new as the registered
one. A robot sends one to the cell's replicas when it has left a cell, or given
up a claim, and repeats it until each replica acknowledges it
(:class:`~mrmp.protocol.messages.ReleaseAckMessage`) or a bounded number of
tries passes.

**Following, in the lockstep model** (``following=True``, for a driver that
moves every allowed robot at once at the end of the tick in which its claim won
its majority): such a robot is *committed* to its move, and hands its Present
off (:class:`~mrmp.protocol.messages.HandoffMessage` to the Present's
replicas). A replica may register a handed-off cell to another robot, and grants
at once the claim it refused for that cell in the meantime; so a robot may
enter, in the same tick, the cell its occupant leaves. A robot hands off only
once its own claim has a majority, so the robots waiting on each other's
handoffs form chains, never cycles: no swap, no rotation.

**Following while driving** (``releases_on_start``, for live bodies that drive
straight from cell to cell at one common speed: ``turning`` bodies, whose turns
are actions of their own): a robot releases its Present the moment its body
starts driving out of it, not once it has arrived; a robot following it in may
then be granted the cell and start while the leader still covers part of it,
always later than the leader started, so the two stay apart (``docs/protocol.md``,
"Following while driving").

**Standing claims** (``keep_refused``, with ``following``, for a perfect
network): a refused claim is kept rather than given up at the step's end; its
robot sends it no more, and its replicas grant it as soon as the cell has no
owner in their registry (a handoff, a release that drops the cell's record, or
the replica giving up its own claim for it). Such a grant is given, like every
grant, only to a cell without an owner, so the argument below is unchanged.

Safety (no two robots ever cover one cell, whatever is lost, delayed,
duplicated or reordered): two majorities of one replica set share at least one
robot, and that robot registers a cell to at most one owner at a time; a
registration lasts at least as long as its owner covers the cell, because its
owner sends the release only after it stopped covering the cell. So two robots
can never both hold a majority for one cell at once. A crashed robot never
releases: it is an obstacle at its last cells. The full argument, and what it
costs in messages, is in ``docs/protocol.md``.

This module is sans-IO: it consumes messages and the driver's time, and returns
messages to send with their recipients. Liveness needs, for each cell to enter,
a majority of its replicas alive and in touch.

Examples
--------
>>> layer = SafetyLayer(index=0, starts=[(0, 0), (0, 2), (4, 4)])
>>> layer.quorum
2
>>> layer.owner_of((0, 2)), layer.owner_of((1, 1))
(1, None)
>>> claim = layer.start_claim((0, 1), now=0.0)
>>> claim.cell, layer.replicas_of((0, 1)), layer.may_enter((0, 1))
((0, 1), (0, 1, 2), False)
>>> layer.handle_reply(ReplyMessage(sender=2, seq=1, claimant=0, claim=claim.claim, cell=(0, 1), granted=True), now=0.1)
[]
>>> layer.may_enter((0, 1))
True
>>> layer.begin_move((0, 1)); layer.end_move((0, 1))
>>> [(type(message).__name__, message.cell, recipients) for message, recipients in layer.expire(now=1.0)]
[('ReleaseMessage', (0, 0), (1, 2))]

The lockstep rule: robot 1 leaves (0, 1) for (0, 2), and robot 0 follows it in, in the same tick:

>>> a, b = SafetyLayer(0, [(0, 0), (0, 1)], following=True), SafetyLayer(1, [(0, 0), (0, 1)], following=True)
>>> follow = a.start_claim((0, 1), now=1)
>>> b.handle_claim(follow, claimant_outranks=False).granted   # robot 1 stands there, not yet leaving
False
>>> lead = b.start_claim((0, 2), now=1)
>>> sends = b.handle_reply(a.handle_claim(lead, claimant_outranks=False), now=1)   # its majority: it commits
>>> [(type(message).__name__, message.cell) for message, _ in sends]   # hands (0, 1) off, grants the claim refused
[('HandoffMessage', (0, 1)), ('ReplyMessage', (0, 1))]
>>> _ = a.handle_handoff(sends[0][0]); _ = a.handle_reply(sends[1][0], now=1)
>>> a.may_enter((0, 1)), b.may_enter((0, 2))
(True, True)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from mrmp.core.cell import Cell
from mrmp.protocol.messages import (
    ClaimMessage,
    HandoffMessage,
    Message,
    ReleaseAckMessage,
    ReleaseMessage,
    ReplyMessage,
)
from mrmp.protocol.replicas import REPLICAS, majority, replica_set

RELEASE_TRIES = 32
"""How often a release is sent to a replica that does not acknowledge it before it is given up.

A replica that missed every try keeps a stale registration: the cell then
needs the other replicas' grants (still a majority of three when only one
replica is stale)."""

Send = tuple[Message, tuple[int, ...]]
"""A message for the robot to stamp and send, and its recipients."""


@dataclass
class _Registration:
    """A cell this robot has registered to a peer, and the claim that asked for it (0: the peer's start)."""

    owner: int
    claim: int
    handed_off: bool = False
    """The owner has committed to leave the cell in the current tick (lockstep model): it may be registered anew."""


@dataclass
class PendingClaim:
    """This robot's own claim in progress.

    ``votes`` are the replicas that granted it (itself included), ``refusers``
    those whose last answer was a refusal. ``committed`` (lockstep model only):
    a majority granted it and the robot has handed its Present off, so it moves
    in this tick whatever comes later.
    """

    number: int
    cell: Cell
    started_at: float
    sent_at: float
    votes: set[int] = field(default_factory=set)
    refusers: set[int] = field(default_factory=set)
    committed: bool = False
    standing: bool = False
    """Refused, and kept for a grant on a handoff or a release: past the step (``keep_refused``), or until its
    robot gives it up (``waits_for_release``)."""
    handoff_repeated: bool = False
    """Committed, and its handoff sent once more (:meth:`SafetyLayer.repeat_handoff`, a lossy network's driver)."""

    @property
    def refused(self) -> bool:
        """Whether some replica's last answer to this claim was a refusal."""
        return bool(self.refusers)


@dataclass
class _Release:
    """A release this robot still sends: the replicas of ``cell`` that have not acknowledged it."""

    claim: int
    cell: Cell
    waiting: set[int]
    sent_at: float = -float("inf")
    tries: int = 0


@dataclass
class SafetyStats:
    """What the layer did: claims made, granted, refused, timed out; replies given; releases sent and given up."""

    claims: int = 0
    granted: int = 0
    refused: int = 0
    timed_out: int = 0
    grants_given: int = 0
    refusals_given: int = 0
    releases: int = 0
    releases_given_up: int = 0


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
        A pending claim, or an unacknowledged release, is sent again after this long.
    replicas:
        Replicas per cell (:data:`~mrmp.protocol.replicas.REPLICAS`).
    keep_releases:
        Whether releases are sent (False for a robot that moves unguarded, which
        claims nothing and so has nothing to release).
    following:
        The lockstep model's rule (``docs/protocol.md``, "Following in the
        lockstep model"): a robot whose claim has a majority hands its Present
        off to that cell's replicas (:class:`~mrmp.protocol.messages.HandoffMessage`)
        and moves in the same tick, and a replica may then register that cell
        to a robot following it in, granting the claims it refused for it
        meanwhile. Only for drivers that move every allowed robot at once, at the
        end of the tick in which its claim won its majority (the lockstep
        simulator); bodies that cover both cells while they move keep the
        default, under which a cell is registered anew only once released.
    resend_refused:
        Under ``following``, send a refused claim again in the step's second
        round (:meth:`resend_claim`), in case the grant a replica gave on a
        handoff was lost; False on a network that loses nothing.
    keep_refused:
        Under ``following``, keep a refused claim past the step (a *standing*
        claim, :attr:`standing`) rather than give it up: its replicas still keep
        it as refused, grant it when the cell's owner hands the cell off or
        releases it, and its robot sends it no more, until it gives it up for
        another decision (``docs/protocol.md``, "A quiet fleet on a perfect network"). For a perfect
        network: a grant that is lost would leave it waiting.
    waits_for_release:
        Live bodies (no ``following``), any network: a claim refused by
        replicas still holding the cell's last owner is not given up but
        *waits*: its replicas keep it as refused and grant it the moment the
        owner's release drops their record (the grant goes with the release's
        acknowledgement, :meth:`take_granted_on_release`), and its robot sends
        it again every ``retry_interval`` to the replicas that have not granted
        it, in case a grant was lost; it is given up only when the robot gives
        it up (``docs/protocol.md``, "Claims that wait for a release"). A robot
        that follows another into its cell then starts as soon as the leader's
        release is in, not a retry later.
    releases_on_start:
        Live bodies that may follow while driving (no ``following``): the
        Present is released when the body starts driving out of it
        (:meth:`begin_move`), so that a robot may be granted it and start into
        it behind its leader (module docstring). Only for bodies whose moves are
        straight drives of one cell at one common speed, started by
        :meth:`begin_move` the moment the drive starts.
    """

    def __init__(
        self,
        index: int,
        starts: Sequence[Cell],
        claim_timeout: float = 4.0,
        retry_interval: float = 1.0,
        replicas: int = REPLICAS,
        keep_releases: bool = True,
        following: bool = False,
        resend_refused: bool = True,
        keep_refused: bool = False,
        waits_for_release: bool = False,
        releases_on_start: bool = False,
    ) -> None:
        self.index = index
        self.fleet_size = len(starts)
        self.replica_count = min(self.fleet_size, replicas)
        self.quorum = majority(self.replica_count)
        self.claim_timeout = claim_timeout
        self.retry_interval = retry_interval
        self.keep_releases = keep_releases
        self.following = following
        self.resend_refused = resend_refused
        self.keep_refused = keep_refused and following
        self.waits_for_release = waits_for_release and not following
        self.releases_on_start = releases_on_start and not following
        self.present_handed_off = False
        self.present_released = False
        """The body drives out of its Present, released already (``releases_on_start``)."""
        self._grants_on_start: list[Send] = []
        self.present: Cell = starts[index]
        self.present_claim = 0
        self.target: Cell | None = None
        self.pending: PendingClaim | None = None
        self.granted_claim: PendingClaim | None = None
        self.stats = SafetyStats()
        self._replicas = replicas
        self._claim_numbers = 0
        self._registry: dict[Cell, _Registration] = {}
        self._highest_claim: dict[int, int] = {}
        self._highest_release: dict[int, int] = {}
        self._releases: dict[tuple[Cell, int], _Release] = {}
        self._deferred: dict[Cell, dict[int, int]] = {}
        self.granted_on_release: list[Send] = []
        for owner, cell in enumerate(starts):
            if owner != index and index in self.replicas_of(cell):
                self._registry[cell] = _Registration(owner, 0)

    def replicas_of(self, cell: Cell) -> tuple[int, ...]:
        """The robots that keep ``cell``'s registry (the same for every robot of the fleet)."""
        return replica_set(cell, self.fleet_size, self._replicas)

    # -- the registry -----------------------------------------------------------------

    def owner_of(self, cell: Cell) -> int | None:
        """The robot this robot's registry names for ``cell`` (itself for its own cells), or None."""
        if (cell == self.present and not self.present_handed_off and not self.present_released) or cell == self.target:
            return self.index
        if self.pending is not None and cell == self.pending.cell:
            return self.index
        if self.granted_claim is not None and cell == self.granted_claim.cell:
            return self.index
        registration = self._registry.get(cell)
        return registration.owner if registration is not None else None

    def can_claim(self, cell: Cell) -> bool:
        """Whether this robot may ask for ``cell``: no peer owns it in its own registry.

        Under the lockstep model's rule any cell may be asked for (its owner may
        hand it off in this tick), but this robot's own Present.
        """
        owner = self.owner_of(cell)
        return owner is None or owner == self.index or self.following

    # -- this robot's claims ----------------------------------------------------------

    def start_claim(self, cell: Cell, now: float) -> ClaimMessage | None:
        """Begin claiming ``cell`` (giving up any other pending claim); None if a peer owns it here.

        The claim goes to :meth:`replicas_of` ``cell`` (but this robot); the
        returned message carries sequence number 0, the robot stamps it.
        """
        if cell == self.present or cell == self.target or not self.can_claim(cell):
            return None
        self.cancel_claim()
        self._claim_numbers += 1
        replica = self.index in self.replicas_of(cell)
        registration = self._registry.get(cell)
        if replica and registration is not None and not registration.handed_off:
            votes: set[int] = set()  # its own vote goes to the peer registered here, until that one hands it off
        elif replica:
            self._registry.pop(cell, None)
            votes = {self.index}
        else:
            votes = set()
        self.pending = PendingClaim(self._claim_numbers, cell, now, now, votes)
        self.stats.claims += 1
        self._commit_if_granted()  # a fleet of one is its own majority (nobody to hand off to)
        return ClaimMessage(self.index, 0, self.pending.number, cell)

    def claim_recipients(self, cell: Cell) -> tuple[int, ...]:
        """Where a claim for ``cell`` goes: its replicas but this robot."""
        return tuple(replica for replica in self.replicas_of(cell) if replica != self.index)

    def may_enter(self, cell: Cell) -> bool:
        """Whether a majority of ``cell``'s replicas registered it to this robot for its pending claim."""
        pending = self.pending
        if pending is None or pending.cell != cell:
            return False
        return pending.committed or (not self._lost(pending) and len(pending.votes) >= self.quorum)

    def _lost(self, pending: PendingClaim) -> bool:
        """Whether ``pending`` is lost: under the lockstep rule, refused by any replica (its robot then decides
        again within the tick, or the claim stands); otherwise refused by more replicas than a majority can spare,
        so that one replica still holding a record of the cell's last owner (its release is on its way) costs the
        claimant nothing while the other two grant.

        >>> layer = SafetyLayer(0, [(0, 0), (0, 1), (0, 2), (0, 3)])
        >>> _ = layer.start_claim((5, 5), now=0.0)
        >>> replicas = layer.claim_recipients((5, 5))
        >>> refusal = lambda replica: ReplyMessage(replica, 1, 0, layer.pending.number, (5, 5), False)
        >>> grant = lambda replica: ReplyMessage(replica, 1, 0, layer.pending.number, (5, 5), True)
        >>> _ = layer.handle_reply(refusal(replicas[0]), now=0.0); layer._lost(layer.pending)
        False
        >>> _ = [layer.handle_reply(grant(replica), now=0.0) for replica in replicas[1:]]; layer.may_enter((5, 5))
        True
        """
        if self.following:
            return pending.refused
        return len(pending.refusers) > len(self.replicas_of(pending.cell)) - self.quorum

    def begin_move(self, cell: Cell) -> None:
        """The body starts entering ``cell`` (which :meth:`may_enter` allowed, or any cell when unguarded).

        With ``releases_on_start`` the Present is released now: its release
        goes out with the next :meth:`releases_due`, and so does the grant this
        robot, as a replica of its Present, gives to a claim that waited for it.

        >>> leader = SafetyLayer(0, [(0, 1), (0, 0)], releases_on_start=True, waits_for_release=True)
        >>> claim = leader.start_claim((0, 2), now=0.0)
        >>> _ = leader.handle_reply(ReplyMessage(1, 1, 0, claim.claim, (0, 2), True), now=0.0)
        >>> leader.handle_claim(ClaimMessage(1, 2, 1, (0, 1)), claimant_outranks=False).granted   # it stands there
        False
        >>> leader.begin_move((0, 2))   # it drives out: (0, 1) is released, and granted to the claim that waited
        >>> [(type(message).__name__, message.cell, to) for message, to in leader.releases_due(now=0.1)]
        [('ReleaseMessage', (0, 1), (1,)), ('ReplyMessage', (0, 1), (1,))]
        >>> leader.owner_of((0, 1)), leader.owner_of((0, 2))
        (1, 0)
        """
        if self.pending is not None and self.pending.cell == cell:
            self.stats.granted += 1
            self.granted_claim = self.pending
        self.pending = None
        self.target = cell
        if self.releases_on_start and cell != self.present and not self.present_released:
            self.present_released = True
            self._release(self.present, self.present_claim)
            if self.index in self.replicas_of(self.present):
                self._grants_on_start.extend(self._grant_deferred(self.present))

    def end_move(self, cell: Cell) -> None:
        """The body stands on ``cell``: it is the new Present; the cells left are released."""
        granted = self.granted_claim
        if cell != self.present:
            if not self.present_released:
                self._release(self.present, self.present_claim)
            self.present_claim = granted.number if granted is not None and granted.cell == cell else 0
        if granted is not None and granted.cell != cell:
            self._release(granted.cell, granted.number)  # the body stopped short of the cell it was allowed
        self.present = cell
        self.present_handed_off = False
        self.present_released = False
        self.target = None
        self.granted_claim = None

    def cancel_claim(self) -> None:
        """Give up the pending claim, releasing it at the replicas that may have granted it."""
        pending = self.pending
        if pending is not None:
            if pending.committed:
                raise RuntimeError("a committed claim is not given up: its robot moves in this tick")
            self.pending = None
            self._release(pending.cell, pending.number)

    def give_up_claim(self) -> list[Send]:
        """Give up the pending claim (:meth:`cancel_claim`); with standing claims, grant the one this robot, as a
        replica of that cell, refused for it meanwhile (the cell is free in its registry now): the grant to send."""
        pending = self.pending
        self.cancel_claim()
        if pending is None or not self.keep_refused or pending.cell in self._registry:
            return []
        if self.index not in self.replicas_of(pending.cell):
            return []
        return self._grant_deferred(pending.cell)

    def expire(self, now: float) -> list[Send]:
        """Time out or resend the pending claim, and send the releases due: the messages to send."""
        sends: list[Send] = []
        pending = self.pending
        if pending is not None and not pending.committed:
            if pending.refused and self.keep_refused:
                if not pending.standing:
                    self.stats.refused += 1
                    pending.standing = True
            elif self._lost(pending) and self.waits_for_release:
                if not pending.standing:
                    self.stats.refused += 1
                    pending.standing = True  # it waits for the release, sent again to those that refused
                if now - pending.sent_at >= self.retry_interval:
                    pending.sent_at = now
                    missing = tuple(replica for replica in self.claim_recipients(pending.cell) if replica not in pending.votes)
                    sends.append((ClaimMessage(self.index, 0, pending.number, pending.cell), missing))
            elif self._lost(pending):
                self.stats.refused += 1
                self.cancel_claim()
            elif now - pending.started_at >= self.claim_timeout:
                self.stats.timed_out += 1
                sends.extend(self.give_up_claim())
            elif now - pending.sent_at >= self.retry_interval and len(pending.votes) < self.quorum:
                pending.sent_at = now
                sends.append((ClaimMessage(self.index, 0, pending.number, pending.cell), self.claim_recipients(pending.cell)))
        sends.extend(self.releases_due(now))
        return sends

    @property
    def standing(self) -> bool:
        """Whether the pending claim is a standing one: refused in an earlier step, kept (``keep_refused``)."""
        pending = self.pending
        return pending is not None and pending.standing and not pending.committed

    def resend_claim(self, now: float) -> list[Send]:
        """Send the pending claim again to the replicas that have not granted it, if it is due for a resend.

        For a driver that gives the exchange of a tick a second round (the
        lockstep simulator): a claim short of its majority whose retry interval
        has passed (at once on a network without delay, where every answer is in
        by then) goes again to the replicas that have not granted it. A refused
        claim is sent again only under the lockstep rule, where a refusing
        replica may have granted it since (its owner handed the cell off) and
        that grant may have been lost; otherwise it is given up.
        """
        pending = self.pending
        if pending is None or pending.committed or len(pending.votes) >= self.quorum:
            return []
        if pending.refused and not (self.following and self.resend_refused):
            return []
        if now - pending.sent_at < self.retry_interval:
            return []
        missing = tuple(replica for replica in self.claim_recipients(pending.cell) if replica not in pending.votes)
        if not missing:
            return []
        pending.sent_at = now
        return [(ClaimMessage(self.index, 0, pending.number, pending.cell), missing)]

    def state_fields(self) -> dict[str, object]:
        """The safety part of this robot's state message: ``target``, ``claim``, ``claim_cell``."""
        claim = self.granted_claim or self.pending
        return {
            "target": self.target,
            "claim": claim.number if claim is not None else 0,
            "claim_cell": claim.cell if claim is not None else None,
        }

    @property
    def unacknowledged_releases(self) -> int:
        """Releases still being sent."""
        return len(self._releases)

    # -- releases ------------------------------------------------------------------------

    def _release(self, cell: Cell, claim: int) -> None:
        """Start sending the release of ``cell`` (registered for ``claim``) to its replicas."""
        if not self.keep_releases:
            return
        waiting = set(self.claim_recipients(cell))
        if waiting:
            self._releases[(cell, claim)] = _Release(claim, cell, waiting)
            self.stats.releases += 1

    def releases_due(self, now: float) -> list[Send]:
        """The releases due now (a claim just given up, or one to send again), without running the claim's timers,
        and the grants given as the body drove out of its Present (``releases_on_start``)."""
        sends: list[Send] = []
        for key, release in list(self._releases.items()):
            if now - release.sent_at < self.retry_interval:
                continue
            if release.tries >= RELEASE_TRIES:
                del self._releases[key]
                self.stats.releases_given_up += 1
                continue
            release.tries += 1
            release.sent_at = now
            sends.append((ReleaseMessage(self.index, 0, release.claim, release.cell), tuple(sorted(release.waiting))))
        sends.extend(self._grants_on_start)
        self._grants_on_start = []
        return sends

    # -- peers' messages ---------------------------------------------------------------

    def handle_claim(self, message: ClaimMessage, claimant_outranks: bool) -> ReplyMessage | None:
        """Grant or refuse a peer's claim; None for a claim that is over, or not for this robot to answer.

        ``claimant_outranks`` says whether the claimant wins a contest with this
        robot's own pending claim on the same cell (this robot then gives up its
        claim and grants). The reply carries sequence number 0; the robot stamps it.
        """
        sender, cell = message.sender, message.cell
        if self.index not in self.replicas_of(cell):
            return None  # not a replica of the cell: its registry does not count
        if message.claim < self._highest_claim.get(sender, 0) or message.claim <= self._highest_release.get(sender, -1):
            return None  # its sender has made a newer claim, or released this one: it is over
        self._highest_claim[sender] = message.claim
        owner = self.owner_of(cell)
        pending = self.pending
        contested = pending is not None and pending.cell == cell and self.granted_claim is None
        if contested and pending is not None and pending.committed:
            contested = False  # it moves in this tick: nobody outranks that
        if owner == self.index and contested and claimant_outranks and cell not in (self.present, self.target):
            self.cancel_claim()
            owner = self.owner_of(cell)
        registration = self._registry.get(cell)
        handed_off = owner != self.index and registration is not None and registration.handed_off
        if owner is None or owner == sender or handed_off:
            self._registry[cell] = _Registration(sender, message.claim)  # only newer claims get here
            self.stats.grants_given += 1
            return ReplyMessage(self.index, 0, sender, message.claim, cell, True)
        if self.following or self.waits_for_release:
            self._deferred.setdefault(cell, {})[sender] = message.claim  # granted if the owner hands the cell off
        self.stats.refusals_given += 1
        return ReplyMessage(self.index, 0, sender, message.claim, cell, False)

    def handle_reply(self, message: ReplyMessage, now: float) -> list[Send]:
        """Count a replica's answer to this robot's pending claim (others are ignored).

        A grant may come after a refusal from the same replica (under the
        lockstep model's rule its owner handed the cell off meanwhile; otherwise
        the owner's release reached it before the claim was sent again) and
        replaces it; under that rule the grant that completes a majority commits
        the claim, and the handoff of the Present is returned to be sent.
        """
        pending = self.pending
        if pending is None or message.claimant != self.index or message.claim != pending.number:
            return []
        if message.cell != pending.cell or message.sender not in self.replicas_of(pending.cell):
            return []
        if message.granted:
            pending.votes.add(message.sender)
            pending.refusers.discard(message.sender)  # its latest answer counts: the record of a release came since
        else:
            pending.refusers.add(message.sender)
        return self._commit_if_granted()

    # -- the lockstep model's handoffs ---------------------------------------------------

    def _commit_if_granted(self) -> list[Send]:
        """Lockstep model: once the pending claim has a majority, commit to it and hand the Present off.

        The handoff goes to the Present's other replicas; as a replica of its
        own Present, this robot grants at once a claim it deferred for it.
        """
        pending = self.pending
        if not self.following or pending is None or pending.committed or len(pending.votes) < self.quorum:
            return []
        pending.committed = True
        self.present_handed_off = True
        sends = self._handoff()
        if self.index in self.replicas_of(self.present):
            sends.extend(self._grant_deferred(self.present))
        return sends

    def repeat_handoff(self) -> list[Send]:
        """The handoff of the Present once more, once per committed claim (lockstep model): for a driver of a
        lossy network, so that a lost handoff does not cost a follower its tick. A replica takes a second copy
        as it takes a duplicate (it names the same record), so the argument is unchanged.

        >>> a = SafetyLayer(0, [(0, 0), (0, 1), (0, 2)], following=True)
        >>> a.repeat_handoff()   # nothing committed
        []
        >>> claim = a.start_claim((1, 0), now=0)
        >>> a.replicas_of((1, 0))
        (0, 1, 2)
        >>> _ = a.handle_reply(ReplyMessage(1, 0, 0, claim.claim, (1, 0), True), now=0)   # its majority: committed
        >>> [(type(message).__name__, message.cell, to) for message, to in a.repeat_handoff()]
        [('HandoffMessage', (0, 0), (1, 2))]
        >>> a.repeat_handoff()   # once only
        []
        """
        pending = self.pending
        if not self.following or pending is None or not pending.committed or pending.handoff_repeated:
            return []
        pending.handoff_repeated = True
        return self._handoff()

    def _handoff(self) -> list[Send]:
        """The handoff of the Present to its other replicas (none when this robot is its only replica)."""
        recipients = self.claim_recipients(self.present)
        return [(HandoffMessage(self.index, 0, self.present_claim, self.present), recipients)] if recipients else []

    def handle_handoff(self, message: HandoffMessage) -> list[Send]:
        """A peer leaves a cell this robot keeps in this tick: mark its registration, grant a deferred claim.

        Only a handoff that names the registration this replica holds for the
        sender counts (a late one, after a release or a newer claim, is ignored).
        """
        cell = message.cell
        registration = self._registry.get(cell)
        if not self.following or registration is None:
            return []
        if registration.owner != message.sender or registration.claim != message.claim:
            return []
        registration.handed_off = True
        return self._grant_deferred(cell)

    def _grant_deferred(self, cell: Cell) -> list[Send]:
        """Register ``cell``, just handed off, to the first claim still current that was refused for it here.

        This robot's own pending claim for the cell comes first (its vote);
        then peers' claims in the order they came. Returns the grant to send.
        """
        waiting = self._deferred.pop(cell, {})
        pending = self.pending
        if pending is not None and pending.cell == cell and self.index not in pending.votes:
            self._registry.pop(cell, None)
            pending.votes.add(self.index)
            pending.refusers.discard(self.index)
            return self._commit_if_granted()
        for claimant, claim in waiting.items():
            if claim != self._highest_claim.get(claimant) or claim <= self._highest_release.get(claimant, -1):
                continue  # given up, released, or superseded since
            self._registry[cell] = _Registration(claimant, claim)
            self.stats.grants_given += 1
            return [(ReplyMessage(self.index, 0, claimant, claim, cell, True), (claimant,))]
        return []

    def handle_release(self, message: ReleaseMessage) -> ReleaseAckMessage:
        """Drop the sender's registration of the cell if it is not newer than the release; acknowledge it.

        The acknowledgement carries sequence number 0; the robot stamps it.
        """
        sender, cell = message.sender, message.cell
        self._highest_release[sender] = max(self._highest_release.get(sender, -1), message.claim)
        registration = self._registry.get(cell)
        if registration is not None and registration.owner == sender and registration.claim <= message.claim:
            del self._registry[cell]
            if self.keep_refused or self.waits_for_release:
                self.granted_on_release = self._grant_deferred(cell)
            else:
                self._deferred.pop(cell, None)
        return ReleaseAckMessage(self.index, 0, sender, message.claim, cell)

    def take_granted_on_release(self) -> list[Send]:
        """The grant of a standing claim that the last release made (``keep_refused``), to send with its acknowledgement."""
        sends, self.granted_on_release = self.granted_on_release, []
        return sends

    def handle_release_ack(self, message: ReleaseAckMessage) -> None:
        """A replica has taken in one of this robot's releases: stop sending it there."""
        if message.owner != self.index:
            return
        release = self._releases.get((message.cell, message.claim))
        if release is None:
            return
        release.waiting.discard(message.sender)
        if not release.waiting:
            del self._releases[(message.cell, message.claim)]
