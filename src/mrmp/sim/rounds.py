"""Synchronous rounds: the simulator of policy ``pibt``, robots computing PIBT by messages.

Each step of decentralized PIBT (:mod:`mrmp.robot.pibt_robot`) is a
conversation in *synchronous rounds* (Lynch, *Distributed Algorithms*, 1996,
chapter 2): in a round every robot receives all messages sent to it in the
previous round, then acts on them. A step runs as follows:

1. every robot sends its beacon to the robots within its radio radius (the
   simulator plays the radio: it delivers a broadcast of radius ``r`` to
   every robot within ``r`` cells, Manhattan distance, of the sender);
2. robots decide in priority order: the highest-priority robot that has not
   decided yet starts its PIBT call, and the rounds run until no message is in
   flight; then the next. Robots farther than two cells apart from every robot
   of another *group* (the connected parts of the "within two cells" relation)
   never exchange a message, so groups run at the same time; the simulator
   serves them one after the other and charges time per group;
3. every robot moves to the cell it reserved; the referee checks the move.

**Bodies.** With ``policy.body: turning`` (LoRR's ``MAPF_T``,
:mod:`mrmp.core.body`) the robots plan as bodies that turn in place
(:class:`~mrmp.robot.pibt_robot.PibtRobot`'s ``turning``; no swap technique):
in a step a robot drives to the cell ahead, turns a quarter, or waits, each
lasting one cell time, and the referee judges every step by that body's rules
(actions, following, no rotation).

**Faults.** Messages cross a link layer with acknowledgements and
retransmission (automatic repeat request): each try is lost, duplicated,
delayed or reordered as the scenario's network says (one draw of
:func:`mrmp.core.faults.message_fates` per try); a lost try or a lost
acknowledgement is sent again after ``2 * delay_max + 1`` ticks. A round ends
when its last message has arrived, so delays make steps take longer (robots
stand still meanwhile) but never change a decision; duplicates are dropped by
the robots. A message that still has not arrived after 64 tries (a cut link)
abandons the step: nobody moves, which is always safe. Messages, tries,
acknowledgements, duplicates and rounds are counted in the result's ``network``.

Deterministic for a seed. Ends when every robot stands on its goal (never in a
lifelong run), at the tick limit, or on Ctrl-C, returning what was computed.

Examples
--------
>>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
>>> swap = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))),
...                 policy=PolicyOptions(name="pibt"))
>>> result = RoundsSimulator(swap).run()
>>> result.success, result.makespan, result.sum_of_costs, result.lower_bound
(True, 7, 11, 8)
"""

from __future__ import annotations

import gc
import time
from collections import Counter
from collections.abc import Container, Sequence
from operator import attrgetter
from typing import Any

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.faults import message_fates
from mrmp.core.heading import right_turns
from mrmp.core.result import RobotResult, RunResult
from mrmp.core.scenario import NetworkFaults, Scenario
from mrmp.core.seeds import Stream, stream_random
from mrmp.policies.pibt_rules import DEAD_END_BONUS
from mrmp.protocol.codec import fixed_sizes
from mrmp.protocol.messages import BeaconMessage, Message, ReserveMessage  # noqa: F401  (ReserveMessage: doctest)
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_robot import RESERVE_RADIUS, PibtRobot
from mrmp.search.flat_map import FlatMap
from mrmp.sim.goals import GoalBook
from mrmp.sim.metrics import default_max_ticks, network_slowdown, shortest_steps
from mrmp.sim.referee import Referee
from mrmp.sim.task_book import hand_out_tasks, task_book
from mrmp.sim.ticking import TickObserver, link_faults, run_result, run_ticks

__all__ = ["MAX_TRIES", "RoundsSimulator", "message_size"]

MAX_TRIES = 64
"""Tries of one message before its link counts as cut and the step is abandoned."""
NO_ROBOT = -1
"""No robot on a cell."""

def message_size(message: object) -> int:
    """Bytes of ``message`` on the wire (every message of a PIBT type has the same size).

    >>> message_size(ReserveMessage(3, 1, 7, (2, 2)))
    22
    """
    return fixed_sizes()[type(message)]


class _CutLink(Exception):
    """A message did not get through in :data:`MAX_TRIES` tries."""


class RoundsSimulator:
    """Runs a scenario with robots computing PIBT by messages (module docstring).

    Parameters
    ----------
    scenario:
        What to run. Its policy options give the radio radius (``radius``),
        the swap technique (``swap``) and turn-aware ordering (``heading_aware``).
    random_ties:
        Give each robot a random generator (seeded with the scenario's seed and
        its index) to break ties between equally near cells
        (:class:`~mrmp.robot.pibt_robot.PibtRobot`'s ``rng``); ``False`` keeps
        the plain neighbour order, as :class:`mrmp.centralized.pibt_step.PIBT`
        without ``rng`` does.
    on_tick:
        Called at the end of every tick with the tick and the robots' cells.
    tie_penalties:
        The robots' tie penalties (:class:`~mrmp.robot.pibt_robot.PibtRobot`);
        None turns them on with ``random_ties``.
    """

    robot_type: type[PibtRobot] = PibtRobot
    """The brain every robot runs."""

    def __init__(
        self,
        scenario: Scenario,
        random_ties: bool = True,
        on_tick: TickObserver | None = None,
        tie_penalties: bool | None = None,
    ) -> None:
        self.scenario = scenario
        self.on_tick = on_tick
        options = scenario.policy
        grid = scenario.grid
        self.flat = FlatMap(grid)
        flat = self.flat
        self.body = body_model(options.body)
        turning = self.body.turns_in_place
        self.robots: list[PibtRobot] = []
        turning_options: dict[str, Any] = (
            {"turning": True, "dead_end_bonus": DEAD_END_BONUS, "guidance": options.guidance} if turning else {}
        )
        for index, spec in enumerate(scenario.robots):
            goal = flat.index(spec.goal)
            start = flat.index(spec.start)
            distance = flat.distances(goal)[start]
            self.robots.append(
                self.robot_type(
                    index,
                    start,
                    goal,
                    flat,
                    tie=int(distance) if distance != float("inf") else 0,
                    heading=spec.heading,
                    radius=options.radius,
                    swap=options.swap and not turning,
                    heading_aware=options.heading_aware,
                    turn_cost=scenario.timing.turn_time / scenario.timing.cell_time,
                    rng=stream_random(scenario.seed, Stream.TIES, index) if random_ties else None,
                    tie_penalties=tie_penalties,
                    **turning_options,
                )
            )
        self.referee = Referee(grid, [spec.id for spec in scenario.robots], self.body)
        self.lengths = shortest_steps(scenario)
        self.max_ticks = scenario.max_ticks or self._default_max_ticks()
        self.tick = 0
        self.step_count = 0
        self._results = [
            RobotResult(spec.id, spec.start, spec.goal, path=[spec.start], headings=[spec.heading])
            for spec in scenario.robots
        ]
        self._durations: list[list[float]] = [[] for _ in scenario.robots]
        self._random = stream_random(scenario.seed, Stream.NETWORK)
        self._links = link_faults(scenario)
        self._perfect = scenario.perfect_network
        self._near: dict[int, list[tuple[int, ...] | None]] = {}
        self._occupant: list[int] = []  # robot on every flat cell this step, NO_ROBOT where none
        self._receivers = [robot.receive_once for robot in self.robots]  # the perfect network's deliveries
        self._group_of: list[int] = []
        self.stats: Counter[str] = Counter()
        self._sizes = fixed_sizes()  # bytes of each message type on the wire, from the message table
        self._goals = GoalBook(scenario.seed, grid.free_cells() if scenario.lifelong else [])
        self.task_book = task_book(scenario, flat)
        if self.task_book is not None:
            self._count_goals()

    def _default_max_ticks(self) -> int:
        """Room for PIBT's steps (as :func:`~mrmp.sim.metrics.default_max_ticks`); over a slow or lossy
        network, times the ticks a round trip can take with its retries, times the robots (the roots of
        a group decide one after the other, each waiting for its rounds)."""
        ticks = default_max_ticks(self.scenario.with_changes(safety=False), self.lengths)
        worst = self.scenario.worst_faults()
        if worst.delay_max or worst.loss:
            slowdown = network_slowdown(self.scenario.with_changes(safety=True))
            ticks = int(ticks * slowdown * max(1, len(self.robots))) if worst.delay_max else int(ticks * slowdown)
        return ticks

    # -- the run ---------------------------------------------------------------------

    def run(self) -> RunResult:
        """Run to the end and return the result (partial on Ctrl-C).

        Python's cyclic garbage collector is paused meanwhile (and restored
        after): a step makes thousands of short-lived containers (the robots'
        views, the messages) and no reference cycles, so reference counting
        frees them all, and the collector's passes over them only cost time.
        """
        started = time.perf_counter()
        robots = self.robots
        self.referee.check_start(
            [spec.start for spec in self.scenario.robots], [spec.heading for spec in self.scenario.robots]
        )
        collecting = gc.isenabled()
        gc.disable()
        try:
            stop_reason = run_ticks(self, lambda: all(robot.at_goal for robot in robots))
        finally:
            if collecting:
                gc.enable()
        return self._result(stop_reason, time.perf_counter() - started)

    def step(self) -> None:
        """One PIBT step: beacons, decisions in priority order, waits for slow rounds, then the moves."""
        self.step_count += 1
        step = self.step_count
        robots = self.robots
        occupant = self._occupant = [NO_ROBOT] * len(self.flat.neighbours)
        for robot in robots:
            occupant[robot.present] = robot.index
        if not self._perfect:
            self._group_of = self._groups()
        outbox = [(robot.index, sent) for robot in robots for sent in robot.begin_step(step)]
        try:
            extra = 0 if self._perfect and self._beacon_round(outbox) else self._rounds(outbox)
            group_time: Counter[int] = Counter()
            # highest priority first: ``(elapsed, tie, -index)`` descending (a stable sort keeps index order)
            order = sorted(robots, key=attrgetter("elapsed", "tie"), reverse=True)
            rounds = self._rounds
            for robot in order:
                if robot.target is None:
                    spent = rounds([(robot.index, sent) for sent in robot.start()])
                    if spent:  # never over a perfect network, whose rounds take no time
                        group_time[self._group_of[robot.index]] += spent
            extra += max(group_time.values(), default=0)
            abandoned = False
        except _CutLink:
            abandoned = True
            extra = 0
            self.stats["abandoned_steps"] += 1
        for _ in range(extra):
            if self.tick >= self.max_ticks:
                return
            self._advance(moves=False)
        if self.tick < self.max_ticks:
            self._advance(moves=not abandoned)

    def _advance(self, moves: bool, movers: Container[int] | None = None) -> None:
        """One tick: the robots move to their reserved cells (``moves``; only the robots in ``movers``, when
        given, end their step) or all stand still."""
        self.tick += 1
        robots = self.robots
        cells = self.flat.cells
        timing = self.scenario.timing
        grid = self.scenario.grid
        cost = grid.cost if grid.has_costs else None
        cell_time, turn_time = timing.cell_time, timing.turn_time
        results, durations = self._results, self._durations
        before = [cells[robot.present] for robot in robots]
        headings_before = [robot.heading for robot in robots]
        turns_in_place = self.body.turns_in_place
        for robot in robots:
            index = robot.index
            result = results[index]
            heading = robot.heading
            duration = cell_time
            if moves and (movers is None or index in movers):
                was = robot.present
                robot.finish_step()
                if turns_in_place:  # every action lasts a cell time: forward (its entry cost), a quarter turn, a wait
                    result.turns += int(robot.heading != heading)
                    if robot.present != was and cost is not None:
                        duration = cell_time * cost(cells[robot.present])
                elif robot.present != was:
                    turns = right_turns(heading, robot.heading)
                    result.turns += turns
                    entry = cell_time * cost(cells[robot.present]) if cost is not None else cell_time
                    duration = turns * turn_time + entry
            result.path.append(cells[robot.present])
            result.headings.append(robot.heading)
            durations[index].append(duration)
        after = [cells[robot.present] for robot in robots]
        if self.body.headed:
            self.referee.check_tick(self.tick, before, after, headings_before, [robot.heading for robot in robots])
        else:
            self.referee.check_tick(self.tick, before, after)
        self._count_goals()
        if self.on_tick is not None:
            self.on_tick(self.tick, after)

    def _count_goals(self) -> None:
        """Count goals reached; in a lifelong run, hand each such robot a new goal (drawn with the seed, or the task book's)."""
        flat = self.flat
        robots = self.robots
        if self.task_book is not None:
            cells = [flat.cells[robot.present] for robot in robots]
            hand_out_tasks(self.task_book, self.tick, cells, self._results, self._set_goal)
            return
        for index in self._goals.arrivals(robot.at_goal for robot in robots):
            self._results[index].goals_reached += 1
            if self.scenario.lifelong:
                robot = robots[index]
                taken = {flat.cell(other.goal) for other in robots}
                goal = self._goals.next_goal(index, taken, flat.cell(robot.present))
                if goal is not None:
                    robot.goal = flat.index(goal)
                    robot.elapsed = 0

    def _set_goal(self, index: int, goal: Cell) -> None:
        robot = self.robots[index]
        robot.goal = self.flat.index(goal)
        robot.elapsed = 0

    # -- rounds ------------------------------------------------------------------------

    def _within(self, cell: int, radius: int) -> tuple[int, ...]:
        """The free flat cells within ``radius`` (Manhattan) of ``cell``, itself excluded (cached per cell)."""
        table = self._near.get(radius)
        if table is None:
            table = self._near[radius] = [None] * len(self.flat.neighbours)
        cells = table[cell]
        if cells is None:
            cells = table[cell] = self._cells_within(cell, radius)
        return cells

    def _cells_within(self, cell: int, radius: int) -> tuple[int, ...]:
        grid = self.scenario.grid
        x, y = self.flat.cell(cell)
        return tuple(
            self.flat.index((x + dx, y + dy))
            for dx in range(-radius, radius + 1)
            for dy in range(-radius + abs(dx), radius - abs(dx) + 1)
            if (dx or dy) and grid.in_bounds((x + dx, y + dy)) and grid.is_free((x + dx, y + dy))
        )

    def _rounds(self, outbox: list[tuple[int, Outgoing]]) -> int:
        """Run rounds until no message is in flight; return the ticks they took.

        A robot acts in a round when it was sent something in the round
        before; robots that heard only beacons and reservations (which ask
        nothing of them) are skipped, in the same order, so decisions and
        counts are those of calling every recipient.
        """
        if not self._perfect:
            return self._faulty_rounds(outbox)
        robots = self.robots
        receivers = self._receivers
        results = self._results
        occupant = self._occupant
        near = self._near
        sizes = self._sizes
        rounds = 0
        while outbox:
            rounds += 1
            acting: dict[int, None] = {}
            ready: set[int] = set()
            for sender, (message, recipients, radius) in outbox:
                result = results[sender]
                if recipients is not None:
                    hearers: Sequence[int] = recipients
                else:
                    assert radius is not None, "a PIBT robot broadcasts within a radius"
                    present = robots[sender].present
                    table = near.get(radius)
                    cells = table[present] if table is not None else None
                    if cells is None:
                        cells = self._within(present, radius)
                    hearers = [other for cell in cells if (other := occupant[cell]) != NO_ROBOT]
                result.messages_sent += len(hearers)
                result.bytes_sent += sizes[type(message)] * len(hearers)
                for recipient in hearers:
                    acting[recipient] = None
                    if receivers[recipient](message):
                        ready.add(recipient)
            if not ready:
                break
            outbox = [(index, sent) for index in acting if index in ready for sent in robots[index].act()]
        self.stats["rounds"] += rounds
        return 0

    def _beacon_round(self, outbox: list[tuple[int, Outgoing]]) -> bool:
        """The beacon round over a perfect network, one call per recipient; False (nothing done) if it does not apply.

        Applies when every robot broadcasts one beacon with the same radius:
        "within the radius" is then symmetric, so the robots a robot hears are
        those that hear it, and each robot's messages sent equal those it receives.
        """
        robots = self.robots
        if len(outbox) != len(robots) or not outbox:
            return False
        radius = outbox[0][1].radius
        if radius is None:
            return False
        beacons: list[BeaconMessage] = []
        for index, (sender, (message, recipients, sent_radius)) in enumerate(outbox):
            if sender != index or recipients is not None or sent_radius != radius or type(message) is not BeaconMessage:
                return False
            beacons.append(message)
        occupant = self._occupant
        results = self._results
        size = self._sizes[BeaconMessage]
        within = self._within
        table = self._near.get(radius)
        for robot in robots:
            cells = table[robot.present] if table is not None else None
            if cells is None:
                cells = within(robot.present, radius)
                table = self._near[radius]
            heard = [beacons[other] for cell in cells if (other := occupant[cell]) != NO_ROBOT]
            result = results[robot.index]
            result.messages_sent += len(heard)
            result.bytes_sent += size * len(heard)
            if heard:
                robot.receive_beacons(heard)
        self.stats["rounds"] += 1
        return True

    def _faulty_rounds(self, outbox: list[tuple[int, Outgoing]]) -> int:
        """:meth:`_rounds` over faulty links: every try drawn by :meth:`_link`."""
        robots = self.robots
        results = self._results
        occupant = self._occupant
        stats = self.stats
        spent = 0
        while outbox:
            stats["rounds"] += 1
            acting: dict[int, None] = {}
            late: list[tuple[int, Message]] = []
            round_time = 0
            for sender, sent in outbox:
                message = sent.message
                if sent.recipients is not None:
                    recipients: Sequence[int] = sent.recipients
                else:
                    assert sent.radius is not None, "a PIBT robot broadcasts within a radius"
                    recipients = [
                        other
                        for cell in self._within(robots[sender].present, sent.radius)
                        if (other := occupant[cell]) != NO_ROBOT
                    ]
                size = self._sizes[type(message)]
                result = results[sender]
                result.messages_sent += len(recipients)
                result.bytes_sent += size * len(recipients)
                for recipient in recipients:
                    latency, copies, held = self._link(sender, recipient)
                    round_time = max(round_time, latency)
                    for _ in range(copies - held):
                        robots[recipient].receive(message)  # type: ignore[arg-type]
                    late.extend((recipient, message) for _ in range(held))
                    acting[recipient] = None
            for recipient, message in late:  # copies held back arrive last in the round
                robots[recipient].receive(message)  # type: ignore[arg-type]
            spent += round_time
            outbox = [(index, sent) for index in acting for sent in robots[index].act()]
        return spent

    def _link(self, sender: int, recipient: int) -> tuple[int, int, int]:
        """Send one message over a faulty link with retransmission: (ticks until it arrives, copies, copies held back)."""
        faults: NetworkFaults = self._links.get((sender, recipient), self.scenario.network)
        rng = self._random
        stats = self.stats
        timeout = 2 * faults.delay_max + 1 if faults.delay_max else 0

        def delay() -> int:
            return rng.randint(faults.delay_min, faults.delay_max)

        waited = 0
        arrival: int | None = None
        copies = held = 0
        for _ in range(MAX_TRIES):
            stats["tries"] += 1
            fates = message_fates(rng, faults.loss, faults.duplicate, faults.reorder, delay)
            stats["lost"] += fates.lost
            stats["duplicated"] += int(fates.duplicated)
            acknowledged = False
            for copy in fates.delivered:
                copies += 1
                held += int(copy.reordered)
                stats["delivered"] += 1
                stats["acks"] += 1
                if arrival is None or waited + int(copy.delay) < arrival:
                    arrival = waited + int(copy.delay)
                if not (faults.loss and rng.random() < faults.loss):
                    acknowledged = True
                else:
                    stats["acks_lost"] += 1
            if acknowledged:
                if copies > 1:
                    stats["extra_copies"] += copies - 1
                return arrival or 0, copies, held
            stats["retransmissions"] += 1
            waited += timeout
        if arrival is not None:
            return arrival, copies, held
        raise _CutLink

    def _groups(self) -> list[int]:
        """Each robot's group: robots within two cells of each other, transitively (union-find)."""
        parent = list(range(len(self.robots)))

        def root(index: int) -> int:
            while parent[index] != index:
                parent[index] = parent[parent[index]]
                index = parent[index]
            return index

        occupant = self._occupant
        for robot in self.robots:
            for cell in self._within(robot.present, RESERVE_RADIUS):
                other = occupant[cell]
                if other != NO_ROBOT:
                    parent[root(other)] = root(robot.index)
        return [root(index) for index in range(len(self.robots))]

    # -- the result --------------------------------------------------------------------

    def _result(self, stop_reason: str, wall_time: float) -> RunResult:
        for index, result in enumerate(self._results):
            result.time_s = sum(self._durations[index][: result.cost])
        network = {name: int(value) for name, value in sorted(self.stats.items())}
        network["steps"] = self.step_count
        network["messages"] = sum(result.messages_sent for result in self._results)
        network["dropped_by_robots"] = sum(sum(robot.dropped.values()) for robot in self.robots)
        network["distance_tables"] = self.flat.tables_computed
        return run_result(
            self, self._results, "pibt", stop_reason, wall_time, network, planning_time_s=self.flat.table_seconds
        )

