"""Causal-PIBT computed by the robots themselves, over a lossy network (policy ``causal``).

Causal-PIBT (K. Okumura, Y. Tamura, X. Défago, "Time-Independent Planning for
Multiple Moving Agents", AAAI 2021) is the asynchronous form of PIBT (Okumura
et al., IJCAI 2019): robots move at unpredictable speeds, and each is
contracted, requesting or extended (:class:`~mrmp.robot.causal_views.Mode`).
Each *activation* of a robot runs one transition; with the priority
``(away from its goal, -(times it reached its goal), index)``, every robot
reaches its goal on biconnected graphs with fewer robots than cells, for any
speeds (the paper's reachability theorem, given fair activations).

:class:`CausalRobot` composes the pieces of one robot's brain:

* its Causal-PIBT variables, :class:`~mrmp.robot.causal_views.CausalState`;
* what it heard of its peers' cells, :class:`~mrmp.robot.causal_peers.KnownPeers`,
  which says whom an activation locks: the robots believed within
  :data:`LOCK_RADIUS` cells of the tail, and the parent and children (one
  activation reads and writes only those);
* the lock protocol, :class:`~mrmp.robot.neighbour_locks.NeighbourLocks`,
  which makes an activation atomic: it locks those robots in index order, and
  once it holds every lock the robot runs its transition;
* the transitions, :class:`~mrmp.robot.causal_transitions.CausalTransitions`,
  over its state and the :class:`~mrmp.robot.causal_views.PeerView` of each
  locked robot that its grant gave; what they write into a peer travels back in
  the peer's release. A locked robot does not change its own state (not even
  the end of a move) until it is released.

**Safety does not rest on this.** Where robots are comes from their state
messages, which can be late, so a robot may miss a neighbour. The body
therefore enters a head only through the :class:`~mrmp.protocol.safety.SafetyLayer`
(a majority of the fleet has registered the cell to the robot): no two bodies
are ever in one cell, whatever the network does (``docs/protocol.md``). A robot
extended into a cell that the registries keep refusing (a neighbour it did not
know of stands there) gives the head up after ``MAX_CLAIM_FAILURES`` claims.

The robot is sans-IO: its driver hands it time, randomness (``rng``) and
messages, and carries out what it returns.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> robot = CausalRobot(0, Grid(1, 3), starts=[(0, 0)], goal=(0, 2))
>>> [type(sent.message).__name__ for sent in robot.activate(now=0)]   # alone: no lock to ask for
['StateMessage']
>>> robot.mode_name, robot.head
('requesting', (0, 1))
>>> [type(sent.message).__name__ for sent in robot.activate(now=0)]   # nobody covers the head
['StateMessage', 'ClaimMessage']
>>> robot.mode_name, robot.head, robot.motion(now=0)
('extended', (0, 1), (0, 1))
>>> [type(sent.message).__name__ for sent in robot.arrived_at((0, 1), now=1)]
['StateMessage']
>>> robot.mode_name, robot.tail
('contracted', (0, 1))
"""

from __future__ import annotations

import random
from collections import Counter
from collections.abc import Sequence

from mrmp.core.body import DEFAULT_BODY, BodyModel, body_model
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.protocol.messages import (
    ADD_CHILD,
    ClaimMessage,
    LockAckMessage,
    LockGrantMessage,
    LockReleaseMessage,
    LockRequestMessage,
    Message,
    ReleaseAckMessage,
    ReleaseMessage,
    ReplyMessage,
    StateMessage,
)
from mrmp.protocol.safety import SafetyLayer
from mrmp.robot.causal_peers import KnownPeer, KnownPeers
from mrmp.robot.causal_transitions import CausalTransitions
from mrmp.robot.causal_views import CausalState, Mode, PeerView, Priority
from mrmp.robot.messaging import Handlers, MessageEndpoint, Outgoing
from mrmp.robot.neighbour_locks import LockSession, NeighbourLocks
from mrmp.search.flat_map import FlatMap

__all__ = [
    "ADD_CHILD",
    "CONTRACTED",
    "EXTENDED",
    "LOCK_RADIUS",
    "MAX_CLAIM_FAILURES",
    "REQUESTING",
    "CausalRobot",
    "Mode",
    "PeerView",
]

CONTRACTED, REQUESTING, EXTENDED = Mode.CONTRACTED, Mode.REQUESTING, Mode.EXTENDED
LOCK_RADIUS = 2
"""An activation locks the robots whose known cells lie within this many cells (Manhattan) of the tail."""
MAX_CLAIM_FAILURES = 8
"""Claims of the head refused or timed out in a row before an extended robot gives the head up."""


class CausalRobot(MessageEndpoint):
    """One robot's Causal-PIBT, free of I/O (see the module docstring).

    Parameters
    ----------
    index:
        The robot's index in the fleet (its name on the wire).
    grid:
        The map, known to every robot.
    starts:
        Every robot's start cell, by index.
    goal:
        This robot's goal.
    rng:
        Random generator for ties between equally near cells.
    retry_interval:
        Lock requests, releases and claims are sent again after this long (driver's time units).
    lock_timeout:
        An activation that got no new lock for this long is abandoned (a peer may have crashed).
    claim_timeout:
        A claim of the head without a majority after this long is abandoned (and made again).
    flat:
        The map's flat form with its distance tables (shared by robots simulated in one process).
    heading:
        The body's initial heading.
    body:
        The body model (:mod:`mrmp.core.body`; ``omni`` when omitted). A body
        that turns in place ranks its candidates in its own model; its driver
        turns it toward the head it may enter (:meth:`motion`) before it drives
        there, reporting each quarter turn with :meth:`turned`.
    state_radius:
        Send states to the robots within this many cells of the tail (a radius
        broadcast) rather than to every peer (None: every peer); at least
        :data:`LOCK_RADIUS` plus the cells a robot can cover between two of a
        peer's states (``docs/protocol.md``, "Neighbourhoods").
    """

    def __init__(
        self,
        index: int,
        grid: Grid,
        starts: Sequence[Cell],
        goal: Cell,
        rng: random.Random | None = None,
        retry_interval: float = 1.0,
        lock_timeout: float = 20.0,
        claim_timeout: float = 4.0,
        flat: FlatMap | None = None,
        heading: Heading = Heading.NORTH,
        state_radius: int | None = None,
        body: BodyModel | None = None,
    ) -> None:
        if state_radius is not None and state_radius < LOCK_RADIUS:
            raise ValueError(f"state radius {state_radius} is below the lock radius {LOCK_RADIUS}")
        self.index = index
        self.state_radius = state_radius
        self.grid = grid
        self.retry_interval = retry_interval
        self.seq = 0
        self.dropped: Counter[str] = Counter()
        self.stats: Counter[str] = Counter()
        rng = rng if rng is not None else random.Random(index)
        self.body = body if body is not None else body_model(DEFAULT_BODY)
        self.transitions = CausalTransitions(grid, goal, rng, flat, self.stats, self.body, heading)
        self.state: CausalState = self.transitions.initial_state(index, starts[index])
        self.peers = KnownPeers(index, starts)
        self.locks = NeighbourLocks(index, self._grant, retry_interval, lock_timeout, self.stats, self.dropped)
        self.safety = SafetyLayer(index, starts, claim_timeout=claim_timeout, retry_interval=retry_interval)
        self.moving = False
        self.body_arrived = False
        self.claim_failures = 0
        self._failed_at: float | None = None

    # -- state ------------------------------------------------------------------------

    @property
    def goal(self) -> Cell:
        """This robot's goal."""
        return self.transitions.goal

    @property
    def tail(self) -> Cell:
        """The cell the robot stands on (contracted) or comes from (extended)."""
        return self.state.tail

    @property
    def head(self) -> Cell | None:
        """The cell chosen next (requesting) or being entered (extended); None when contracted."""
        return self.state.head

    @property
    def mode(self) -> Mode:
        """Contracted, requesting or extended."""
        return self.state.mode

    @property
    def mode_name(self) -> str:
        """``"contracted"``, ``"requesting"`` or ``"extended"``."""
        return self.state.mode.name.lower()

    @property
    def parent(self) -> int:
        """The robot whose priority this one inherited (its own index when none)."""
        return self.state.parent

    @property
    def children(self) -> set[int]:
        """The robots that inherited this robot's priority."""
        return self.state.children

    @property
    def reached(self) -> int:
        """How often the robot reached its goal."""
        return self.state.reached

    @property
    def inherited(self) -> Priority:
        """The priority the robot holds (own or inherited)."""
        return self.state.inherited

    @property
    def own_priority(self) -> Priority:
        """This robot's own priority (not inherited)."""
        return self.state.own_priority

    @property
    def visited(self) -> set[Cell]:
        """The visited set S of the robot's inheritance tree."""
        return self.state.visited

    @property
    def candidates(self) -> list[Cell]:
        """The candidate cells C for a head."""
        return self.state.candidates

    @property
    def known(self) -> dict[int, KnownPeer]:
        """Each peer's newest known state: its sequence number and cells."""
        return self.peers.known

    @property
    def heard(self) -> dict[int, tuple[float, bool]]:
        """When each peer's newest state arrived, and whether it said the peer stood on its goal."""
        return self.peers.heard

    @property
    def locked_by(self) -> tuple[int, int] | None:
        """``(locker, session)`` holding this robot's lock, if any."""
        return self.locks.holder

    @property
    def session(self) -> LockSession | None:
        """This robot's activation in progress, if any."""
        return self.locks.session

    @property
    def at_goal(self) -> bool:
        """Whether the body stands on the goal, contracted."""
        return self.state.mode is not Mode.EXTENDED and self.state.tail == self.goal

    @property
    def body_on_goal(self) -> bool:
        """Whether the body stands on the goal: contracted there, or moved there and not yet contracted (locked)."""
        return self.at_goal or (self.body_arrived and self.state.head == self.goal)

    @property
    def idle(self) -> bool:
        """Whether no activation of this robot is under way."""
        return self.locks.idle

    def set_goal(self, goal: Cell) -> None:
        """A new goal (lifelong runs): the robot is away from a goal again."""
        self.transitions.set_goal(self.state, goal)

    def state_message(self) -> StateMessage:
        """The robot's state for every peer: tail (Present), head (Next), arrival, safety state."""
        state = self.state
        return self._state(state.tail, state.head if state.head is not None else state.tail, self.heading, self.at_goal)

    def _state_outgoing(self) -> Outgoing:
        """The state message, to the robots within the state radius (every peer without one)."""
        return Outgoing(self.state_message(), None, self.state_radius)

    def _grant(self, locker: int, session: int) -> LockGrantMessage:
        """This robot's grant of its lock, carrying its current state."""
        return self.state.grant(locker, session)

    def _numbered(self, outgoing: list[Outgoing]) -> list[Outgoing]:
        """What the lock protocol sends, each message with this robot's next sequence number, in order."""
        return [item._replace(message=self._stamp(item.message)) for item in outgoing]

    # -- activations ---------------------------------------------------------------------

    def activate(self, now: float) -> list[Outgoing]:
        """Begin an activation, if none is under way (a robot locked by a peer waits in line for its own lock).

        An extended robot whose body has arrived contracts instead, once no peer holds its lock; a
        robot contracted on its goal that no known robot needs stays idle.
        """
        if not self.locks.idle:
            return []
        if self.state.mode is Mode.EXTENDED:
            return self._finish_move_when_free(now)
        if self._nothing_to_do():
            return []
        self.stats["activations"] += 1
        sent = self._numbered(self.locks.begin(self._near(), now))
        return sent + self._transition_when_locked(now)

    def _near(self) -> set[int]:
        """The robots this robot believes within :data:`LOCK_RADIUS` of its tail, and its parent and children."""
        state = self.state
        near = self.peers.near(state.tail, LOCK_RADIUS) | state.children
        if state.has_parent:
            near.add(state.parent)
        return near

    def _nothing_to_do(self) -> bool:
        """Contracted on the goal, alone in its tree, and no robot known to request its tail."""
        state = self.state
        return (
            state.mode is Mode.CONTRACTED
            and state.tail == self.goal
            and not state.has_parent
            and not state.children
            and not self.peers.requested(state.tail)
        )

    def _transition_when_locked(self, now: float) -> list[Outgoing]:
        """Once every lock is held: run the transition, then release everyone with the write-backs."""
        if not self.locks.all_locked:
            return []
        peers = {grant.sender: PeerView.from_grant(grant) for grant in self.locks.grants}
        self.transitions.act(self.state, peers)
        write_backs = {index: view.write_back() for index, view in peers.items()}
        sent = self._numbered(self.locks.release(write_backs, now))
        sent.append(self._state_outgoing())
        if self.state.mode is Mode.EXTENDED:
            self.claim_failures = 0
            sent.extend(self._claim_head(now))
        return sent

    # -- the body ---------------------------------------------------------------------------

    def _claim_head(self, now: float) -> list[Outgoing]:
        head = self.state.head
        assert head is not None
        self._failed_at = None
        claim = self.safety.start_claim(head, now)
        if claim is None:
            self._failed_at = now
            self.claim_failures += 1
            return []
        self.stats["claims"] += 1
        return [Outgoing(self._stamp(claim), self.safety.claim_recipients(claim.cell))]

    def motion(self, now: float) -> Cell | None:
        """The cell the body may start entering now (a majority registered it to this robot), if any."""
        head = self.state.head
        if self.state.mode is not Mode.EXTENDED or self.moving or self.body_arrived or head is None:
            return None
        if not self.safety.may_enter(head):
            return None
        self.safety.begin_move(head)
        self.moving = True
        self.stats["moves"] += 1
        return head

    @property
    def heading(self) -> Heading:
        """The body's heading (the one its transitions rank candidates from)."""
        return self.transitions.heading

    @heading.setter
    def heading(self, heading: Heading) -> None:
        self.transitions.heading = heading

    def turned(self, heading: Heading) -> list[Outgoing]:
        """The body has ended a quarter turn in place, toward its head, and now faces ``heading``; it says so."""
        self.heading = heading
        return [self._state_outgoing()]

    def arrived_at(self, cell: Cell, now: float, heading: Heading | None = None) -> list[Outgoing]:
        """The body stands on ``cell`` (its head); contract now, or once no peer holds this robot's lock."""
        if heading is not None:
            self.heading = heading
        self.moving = False
        self.body_arrived = True
        return self._finish_move_when_free(now)

    def _finish_move_when_free(self, now: float) -> list[Outgoing]:
        """Finish the body's move once it has arrived, no activation of this robot is under way and no peer holds its lock."""
        if self.body_arrived and self.locks.holder is None and self.locks.idle:
            return self._finish_move(now)
        return []

    def _finish_move(self, now: float) -> list[Outgoing]:
        """The head becomes the tail (the authors' ``actExtended``); the body's move is over."""
        self.transitions.act_extended(self.state)
        self.body_arrived = False
        self.safety.end_move(self.state.tail)
        return [self._state_outgoing(), *self._safety_sends(now)]

    def _safety_sends(self, now: float) -> list[Outgoing]:
        """The safety layer's messages due now (releases of the cells left, claims to resend), stamped."""
        return self._stamped(self.safety.expire(now))

    def _give_up_head(self) -> list[Outgoing]:
        """Extended into a cell the registries keep refusing: contract again on the tail."""
        self.stats["heads_given_up"] += 1
        self.safety.cancel_claim()
        self.transitions.give_up_head(self.state)
        return [self._state_outgoing()]

    # -- timers -------------------------------------------------------------------------------

    def expire(self, now: float) -> list[Outgoing]:
        """Resend what is unanswered, abandon a stuck activation, renew the head's claim; finish a deferred move."""
        sent = self._numbered(self.locks.expire(now))
        sent.extend(self._transition_when_locked(now))
        safety_sends = self._safety_sends(now)
        sent.extend(safety_sends)
        if self.state.mode is Mode.EXTENDED and not self.moving and not self.body_arrived:
            if any(isinstance(item.message, ClaimMessage) for item in safety_sends):
                pass  # the claim is still on its way
            elif self.safety.pending is None:
                if self._failed_at is None:
                    self._failed_at = now
                    self.claim_failures += 1
                if self.claim_failures >= MAX_CLAIM_FAILURES and self.locks.holder is None and self.locks.idle:
                    sent.extend(self._give_up_head())
                elif now - self._failed_at >= 2 * self.retry_interval:
                    sent.extend(self._claim_head(now))  # a cell is free again once its owner's release arrives
        else:
            sent.extend(self._finish_move_when_free(now))
        return sent

    def heartbeat(self) -> list[Outgoing]:
        """The state message every peer gets regularly (it tells where this robot is)."""
        return [self._state_outgoing()]

    # -- messages in ------------------------------------------------------------------------

    def receive(self, message: Message, now: float) -> list[Outgoing]:
        """Take in one decoded message; return the answers to send."""
        sender = message.sender
        if sender == self.index or not 0 <= sender < self.safety.fleet_size:
            self.dropped["own" if sender == self.index else "unknown_sender"] += 1
            return []
        handler = self.handlers.get(message)
        if handler is None:
            self.dropped["other_type"] += 1
            return []
        return handler(self, message, now)

    handlers = Handlers()
    """What the robot does with each type of message (others are dropped and counted)."""

    @handlers.on(StateMessage)
    def _on_state(self, message: StateMessage, now: float) -> list[Outgoing]:
        if not self.peers.take_state(message, now):
            self.dropped["stale_state"] += 1
        return []

    @handlers.on(ClaimMessage)
    def _on_claim(self, message: ClaimMessage, now: float) -> list[Outgoing]:
        return self._answer_claim(message, self.peers.present_of(message.sender, message.cell), self.state.tail)

    @handlers.on(ReplyMessage)
    def _on_reply(self, message: ReplyMessage, now: float) -> list[Outgoing]:
        self.safety.handle_reply(message, now)
        return []

    @handlers.on(ReleaseMessage)
    def _on_cell_release(self, message: ReleaseMessage, now: float) -> list[Outgoing]:
        return self._answer_release(message)

    @handlers.on(ReleaseAckMessage)
    def _on_cell_release_ack(self, message: ReleaseAckMessage, now: float) -> list[Outgoing]:
        self.safety.handle_release_ack(message)
        return []

    @handlers.on(LockRequestMessage)
    def _on_lock_request(self, message: LockRequestMessage, now: float) -> list[Outgoing]:
        return self._numbered(self.locks.take_request(message))

    @handlers.on(LockGrantMessage)
    def _on_lock_grant(self, message: LockGrantMessage, now: float) -> list[Outgoing]:
        sent = self._numbered(self.locks.take_grant(message, now))
        return sent + self._transition_when_locked(now)

    @handlers.on(LockReleaseMessage)
    def _on_lock_release(self, message: LockReleaseMessage, now: float) -> list[Outgoing]:
        """Acknowledge; take in what the lock's holder wrote; then finish a deferred move and serve the line."""
        ack, of_holder = self.locks.take_release(message)
        sent = self._numbered([ack])
        if of_holder:
            self.transitions.apply_release(self.state, message)
        sent.extend(self._finish_move_when_free(now))
        sent.extend(self._numbered(self.locks.serve_line(now)))
        return sent + self._transition_when_locked(now)

    @handlers.on(LockAckMessage)
    def _on_lock_ack(self, message: LockAckMessage, now: float) -> list[Outgoing]:
        self.locks.take_ack(message)
        return []
