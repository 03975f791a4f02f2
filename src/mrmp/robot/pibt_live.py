"""Locally sequenced PIBT for robots that cannot see each other: the sans-IO brain of ``pibt --live``.

:class:`~mrmp.robot.pibt_reliable.ReliablePibtRobot` (acknowledgements and
timers in the manner of Awerbuch's α synchronizer, J. ACM 32(4), 1985) needs a
sensor that tells it which cells within 2 hold a body at the start of a step.
A live process has no such sensor. :class:`LivePibtRobot` derives it from what
it knows instead (``docs/protocol.md``, "Local sequencing", "Live"):

* it keeps, for every peer, the cell it last heard of and the step at whose
  start the peer stood there (every robot's start cell, at step 1, to begin
  with). A robot moves at most one cell per step, so a peer last known at cell
  ``c`` at step ``s`` is, at the start of step ``k``, within ``k - s`` cells of
  ``c``: it can be within ``r`` cells only if ``|c - here| <= r + k - s``;
* every broadcast of radius ``r`` goes to exactly those peers (a superset of
  the robots truly within ``r``); the step's beacon goes ``lookout`` cells
  further, so the robots about to come near stay known freshly. At the start of a step the robot waits
  for this step's beacon of every peer that can be within its radio radius
  before it starts or joins a call; the cells within 2 of those beacons are
  what a sensor would have seen;
* beacons are not acknowledged: a robot that waits for a peer's beacon sends
  its own to that peer again, every ``beacon_retry`` (or at gaps doubling up
  to ``longest_beacon_gap`` times that), marked as *asking*
  for the peer's; a robot answers such a beacon of this step, or one from a
  peer it did not send its own to, with its beacon (*pulling*). So the robot
  that needs a beacon keeps asking until it has it, and a peer that has this
  robot's beacon is sent nothing more;
* messages of a later step (a peer whose clock runs a little ahead) are kept
  until the robot's own step begins;
* its beacon tells *news* (:class:`~mrmp.protocol.pibt_local.NewsBeaconMessage`):
  where the peers it heard of at the start of this step or the last stood,
  as heard, so that its neighbours learn of the robots around it without
  hearing each of them, and wait for and address fewer peers. Each entry is
  a fact of the form above, so the bound still holds.

A robot whose body has not yet been allowed into the cell it decided on in an
earlier step is *held* (:meth:`LivePibtRobot.begin_step`): it neither starts a
call nor answers a request to leave its cell until its body is allowed in
(:meth:`LivePibtRobot.release`: then it goes on as if nothing had happened);
if that does not come in time (:meth:`LivePibtRobot.give_up`), it refuses the
requests and, at its turn, stays. So a robot leaves a cell in a step only when
its body owns that cell already (``docs/protocol.md`` gives why this keeps the
bodies' execution free of deadlocks). A peer silent for long is taken for crashed (:meth:`LivePibtRobot.crash`): an
obstacle on its last known cell, no longer waited for. Counted: ``crashed``, ``held`` (steps begun held),
``gave_up`` (steps in which the grant did not come in time) and ``pulled``
(beacons sent again to answer a peer's).

Examples
--------
Two robots that start five cells apart know it from the scenario: neither waits
for the other in step 1, and each addresses only peers that can be near.

>>> from mrmp.core.grid import Grid
>>> from mrmp.search.flat_map import FlatMap
>>> flat = FlatMap(Grid(6, 1))
>>> a = LivePibtRobot(0, flat.index((0, 0)), flat.index((1, 0)), flat, starts=[flat.index((0, 0)), flat.index((5, 0))])
>>> [item.recipients for item in a.begin_step(1)], a.possibly_within(2)
([()], [])
>>> [flat.cell(cell) for cell in (a.target,)] if a.act() else None  # it decides alone, at once
[(1, 0)]

Five steps later the peer can be anywhere within 5 + 2 cells: robot 0 waits
for its beacon before it starts.

>>> a.present, a.step = flat.index((0, 0)), 5
>>> _ = a.begin_step(6)
>>> a.possibly_within(2), a.complete
([1], False)
"""

from __future__ import annotations

import random
from collections.abc import Iterable, Sequence

import numpy as np

from mrmp.core.heading import Heading
from mrmp.protocol.messages import AnswerMessage, BeaconMessage, PibtMessage, PullMessage
from mrmp.protocol.pibt_local import MAX_NEWS, CallInheritMessage, News, NewsBeaconMessage
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_reliable import ReliablePibtRobot
from mrmp.robot.pibt_robot import MIN_RADIUS, RESERVE_RADIUS
from mrmp.search.flat_map import FlatMap

__all__ = ["KnownCells", "LivePibtRobot"]


class KnownCells:
    """Where each peer was last known to stand, and at the start of which step, as arrays indexed by peer.

    :meth:`within` answers :meth:`LivePibtRobot.possibly_within`'s question for
    every peer at once: a peer last known at ``(px, py)`` at the start of step
    ``heard`` can stand within ``radius`` cells of ``(x, y)`` at the start of
    step ``step`` only if ``|px - x| + |py - y| <= radius + max(0, step - heard)``.

    >>> known = KnownCells()
    >>> known.set(3, (0, 6), 1); known.set(1, (0, 1), 4)
    >>> known.within((0, 0), 2, 4), known.within((0, 0), 2, 7)   # peer 3 can have come 6 cells closer by step 7
    ([1], [1, 3])
    """

    def __init__(self) -> None:
        self._x = np.zeros(0, dtype=np.int64)
        self._y = np.zeros(0, dtype=np.int64)
        self._heard = np.zeros(0, dtype=np.int64)
        self._known = np.zeros(0, dtype=bool)

    def set(self, peer: int, cell: tuple[int, int], step: int) -> None:
        """``peer`` stood on ``cell`` at the start of ``step``."""
        if peer >= len(self._known):
            size = max(peer + 1, 2 * len(self._known))
            self._x, self._y, self._heard = (np.resize(array, size) for array in (self._x, self._y, self._heard))
            known = np.zeros(size, dtype=bool)
            known[: len(self._known)] = self._known
            self._known = known
        self._x[peer], self._y[peer], self._heard[peer], self._known[peer] = cell[0], cell[1], step, True

    def can_be_within(self, peer: int, here: tuple[int, int], radius: int, step: int) -> bool:
        """Whether ``peer`` (known) can stand within ``radius`` cells of ``here`` at the start of ``step``: the bound
        of :meth:`within`, for one peer.

        >>> known = KnownCells()
        >>> known.set(3, (0, 6), 1)
        >>> known.can_be_within(3, (0, 0), 2, 4), known.can_be_within(3, (0, 0), 2, 5)
        (False, True)
        """
        distance = abs(int(self._x[peer]) - here[0]) + abs(int(self._y[peer]) - here[1])
        return distance <= radius + max(0, step - int(self._heard[peer]))

    def within(self, here: tuple[int, int], radius: int, step: int) -> list[int]:
        """The peers that can stand within ``radius`` cells of ``here`` at the start of ``step``, in index order."""
        distance = np.abs(self._x - here[0]) + np.abs(self._y - here[1])
        reach = radius + np.maximum(0, step - self._heard)
        return [int(peer) for peer in np.flatnonzero(self._known & (distance <= reach))]


class LivePibtRobot(ReliablePibtRobot):
    """A :class:`ReliablePibtRobot` that knows, instead of sensing, which robots can be near (module docstring).

    Parameters are those of :class:`~mrmp.robot.pibt_reliable.ReliablePibtRobot`, and:

    starts:
        Every robot's start cell (flat index), by robot index: where each
        stands at the start of step 1. Without it the robot knows nobody
        (:meth:`meet` adds what it knows).
    lookout:
        The step's beacon goes this many cells further than the radio radius
        (widened by what each peer can have driven), so that the robots about
        to come near are known freshly and seldom have to be waited for.
    """

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
        starts: Sequence[int] = (),
        lookout: int = 2,
    ) -> None:
        super().__init__(
            index, start, goal, flat, tie=tie, heading=heading, radius=radius, swap=swap,
            heading_aware=heading_aware, turn_cost=turn_cost, rng=rng, tie_penalties=tie_penalties,
            turning=turning, dead_end_bonus=dead_end_bonus, guidance=guidance, retry=retry, beacon_retry=beacon_retry,
        )  # fmt: skip
        self.known: dict[int, tuple[int, int]] = {}
        """Per peer: the cell it was last heard of, and the step at whose start it stood there."""
        self._known_cells = KnownCells()
        """:attr:`known` as arrays, for :meth:`possibly_within` over a large fleet in one pass."""
        self.held = False
        """Whether the robot may not leave its cell in this step (its body does not own it yet)."""
        self.lookout = lookout
        self._unknown: set[int] = set()
        self._early: list[PibtMessage] = []
        self._beacon_to: set[int] = set()
        self._gave_up = False
        self._asked: list[CallInheritMessage] = []
        self._news: tuple[News, ...] = ()
        self.crashed: dict[int, int] = {}
        """Peers taken for crashed (:meth:`crash`), by the cell each was last known on."""
        self.departed: set[int] = set()
        """Peers whose run is over (:meth:`depart`): taken for crashed for good."""
        self.meet(starts)

    def meet(self, starts: Sequence[int], step: int = 1) -> None:
        """Know every robot's cell at the start of ``step`` (by robot index; this robot's own is skipped)."""
        for peer, cell in enumerate(starts):
            if peer != self.index:
                self.learn(peer, cell, step)

    def learn(self, peer: int, cell: int, step: int) -> None:
        """Know that ``peer`` stood on ``cell`` at the start of ``step`` (older news than what is known is ignored).

        A peer waited for that this news puts out of reach is no longer waited
        for: the robot's beacon, sent again while it waits, goes only to the
        peers that can be near, so a peer that fresher news (a fleet heartbeat)
        put farther away would never get it, and never answer with its own.
        """
        old = self.known.get(peer)
        if old is None or step >= old[1]:
            self.known[peer] = (cell, step)
            self._known_cells.set(peer, self.flat.cells[cell], step)
        if peer in self._unknown and not self._may_be_within(peer, max(self.radius, RESERVE_RADIUS)):
            self._unknown.discard(peer)
            self.wake = True

    def _may_be_within(self, peer: int, radius: int) -> bool:
        """Whether ``peer`` can stand within ``radius`` cells at the start of this step (as :meth:`possibly_within`)."""
        return self._known_cells.can_be_within(peer, self.flat.cells[self.present], radius, self.step)

    def _fresh_news(self) -> tuple[News, ...]:
        """What this step's beacon tells of others: where the peers heard of since the last step's start stood.

        At most :data:`~mrmp.protocol.pibt_local.MAX_NEWS` of them, the
        nearest first; nothing of a peer taken for crashed.
        """
        cells, step = self.flat.cells, self.step
        x, y = cells[self.present]
        fresh = [
            (abs(cells[cell][0] - x) + abs(cells[cell][1] - y), peer, cell, heard)
            for peer, (cell, heard) in self.known.items()
            if step - 1 <= heard <= step and peer not in self.crashed
        ]
        fresh.sort()
        return tuple((peer, cells[cell], heard) for _, peer, cell, heard in fresh[:MAX_NEWS])

    def _beacon(self, asks: bool = False) -> NewsBeaconMessage:
        """This step's beacon, with the news it tells (:meth:`_fresh_news`, chosen when the step began);
        ``asks``: for the beacons of the peers it goes to (sent again to the peers waited for)."""
        beacon = super()._beacon()
        return NewsBeaconMessage(
            beacon.sender, beacon.seq, beacon.step, beacon.present, beacon.goal, beacon.elapsed, beacon.tie,
            beacon.heading, self._news, asks,
        )  # fmt: skip

    def possibly_within(self, radius: int) -> list[int]:
        """The peers that can stand within ``radius`` cells at the start of this step (module docstring)."""
        near = self._known_cells.within(self.flat.cells[self.present], radius, self.step)
        crashed = self.crashed
        return [peer for peer in near if peer not in crashed] if crashed else near

    @property
    def complete(self) -> bool:
        """Whether this step's beacon of every peer that can be within the radio radius has arrived."""
        return self._complete()

    @property
    def heard_later_step(self) -> bool:
        """Whether a message of a later step than this one waits for its step (a peer is ahead)."""
        return bool(self._early)

    # -- the step ------------------------------------------------------------------

    def begin_step(self, step: int, sensed: Iterable[int] = (), now: int = 0, held: bool = False) -> list[Outgoing]:
        """Start step ``step`` at time ``now``; ``held``: the body does not own its cell yet (module docstring).

        ``sensed`` is ignored: a live robot senses no other body; which cells
        hold one follows from this step's beacons of the peers that can be near.
        """
        self.held, self._gave_up, self._asked = held, False, []
        if held:
            self.stats["held"] += 1
        super().begin_step(step, (), now)  # its one message, the step's beacon, goes out below: with news, by name
        self._news = self._fresh_news()
        lookout = tuple(self.possibly_within(self.radius + self.lookout))
        out = [Outgoing(self._beacon(), lookout)]
        self._beacon_to = set(lookout)
        self._unknown = set(self.possibly_within(max(self.radius, RESERVE_RADIUS)))
        for peer, cell in self.crashed.items():
            self._obstacle(peer, cell)
        early, self._early = self._early, []
        for message in early:
            if message.step == step:
                self.receive(message)
            else:
                self.dropped["stale"] += 1
        return out

    def crash(self, peer: int) -> None:
        """Take ``peer`` for crashed: an obstacle on the cell it was last known on, waited for and addressed no more."""
        known = self.known.get(peer)
        if known is None or peer in self.crashed:
            return
        self.crashed[peer] = known[0]
        self.stats["crashed"] += 1
        self._unknown.discard(peer)
        for entry in self._unacknowledged.values():
            entry.pending.discard(peer)
        self._obstacle(peer, known[0])
        self.wake = True

    def revive(self, peer: int) -> None:
        """``peer``, taken for crashed, was heard again: from the next step on it is a robot like the others
        (unless it said farewell: :meth:`depart`; what is heard of it after that is a late copy)."""
        if peer not in self.departed:
            self.crashed.pop(peer, None)

    def depart(self, peer: int, cell: int) -> None:
        """``peer``'s run is over, on ``cell``: an obstacle there for good, waited for and addressed no more.

        >>> from mrmp.core.grid import Grid
        >>> from mrmp.search.flat_map import FlatMap
        >>> flat = FlatMap(Grid(4, 1))
        >>> a = LivePibtRobot(0, 0, 3, flat, starts=[0, 2])
        >>> a.depart(1, 2); a.revive(1)
        >>> a.crashed, a.possibly_within(4)
        ({1: 2}, [])
        """
        self.departed.add(peer)
        self.crashed.pop(peer, None)
        self.learn(peer, cell, self.step)
        self.crash(peer)

    def _obstacle(self, peer: int, cell: int) -> None:
        """``peer`` stands on ``cell`` for good this step: occupied, reserved by it, decided, settled there."""
        self._occupants[cell] = peer
        self._goals[peer] = cell
        self._settled.add(cell)
        self._reserved[cell] = peer
        self._targets[peer] = cell
        self._final.add(peer)

    def _known_within(self, radius: int) -> set[int]:
        return super()._known_within(radius) - self.crashed.keys()

    def release(self) -> None:
        """The body now owns the cell the robot stands on (its last move was allowed): it may take part in calls."""
        if self.held:
            self.held = False
            self.wake = True

    def on_tick(self, now: int) -> list[Outgoing]:
        """:meth:`ReliablePibtRobot.on_tick`, its broadcasts addressed to the peers that can be near; the beacon
        sent again only to the peers whose beacon it waits for, and asking for theirs.

        Beacons are not acknowledged (:attr:`acknowledges_beacons`): a peer
        that needs this robot's beacon waits for it and asks for it in turn, so
        the robot that waits does the asking, and a peer that has the beacon
        is sent nothing more.
        """
        out = self._address(super().on_tick(now))
        for index, item in enumerate(out):
            if isinstance(item.message, BeaconMessage):
                awaited = tuple(sorted(self._unknown))
                out[index] = Outgoing(self._beacon(asks=True), awaited)
                self._beacon_to.update(awaited)
        return [item for item in out if item.recipients != ()]

    def _address(self, out: list[Outgoing]) -> list[Outgoing]:
        """Turn every radius broadcast into a message to the peers that can be within the radius."""
        addressed = []
        for item in out:
            if item.recipients is None and item.radius is not None:
                item = Outgoing(item.message, tuple(self.possibly_within(item.radius)))
            addressed.append(item)
        return addressed

    # -- receiving -----------------------------------------------------------------

    def receive(self, message: PibtMessage) -> bool:
        """Keep a message of a later step for that step; learn where a beacon's sender stands; then as the parent."""
        if message.step > self.step:
            self._early.append(message)
            return False
        if isinstance(message, BeaconMessage) and message.sender != self.index:
            sender = message.sender
            cell = self.flat.index(message.present)
            self.learn(sender, cell, message.step)
            if isinstance(message, NewsBeaconMessage):
                self._take_news(message.news)
            if message.step == self.step:
                self._take_step_beacon(sender, cell, asks=isinstance(message, NewsBeaconMessage) and message.asks)
        return super().receive(message)

    def _take_news(self, news: tuple[News, ...]) -> None:
        """Learn where a beacon's sender heard its peers stood (:meth:`learn`).

        News of a step later than the robot's own is not taken: where a peer
        stood later does not bound where it stands now. Nor is news of a
        robot the fleet does not have, or of a cell off the map (counted
        ``bad_news``).
        """
        known, step = self.known, self.step
        for peer, place, heard in news:
            if peer == self.index or heard > step:
                continue
            cell = self.flat.index_on_grid(place)
            if peer not in known or cell is None:
                self.dropped["bad_news"] += 1
                continue
            self.learn(peer, cell, heard)

    def _take_step_beacon(self, sender: int, cell: int, asks: bool) -> None:
        """This step's beacon of ``sender``: one peer fewer to wait for, a body within 2 if it is.

        Answered with this robot's beacon when ``sender`` was not sent it, or
        ``asks`` for it (it still waits for ours).
        """
        if sender in self._unknown:
            self._unknown.discard(sender)
            x, y = self.flat.cells[self.present]
            px, py = self.flat.cells[cell]
            if abs(px - x) + abs(py - y) <= RESERVE_RADIUS and cell not in self._sensed:
                self._sensed = (*self._sensed, cell)
        if sender not in self._beacon_to or asks:
            self.stats["pulled"] += 1
            self._beacon_to.add(sender)
            self._replies.append(Outgoing(self._beacon(), (sender,)))

    def receive_beacons(self, beacons: list[BeaconMessage]) -> None:
        """As the parent, but only the robots within the radio radius count as near (the start rule waits for them):
        a beacon that looks further (``lookout``) comes from robots whose final reservation may not reach this one."""
        before = len(self._near)
        super().receive_beacons(beacons)
        x, y = self.flat.cells[self.present]
        self._near[before:] = [
            message.sender
            for message in beacons
            if abs(message.present[0] - x) + abs(message.present[1] - y) <= self.radius
        ]

    def _complete(self) -> bool:
        return not self._unknown and super()._complete()

    acknowledges_beacons = False  # a robot asks for the beacon it waits for instead (on_tick)

    def _beacon_heard(self) -> bool:
        """Every beacon it waits for has come: its own is sent again only to ask for those (:meth:`on_tick`)."""
        return not self._unknown

    # -- a held robot waits for its grant, then stays -----------------------------

    def give_up(self) -> None:
        """The grant did not come in time: a held robot refuses what it was asked and, at its turn, stays."""
        if self.held and not self._gave_up:
            self._gave_up = True
            self.wake = True
            self.stats["gave_up"] += 1

    def act(self) -> list[Outgoing]:
        """:meth:`ReliablePibtRobot.act`, requests kept while held taken up (or refused), broadcasts addressed."""
        out: list[Outgoing] = []
        if self._asked and (not self.held or self._gave_up):
            asked, self._asked = self._asked, []
            if self.held:
                for message in asked:
                    self.stats["refused"] += 1
                    out.append(Outgoing(AnswerMessage(self.index, self._seq(), self.step, False), (message.sender,)))
                self._track(out)
            else:
                self._control.extend(asked)
        return self._address(out + super().act())

    def _take_inherit_local(self, message: CallInheritMessage, out: list[Outgoing]) -> None:
        if self.held and not self._gave_up:
            self._asked.append(message)  # answered once the grant comes, or refused when it does not
            return
        if self.held:
            self.stats["refused"] += 1  # it cannot leave its cell this step: the asker tries its next cell
            out.append(Outgoing(AnswerMessage(self.index, self._seq(), self.step, False), (message.sender,)))
            return
        super()._take_inherit_local(message, out)

    def _take_pull_local(self, message: PullMessage, out: list[Outgoing]) -> None:
        if not self.held:
            super()._take_pull_local(message, out)

    def _may_start(self) -> bool:
        return (not self.held or self._gave_up) and super()._may_start()

    def _begin_call(self, out: list[Outgoing]) -> None:
        if self.held and self._parent is None:
            self._claim(self.present, False, out)  # its turn came while held: it stays, as a call with no cell left does
            return
        super()._begin_call(out)
