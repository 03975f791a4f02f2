"""Locally sequenced PIBT over a network that loses, delays, duplicates and reorders: acknowledgements and timers.

:class:`~mrmp.robot.pibt_local.LocalPibtRobot` rests on synchronous rounds:
what is sent in a round arrives in the next. :class:`ReliablePibtRobot` keeps
its rules and replaces that assumption by acknowledgements, in the manner of
Awerbuch's α synchronizer (B. Awerbuch, "Complexity of network
synchronization", J. ACM 32(4), 1985: a node moves on when every neighbour has
acknowledged its messages):

* every message but an acknowledgement is acknowledged by its recipient
  (:class:`~mrmp.protocol.pibt_local.CallAckMessage`), second copies too, and
  sent again every ``retry`` ticks to the recipients that have not
  acknowledged it (the robot's own timers: :meth:`ReliablePibtRobot.on_tick`,
  time passed in);
* the robot's sensor tells it which cells within 2 hold a body
  (:meth:`ReliablePibtRobot.begin_step`'s ``sensed``): until it has the beacon
  of each, it neither starts a call nor takes part in one (it could take a cell
  it believes empty), and it sends its beacon again until each has
  acknowledged it;
* a provisional reservation becomes final once every robot within 2 cells has
  acknowledged it (instead of "after one round"). An acknowledgement carries
  its sender's own reservation: of two calls claiming one cell, each either
  heard the other's claim before claiming (and passed the cell by) or receives
  it in the acknowledgement of its own claim, before confirming; the call of
  lower priority withdraws, as in synchronous rounds. A reservation that no
  other robot can rival (every robot next to the cell known to have decided for
  good, :meth:`~mrmp.robot.pibt_local.LocalPibtRobot._uncontested`) is final at
  once, as in synchronous rounds: the robot knows every robot within 2 cells
  before it claims;
* a call never takes the cell of a robot busy in the same call (no
  rotations): a step can end before such a call has finished, and the robot
  whose cell was taken would then stay;
* the reach of a stalled robot does not grow (``reach_cap`` 0): the beacon
  and the final reservation go to the radio radius only;
* a robot asked to join a call first waits for every robot within 2 cells
  that outranks the call and has not decided for good, other than robots of
  that call (:attr:`ReliablePibtRobot.waits_to_join`): over a lossy network a
  call started apart could otherwise take the cell that a robot of higher
  rank wants, which central PIBT lets go first (``docs/protocol.md``, "Over a
  faulty network", gives why no robot waits forever);
* the claim of its own cell by the robot asked to leave it is no rival claim
  (:meth:`_take_ack`, and :class:`~mrmp.robot.pibt_local.LocalPibtRobot`'s
  reservations): the asker waits for its answer, in whatever order the two
  come.

The step ends at a tick the driver's clock fixes for everyone; a robot that
has decided for good moves, any other stays (an abandoned step, counted).
Every robot moving into a cell knows its occupant decided for good to leave
(its final reservation or its answer), and decided reservations are unique,
so the moves are safe whatever was lost. Counted by the robot: ``acks``,
``retransmissions``, ``stale`` and ``duplicate`` (in ``dropped``), with the
counts of :class:`~mrmp.robot.pibt_local.LocalPibtRobot`.

Examples
--------
Two robots, and a network that loses every other datagram: the timers send
again what was lost, and both decide.

>>> from mrmp.core.grid import Grid
>>> from mrmp.search.flat_map import FlatMap
>>> flat = FlatMap(Grid.from_rows(["#.#", "..."]))
>>> a = ReliablePibtRobot(0, flat.index((0, 0)), flat.index((0, 2)), flat, tie=2)
>>> b = ReliablePibtRobot(1, flat.index((0, 1)), flat.index((0, 0)), flat, tie=1)
>>> robots = (a, b)
>>> sent = [(0, item) for item in a.begin_step(1, sensed=[b.present])]
>>> sent += [(1, item) for item in b.begin_step(1, sensed=[a.present])]
>>> datagrams = 0
>>> for now in range(1, 20):
...     for sender, item in sent:
...         datagrams += 1
...         if datagrams % 2 == 0:
...             _ = robots[1 - sender].receive(item.message)
...     sent = [(robot.index, item) for robot in robots for item in robot.act() + robot.on_tick(now)]
>>> a.final and b.final, [flat.cell(robot.finish_step()) for robot in robots], a.stats["retransmissions"] > 0
(True, [(0, 1), (1, 1)], True)
"""

from __future__ import annotations

import random
from collections.abc import Iterable

from mrmp.core.heading import Heading
from mrmp.protocol.messages import BeaconMessage, PibtMessage, PullMessage
from mrmp.protocol.pibt_local import NO_CLAIM, CallAckMessage, CallInheritMessage, CallReserveMessage
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_local import NO_RANK, LocalPibtRobot
from mrmp.robot.pibt_robot import MIN_RADIUS, RESERVE_RADIUS
from mrmp.search.flat_map import FlatMap

__all__ = ["ReliablePibtRobot"]


class _Unacknowledged:
    """A message sent and not yet acknowledged by every recipient it must reach."""

    __slots__ = ("item", "pending", "sent_at")

    def __init__(self, item: Outgoing, pending: set[int], sent_at: int) -> None:
        self.item = item
        self.pending = pending
        self.sent_at = sent_at


class ReliablePibtRobot(LocalPibtRobot):
    """A :class:`~mrmp.robot.pibt_local.LocalPibtRobot` with acknowledgements and timers (module docstring).

    Parameters are those of :class:`~mrmp.robot.pibt_robot.PibtRobot`, and:

    retry:
        Ticks to wait for an acknowledgement before sending a message again
        (at least 1; ``2 * delay_max + 1`` covers a round trip).
    beacon_retry:
        The same for the step's beacon (by default ``retry``). A copy of a
        beacon goes to every peer near that has not acknowledged it, and a peer
        whose own beacon was not acknowledged answers it with that beacon
        (:class:`~mrmp.robot.pibt_live.LivePibtRobot`), so a live robot sends
        it again less eagerly than a call's messages, each to one peer.
    """

    rotations = False

    preempts = False
    """No wound-wait (:attr:`~mrmp.robot.pibt_local.LocalPibtRobot.preempts`): a call that meets a robot busy in
    another call passes its cell by, as before."""

    reach_cap = 0
    """The reach stays the radio radius: only robots within 2 cells acknowledge a final reservation, so a robot
    farther away that waited for it could wait in vain for the rest of the step (and an abandoned step, counted
    as a stall, would widen the reach further)."""

    def __init__(
        self,
        index: int,
        start: int,
        goal: int,
        flat: FlatMap,
        *,
        tie: int = 0,
        heading: Heading = Heading.NORTH,
        radius: int = MIN_RADIUS,
        swap: bool = True,
        heading_aware: bool = False,
        turn_cost: float = 0.5,
        rng: random.Random | None = None,
        tie_penalties: bool | None = None,
        turning: bool = False,
        dead_end_bonus: int = 0,
        guidance: str = "none",
        retry: int = 1,
        beacon_retry: int | None = None,
    ) -> None:
        super().__init__(
            index, start, goal, flat, tie=tie, heading=heading, radius=radius, swap=swap,
            heading_aware=heading_aware, turn_cost=turn_cost, rng=rng, tie_penalties=tie_penalties,
            turning=turning, dead_end_bonus=dead_end_bonus, guidance=guidance,
        )  # fmt: skip
        beacon_retry = retry if beacon_retry is None else beacon_retry
        if min(retry, beacon_retry) < 1:
            raise ValueError(f"retry {min(retry, beacon_retry)} is below 1 tick")
        self.retry = retry
        self.beacon_retry = beacon_retry
        self._now = 0
        self._sensed: tuple[int, ...] = ()
        self._unacknowledged: dict[int, _Unacknowledged] = {}
        self._beacon_seq = 0
        self._beacon_sent_at = 0
        self._beacon_gap = beacon_retry
        """How long after the beacon was last sent it is sent again (:attr:`longest_beacon_gap`)."""
        self._beacon_acks: set[int] = set()
        self._replies: list[Outgoing] = []
        self._deferred = False
        self._claim_seq = 0
        self._latest: dict[int, int] = {}
        self._requests_waiting: list[CallInheritMessage] = []

    # -- the step ------------------------------------------------------------------

    def begin_step(self, step: int, sensed: Iterable[int] = (), now: int = 0) -> list[Outgoing]:
        """Start step ``step`` at tick ``now``; ``sensed``: the cells within 2 that hold a body (the robot's sensor)."""
        out = super().begin_step(step)
        self._now = now
        self._sensed = tuple(cell for cell in sensed if cell != self.present)
        self._unacknowledged = {}
        self._beacon_seq = self.seq
        self._beacon_sent_at = now
        self._beacon_gap = self.beacon_retry
        self._beacon_acks = set()
        self._replies = []
        self._deferred = False
        self._claim_seq = 0
        self._latest = {}
        self._requests_waiting = []
        return out

    def on_tick(self, now: int) -> list[Outgoing]:
        """The robot's timers at tick ``now``: send again what was not acknowledged within ``retry`` ticks (the
        beacon: ``beacon_retry``)."""
        self._now = now
        out: list[Outgoing] = []
        if not self._beacon_heard() and now - self._beacon_sent_at >= self._beacon_gap:
            self._beacon_sent_at = now
            self._beacon_gap = min(2 * self._beacon_gap, self.longest_beacon_gap * self.beacon_retry)
            self.stats["retransmissions"] += 1
            out.append(Outgoing(self._beacon(), None, self.reach))
        for entry in self._unacknowledged.values():
            if entry.pending and now - entry.sent_at >= self.retry:
                entry.sent_at = now
                self.stats["retransmissions"] += len(entry.pending)
                out.append(Outgoing(entry.item.message, tuple(sorted(entry.pending))))
        return out

    def _beacon(self) -> BeaconMessage:
        cells = self.flat.cells
        return BeaconMessage(
            self.index, self._beacon_seq, self.step, cells[self.present], cells[self.goal], self.elapsed, self.tie,
            self.heading,
        )  # fmt: skip

    def _beacon_heard(self) -> bool:
        """Every body within 2 cells is a robot whose beacon arrived and who acknowledged ours."""
        occupants, acks = self._occupants, self._beacon_acks
        return all(occupants.get(cell) in acks for cell in self._sensed)

    def _complete(self) -> bool:
        """The robot knows who stands on every cell within 2 that holds a body."""
        occupants = self._occupants
        return all(cell in occupants for cell in self._sensed)

    # -- receiving -----------------------------------------------------------------

    def receive(self, message: PibtMessage) -> bool:
        """Take in a message of this step (acknowledging it, second copies too, a beacon only if
        :attr:`acknowledges_beacons`); True when :meth:`act` should run."""
        if message.step != self.step:
            self.dropped["stale"] += 1
            return False
        if isinstance(message, CallAckMessage):
            return self._take_ack(message)
        if self.acknowledges_beacons or not isinstance(message, BeaconMessage):
            self._acknowledge(message)
        key = (message.sender, message.seq)
        if key in self._seen:
            self.dropped["duplicate"] += 1
            return True  # the acknowledgement goes out in act
        self._seen.add(key)
        if isinstance(message, CallReserveMessage | CallInheritMessage):  # both say what the sender reserved
            if message.seq < self._latest.get(message.sender, 0):
                self.dropped["overtaken"] += 1  # a later reservation of the sender arrived first
                return True
            self._latest[message.sender] = message.seq
        self.receive_once(message)
        return True

    acknowledges_beacons = True
    """Whether a beacon is acknowledged like any other message; the live brain asks for a missing beacon instead
    (:class:`~mrmp.robot.pibt_live.LivePibtRobot`)."""

    longest_beacon_gap = 1
    """In a step, the beacon is sent again ``beacon_retry`` after it was sent, then at gaps doubling up to this
    many times ``beacon_retry`` (1: every ``beacon_retry``)."""

    def _acknowledge(self, message: PibtMessage) -> None:
        """Queue the acknowledgement of ``message``, with this robot's reservation (sent in :meth:`act`)."""
        claim = self.target
        cell = self.flat.cells[claim] if claim is not None else NO_CLAIM
        root, (elapsed, tie, _) = self._root, self._rank
        self.seq += 1
        ack = CallAckMessage(self.index, self.seq, self.step, message.seq, cell, root, elapsed, tie, self._confirmed)
        self._replies.append(Outgoing(ack, (message.sender,)))
        self.stats["acks"] += 1

    def _take_ack(self, message: CallAckMessage) -> bool:
        """An acknowledgement: its sender has the message; its claim, of higher rank, of the cell this robot claims
        provisionally makes the robot withdraw (unless it is the claim to stay of the robot asked to leave)."""
        sender = message.sender
        if message.acked == self._beacon_seq:
            self._beacon_acks.add(sender)
        entry = self._unacknowledged.get(message.acked)
        if entry is not None:
            entry.pending.discard(sender)
        if message.claim != NO_CLAIM and not self._confirmed and self.target is not None:
            cell = self.flat.index(message.claim)
            if cell == self.target and cell != self.present and sender not in (self.index, self._waiting):
                theirs = (message.settled, self._occupants.get(cell) == sender, message.rank)
                if theirs > (False, False, self._rank):
                    self._lost = True  # a call of higher priority claims our cell: withdraw
                    self._reserved[cell] = sender
        return True

    # -- acting --------------------------------------------------------------------

    def act(self) -> list[Outgoing]:
        """:meth:`LocalPibtRobot.act`, then the acknowledgements owed; messages to acknowledge are remembered."""
        out: list[Outgoing] = []
        if self._deferred and self._complete():
            self._deferred = False
            super()._begin_call(out)
        if self._requests_waiting:
            self._take_waiting_requests(out)
        out.extend(super().act())
        if self._requests_waiting and not self._idle():
            self._take_waiting_requests(out)  # busy now, in its own call or another: refused
        self._track(out)
        if not self._confirmed and self._may_confirm():  # nobody within 2 cells to hear the claim: it stands at once
            settled = super().act()
            self._track(settled)
            out.extend(settled)
        replies, self._replies = self._replies, []
        return replies + out

    def _track(self, out: list[Outgoing]) -> None:
        """Remember what ``out`` sends until acknowledged: named recipients, or the known robots within 2 cells."""
        now = self._now
        for item in out:
            message = item.message
            pending = set(item.recipients) if item.recipients is not None else self._known_within(RESERVE_RADIUS)
            self._unacknowledged[message.seq] = _Unacknowledged(item, pending, now)

    def _known_within(self, radius: int) -> set[int]:
        cells = self.flat.cells
        x, y = cells[self.present]
        return {
            robot
            for cell, robot in self._occupants.items()
            if robot != self.index and abs(cells[cell][0] - x) + abs(cells[cell][1] - y) <= radius
        }

    def _may_confirm(self) -> bool:
        """Every robot within 2 cells acknowledged the provisional reservation (no conflict came back)."""
        entry = self._unacknowledged.get(self._claim_seq)
        return entry is not None and not entry.pending  # None: sent in this very act, not yet out

    def _may_start(self) -> bool:
        return self._complete() and super()._may_start()

    waits_to_join = True
    """Whether a robot asked to join a call first waits for every robot near it that outranks the call (module
    docstring); meanwhile it may start its own call or join one of higher rank, and it refuses the request once busy."""

    def _may_join(self, message: CallInheritMessage) -> bool:
        """Every robot within 2 cells that outranks the call of ``message`` has decided for good, or is in that call."""
        rank, root, asker = message.rank, message.root, message.sender
        final, ranks, calls = self._final, self._ranks, self._calls
        for other in self._near:
            if other in final or other in (asker, root) or calls.get(other) == root:
                continue
            if ranks.get(other, NO_RANK) > rank:
                return False
        return True

    def _take_inherit_local(self, message: CallInheritMessage, out: list[Outgoing]) -> None:
        """A request to join a call: kept until the robot may join it (:attr:`waits_to_join`), then as in synchronous
        rounds."""
        if self.waits_to_join and self._idle() and not self._done and not (self._complete() and self._may_join(message)):
            self._requests_waiting.append(message)
            self.stats["join_waits"] += 1
            return
        super()._take_inherit_local(message, out)

    def _take_waiting_requests(self, out: list[Outgoing]) -> None:
        """Take up the requests that wait (:attr:`waits_to_join`), the call of highest rank first: joined, refused
        when busy, or kept waiting."""
        waiting, self._requests_waiting = self._requests_waiting, []
        for message in sorted(waiting, key=lambda message: message.rank, reverse=True):
            self._take_inherit_local(message, out)

    def _begin_call(self, out: list[Outgoing]) -> None:
        if not self._complete():
            self._deferred = True  # asked before every neighbour is known: decide once they are
            return
        super()._begin_call(out)

    def _take_pull_local(self, message: PullMessage, out: list[Outgoing]) -> None:
        if self._complete():  # else it could take a cell whose claimants it does not all know
            super()._take_pull_local(message, out)

    reconsiders_at_every_decision = True  # acknowledgements, crashed peers and the live lookout also tell decisions

    def _reservation(self, message: CallReserveMessage, final: bool) -> Outgoing:
        """By radio to every robot within 2 cells (the radio radius when final): each acknowledges, with its claim."""
        return Outgoing(message, None, self.reach if final else RESERVE_RADIUS)

    def _reserve(self, cell: int, out: list[Outgoing], final: bool = False) -> None:
        super()._reserve(cell, out, final)
        if not final:
            self._claim_seq = self.seq
