"""PIBT whose calls the robots sequence themselves: the sans-IO brain of ``pibt`` with local sequencing.

:class:`~mrmp.robot.pibt_robot.PibtRobot` decides as central PIBT (Okumura,
Machida, Défago and Tamura, IJCAI 2019; AIJ 310, 2022) when a driver starts
the robots one at a time in priority order. :class:`LocalPibtRobot` needs no
such driver: every robot decides *itself* when its call starts, from what its
neighbours told it, and several calls run at once in different parts of the
map. The step runs in synchronous rounds (Lynch, *Distributed Algorithms*,
1996, ch. 2: every robot takes in what was sent to it in the round before,
then acts):

1. every robot broadcasts its beacon (cell, goal, priority) to the robots
   within its radio radius (at least 2 cells);
2. a robot that has not decided and was not asked to decide *starts its own
   call* (it becomes a *root*) in the first round in which every robot whose
   beacon it heard and that has a higher priority has decided for good (its
   final reservation reaches as far as its beacon), and no robot within 2
   cells is in the middle of a call (it holds a provisional reservation).
   Everything a call reads lies within 2 cells of the robots it reaches, and a
   call reaches robots only through their neighbours, so this is the local form
   of "the highest-priority robot that has not decided starts" (exactly that
   when the radius covers the map). A beacon reaches the robot's *reach*: the
   radio radius, grown by one cell for every step beyond ``stall_slack`` that
   the robot has *stalled* (ended a step no nearer its goal, away from it; with
   ``stall_from_best``, no nearer than it has ever been), up to ``reach_cap``
   cells. So the robots around a robot that is stuck wait for its call,
   which then pushes them in the order central PIBT would, farther
   than 2 cells; a robot that advances keeps the radio radius. The cap bounds
   what one robot sends in a step independently of the number of robots;
3. an asked robot (priority inheritance, :class:`CallInheritMessage`) decides
   at once, within the call of the robot that asked (its *root*), as in PIBT;
4. a reservation (:class:`CallReserveMessage`, to every robot within 2
   cells, and when final also to the robots within the radius that the robot
   outranks; by name, leaving out the robots known to have decided for good,
   which ignore it) is *provisional* for one round: two calls can reserve the same cell
   only in the same round (a robot that reserves a cell has heard every
   earlier reservation of it, since both reservers stand next to the cell and
   so within 2 cells of each other). In the next round both hear of it; the
   call of lower priority withdraws and tries its next cell; staying on one's
   own cell always wins (whoever reserved it asked its occupant, who refuses),
   except against a call of higher priority that takes the occupant over (7).
   A robot that has decided and whose reservation survived its round says so:
   the same reservation, marked *final*, and the answer to its parent. A
   reservation that no other robot can rival is final at once: every robot
   standing next to the cell (only those can claim it) is known to have
   decided for good (:meth:`LocalPibtRobot._uncontested`);
5. a robot treats the cell of a neighbour as free to take only when that
   neighbour's reservation elsewhere is final, or the neighbour is in the same
   call (PIBT's rotations);
6. at the end of the step a robot moves if it has decided *finally*; one that
   has not (it did not finish in time) stays and counts an abandoned step;
7. calls meet as transactions do under *wound-wait* (:attr:`LocalPibtRobot.preempts`):
   a call that needs a robot busy in a call of lower priority (or a cell that
   such a call reserved and whose occupant has not decided for good) asks the
   robot anyway; the robot, unless it has decided for good, gives its call up
   (:class:`~mrmp.protocol.pibt_local.CallAbortMessage`, passed up to the
   root; a robot waiting for the answer of the robot it asked first passes
   :class:`~mrmp.protocol.pibt_local.CallWoundMessage` down to it) and takes
   the request. A call that needs a robot busy in a call of higher priority
   waits until that robot has decided for good or given up, and a robot pulled
   by the swap technique claims with its puller's call's rank. So where calls
   started apart meet, the one of higher priority goes on as if it had run
   first, as in central PIBT.

**Bodies that turn in place** (``turning``) follow the *ahead-or-stay* rule
(:attr:`~mrmp.robot.pibt_robot.PibtRobot.turns_by_staying`): a robot decides
for the cell ahead or for its own, turning toward the neighbour it chose,
after asking that neighbour's occupant to leave; an answer says the robot
asked drives away, turns to leave (its asker stays behind it), or cannot. No
decision for good is cancelled afterwards, and calls do not rotate
(``docs/protocol.md``, "Planning for ``turning`` bodies").

Counted by the robot itself (:attr:`LocalPibtRobot.stats`): ``waits`` (times
it looked at the start rule and could not start yet; a waiting robot looks
again only once no robot it waits for is left), ``withdrawn`` (reservations lost to a call
of higher priority), ``refused`` (requests refused because it was busy),
``passed_busy`` (cells passed by because their occupant was busy in another
call: with ``turning`` bodies, or without :attr:`LocalPibtRobot.preempts`),
``settled_at_once`` (reservations final at once, with no rival possible),
``aborted`` (calls it gave up for a call of higher priority), ``blocked`` (times it
waited for a robot busy in a call of higher priority) and ``abandoned`` (steps it ended undecided); :attr:`LocalPibtRobot.stalled`
and :attr:`LocalPibtRobot.reach` are its stall count and this step's reach.

Examples
--------
Two robots in a corridor ``0-1-2`` with a bay above cell 1 (as in
:mod:`mrmp.robot.pibt_robot`): nobody tells robot 0 to start; it starts
because nobody within 2 cells outranks it, while robot 1 waits for it.

>>> from mrmp.core.grid import Grid
>>> from mrmp.search.flat_map import FlatMap
>>> flat = FlatMap(Grid.from_rows(["#.#", "..."]))
>>> a = LocalPibtRobot(0, flat.index((0, 0)), flat.index((0, 2)), flat, tie=2)
>>> b = LocalPibtRobot(1, flat.index((0, 1)), flat.index((0, 0)), flat, tie=1)
>>> robots = {0: a, 1: b}
>>> sent = [(robot.index, item) for robot in (a, b) for item in robot.begin_step(1)]
>>> rounds = 0
>>> while sent or any(robot.wake for robot in (a, b)):
...     rounds += 1
...     for sender, item in sent:
...         _ = robots[1 - sender].receive(item.message)
...     sent = [(robot.index, item) for robot in (a, b) for item in robot.act()]
>>> [flat.cell(robot.finish_step()) for robot in (a, b)], rounds, b.stats["waits"]
([(0, 1), (1, 1)], 4, 1)

Robot 1, asked, took the bay: nobody else stands next to it, so its
reservation was final at once; robot 0's claim of robot 1's cell waited its
round.

>>> a.stats["settled_at_once"], b.stats["settled_at_once"]
(0, 1)
"""

from __future__ import annotations

import random
from collections import Counter

from mrmp.core.heading import Heading
from mrmp.protocol.messages import AnswerMessage, BeaconMessage, Message, PullMessage
from mrmp.protocol.pibt_local import (
    CallAbortMessage,
    CallInheritMessage,
    CallReserveMessage,
    CallWoundMessage,
    NewsBeaconMessage,
)
from mrmp.robot.messaging import Handlers, Outgoing
from mrmp.robot.pibt_robot import MIN_RADIUS, RESERVE_RADIUS, PibtRobot
from mrmp.search.flat_map import FlatMap

__all__ = ["LocalPibtRobot"]

Rank = tuple[int, int, int]
"""A priority ``(elapsed, tie, -index)``: larger goes first."""

NO_RANK: Rank = (-1, 0, 0)
"""Below every robot's priority: the rank of a robot not heard."""


class LocalPibtRobot(PibtRobot):
    """One robot's PIBT brain that decides itself when its call starts (module docstring).

    Parameters are those of :class:`~mrmp.robot.pibt_robot.PibtRobot`.
    After :meth:`begin_step` and after every :meth:`act`, :attr:`wake` says
    whether the robot wants to act in the next round even if nothing reaches
    it (a timer of one round: its provisional reservation becomes final then).
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
    ) -> None:
        super().__init__(
            index, start, goal, flat, tie=tie, heading=heading, radius=radius, swap=swap,
            heading_aware=heading_aware, turn_cost=turn_cost, rng=rng, tie_penalties=tie_penalties,
            turning=turning, dead_end_bonus=dead_end_bonus, guidance=guidance,
        )  # fmt: skip
        self.stats: Counter[str] = Counter()
        self.wake = False
        self._ranks: dict[int, Rank] = {}
        self._near: list[int] = []
        self._listeners: list[int] = []  # robots within 2 cells (they hear its reservations)
        self._waiters: list[int] = []  # robots farther away within the radius that it outranks (they may wait for it)
        self._final: set[int] = set()
        self._above = 0  # robots heard that outrank it and are not known to have decided for good
        self._calls: dict[int, int] = {}  # robot -> root of the call its provisional reservation belongs to
        self._claims: dict[int, Rank] = {}  # robot -> rank of the call of its latest reservation
        self._root = index
        self._rank: Rank = self.priority
        self._own_rank: Rank = self.priority  # this step's priority, kept: it is compared with every rank heard
        self._confirmed = True
        self._finishing: bool | None = None
        self._lost = False
        self._withdrawn = False  # lost its reservation while waiting for an answer: the answer comes first
        self._done = False
        self._blocked_by: int | None = None  # a robot of a call of higher priority whose cell it waits for
        self._unblocked = False  # that robot decided for good or gave its call up
        self._wound: CallInheritMessage | None = None  # the request of a call of higher priority, kept until free
        self._wounded = False  # a call of higher priority wants a robot of its call: give it up
        self._wound_passed = False  # the robot it asked was told so
        self._child_gave_up = False  # the robot it asked gave the call up
        self.stalled = 0
        self.reach = radius
        self._y_size = flat.y_size
        self._before = 0.0  # distance to the goal at the start of the step
        self._nearest = 0.0  # the nearest it has been to ``_nearest_goal`` (with ``stall_from_best``)
        self._nearest_goal: int | None = None
        self._wound_wait = self.preempts and not self.turning  # :meth:`_preempts`, read on every act
        self._informing = self.informing.table()

    # -- the step ------------------------------------------------------------------

    def begin_step(self, step: int) -> list[Outgoing]:
        """Start step ``step``: forget the last step's view, announce cell, goal and priority; act next round."""
        out = super().begin_step(step)
        self._before = self.flat.distances(self.goal)[self.present]
        radius, grown = self.radius, self.stalled - self.stall_slack
        reach = self.reach = radius if grown <= 0 else min(radius + grown, max(radius, self.reach_cap))
        if reach != radius:
            out = [Outgoing(item.message, None, reach) for item in out]
        self._ranks = {}
        self._near = []
        self._listeners = []
        self._waiters = []
        self._final = set()
        self._above = 0
        self._calls = {}
        self._claims = {}
        self._root, self._rank = self.index, self.priority
        self._own_rank = self._rank
        self._confirmed, self._finishing, self._lost, self._done = True, None, False, False
        self._withdrawn = False
        self._blocked_by, self._unblocked = None, False
        self._wound, self._wounded, self._wound_passed, self._child_gave_up = None, False, False, False
        self.wake = True  # evaluate the start rule once the beacons are in
        return out

    @property
    def final(self) -> bool:
        """Whether the robot has decided for good this step (it moves at the step's end)."""
        return self._done

    def receive_once(self, message: Message) -> bool:
        """Take in one message (see :meth:`PibtRobot.receive`); True when the robot should act on it this round."""
        inform = self._informing.get(type(message))  # :meth:`Handlers.get`, inlined: this runs for every message heard
        if inform is not None:
            return bool(inform(self, message))
        self._control.append(message)
        return True

    def receive_beacons(self, beacons: list[BeaconMessage]) -> None:
        """Take in beacons: cells, goals and priorities (:meth:`PibtRobot.receive_beacons`); note the robots within 2 cells."""
        occupants, goals, settled = self._occupants, self._goals, self._settled
        ranks, near, listeners, waiters = self._ranks, self._near, self._listeners, self._waiters
        y_size = self._y_size
        x, y = self.flat.cells[self.present]
        mine = self._own_rank
        above = 0
        for message in beacons:  # one loop for both classes' bookkeeping: this runs for every beacon heard
            sender = message.sender
            there_x, there_y = message.present
            cell = there_x * y_size + there_y
            goal_x, goal_y = message.goal
            goal = goals[sender] = goal_x * y_size + goal_y
            occupants[cell] = sender
            if cell == goal:
                settled.add(cell)
            rank = ranks[sender] = (message.elapsed, message.tie, -sender)
            near.append(sender)  # the radio brings a beacon only within its sender's reach
            if rank > mine:
                above += 1
            if abs(there_x - x) + abs(there_y - y) <= RESERVE_RADIUS:
                listeners.append(sender)
            elif rank < mine:
                waiters.append(sender)
        self._above += above

    reach_cap = 8
    """The largest reach a stalled robot's beacon and final reservation grow to (cells)."""
    stall_slack = 2
    """Steps a robot may stall before its reach grows beyond ``radius`` (one cell per further step)."""
    stall_from_best = False
    """Whether a step counts as a stall unless it ends nearer the goal than the robot has ever been.

    False (the default): a stall is a step that ends no nearer the goal than
    it began, so a robot that steps back and forth never stalls two steps in a
    row and its reach stays at the radius. True: a stall is a step that
    neither ends on the goal nor sets a new record of nearness since the goal
    was set, so such a robot's reach grows too. That gets more jams in
    narrow corridors through, at up to 2.7 times the messages
    (``docs/protocol.md``, "Limits of local sequencing").
    """

    rotations = True
    """Take the cell of a robot busy in the robot's own call (PIBT's rotations): safe when every call ends in its step.

    Never for bodies that turn in place (``turning``): they follow one another but may not rotate.
    """

    def _may_rotate(self) -> bool:
        """Whether the robot may take the cell of a robot busy in its own call (:attr:`rotations`, never when ``turning``)."""
        return self.rotations and not self.turning

    turns_by_staying = True
    """Bodies that turn in place decide for the cell ahead or their own (:attr:`PibtRobot.turns_by_staying`):
    a decision for good is never cancelled by a robot that turns."""

    informing = Handlers()

    @informing.on(BeaconMessage, NewsBeaconMessage)
    def _take_beacon_local(self, message: BeaconMessage) -> bool:
        self.receive_beacons([message])
        return False

    @informing.on(CallReserveMessage)
    def _take_call_reservation(self, message: CallReserveMessage) -> bool:
        if self._done:
            return False  # decided for good: nothing it hears can change its cell, and the next step forgets it all
        sender = message.sender
        x, y = message.cell
        cell = x * self._y_size + y  # the flat index (FlatGrid.index), inlined: this runs for every reservation heard
        reserved, targets = self._reserved, self._targets
        old = targets.get(sender)
        if old is not None and old != cell and reserved.get(old) == sender:
            if old == self.present and self._parent is not None:
                reserved[old] = self._parent  # its own cell stays promised to the robot that pushed it
            else:
                del reserved[old]  # a reservation replaced (after a lost conflict or backtracking)
                self._restore_holder(old)
        targets[sender] = cell
        root = message.root
        rank = self._claims[sender] = (message.root_elapsed, message.root_tie, -root)
        final = message.final
        if final:
            waited = self._ranks.get(sender, NO_RANK) > self._own_rank  # it may have waited for the sender
            decided = self._final
            if waited and sender not in decided:
                self._above -= 1
            decided.add(sender)
            self._calls.pop(sender, None)
            if sender == self._blocked_by:
                self._unblocked = True  # the robot of a call of higher priority it waited for decided for good
        else:
            waited = False
            self._calls[sender] = root
        if cell == self.target and not self._confirmed and sender != self.index:
            if sender == self._waiting:
                reserved[cell] = sender  # the robot asked to leave it stays: its answer says whether it turns to leave
                return True
            if cell != self.present and (message.final or rank > self._rank):
                self._lost = True  # a call of higher priority reserved it in the same round: withdraw
                reserved[cell] = sender
            else:
                reserved[cell] = self.index
            return True
        holder = reserved.get(cell)
        if holder is None or holder == sender or targets.get(holder) != cell or self._outranks(sender, holder, cell):
            reserved[cell] = sender  # two claims of one cell in one round: the winner holds it, as the robots decide
        if self._unblocked:
            return True
        # a robot waiting to start reconsiders when the last robot it may have waited for decided for good
        if self.target is None and final and (old is not None or waited):
            return self.reconsiders_at_every_decision or (not self._above and not self._calls)
        return False

    @informing.on(CallAbortMessage)
    def _take_abort(self, message: CallAbortMessage) -> bool:
        """A robot gave its call up: forget its reservation; act when it was the robot this one asked or waits for."""
        if self._done:
            return False
        sender = message.sender
        cell = self._targets.pop(sender, None)
        if cell is not None and self._reserved.get(cell) == sender:
            del self._reserved[cell]
            self._restore_holder(cell)
        self._calls.pop(sender, None)
        self._claims.pop(sender, None)
        if sender == self._waiting and message.root == self._root:
            self._child_gave_up = True  # the robot it asked gave this call up (not one it was in before it was asked)
            return True
        if sender == self._blocked_by:
            self._unblocked = True
            return True
        if self._idle():
            return self.reconsiders_at_every_decision or (not self._above and not self._calls)
        return False

    reconsiders_at_every_decision = False
    """Whether a waiting robot reconsiders starting whenever a robot it may have waited for decides for good.

    When False it reconsiders only once no robot heard that outranks it is left
    undecided and none heard is in the middle of a call, which :meth:`_may_start`
    needs anyway (those robots are all within its radius: every reach is at
    least the radius). A brain that learns of decisions otherwise sets it.
    """

    def _restore_holder(self, cell: int) -> None:
        """Give ``cell``, whose holder here gave its claim up, to the best claim of it still standing, if any.

        Another claim may have lost here to the one given up: a decision for
        good heard first, whose holder has since moved on, or (when a call of
        higher priority takes a robot over) a provisional claim that lost to
        its occupant staying, before the occupant gave its call up.
        """
        best: int | None = None
        for robot, target in self._targets.items():
            if target == cell and (best is None or self._outranks(robot, best, cell)):
                best = robot
        if best is not None:
            self._reserved[cell] = best

    def _outranks(self, claimant: int, holder: int, cell: int) -> bool:
        """Whether ``claimant``'s claim of ``cell`` beats ``holder``'s.

        A claim decided for good first (decided reservations are unique), then
        staying on one's cell, then the call's rank. The first rule does not
        rest on the beacons heard: the occupant of a cell may not be known yet
        when its claims arrive over a faulty network.
        """
        final = self._final
        if (claimant in final) != (holder in final):
            return claimant in final
        occupant = self._occupants.get(cell)
        if (occupant == claimant) != (occupant == holder):
            return occupant == claimant
        return self._claims.get(claimant, (0, 0, 0)) > self._claims.get(holder, (0, 0, 0))

    # -- acting --------------------------------------------------------------------

    def act(self) -> list[Outgoing]:
        """Act on this round: settle the last round's reservation, take requests and answers, maybe start."""
        out: list[Outgoing] = []
        self.wake = False
        if (self._control or self._child_gave_up) and self._wound_wait and not self._done:
            self._take_wounds(out)
        if self._lost:
            self._lost = False
            self.stats["withdrawn"] += 1
            self._finishing = None
            self._withdraw(out)
        elif not self._confirmed and self._may_confirm():
            self._confirmed = True
            if self._finishing is not None:
                moved, self._finishing = self._finishing, None
                self._finalize(moved, out)
        if self._control:
            control, self._control = self._control, []
            inherits = sorted(
                (message for message in control if isinstance(message, CallInheritMessage)),
                key=lambda message: message.rank,
                reverse=True,
            )
            for inherit in inherits:
                self._take_inherit_local(inherit, out)
            for message in control:
                if isinstance(message, AnswerMessage):
                    self._take_answer(message, out)
                elif isinstance(message, PullMessage):
                    self._take_pull_local(message, out)
        if self._unblocked:
            self._unblocked = False
            if self._blocked_by is not None and not self._done:
                self._blocked_by = None
                self._continue(out)  # the cell it waited for: look at it again
        if self._wound is not None and (self._done or self._idle()):
            wound, self._wound = self._wound, None
            self._take_inherit_local(wound, out)  # refused when decided for good, taken when free
        if self.target is None and self._parent is None and self._blocked_by is None:  # idle (:meth:`_idle`), inlined
            if self._may_start():
                self._root, self._rank = self.index, self._own_rank
                self._begin_call(out)
            else:
                self.stats["waits"] += 1
        return out

    def _idle(self) -> bool:
        """Whether the robot is in no call: it has reserved nothing, nobody asked it, and it waits for no cell."""
        return self.target is None and self._parent is None and self._blocked_by is None

    preempts = True
    """Whether a call of higher priority takes over the robots of a call of lower priority that it meets (wound-wait).

    Rosenkrantz, Stearns and Lewis, "System level concurrency control for
    distributed database systems", ACM TODS 3(2), 1978: an older transaction
    that needs what a younger one holds *wounds* it (the younger one is
    aborted), a younger one waits for an older one. Here the call of higher
    priority asks the robot anyway (:class:`CallInheritMessage`); the robot,
    if it has not decided for good, gives its call up
    (:class:`~mrmp.protocol.pibt_local.CallAbortMessage`, after telling the
    robot it asked to do the same, :class:`~mrmp.protocol.pibt_local.CallWoundMessage`)
    and takes the request. A call that meets a robot busy in a call of higher
    priority waits until that robot has decided for good or given up, instead
    of passing its cell by. So the call of higher priority decides as it would
    had it run first, as in central PIBT. Only a robot that has not decided for
    good gives a call up, and a decision for good never rests on a call that
    can still be given up: a rotation ends its call at once.
    """

    def _preempts(self) -> bool:
        """Whether this robot's calls take robots over from calls of lower priority (:attr:`preempts`; not ``turning``)."""
        return self._wound_wait

    def _take_wounds(self, out: list[Outgoing]) -> None:
        """Before anything else this round: give the call up when a call of higher priority wants one of its robots.

        Wounded (a request of a call of higher priority, or the robot that
        asked this one passing such a request on): give the call up at once
        when waiting for no answer; else pass the request on to the robot it
        asked, and give up when that robot does. The robot it asked giving up
        makes it give up too.
        """
        busy = not self._idle()
        for message in self._control:
            if isinstance(message, CallWoundMessage):
                if message.sender == self._parent and busy:
                    self._wounded = True
                elif self._wound is not None and message.sender == self._wound.sender:
                    self._refuse(self._wound, out)  # its asker gives its own call up: this robot never joined it
                    self._wound = None
            elif isinstance(message, CallInheritMessage) and busy and self._preempts() and message.rank > self._rank:
                self._wounded = True
        if self._child_gave_up or (self._wounded and self._waiting is None):
            self._abort(out)
        elif self._wounded and not self._wound_passed:
            self._wound_passed = True
            assert self._waiting is not None
            out.append(Outgoing(CallWoundMessage(self.index, self._seq(), self.step), (self._waiting,)))

    def _abort(self, out: list[Outgoing]) -> None:
        """Give the call up: forget its reservations and say so to the robots within 2 cells; free again."""
        self.stats["aborted"] += 1
        root = self._root
        reserved, targets = self._reserved, self._targets
        targets.pop(self.index, None)
        if self.target is not None and reserved.get(self.target) == self.index:
            del reserved[self.target]
            self._restore_holder(self.target)
        if self._parent is not None and reserved.get(self.present) == self._parent:
            del reserved[self.present]
            self._restore_holder(self.present)
        self.target = self._parent = self._waiting = self._blocked_by = self._finishing = self._pulled = None
        self._confirmed, self._lost, self._withdrawn, self._unblocked = True, False, False, False
        self._wounded, self._wound_passed, self._child_gave_up = False, False, False
        self._root, self._rank = self.index, self.priority
        decided = self._final
        recipients = tuple(robot for robot in self._listeners if robot not in decided)
        out.append(Outgoing(CallAbortMessage(self.index, self._seq(), self.step, root), recipients))

    def _withdraw(self, out: list[Outgoing]) -> None:
        """The reservation lost to a call of higher priority: the next cell, once the robot asked for it (if any) answered."""
        if self._waiting is not None:
            self._withdrawn = True  # the robot it asked may be deciding in its call: its answer comes first
        else:
            self._next_cell(out)

    def _next_cell(self, out: list[Outgoing]) -> None:
        """The reservation lost to a call of higher priority: try the next cell."""
        self.target = None
        self._next += 1
        self._continue(out)

    def _take_answer(self, message: AnswerMessage, out: list[Outgoing]) -> None:
        """An answer to an inheritance; after a withdrawal, whatever it says, the next cell.

        A robot whose reservation of an occupied cell lost, while it waited for
        the occupant's answer, waits on: the occupant may have taken the request
        (the winner's came later, or never) and be deciding within this robot's
        call. Going on at once would run two branches of one call side by side,
        whose claims of one cell carry the same rank and so could both stand.
        """
        if self._withdrawn and message.sender == self._waiting:
            self._withdrawn = False
            self._waiting = None
            self._next_cell(out)
            return
        super()._take_answer(message, out)

    def _may_confirm(self) -> bool:
        """Whether the provisional reservation has survived: in synchronous rounds, one round has passed."""
        return True

    def _may_start(self) -> bool:
        """Every robot within 2 cells of higher priority has decided, and none is in the middle of a call."""
        mine = self._own_rank
        final, targets, ranks = self._final, self._targets, self._ranks
        for other in self._near:
            if other in final:
                continue
            if other in targets or ranks[other] > mine:
                return False
        return True

    def start(self) -> list[Outgoing]:
        """Not used: the robot starts by itself in :meth:`act` (kept for the driver interface)."""
        return []

    def _take_inherit_local(self, message: CallInheritMessage, out: list[Outgoing]) -> None:
        if self._wounded and not self._done and not self._idle() and message.rank > self._rank:
            if self._wound is None:
                self._wound = message  # taken once its call is given up (:meth:`_take_wounds`)
                return
            if message.rank > self._wound.rank:
                self._wound, message = message, self._wound  # the request of the highest call is kept, the other refused
        if not self._idle():
            self._refuse(message, out)  # busy in a call already: the asker tries its next cell
            return
        self._reserved[self.present] = message.sender
        self._targets[message.sender] = self.present
        self._claims[message.sender] = message.rank  # its reservation may arrive later than this request, or never
        self._parent = message.sender
        self._root, self._rank = message.root, message.rank
        self._begin_call(out)

    def _refuse(self, message: CallInheritMessage, out: list[Outgoing]) -> None:
        """Answer a request that this robot stays, without taking part in the call."""
        self.stats["refused"] += 1
        out.append(Outgoing(AnswerMessage(self.index, self._seq(), self.step, False), (message.sender,)))

    def _take_pull_local(self, message: PullMessage, out: list[Outgoing]) -> None:
        cell = self.flat.index(message.cell)
        if self._idle() and cell not in self._reserved:
            self._rank = self.priority
            if self._preempts():  # the pull is part of the puller's call, as in central PIBT (rule 7)
                self._rank = max(self._rank, self._claims.get(message.sender, NO_RANK))
            self._root = -self._rank[2]
            self._candidates, self._next, self._pulled = [cell], 0, None
            self._continue(out)

    def finish_step(self) -> int:
        """Move to the reserved cell if decided for good, else stay (an abandoned step); return the cell."""
        if not self._done:
            self.stats["abandoned"] += 1
            self.target = None
        cell = super().finish_step()
        distance = self.flat.distances(self.goal)[cell]
        self.stalled = 0 if self._progressed(distance) or cell == self.goal else self.stalled + 1
        return cell

    def _progressed(self, distance: float) -> bool:
        """Whether the step that ended ``distance`` from the goal made progress (see :attr:`stall_from_best`)."""
        if not self.stall_from_best:
            return distance < self._before
        if self._nearest_goal != self.goal:  # the first step towards this goal: the record starts where it began
            self._nearest_goal, self._nearest = self.goal, self._before
        if distance < self._nearest:
            self._nearest = distance
            return True
        return False

    # -- PIBT's call, by messages -------------------------------------------------------

    def _reserve(self, cell: int, out: list[Outgoing], final: bool = False) -> None:
        self.target = cell
        self._reserved[cell] = self.index
        self._targets[self.index] = cell
        self._claims[self.index] = self._rank
        self._confirmed = final
        if not final:
            self.wake = True
        self.seq += 1
        root, (elapsed, tie, _) = self._root, self._rank
        message = CallReserveMessage(self.index, self.seq, self.step, self.flat.cells[cell], root, elapsed, tie, final)
        out.append(self._reservation(message, final))

    def _reservation(self, message: CallReserveMessage, final: bool) -> Outgoing:
        """Where a reservation goes: the robots that can still use it, by name.

        The robots within 2 cells (they may claim the cell, or take ours) and,
        when final, the robots within the radius that it outranks (they may
        wait for it to decide); neither if known to have decided for good
        already, since a robot decided for good ignores every reservation.
        Every robot within the radius has reached this robot with its beacon
        (every reach is at least the radius), so these are exactly the robots
        a radio broadcast would reach and use. A stalled robot's final
        reservation goes by radio to its whole reach, which can hold robots it
        has not heard.
        """
        if final and self.reach != self.radius:
            return Outgoing(message, None, self.reach)
        decided = self._final
        recipients = [robot for robot in self._listeners if robot not in decided]
        if final:
            recipients.extend(robot for robot in self._waiters if robot not in decided)
        return Outgoing(message, tuple(recipients))

    def _continue(self, out: list[Outgoing]) -> None:
        if self._wounded:
            self._abort(out)  # a call of higher priority wants a robot of this call: give it up instead of going on
            return
        here = self.present
        reserved, occupants, targets, final = self._reserved, self._occupants, self._targets, self._final
        candidates = self._candidates
        while self._next < len(candidates):
            cell = candidates[self._next]
            occupant = occupants.get(cell)
            if cell in reserved and not self._contestable(cell, occupant):
                self._next += 1
                continue
            if self.turning and cell != here and cell != self._ahead_cell:
                if self._turns_toward(cell, occupant, out):
                    return
                continue
            if occupant is None or occupant == self.index or occupant in final:
                if occupant is not None and targets.get(occupant) == here:
                    self._next += 1  # would swap
                    continue
                self._claim(cell, True, out)
                return
            target = targets.get(occupant)
            if target is not None and self._preempts() and self._calls.get(occupant, self._root) != self._root:
                if self._claims.get(occupant, NO_RANK) < self._rank:
                    self._ask(cell, occupant, out)  # busy in a call of lower priority: wound it (:attr:`preempts`)
                    return
                if target != here:
                    self.stats["blocked"] += 1
                    self._blocked_by = occupant  # busy in a call of higher priority: wait until it decides
                    return
            if target == here:
                self._next += 1  # the occupant moves into our cell: taking its cell would swap
                continue
            if target is not None:
                if self._may_rotate() and self._calls.get(occupant) == self._root:
                    self._reserve(cell, out)  # a robot of our own call leaves it (a rotation, as in PIBT)
                    self._finish(True, out)
                    return
                self.stats["passed_busy"] += 1  # busy in another call: it may yet stay
                self._next += 1
                continue
            self._ask(cell, occupant, out)
            return
        self._claim(here, False, out)  # no candidate left: stay

    def _contestable(self, cell: int, occupant: int | None) -> bool:
        """Whether ``cell``, reserved, is reserved in a call of lower priority and its occupant can still be asked.

        Then the call asks the occupant as if the cell were not reserved: the
        occupant takes the request of higher priority first, or gives its own
        call up for it (:attr:`preempts`).
        """
        if not self._preempts() or occupant is None or occupant == self.index or occupant in self._final:
            return False
        holder = self._reserved[cell]
        return holder != self.index and holder not in self._final and self._claims.get(holder, NO_RANK) < self._rank

    def _ask(self, cell: int, occupant: int, out: list[Outgoing]) -> None:
        """Reserve ``cell`` and ask its ``occupant`` to decide within this call (priority inheritance)."""
        self._reserve(cell, out)
        self._waiting = occupant
        root, (elapsed, tie, _) = self._root, self._rank
        inherit = CallInheritMessage(self.index, self._seq(), self.step, self.flat.cells[cell], root, elapsed, tie)
        out.append(Outgoing(inherit, (occupant,)))

    def _turns_toward(self, cell: int, occupant: int | None, out: list[Outgoing]) -> bool:
        """Ahead-or-stay: the robot chose ``cell``, which its body does not face; False when it passes the cell by.

        It stays, turning toward ``cell``; an occupant that has not decided is
        first asked to leave (it may drive away now, or turn to leave next
        step), and the robot stays once it answers (:meth:`_take_answer`). A
        cell whose occupant comes to this robot's cell, or is busy in a call, is
        passed by (the next candidate is up); True otherwise (the call went on).
        """
        if occupant is not None and occupant != self.index and occupant not in self._final:
            if self._targets.get(occupant) is not None:
                self._next += 1  # it comes here, or is busy in a call: turning toward it is no use
                return False
            self._reserve(cell, out)
            self._waiting = occupant
            root, (elapsed, tie, _) = self._root, self._rank
            inherit = CallInheritMessage(self.index, self._seq(), self.step, self.flat.cells[cell], root, elapsed, tie)
            out.append(Outgoing(inherit, (occupant,)))
            return True
        self._stay_turning(cell, out)
        return True

    def _claim(self, cell: int, moved: bool, out: list[Outgoing]) -> None:
        """Reserve ``cell`` (free, left for good by its occupant, or the robot's own) and end the call.

        For good at once when no other robot can claim the cell in this step
        (:meth:`_uncontested`); provisionally otherwise, final once the claim
        has survived (:meth:`_may_confirm`).
        """
        if self.settles_uncontested and self._uncontested(cell):
            self.stats["settled_at_once"] += 1
            self.target = cell
            self._finalize(moved, out)
        else:
            self._reserve(cell, out)
            self._finish(moved, out)

    settles_uncontested = True
    """Whether a claim no other robot can contest is final at once, without a provisional round."""

    def _uncontested(self, cell: int) -> bool:
        """No robot but this one that stands on ``cell`` or next to it is undecided.

        Only such a robot can claim ``cell`` in this step (a robot moves one
        cell, pushed or not), and every one of them is within 2 cells of this
        robot, so it is known here (its beacon came in before any call began);
        a robot known to have decided for good will not claim again.
        """
        occupants, final, index = self._occupants, self._final, self.index
        for place in (cell, *self.flat.neighbours[cell]):
            other = occupants.get(place)
            if other is not None and other != index and other not in final:
                return False
        return True

    def _finish(self, moved: bool, out: list[Outgoing]) -> None:
        if self._confirmed:
            self._finalize(moved, out)
        else:
            self._finishing = moved  # final once the reservation has survived its round

    def _finalize(self, moved: bool, out: list[Outgoing]) -> None:
        self._done = True
        self._final.add(self.index)
        assert self.target is not None
        self._reserve(self.target, out, final=True)
        super()._finish(moved, out)
