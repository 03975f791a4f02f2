"""Causal-PIBT computed by the robots themselves, over a lossy network (policy ``causal``).

Causal-PIBT (K. Okumura, Y. Tamura, X. Défago, "Time-Independent Planning for
Multiple Moving Agents", AAAI 2021) is the asynchronous form of PIBT (Okumura
et al., IJCAI 2019): robots move at unpredictable speeds, and each is

* **contracted**: on its *tail* cell;
* **requesting**: contracted, with a *head* cell chosen next to the tail;
* **extended**: covering tail and head while its body moves from one to the other.

Each *activation* of a robot runs one transition (``actContracted``,
``actRequesting``, ``actExtended`` of the authors' implementation): priority
inheritance from a requesting robot of higher priority whose head is this
robot's tail (it becomes this robot's *parent*, this robot its *child*), the
choice of a head among the candidate cells ``C`` not yet taken by the tree
(``S``, the visited set), backtracking to the parent when no candidate is left,
and the contest of the robots requesting one head (the highest priority wins
and extends if nobody covers the head). The priority of a robot is
``(away from its goal, -(times it reached its goal), index)``; with it, every
robot reaches its goal on biconnected graphs with fewer robots than cells, for
any speeds (the paper's reachability theorem, given fair activations).

**Atomicity by messages.** One activation reads and writes only robots whose
tail lies within two cells of the robot's tail (parent and children are
adjacent, a robot requesting a cell is next to it, a robot extended into a
neighbour cell has its tail within two cells). So a robot first *locks* them:
it sends :class:`~mrmp.protocol.messages.LockRequestMessage` to each robot it
believes within two cells (and its parent and children), one after the other in
index order, itself included at its place, which rules out deadlock (ordered
resource acquisition); each lock is answered by a
:class:`~mrmp.protocol.messages.LockGrantMessage` carrying the granting robot's
Causal-PIBT state. Holding all locks, the robot runs its transition on those
states and sends each locked robot a
:class:`~mrmp.protocol.messages.LockReleaseMessage` with what it wrote into it
(operation bits and a visited set), answered by
:class:`~mrmp.protocol.messages.LockAckMessage`. Requests and releases are
resent every ``retry_interval`` until answered; every message carries the
activation number (``session``), so duplicates re-send the same answer, a grant
or ack of another session is dropped and counted, a request of a session
already released is ignored, and an activation that cannot get its locks within
``lock_timeout`` is abandoned (released everywhere, written back nowhere). A
locked robot does not change its own state until it is released.

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
from dataclasses import dataclass, field

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.protocol.messages import (
    ADD_CHILD,
    CLEAR_PARENT,
    CONTRACT,
    MAX_VISITED_CELLS,
    REMOVE_CHILD,
    SET_VISITED,
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
from mrmp.robot.messaging import Handlers, MessageEndpoint, Outgoing
from mrmp.search.flat_map import FlatMap

__all__ = [
    "CONTRACTED",
    "EXTENDED",
    "LOCK_RADIUS",
    "MAX_CLAIM_FAILURES",
    "REQUESTING",
    "CausalRobot",
    "PeerView",
]

CONTRACTED, REQUESTING, EXTENDED = 0, 1, 2
MODE_NAMES = ("contracted", "requesting", "extended")
LOCK_RADIUS = 2
"""An activation locks the robots whose known cells lie within this many cells (Manhattan) of the tail."""
MAX_CLAIM_FAILURES = 8
"""Claims of the head refused or timed out in a row before an extended robot gives the head up."""

Priority = tuple[int, int, int]
"""``(away from goal, -(goals reached), index)``: larger is higher."""


@dataclass
class PeerView:
    """A locked robot's Causal-PIBT state, from its grant, and what this activation writes into it."""

    index: int
    mode: int
    tail: Cell
    head: Cell | None
    priority: Priority
    visited: set[Cell]
    operations: int = 0
    new_visited: set[Cell] | None = None

    def covers(self, cell: Cell) -> bool:
        """Whether the robot stands on ``cell`` or is extended into it (the authors' ``occupied``)."""
        return self.tail == cell or (self.mode == EXTENDED and self.head == cell)


@dataclass
class _Session:
    """One activation in progress: the robots to lock, in index order, and their grants."""

    number: int
    order: list[int]
    started_at: float
    sent_at: float = -1.0
    progress_at: float = -1.0
    position: int = 0
    views: dict[int, PeerView] = field(default_factory=dict)
    releases: dict[int, LockReleaseMessage] = field(default_factory=dict)
    releasing: bool = False


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
    ) -> None:
        self.index = index
        self.grid = grid
        self.flat = flat if flat is not None else FlatMap(grid)
        self.goal = goal
        self.rng = rng if rng is not None else random.Random(index)
        self.retry_interval = retry_interval
        self.lock_timeout = lock_timeout
        self.heading = heading
        self.tail: Cell = starts[index]
        self.head: Cell | None = None
        self.mode = CONTRACTED
        self.parent = index
        self.children: set[int] = set()
        self.reached = 0
        self.away = int(self.tail != goal)
        self.inherited: Priority = self.own_priority
        self.visited: set[Cell] = set()
        self.candidates: list[Cell] = []
        self._reset()
        self.safety = SafetyLayer(index, starts, claim_timeout=claim_timeout, retry_interval=retry_interval)
        self.moving = False
        self.body_arrived = False
        self.claim_failures = 0
        self._failed_at: float | None = None
        self.seq = 0
        self.known: dict[int, tuple[int, tuple[Cell, ...]]] = {
            other: (-1, (cell,)) for other, cell in enumerate(starts) if other != index
        }
        self.known_heads: dict[int, Cell] = {}
        self.heard: dict[int, tuple[float, bool]] = {}
        """When each peer's newest state arrived, and whether it said the peer stood on its goal."""
        self.locked_by: tuple[int, int] | None = None
        self._released: dict[int, int] = {}
        self._waiting: dict[int, int] = {}
        self._sessions = 0
        self.session: _Session | None = None
        self.dropped: Counter[str] = Counter()
        self.stats: Counter[str] = Counter()
        self._distances = self.flat.distances(self.flat.index(goal))

    # -- state ------------------------------------------------------------------------

    @property
    def own_priority(self) -> Priority:
        """This robot's own priority (not inherited)."""
        return (self.away, -self.reached, self.index)

    @property
    def mode_name(self) -> str:
        """``"contracted"``, ``"requesting"`` or ``"extended"``."""
        return MODE_NAMES[self.mode]

    @property
    def at_goal(self) -> bool:
        """Whether the body stands on the goal, contracted."""
        return self.mode != EXTENDED and self.tail == self.goal

    @property
    def body_on_goal(self) -> bool:
        """Whether the body stands on the goal: contracted there, or moved there and not yet contracted (locked)."""
        return self.at_goal or (self.body_arrived and self.head == self.goal)

    @property
    def idle(self) -> bool:
        """Whether no activation of this robot is under way."""
        return self.session is None

    def set_goal(self, goal: Cell) -> None:
        """A new goal (lifelong runs): the robot is away from a goal again."""
        self.goal = goal
        self._distances = self.flat.distances(self.flat.index(goal))
        self.away = int(self.tail != goal)
        if self.parent == self.index:
            self.inherited = self.own_priority

    def _reset(self) -> None:
        """The authors' ``reset``: empty S, candidates the neighbours and the tail, own priority."""
        self.visited = set()
        self.candidates = [*self.grid.neighbours(self.tail), self.tail]
        self.inherited = self.own_priority

    def state_message(self) -> StateMessage:
        """The robot's state for every peer: tail (Present), head (Next), arrival, safety state."""
        return self._state(self.tail, self.head if self.head is not None else self.tail, self.heading, self.at_goal)

    def _near(self) -> list[int]:
        """The robots this robot believes within :data:`LOCK_RADIUS` of its tail, and its parent and children."""
        x, y = self.tail
        near = {
            other
            for other, (_, cells) in self.known.items()
            if any(abs(cx - x) + abs(cy - y) <= LOCK_RADIUS for cx, cy in cells)
        }
        near |= self.children
        if self.parent != self.index:
            near.add(self.parent)
        return sorted(near)

    # -- activations ---------------------------------------------------------------------

    def activate(self, now: float) -> list[Outgoing]:
        """Begin an activation, if none is under way (a robot locked by a peer waits in line for its own lock).

        An extended robot whose body has arrived contracts instead, once no peer holds its lock; a
        robot contracted on its goal that no known robot needs stays idle.
        """
        if self.session is not None:
            return []
        if self.mode == EXTENDED:
            return self._finish_move_when_free(now)
        if self._nothing_to_do():
            return []
        self._sessions += 1
        self.stats["activations"] += 1
        order = sorted({*self._near(), self.index})
        self.session = _Session(self._sessions, order, now)
        return self._advance(now)

    def _nothing_to_do(self) -> bool:
        """Contracted on the goal, alone in its tree, and no robot known to request its tail."""
        return (
            self.mode == CONTRACTED
            and self.tail == self.goal
            and self.parent == self.index
            and not self.children
            and self.tail not in self.known_heads.values()
        )

    def _advance(self, now: float) -> list[Outgoing]:
        """Take the next lock in order: this robot's own when free, or ask the next peer."""
        session = self.session
        assert session is not None
        while session.position < len(session.order):
            member = session.order[session.position]
            if member != self.index:
                session.sent_at = now
                return [Outgoing(self._stamp(LockRequestMessage(self.index, 0, session.number)), (member,))]
            if self.locked_by is not None and self.locked_by[0] != self.index:
                self._waiting.setdefault(self.index, session.number)
                return []  # locked by a peer: wait in line for its release
            self._waiting.pop(self.index, None)
            self.locked_by = (self.index, session.number)
            session.position += 1
        return self._run_transition(now)

    def _run_transition(self, now: float) -> list[Outgoing]:
        """All locks held: run this robot's transition, then release everyone with the write-backs."""
        session = self.session
        assert session is not None
        views = session.views
        if self.mode == CONTRACTED:
            self._act_contracted(views)
        elif self.mode == REQUESTING:
            self._act_requesting(views)
        self.locked_by = None
        sent: list[Outgoing] = self._grant_next_waiting(now)  # with this robot's new state
        for member, view in views.items():
            visited = tuple(_bounded(view.new_visited, view.tail)) if view.new_visited is not None else ()
            session.releases[member] = LockReleaseMessage(self.index, 0, session.number, view.operations, visited)
        sent.extend(self._start_releasing(session, now))
        sent.append(Outgoing(self.state_message()))
        if self.mode == EXTENDED:
            sent.extend(self._claim_head(now))
        return sent

    def _send_releases(self, session: _Session, now: float) -> list[Outgoing]:
        """Send (again) every release of ``session`` not yet acknowledged."""
        session.sent_at = now
        return [Outgoing(self._stamp(release), (member,)) for member, release in session.releases.items()]

    def _start_releasing(self, session: _Session, now: float) -> list[Outgoing]:
        """The locks of ``session`` are given back: send its releases (none: the activation is over)."""
        session.releasing = True
        if not session.releases:
            self.session = None
        return self._send_releases(session, now)

    def _abandon(self, now: float) -> list[Outgoing]:
        """Give the activation up: release every robot asked so far, writing nothing back."""
        session = self.session
        assert session is not None
        self.stats["abandoned"] += 1
        sent: list[Outgoing] = []
        self._waiting.pop(self.index, None)
        if self.locked_by == (self.index, session.number):
            self.locked_by = None
            sent = self._grant_next_waiting(now)
        session.releases = {
            member: LockReleaseMessage(self.index, 0, session.number)
            for member in session.order[: session.position + 1]
            if member != self.index
        }
        return sent + self._start_releasing(session, now)

    # -- the transitions (the authors' actContracted, actRequesting, priorityInheritance) ----------

    def _covered(self, cell: Cell, views: dict[int, PeerView]) -> bool:
        return any(view.covers(cell) for view in views.values())

    def _release_children(self, views: dict[int, PeerView]) -> None:
        for child in self.children:
            if child in views:
                views[child].operations |= CLEAR_PARENT
        self.children = set()

    def _leave_parent(self, views: dict[int, PeerView]) -> None:
        if self.parent != self.index and self.parent in views:
            views[self.parent].operations |= REMOVE_CHILD
        self.parent = self.index

    def _priority_inheritance(self, views: dict[int, PeerView]) -> None:
        requesters = [view for view in views.values() if view.mode == REQUESTING and view.head == self.tail]
        if not requesters:
            return
        winner = max(requesters, key=lambda view: view.priority)
        if winner.priority <= self.inherited:
            return
        self._release_children(views)
        self._leave_parent(views)
        self.parent = winner.index
        winner.operations |= ADD_CHILD
        self.inherited = winner.priority
        self.visited = set(winner.visited)
        if self.mode == REQUESTING and self.head is not None:
            self.visited.add(self.head)
        self.candidates = [cell for cell in self.grid.neighbours(self.tail) if cell not in self.visited]
        self.stats["inherited"] += 1

    def _act_contracted(self, views: dict[int, PeerView]) -> None:
        if not self.candidates and self.parent == self.index:
            self._release_children(views)
            self._reset()
        self._priority_inheritance(views)
        if not self.candidates:
            parent = views.get(self.parent)
            if self.parent != self.index and parent is not None and parent.head == self.tail:
                merged = parent.visited | self.visited
                parent.new_visited = merged
                parent.operations |= SET_VISITED | CONTRACT
                self.stats["backtracked"] += 1
            return
        chosen = self._next_cell(views)
        if chosen == self.tail:
            self._release_children(views)
            self._reset()
            return
        self.candidates.remove(chosen)
        self.visited |= {chosen, self.tail}
        self.head = chosen
        self.mode = REQUESTING

    def _act_requesting(self, views: dict[int, PeerView]) -> None:
        self._priority_inheritance(views)
        parent = views.get(self.parent)
        if self.parent != self.index and parent is not None and self.head in parent.visited:
            self.head = None
            self.mode = CONTRACTED
            return
        head = self.head
        if head is None or self._covered(head, views):
            return
        rivals = [view for view in views.values() if view.mode == REQUESTING and view.head == head]
        winner = max((view.priority for view in rivals), default=None)
        if winner is not None and winner > self.inherited:
            for view in rivals:
                if view.priority != winner:
                    view.operations |= CONTRACT
            self.head = None  # a rival of higher priority wins the contest for this head
            self.mode = CONTRACTED
            return
        for view in rivals:
            view.operations |= CONTRACT
        self._leave_parent(views)
        self._release_children(views)
        self.mode = EXTENDED
        self.claim_failures = 0

    def _next_cell(self, views: dict[int, PeerView]) -> Cell:
        """The authors' ``nextNode``: the candidate nearest the goal; ties to free cells, then wider ones, then at random."""
        if self.tail in self.candidates and self.tail == self.goal:
            return self.tail
        flat = self.flat
        distances = self._distances
        best = min(distances[flat.index(cell)] for cell in self.candidates)
        nearest = [cell for cell in self.candidates if distances[flat.index(cell)] == best]
        if len(nearest) == 1:
            return nearest[0]
        free = [cell for cell in nearest if not self._covered(cell, views)]
        if len(free) == 1:
            return free[0]
        if free:
            widest = max(len(self.grid.neighbours(cell)) for cell in free)
            return self.rng.choice([cell for cell in free if len(self.grid.neighbours(cell)) == widest])
        return self.rng.choice(nearest)

    # -- the body ---------------------------------------------------------------------------

    def _claim_head(self, now: float) -> list[Outgoing]:
        assert self.head is not None
        self._failed_at = None
        claim = self.safety.start_claim(self.head, now)
        if claim is None:
            self._failed_at = now
            self.claim_failures += 1
            return []
        self.stats["claims"] += 1
        return [Outgoing(self._stamp(claim), self.safety.claim_recipients(claim.cell))]

    def motion(self, now: float) -> Cell | None:
        """The cell the body may start entering now (a majority registered it to this robot), if any."""
        if self.mode != EXTENDED or self.moving or self.body_arrived or self.head is None:
            return None
        if not self.safety.may_enter(self.head):
            return None
        self.safety.begin_move(self.head)
        self.moving = True
        self.stats["moves"] += 1
        return self.head

    def arrived_at(self, cell: Cell, now: float, heading: Heading | None = None) -> list[Outgoing]:
        """The body stands on ``cell`` (its head); contract now, or once no peer holds this robot's lock."""
        if heading is not None:
            self.heading = heading
        self.moving = False
        self.body_arrived = True
        return self._finish_move_when_free(now)

    def _finish_move_when_free(self, now: float) -> list[Outgoing]:
        """Finish the body's move once it has arrived, no activation of this robot is under way and no peer holds its lock."""
        if self.body_arrived and self.locked_by is None and self.session is None:
            return self._finish_move(now)
        return []

    def _finish_move(self, now: float) -> list[Outgoing]:
        """The authors' ``actExtended``: the head becomes the tail; count a goal reached; reset."""
        assert self.head is not None
        self.tail = self.head
        self.head = None
        self.mode = CONTRACTED
        self.body_arrived = False
        self.safety.end_move(self.tail)
        if self.away and self.tail == self.goal:
            self.reached += 1
        self.away = int(self.tail != self.goal)
        self._reset()
        return [Outgoing(self.state_message()), *self._safety_sends(now)]

    def _safety_sends(self, now: float) -> list[Outgoing]:
        """The safety layer's messages due now (releases of the cells left, claims to resend), stamped."""
        return [Outgoing(self._stamp(message), recipients) for message, recipients in self.safety.expire(now)]

    def _give_up_head(self) -> list[Outgoing]:
        """Extended into a cell the registries keep refusing: contract again on the tail."""
        self.stats["heads_given_up"] += 1
        self.safety.cancel_claim()
        self.head = None
        self.mode = CONTRACTED
        self._reset()
        return [Outgoing(self.state_message())]

    # -- timers -------------------------------------------------------------------------------

    def expire(self, now: float) -> list[Outgoing]:
        """Resend what is unanswered, abandon a stuck activation, renew the head's claim; finish a deferred move."""
        sent: list[Outgoing] = []
        session = self.session
        if session is not None and now - session.sent_at >= self.retry_interval:
            if session.releasing:
                sent.extend(self._send_releases(session, now))
                self.stats["resent"] += len(session.releases)
            elif now - max(session.started_at, session.progress_at) >= self.lock_timeout:
                sent.extend(self._abandon(now))
            elif session.position < len(session.order):
                sent.extend(self._advance(now))
                self.stats["resent"] += 1
        safety_sends = self._safety_sends(now)
        sent.extend(safety_sends)
        if self.mode == EXTENDED and not self.moving and not self.body_arrived:
            if any(isinstance(item.message, ClaimMessage) for item in safety_sends):
                pass  # the claim is still on its way
            elif self.safety.pending is None:
                if self._failed_at is None:
                    self._failed_at = now
                    self.claim_failures += 1
                if self.claim_failures >= MAX_CLAIM_FAILURES and self.locked_by is None and self.session is None:
                    sent.extend(self._give_up_head())
                elif now - self._failed_at >= 2 * self.retry_interval:
                    sent.extend(self._claim_head(now))  # a cell is free again once its owner's release arrives
        else:
            sent.extend(self._finish_move_when_free(now))
        return sent

    def heartbeat(self) -> list[Outgoing]:
        """The state message every peer gets regularly (it tells where this robot is)."""
        return [Outgoing(self.state_message())]

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
        self._take_state(message, now)
        return []

    @handlers.on(ClaimMessage)
    def _on_claim(self, message: ClaimMessage, now: float) -> list[Outgoing]:
        _, cells = self.known.get(message.sender, (0, (message.cell,)))
        return self._answer_claim(message, cells[0], self.tail)

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
        return self._take_request(message)

    @handlers.on(LockGrantMessage)
    def _on_lock_grant(self, message: LockGrantMessage, now: float) -> list[Outgoing]:
        return self._take_grant(message, now)

    @handlers.on(LockReleaseMessage)
    def _on_lock_release(self, message: LockReleaseMessage, now: float) -> list[Outgoing]:
        return self._take_release(message, now)

    @handlers.on(LockAckMessage)
    def _on_lock_ack(self, message: LockAckMessage, now: float) -> list[Outgoing]:
        self._take_ack(message)
        return []

    def _take_state(self, message: StateMessage, now: float) -> None:
        sender = message.sender
        if message.seq <= self.known.get(sender, (-1, ()))[0]:
            self.dropped["stale_state"] += 1
        else:
            self.heard[sender] = (now, message.arrived)
            cells = (message.present, *(cell for cell in (message.target, message.claim_cell) if cell is not None))
            self.known[sender] = (message.seq, cells)
            if message.next != message.present:
                self.known_heads[sender] = message.next
            else:
                self.known_heads.pop(sender, None)

    def _grant(self, locker: int, session: int) -> Outgoing:
        grant = LockGrantMessage(
            self.index,
            0,
            locker,
            session,
            self.mode,
            self.tail,
            self.head,
            bool(self.inherited[0]),
            -self.inherited[1],
            self.inherited[2],
            tuple(_bounded(self.visited, self.tail)),
        )
        return Outgoing(self._stamp(grant), (locker,))

    def _take_request(self, message: LockRequestMessage) -> list[Outgoing]:
        locker, number = message.sender, message.session
        if number <= self._released.get(locker, 0):
            self.dropped["stale_lock_request"] += 1
            return []
        if self.locked_by == (locker, number):
            return [self._grant(locker, number)]  # a copy, or the grant was lost: grant again
        if self.locked_by is not None:
            self.stats["busy"] += 1
            self._waiting[locker] = max(self._waiting.get(locker, 0), number)
            return []  # granted when this robot is released (or asked again later)
        self.locked_by = (locker, number)
        return [self._grant(locker, number)]

    def _grant_next_waiting(self, now: float) -> list[Outgoing]:
        """Unlocked: lock for the robot that has waited longest (this one included), if its activation is still on."""
        while self._waiting and self.locked_by is None:
            locker = next(iter(self._waiting))
            number = self._waiting.pop(locker)
            if locker == self.index:
                session = self.session
                if session is not None and session.number == number and not session.releasing:
                    return self._advance(now)
            elif number > self._released.get(locker, 0):
                self.locked_by = (locker, number)
                return [self._grant(locker, number)]
        return []

    def _take_grant(self, message: LockGrantMessage, now: float) -> list[Outgoing]:
        session = self.session
        if (
            session is None
            or session.releasing
            or message.locker != self.index
            or message.session != session.number
            or session.position >= len(session.order)
            or session.order[session.position] != message.sender
        ):
            self.dropped["stale_grant"] += 1
            return []
        session.views[message.sender] = PeerView(
            message.sender,
            message.mode,
            message.tail,
            message.head,
            (int(message.urgent), -message.reached, message.rank),
            set(message.visited),
        )
        session.position += 1
        session.progress_at = now
        return self._advance(now)

    def _take_release(self, message: LockReleaseMessage, now: float) -> list[Outgoing]:
        locker, number = message.sender, message.session
        ack = Outgoing(self._stamp(LockAckMessage(self.index, 0, locker, number)), (locker,))
        if self.locked_by == (locker, number):
            self._apply(message)
            self.locked_by = None
        elif number <= self._released.get(locker, 0):
            self.dropped["duplicate_release"] += 1
        self._released[locker] = max(self._released.get(locker, 0), number)
        sent = [ack, *self._finish_move_when_free(now)]
        if self.locked_by is None:
            sent.extend(self._grant_next_waiting(now))
        return sent

    def _apply(self, message: LockReleaseMessage) -> None:
        """Carry out what the locker wrote into this robot."""
        operations = message.operations
        if operations & CLEAR_PARENT and self.parent == message.sender:
            self.parent = self.index
        if operations & REMOVE_CHILD:
            self.children.discard(message.sender)
        if operations & ADD_CHILD:
            self.children.add(message.sender)
        if operations & SET_VISITED:
            self.visited = set(message.visited)
            self.candidates = [cell for cell in self.candidates if cell not in self.visited]
        if operations & CONTRACT and self.mode == REQUESTING:
            self.head = None
            self.mode = CONTRACTED
        self.stats["written"] += 1 if operations else 0

    def _take_ack(self, message: LockAckMessage) -> None:
        session = self.session
        if session is None or not session.releasing or message.locker != self.index or message.session != session.number:
            self.dropped["stale_ack"] += 1
            return
        if session.releases.pop(message.sender, None) is None:
            self.dropped["duplicate_ack"] += 1
        if not session.releases:
            self.session = None


def _bounded(cells: set[Cell] | None, around: Cell) -> list[Cell]:
    """At most :data:`MAX_VISITED_CELLS` of ``cells``, the nearest to ``around`` (sorted, for a deterministic wire form)."""
    if not cells:
        return []
    ordered = sorted(cells, key=lambda cell: (abs(cell[0] - around[0]) + abs(cell[1] - around[1]), cell))
    return sorted(ordered[:MAX_VISITED_CELLS])
