"""A robot that computes PIBT with its neighbours, by messages: the sans-IO brain of policy ``pibt``.

PIBT (Okumura, Machida, Défago and Tamura, "Priority Inheritance with
Backtracking for Iterative Multi-agent Path Finding", IJCAI 2019; AIJ 310,
2022) decides every robot's next cell one step at a time. The paper notes that
it "can be fully decentralized": everything a robot needs lies within two
hops. Here each robot holds only what its messages told it, and the step is a
conversation:

1. :meth:`PibtRobot.begin_step`: the robot sends a :class:`BeaconMessage` (its
   cell, goal, heading and priority) to every robot within ``radius`` cells
   (Manhattan distance, at least 2);
2. when its turn comes (:meth:`PibtRobot.start`) or when a neighbour reserves
   its cell and asks it to decide (:class:`InheritMessage`, *priority
   inheritance*), it tries its candidate cells, nearest to its goal first. It
   skips cells reserved by others and cells whose occupant moves into its own
   cell (no swap); it reserves a cell with a :class:`ReserveMessage` to every
   robot within 2 cells (everyone who could want that cell, or check whether
   the sender has decided); if the cell is occupied by a robot that has not
   decided, it sends that robot an :class:`InheritMessage` and waits for its
   :class:`AnswerMessage`; on "could not move" it tries its next candidate
   (*backtracking*); with no candidate left it stays and answers "could not
   move" to the robot that pushed it;
3. with ``swap`` on, the swap technique of LaCAM* engineering (Okumura, AAMAS
   2024) lets two robots pass each other in a corridor: the robot walks away
   from its goal and asks the other to follow (:class:`PullMessage`);
4. :meth:`PibtRobot.finish_step`: every robot has decided; it moves to the
   cell it reserved.

**Bodies that turn in place** (``turning``: LoRR's ``MAPF_T``,
:mod:`mrmp.core.body`) drive only to the cell ahead. With ``turning`` on, a
robot ranks all its neighbours with the turns toward them
(:func:`~mrmp.policies.pibt_rules.turning_candidates`), as the central
generator does (:class:`mrmp.centralized.pibt_step.PIBT` with
``turning_y_size``); once decided it drives on when its cell is ahead, and
otherwise turns toward it or waits and stays
(:func:`~mrmp.policies.pibt_rules.turning_action`). A robot that stays tells
the robot that reserved its cell (:class:`StayMessage`), which then stays too
and tells the robot that reserved *its* cell, and so on down the chain: the
central generator's cancellation, by messages. A robot planned by priority
inheritance never takes the cell of a robot already moving (so no cycle of
robots can follow one another round a loop), and there is no swap technique
(it walks a robot backwards).

Its decisions equal those of :class:`mrmp.centralized.pibt_step.PIBT` given
the same priorities, when robots start in priority order and every message of
a round arrives before the next round (the synchronous rounds of
:mod:`mrmp.sim.rounds`); the swap test reads only what the robot heard, so it
can differ when a corridor walk leaves the radio radius. ``docs/protocol.md``
states the argument and its limits.

**Priorities** are dynamic, as in PIBT: ``(elapsed, tie, -index)`` where
``elapsed`` counts the steps since the robot last stood on its goal and
``tie`` is the distance from its start to its first goal (pypibt's
``dist / |V|`` fraction, as an integer). The highest-priority robot always
gets its best cell, so on graphs where every edge lies on a cycle every robot
reaches its goal (the PIBT theorem; bound in ``docs/algorithms.md``).

Nothing here reads a clock, draws a random number or opens a socket: the
driver delivers messages (:meth:`PibtRobot.receive`), lets the robot act on
what a round brought (:meth:`PibtRobot.act`), and carries out what it returns.

Examples
--------
Two robots in a corridor ``0-1-2`` with a bay above cell 1: robot 0 (at 0,
for 2) asks robot 1 (at 1, for 0) for cell 1; robot 1 inherits, cannot swap,
and steps into the bay.

>>> from mrmp.core.grid import Grid
>>> from mrmp.search.flat_map import FlatMap
>>> flat = FlatMap(Grid.from_rows(["#.#", "..."]))
>>> a = PibtRobot(0, flat.index((0, 0)), flat.index((0, 2)), flat, tie=2)
>>> b = PibtRobot(1, flat.index((0, 1)), flat.index((0, 0)), flat, tie=1)
>>> beacons = a.begin_step(1) + b.begin_step(1)
>>> for sent in beacons:
...     asks = (b if sent.message.sender == 0 else a).receive(sent.message)
>>> sent = a.start()
>>> [type(item.message).__name__ for item in sent]
['ReserveMessage', 'InheritMessage']
>>> [b.receive(item.message) for item in sent]   # the reservation informs; the inheritance asks
[False, True]
>>> [type(item.message).__name__ for item in b.act()]
['ReserveMessage', 'AnswerMessage']
>>> flat.cell(b.target)
(1, 1)
"""

from __future__ import annotations

import random
from collections import Counter
from collections.abc import Sequence

from mrmp.core.heading import Heading
from mrmp.policies.pibt_rules import (
    ahead_cell,
    heading_candidates,
    sorted_candidates,
    swap_possible,
    swap_required,
    turning_action,
    turning_candidates,
)
from mrmp.protocol.messages import (
    AnswerMessage,
    BeaconMessage,
    InheritMessage,
    Message,
    PibtMessage,
    PullMessage,
    ReserveMessage,
    StayMessage,
)
from mrmp.robot.messaging import Handlers, Outgoing
from mrmp.search.flat_map import FlatMap

__all__ = ["MIN_RADIUS", "RESERVE_RADIUS", "PibtRobot"]

MIN_RADIUS = 2
"""The smallest radio radius PIBT works with: two robots two cells apart may want the same cell."""
RESERVE_RADIUS = 2
"""Reservations go to every robot within 2 cells: all that could want the cell, or push the sender."""


class PibtRobot:
    """One robot's PIBT brain (module docstring has the protocol).

    Parameters
    ----------
    index:
        The robot's index in the scenario (its name on the wire).
    start, goal:
        Flat cells of ``flat``.
    flat:
        The map, known beforehand, with its distance lists.
    tie:
        Fixed tie-breaker of the priority (larger goes first).
    heading:
        Initial heading.
    radius:
        Radio radius of beacons, in cells (Manhattan), at least :data:`MIN_RADIUS`.
    swap:
        Use the swap technique (LaCAM* engineering, Okumura AAMAS 2024).
    heading_aware:
        Turning costs time: rank candidate cells by the heading-aware cost to the goal
        (:meth:`~mrmp.search.flat_map.FlatMap.heading_distances`, right turns costing
        ``turn_cost`` each; :func:`~mrmp.policies.pibt_rules.heading_candidates`).
    turn_cost:
        With ``heading_aware``: one right turn's cost in cells (``turn_time / cell_time``).
    rng:
        Breaks ties between equally near cells at random, as pypibt does
        (without it PIBT often cycles forever in crowds). None keeps the plain
        neighbour order of the central generator, which makes decisions
        reproducible by hand.
    tie_penalties:
        Rank equally near cells by the tie penalties of
        :func:`~mrmp.policies.pibt_rules.sorted_candidates` (dead ends last;
        cells of robots standing on their goals after free ones) before the
        random tie-break (not with ``heading_aware``, which ranks by its own costs). None
        (the default) turns them on exactly when ``rng`` is given.
    turning:
        The body turns in place (``turning``; module docstring): candidates
        ranked by :meth:`~mrmp.search.flat_map.FlatMap.heading_distances` with a
        quarter turn either way costing one tick; needs ``swap`` off.
    dead_end_bonus:
        Steps of priority added, on top of the step itself, for every step the
        robot ends in a dead end (a cell with one neighbour) away from its goal:
        the Start-Kit's rule (``default_planner/planner.cpp``: ``p[i] + 10``), so
        that a robot shut in a dead end outranks the robot that waits at its
        mouth. Without the swap technique (bodies that turn in place) the two
        would otherwise wait for each other for ever.
    guidance:
        With ``turning``: the lanes that shape its tables (a name of
        :data:`~mrmp.search.guidance.GUIDANCE_TABLE`; ``none``, the default,
        leaves them the (cell, heading) distances).
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
        if radius < MIN_RADIUS:
            raise ValueError(f"radius {radius} is below {MIN_RADIUS}: robots two cells apart could take the same cell")
        if turning and swap:
            raise ValueError("bodies that turn in place have no swap technique: it walks a robot backwards")
        self.index = index
        self.present = start
        self.goal = goal
        self.flat = flat
        self.tie = tie
        self.heading = heading
        self.radius = radius
        self.swap = swap
        self.heading_aware = heading_aware
        self.turn_cost = turn_cost
        self._noise = rng.random if rng is not None else None
        self.tie_penalties = rng is not None if tie_penalties is None else tie_penalties
        self.turning = turning
        self._ahead_or_stay = turning and self.turns_by_staying
        self.dead_end_bonus = dead_end_bonus
        self.guidance = guidance
        self.elapsed = 0
        self.step = 0
        self.seq = 0
        self.target: int | None = None
        self.next_heading = heading  # turning: the heading at the end of this step
        self.drives = False  # turning: whether the robot drives to ``target`` this step (else it stays)
        self._stays_owed: list[int] = []
        self._staying: set[int] = set()  # turning: robots that told this one they stay, this step
        self._stay_toward = start  # turning, ahead-or-stay: the neighbour it turns toward if it stays
        self._ahead_cell = -1  # turning: the cell ahead at the start of its call (-1: none)
        self.dropped: Counter[str] = Counter()
        # what this step's messages told the robot
        self._occupants: dict[int, int] = {}
        self._goals: dict[int, int] = {}
        self._reserved: dict[int, int] = {}
        self._targets: dict[int, int] = {}
        self._seen: set[tuple[int, int]] = set()
        self._control: list[Message] = []
        self._settled: set[int] = set()  # cells where, as far as the robot heard, a robot stands on its own goal
        # the robot's own PIBT call, while it runs
        self._candidates: list[int] = []
        self._next = 0
        self._pulled: int | None = None
        self._parent: int | None = None
        self._waiting: int | None = None

    # -- state ---------------------------------------------------------------------

    @property
    def priority(self) -> tuple[int, int, int]:
        """``(elapsed, tie, -index)``: larger goes first."""
        return (self.elapsed, self.tie, -self.index)

    @property
    def decided(self) -> bool:
        """Whether the robot knows its cell for the end of this step."""
        return self.target is not None and self._waiting is None

    @property
    def at_goal(self) -> bool:
        """Whether the robot stands on its goal."""
        return self.present == self.goal

    def _seq(self) -> int:
        self.seq += 1
        return self.seq

    # -- the step ------------------------------------------------------------------

    def begin_step(self, step: int) -> list[Outgoing]:
        """Start step ``step``: forget the last step's view and announce cell, goal and priority."""
        self.step = step
        self.target = None
        self.next_heading = self.heading
        self.drives = False
        self._stay_toward = self.present
        self._stays_owed = []
        self._staying = set()
        self._waiting = self._parent = self._pulled = None
        self._occupants = {self.present: self.index}
        self._goals = {self.index: self.goal}
        self._reserved = {}
        self._targets = {}
        self._seen = set()
        self._control = []
        self._settled = {self.present} if self.present == self.goal else set()
        cells = self.flat.cells
        self.seq += 1
        beacon = BeaconMessage(
            self.index, self.seq, step, cells[self.present], cells[self.goal], self.elapsed, self.tie, self.heading
        )
        return [Outgoing(beacon, None, self.radius)]

    def receive(self, message: PibtMessage) -> bool:
        """Take in a message delivered this round; act on it in :meth:`act`.

        Messages of another step and second copies are dropped and counted.
        Returns whether the message waits for :meth:`act` (a request or an
        answer; beacons and reservations only inform), so that a driver may
        skip :meth:`act` for robots that only heard beacons and reservations.
        """
        if message.step != self.step:
            self.dropped["stale"] += 1
            return False
        key = (message.sender, message.seq)
        seen = self._seen
        if key in seen:
            self.dropped["duplicate"] += 1
            return False
        seen.add(key)
        return self.receive_once(message)

    def receive_once(self, message: Message) -> bool:
        """:meth:`receive` for a driver that delivers every message exactly once, in its step (a perfect network).

        The same effect and answer, without the checks for stale messages and
        second copies, which such a driver never delivers.
        """
        inform = self.informing.get(message)
        if inform is not None:
            inform(self, message)
            return bool(self._stays_owed)
        self._control.append(message)
        return True

    informing = Handlers()
    """Messages that only inform (taken in on receipt); the others wait for :meth:`act`."""

    @informing.on(BeaconMessage)
    def _take_beacon(self, message: BeaconMessage) -> None:
        self.receive_beacons([message])

    @informing.on(ReserveMessage)
    def _take_reservation(self, message: ReserveMessage) -> None:
        cell = self.flat.index(message.cell)
        self._reserved[cell] = message.sender
        self._targets[message.sender] = cell
        if self.turning and cell == self.present and message.sender != self.index and self.decided and not self.drives:
            self._stays_owed.append(message.sender)  # it would drive into a robot that stays

    def receive_beacons(self, beacons: list[BeaconMessage]) -> None:
        """Take in this step's beacons, each delivered exactly once (a perfect network), in one call.

        The effect of one :meth:`receive` call per beacon, without the checks
        for stale messages and second copies, which a perfect network never
        delivers: the simulator delivers the beacon round this way.
        :meth:`LocalPibtRobot.receive_beacons <mrmp.robot.pibt_local.LocalPibtRobot.receive_beacons>` does the
        same bookkeeping in its own loop (for speed): keep the two alike.
        """
        occupants, goals, settled = self._occupants, self._goals, self._settled
        y_size = self.flat.y_size  # the flat index (FlatGrid.index), inlined: this runs for every beacon heard
        for message in beacons:
            sender = message.sender
            x, y = message.present
            cell = x * y_size + y
            x, y = message.goal
            goal = goals[sender] = x * y_size + y
            occupants[cell] = sender
            if cell == goal:
                settled.add(cell)

    def act(self) -> list[Outgoing]:
        """Act on the requests and answers of this round; return what to send."""
        out: list[Outgoing] = []
        if self._stays_owed:
            owed, self._stays_owed = self._stays_owed, []
            out.extend(Outgoing(StayMessage(self.index, self._seq(), self.step), (taker,)) for taker in owed)
        if not self._control:
            return out
        control, self._control = self._control, []
        requests = self.requests
        for message in control:
            handler = requests.get(message)
            if handler is not None:
                handler(self, message, out)
        return out

    requests = Handlers()
    """Messages that ask the robot to act (taken in by :meth:`act`)."""

    @requests.on(InheritMessage)
    def _take_inherit(self, message: InheritMessage, out: list[Outgoing]) -> None:
        if self.target is not None:
            self.dropped["late_inherit"] += 1  # cannot happen in synchronous rounds; refuse
            out.append(Outgoing(AnswerMessage(self.index, self._seq(), self.step, False), (message.sender,)))
            return
        self._reserved[self.present] = message.sender
        self._targets[message.sender] = self.present
        self._parent = message.sender
        self._begin_call(out)

    @requests.on(AnswerMessage)
    def _take_answer(self, message: AnswerMessage, out: list[Outgoing]) -> None:
        if message.sender != self._waiting:
            self.dropped["unexpected_answer"] += 1
            return
        self._waiting = None
        cell = self._candidates[self._next]
        if message.moved and not (self._ahead_or_stay and cell != self._ahead_cell):
            self._finish(True, out)
        elif self._ahead_or_stay and (message.moved or message.turns):
            self._stay_turning(cell, out)  # it leaves, now or next step: stay, facing its cell
        else:
            self._next += 1  # backtracking: the pushed robot stays; try the next cell
            self._continue(out)

    @requests.on(StayMessage)
    def _take_stay(self, message: StayMessage, out: list[Outgoing]) -> None:
        self._staying.add(message.sender)  # it may come before the answer of the same robot: kept for the decision
        if self.drives and self._occupants.get(self.target) == message.sender:  # type: ignore[arg-type]
            self.drives = False  # the robot ahead stays: so does this one, facing it
            self._tell_taker(out)

    @requests.on(PullMessage)
    def _take_pull(self, message: PullMessage, out: list[Outgoing]) -> None:
        cell = self.flat.index(message.cell)
        if self.target is None and cell not in self._reserved:
            self._reserve(cell, out)

    def start(self) -> list[Outgoing]:
        """This robot's turn to decide (it is the highest-priority robot not yet decided)."""
        out: list[Outgoing] = []
        if self.target is None:
            self._begin_call(out)
        return out

    def finish_step(self) -> int:
        """Move to the reserved cell (or stay, when undecided); update heading and priority; return the cell."""
        if self.turning:
            if self.target is not None and self.drives:
                self.present = self.target
            if self.target is not None:
                self.heading = self.next_heading
            self._count_elapsed()
            return self.present
        target = self.target if self.target is not None else self.present
        if target != self.present:
            cells = self.flat.cells
            self.heading = Heading.between(cells[self.present], cells[target])
        self.present = target
        self._count_elapsed()
        return target

    def _count_elapsed(self) -> None:
        """One more step away from the goal (plus ``dead_end_bonus`` in a dead end), or 0 on it."""
        if self.present == self.goal:
            self.elapsed = 0
        else:
            self.elapsed += 1 + (self.dead_end_bonus if len(self.flat.neighbours[self.present]) == 1 else 0)

    # -- PIBT's call, by messages -------------------------------------------------------

    def _reserve(self, cell: int, out: list[Outgoing]) -> None:
        self.target = cell
        self._reserved[cell] = self.index
        self._targets[self.index] = cell
        self.seq += 1
        out.append(Outgoing(ReserveMessage(self.index, self.seq, self.step, self.flat.cells[cell]), None, RESERVE_RADIUS))

    def _begin_call(self, out: list[Outgoing]) -> None:
        flat = self.flat
        if self.turning:
            candidates = turning_candidates(
                flat.neighbours,
                self.present,
                int(self.heading),
                flat.heading_distances(self.goal, 1.0, True, self.guidance),
                flat.y_size,
                flat.entry_costs,
                self._noise,
            )
        elif self.heading_aware:
            candidates = heading_candidates(
                flat.neighbours,
                self.present,
                flat.heading_distances(self.goal, self.turn_cost),
                self.heading,
                flat.y_size,
                self.turn_cost,
                flat.entry_costs,
                self._noise,
            )
        else:
            candidates = sorted_candidates(
                flat.neighbours,
                self.present,
                flat.distances(self.goal),
                self._noise,
                self._settled if self.tie_penalties else None,
            )
        if self.turning:
            self._ahead_cell = ahead_cell(flat.neighbours, self.present, int(self.heading), flat.y_size)
        self._pulled = None
        if self.swap:
            self._pulled = self._swap_partner(candidates, flat.distances(self.goal))
            if self._pulled is not None:
                candidates.reverse()
        self._candidates = candidates
        self._next = 0
        self._continue(out)

    def _continue(self, out: list[Outgoing]) -> None:
        here = self.present
        reserved, occupants, targets = self._reserved, self._occupants, self._targets
        candidates = self._candidates
        while self._next < len(candidates):
            cell = candidates[self._next]
            if cell in reserved:
                self._next += 1
                continue
            occupant = occupants.get(cell)
            if occupant is not None and targets.get(occupant) == here:
                self._next += 1  # the occupant moves into our cell: taking its cell would swap
                continue
            if self.turning and self._closes_cycle(occupant, cell):
                self._next += 1
                continue
            self._reserve(cell, out)
            if occupant is not None and occupant != self.index and occupant not in targets:
                self._waiting = occupant  # priority inheritance
                out.append(Outgoing(InheritMessage(self.index, self._seq(), self.step, self.flat.cell(cell)), (occupant,)))
                return
            self._finish(True, out)
            return
        self._reserve(here, out)  # no candidate left: stay
        self._finish(False, out)

    def _finish(self, moved: bool, out: list[Outgoing]) -> None:
        if self.turning:
            self._settle_turn(moved, out)
        pulled = self._pulled
        if moved and self._next == 0 and pulled is not None:
            here = self.present
            if pulled not in self._targets and here not in self._reserved:
                self._reserved[here] = pulled
                self._targets[pulled] = here
                out.append(Outgoing(PullMessage(self.index, self._seq(), self.step, self.flat.cell(here)), (pulled,)))
        if self._parent is not None:
            turns = self._ahead_or_stay and not moved and self._stay_toward != self.present
            out.append(Outgoing(AnswerMessage(self.index, self._seq(), self.step, moved, turns), (self._parent,)))
            self._parent = None

    turns_by_staying = False
    """With ``turning``: whether a robot's decision says at once whether it drives (the *ahead-or-stay* rule).

    False (the central generator's rule): a robot reserves the neighbour it
    chose even when it only turns toward it, and whoever reserved the cell of a
    robot that stays hears a :class:`StayMessage` and stays too, down the
    chain: a decision can be cancelled after it was made. True: a robot
    decides for the cell ahead (it drives) or for its own cell (it stays,
    turning toward the neighbour it chose, :meth:`_stay_turning`); it still
    asks that neighbour's occupant to leave, as PIBT would, and waits for the
    answer. Asked to leave, a robot answers "moved" when it drives away, and
    "stays, turns to leave" (:class:`AnswerMessage`'s ``turns``) when it turns
    toward another cell; the asker then stays behind it, facing it, and says
    the same to its own asker: the central rule's chain of robots that stay,
    decided before anyone decides for good. A plain "could not move" sends the
    asker to its next cell. Local sequencing needs it, since a decision for
    good must stay good (``docs/protocol.md``, "Planning for ``turning`` bodies").
    """

    def _stay_turning(self, toward: int, out: list[Outgoing]) -> None:
        """Decide to stay this step, turning toward ``toward`` (ahead-or-stay rule): the call's last candidate, its own cell."""
        self._stay_toward = toward
        self._next = len(self._candidates)
        self._continue(out)

    def _closes_cycle(self, occupant: int | None, cell: int) -> bool:
        """Whether taking ``cell`` (of ``occupant``) could close a cycle: this robot is pushed, ``occupant`` moves.

        Of the robots of a cycle, each taking the next one's cell, the last to
        decide was pushed (its cell was reserved while it had not decided) and
        takes the cell of one that has decided to move (``docs/protocol.md``).
        """
        return (
            self._parent is not None
            and occupant is not None
            and occupant != self.index
            and self._targets.get(occupant, cell) != cell
        )

    def _settle_turn(self, moved: bool, out: list[Outgoing]) -> None:
        """Decided: drive on to the cell ahead, or turn toward the cell (or wait) and stay, telling whoever took this one."""
        assert self.target is not None
        here, heading = self.present, int(self.heading)
        flat = self.flat
        table = flat.heading_distances(self.goal, 1.0, True, self.guidance)
        chosen = self._stay_toward if self.turns_by_staying and self.target == here else self.target
        facing = turning_action(flat.neighbours, here, heading, chosen, table, flat.y_size)
        self.next_heading = Heading(facing)
        self.drives = self.target != here and facing == heading and self._occupants.get(self.target) not in self._staying
        if not self.drives and moved and not self.turns_by_staying:  # on a failure its asker hears it in the answer
            self._tell_taker(out)

    def _tell_taker(self, out: list[Outgoing]) -> None:
        """Send a :class:`StayMessage` to the robot that reserved this robot's cell, if one did."""
        taker = self._reserved.get(self.present)
        if taker is not None and taker != self.index and self._targets.get(taker) == self.present:
            out.append(Outgoing(StayMessage(self.index, self._seq(), self.step), (taker,)))

    def _swap_partner(self, candidates: list[int], distances: Sequence[float]) -> int | None:
        """``is_swap_required_and_possible`` on what the robot heard: the robot to pull, or None."""
        flat = self.flat
        neighbours, occupants, targets, goals = flat.neighbours, self._occupants, self._targets, self._goals
        settled = self._settled
        here = self.present
        best = candidates[0]
        other = occupants.get(best)
        if (
            other is not None
            and other != self.index
            and other not in targets
            and swap_required(neighbours, settled, distances, flat.distances(goals[other]), here, best)
            and swap_possible(neighbours, settled, best, here)
        ):
            return other
        if best != here:  # "clear" operation, as in push and swap
            for cell in neighbours[here]:
                other = occupants.get(cell)
                if (
                    other is not None
                    and best != cell
                    and swap_required(neighbours, settled, flat.distances(goals[other]), distances, here, best)
                    and swap_possible(neighbours, settled, best, here)
                ):
                    return other
        return None
