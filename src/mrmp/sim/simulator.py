"""The lockstep simulator: every robot's brain, a simulated network, ideal bodies and the referee.

Per tick, as in the thesis (sections 3.5-3.6), with the safety layer:

1. every robot computes its intended Next and sends Present and Next to its peers;
2. the network delivers what is due (at once with zero delay; later with delay,
   so decisions rest on stale knowledge), and robots answer claims;
3. every robot checks for obstacles and decides; a guarded robot claims the
   cell it chose, and the claims and their answers are delivered; a claim
   still short of its majority and due for a resend (at once on a network
   without delay: an answer was lost) is sent again, and delivered;
4. every robot whose move is allowed (guarded: a majority registered the cell
   to it; unguarded: always) moves, turning right first when the heading
   changes, and observes its new cell; with bodies that turn in place
   (``policy.body: turning``) a robot moves only to the cell ahead, and a robot
   that decided to turn toward a neighbour turns a quarter instead, on its cell
   (:meth:`~mrmp.robot.robot.Robot.turn`);
5. the referee checks the new configuration, and the robots' timers run;
6. robots on their goals count a goal reached; in a lifelong run each then
   receives a new goal (drawn with the run's seed).

A robot whose policy has an interaction radius sends its state to the robots
within that radius plus its knowledge lease (:func:`neighbourhood`), and the
network delivers such a radius broadcast to the robots whose bodies stand
there, found through a spatial index (:mod:`mrmp.sim.spatial`): no step of a
tick scans the fleet per message. On a perfect network the robots are *quiet*
(the default): a state goes out when it changes (and every
:data:`STATE_REFRESH` ticks), and a refused claim stands rather than being
sent again every tick; their policies decide as with states every tick
(``docs/protocol.md``, "A quiet fleet on a perfect network").

Time for the safety layer's timers is counted in ticks. The run ends when every
robot stands on its goal (never, in a lifelong run: it ends with "time up" at
the tick limit), at the tick limit, or when the same configuration of
every robot's cell and heading has recurred too often ("deadlock" if nobody
moved meanwhile, else "livelock"), or on Ctrl-C ("interrupted"), always
returning what was computed. It is deterministic for a seed.

Examples
--------
>>> from mrmp.core import Grid, RobotSpec, Scenario
>>> swap = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))))
>>> result = simulate(swap)
>>> result.success, result.makespan, result.sum_of_costs, result.lower_bound
(True, 6, 10, 8)
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Sequence

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.errors import InputError
from mrmp.core.heading import Heading, right_turns
from mrmp.core.result import RobotResult, RunResult
from mrmp.core.scenario import NetworkFaults, Scenario
from mrmp.policies.base import Decision, Policy, interaction_radius
from mrmp.protocol.codec import DecodeError, decode
from mrmp.protocol.messages import Message
from mrmp.robot.robot import Outgoing, Robot
from mrmp.sim.goals import GoalBook
from mrmp.sim.metrics import default_max_ticks, network_slowdown, shortest_steps
from mrmp.sim.policy_table import POLICY_TABLE, body_problem, make_policy, policy_entry
from mrmp.sim.referee import Referee
from mrmp.sim.spatial import SpatialIndex
from mrmp.sim.task_book import hand_out_tasks, task_book
from mrmp.sim.ticking import TickObserver, run_result, run_ticks, scenario_network, send_counted

RECURRENCE_LIMIT = 10
"""How often one configuration may recur before the run is declared stuck (plus
twice the claim timeout, so that robots waiting for late answers are not, and
times the expected tries of a claim under loss)."""


def safety_timers(delay_max: int) -> tuple[int, int]:
    """Retry interval and claim timeout, in ticks, for a network delaying up to ``delay_max`` ticks.

    A claim and its answer take up to ``2 * delay_max`` ticks (within the tick
    on a network without delay); a claim still short of its majority after one
    such round trip is sent again when the robot's timers run at the end of
    that tick, and abandoned after about three (``3 * (2 * delay_max + 1) + 1``
    ticks).

    >>> safety_timers(0), safety_timers(3)
    ((0, 4), (6, 22))
    """
    retry = 2 * delay_max
    return retry, 3 * (retry + 1) + 1


EXTRA_ROUNDS = 6
"""Rounds of exchange a tick adds, on a network that is not perfect, after its three (:meth:`Robot.exchange_again
<mrmp.robot.robot.Robot.exchange_again>`): a tick stands for a move, which lasts many message round trips, and in
these rounds the robots make up within the tick for what was lost (``docs/protocol.md``, "More rounds on a lossy
network")."""


LOSS_LEASE = 2
"""Extra ticks a robot keeps a peer's state on a lossy network: it forgets a peer only after that many more
heartbeats in a row were lost."""


STATE_REFRESH = 8
"""Ticks between two sends of a robot's unchanged state on a perfect network (a changed state goes at once;
``docs/protocol.md``, "A quiet fleet on a perfect network")."""


def state_refresh(policy: Policy, faults: NetworkFaults) -> int | None:
    """Ticks between two sends of an unchanged state by a robot running ``policy``; None: every tick.

    Only on a perfect network, for a policy with an interaction radius: a network that loses, delays,
    duplicates or reorders messages gets a state every tick, as a heartbeat.

    >>> from mrmp.policies.thesis import ThesisPolicy
    >>> state_refresh(ThesisPolicy(), NetworkFaults()), state_refresh(ThesisPolicy(), NetworkFaults(loss=0.1))
    (8, None)
    """
    if interaction_radius(policy) is None or not faults.is_perfect:
        return None
    return STATE_REFRESH


def neighbourhood(policy: Policy, faults: NetworkFaults) -> tuple[int | None, int | None]:
    """The state radius and knowledge lease (ticks) of a robot running ``policy`` over a network with ``faults``.

    The lease covers the network's longest delay (and :data:`LOSS_LEASE` more
    heartbeats when it loses messages). The radius is the policy's interaction
    radius plus twice the lease: two robots approaching each other close two
    cells a tick, so every state either sent in the last ``lease`` ticks by a
    robot now within the interaction radius reached this robot
    (``docs/protocol.md``, "Neighbourhoods"). A policy without an interaction
    radius: (None, None), states to every peer, kept for ever.

    >>> from mrmp.policies.thesis import ThesisPolicy
    >>> neighbourhood(ThesisPolicy(), NetworkFaults()), neighbourhood(ThesisPolicy(), NetworkFaults(loss=0.1, delay_max=2))
    ((2, 0), (10, 4))
    """
    radius = interaction_radius(policy)
    if radius is None:
        return None, None
    lease = faults.delay_max + (LOSS_LEASE if faults.loss > 0 else 0)
    return radius + 2 * lease, lease


class LockstepSimulator:
    """Runs a scenario tick by tick (see the module docstring).

    Parameters
    ----------
    scenario:
        What to run; its policy, network faults, seed and tick limit apply.
    record_decisions:
        Keep every robot's :class:`~mrmp.policies.base.Decision` of every tick
        in :attr:`decisions` (for tests and traces).
    policies:
        One policy per robot, replacing the scenario's (for example robots
        following a central plan).
    record_messages:
        Keep the ``(sender id, recipient id, kind)`` of every message sent,
        tick by tick, in the result's ``message_log`` (for drawing them).
    on_tick:
        Called at the end of every tick with the tick and the robots' cells
        (for watching a run as it goes).
    following:
        Run the safety layer under the lockstep model's rule (the default): a
        robot may enter a cell its occupant leaves in the same tick, once that
        one has handed it off (``docs/protocol.md``). False keeps the rule of
        live bodies, under which a cell is entered only after its release.
    quiet:
        On a perfect network, send a robot's unchanged state only every
        :data:`STATE_REFRESH` ticks, leave out the repairs of lost messages, and
        keep refused claims standing (the default; ``docs/protocol.md``, "What it
        costs"). False: states every tick and refused claims sent again every
        tick, as on a faulty network (the same decisions, more messages).
    """

    def __init__(
        self,
        scenario: Scenario,
        record_decisions: bool = False,
        policies: Sequence[Policy] | None = None,
        *,
        record_messages: bool = False,
        on_tick: TickObserver | None = None,
        following: bool = True,
        quiet: bool = True,
    ) -> None:
        self.scenario = scenario
        grid = scenario.grid
        starts = [spec.start for spec in scenario.robots]
        faults = scenario.worst_faults()
        retry, timeout = safety_timers(faults.delay_max)
        self.body = body_model(scenario.policy.body)
        self.robots = []
        for index, spec in enumerate(scenario.robots):
            policy = policies[index] if policies is not None else make_policy(scenario.policy, scenario.timing)
            state_radius, lease = neighbourhood(policy, faults)
            self.robots.append(
                Robot(
                    spec,
                    index,
                    grid,
                    policy,
                    starts,
                    guarded=scenario.safety,
                    claim_timeout=timeout,
                    retry_interval=retry,
                    state_radius=state_radius,
                    knowledge_lease=lease,
                    following=following,
                    state_refresh=state_refresh(policy, faults) if quiet else None,
                    lossy=not (quiet and faults.is_perfect),
                    body=self.body,
                )
            )
        self.extra_rounds = 0 if faults.is_perfect else EXTRA_ROUNDS
        self.bodies = SpatialIndex(starts)
        """Where every body stands: the simulated radio delivers radius broadcasts through it."""
        slowdown = network_slowdown(scenario) if scenario.safety else 1.0
        per_round_trip = slowdown / (2 * faults.delay_max + 1)
        self.recurrence_limit = int((RECURRENCE_LIMIT + 2 * timeout) * max(1.0, per_round_trip))
        self.network = scenario_network(scenario)
        self.referee = Referee(grid, [spec.id for spec in scenario.robots], self.body)
        self.lengths = shortest_steps(scenario)
        self.max_ticks = scenario.max_ticks or default_max_ticks(scenario, self.lengths)
        self.record_decisions = record_decisions
        self.decisions: list[list[Decision]] = []
        self.tick = 0
        self._results = [
            RobotResult(spec.id, spec.start, spec.goal, path=[spec.start], headings=[spec.heading])
            for spec in scenario.robots
        ]
        self._durations: list[list[float]] = [[] for _ in scenario.robots]
        self._recurrences: Counter[tuple[tuple[Cell, ...], tuple[Heading, ...]]] = Counter()
        self._still_since = 0
        self._everyone = range(len(self.robots))
        self._goals = GoalBook(scenario.seed, grid.free_cells() if scenario.lifelong else [])
        self.task_book = task_book(scenario)
        if self.task_book is not None:
            self._count_goals()
        self.on_tick = on_tick
        self._ids = [spec.id for spec in scenario.robots]
        self._message_log: list[list[tuple[str, str, str]]] | None = [[]] if record_messages else None

    def run(self) -> RunResult:
        """Run to the end and return the result (partial on Ctrl-C)."""
        started = time.perf_counter()
        self.referee.check_start([robot.present for robot in self.robots])
        stop_reason = run_ticks(self, lambda: all(robot.arrived for robot in self.robots), self._stuck)
        return self._result(stop_reason, time.perf_counter() - started)

    def step(self) -> None:
        """Advance one tick."""
        self.tick += 1
        tick = self.tick
        robots = self.robots
        if self._message_log is not None:
            self._message_log.append([])
        for robot in robots:
            self._send(robot, robot.announce(tick))
        self._drain()
        for robot in robots:
            self._send(robot, robot.decide(tick))
        self._drain()
        for robot in robots:
            self._send(robot, robot.retry(tick))
        self._drain()
        for _ in range(self.extra_rounds):
            for robot in robots:
                self._send(robot, robot.exchange_again(tick))
            self._drain()
        if self.record_decisions:
            self.decisions.append([robot.last_decision for robot in robots])  # type: ignore[misc]
        before = [robot.present for robot in robots]
        headings_before = [robot.heading for robot in robots]
        targets = [robot.motion(tick) for robot in robots]
        timing = self.scenario.timing
        grid = self.scenario.grid
        quarter = self.body.turn_ticks(timing.turn_time, timing.cell_time) * timing.cell_time
        moved = False
        for robot, target in zip(robots, targets):
            result = self._results[robot.index]
            heading = robot.heading
            duration = timing.cell_time
            turn = robot.turn(tick) if target is None else None
            if turn is not None:
                moved = True
                result.turns += 1
                duration = quarter
                robot.turned(turn)
            elif target is not None and target != robot.present:
                moved = True
                try:
                    new_heading = Heading.between(robot.present, target)
                except ValueError:
                    new_heading = heading
                turns = self.body.quarter_turns(heading, new_heading) if self.body.headed else right_turns(heading, new_heading)
                result.turns += turns
                cost = grid.cost(target) if grid.in_bounds(target) else 1.0
                duration = turns * timing.turn_time + timing.cell_time * cost
                heading = new_heading
            if target is not None:
                if target != robot.present:
                    self.bodies.move(robot.index, robot.present, target)
                robot.arrived_at(target, heading)
            result.path.append(robot.present)
            result.headings.append(robot.heading)
            self._durations[robot.index].append(duration)
        if self.body.headed:
            after_headings = [robot.heading for robot in robots]
            self.referee.check_tick(tick, before, [robot.present for robot in robots], headings_before, after_headings)
        else:
            self.referee.check_tick(tick, before, [robot.present for robot in robots])
        self._still_since = self._still_since + 1 if not moved else 0
        self._count_goals()
        for robot in robots:
            self._send(robot, robot.expire(tick))
        if self.on_tick is not None:
            self.on_tick(tick, [robot.present for robot in robots])

    def _send(self, robot: Robot, outgoing: list[Outgoing]) -> None:
        result = self._results[robot.index]
        log = self._message_log
        for item in outgoing:
            recipients = send_counted(self.network, robot.index, item, self._everyone, self.tick, result, self._near)
            if log is not None:
                self._log_message(log[-1], robot.index, item.message, recipients)

    def _near(self, sender: int, radius: int) -> list[int]:
        """The robots whose bodies stand within ``radius`` cells of ``sender``'s body."""
        bodies = self.bodies
        return bodies.within(bodies.cell_of(sender), radius)

    def _log_message(
        self, entries: list[tuple[str, str, str]], sender: int, message: Message, recipients: Sequence[int] | range
    ) -> None:
        """Note in this tick's ``entries`` one message sent to each of ``recipients`` (but its sender)."""
        kind = message_kind(message)
        ids = self._ids
        name = ids[sender]
        entries.extend((name, ids[recipient], kind) for recipient in recipients if recipient != sender)

    def _drain(self) -> None:
        """Deliver everything due by this tick, including answers sent meanwhile."""
        robots = self.robots
        tick = self.tick
        decoded: dict[bytes, Message | None] = {}
        while True:
            batch = self.network.deliver(tick)
            if not batch:
                return
            for _, recipient, payload in batch:
                if payload in decoded:
                    message = decoded[payload]
                else:
                    try:
                        message = decode(payload)
                    except DecodeError:
                        message = None
                    decoded[payload] = message
                robot = robots[recipient]
                replies = robot.receive_datagram(payload, tick) if message is None else robot.receive(message, tick)
                if replies:
                    self._send(robot, replies)

    def _count_goals(self) -> None:
        """Count goals reached this tick; in a lifelong run, hand each such robot a new goal.

        New goals are drawn, with the run's seed, among free cells that are
        nobody's goal and not the robot's own cell, robots taken in index order.
        """
        robots = self.robots
        if self.task_book is not None:
            hand_out_tasks(self.task_book, self.tick, [robot.present for robot in robots], self._results, self._set_goal)
            return
        for index in self._goals.arrivals(robot.arrived for robot in robots):
            self._results[index].goals_reached += 1
            if self.scenario.lifelong:
                robot = robots[index]
                goal = self._goals.next_goal(index, {other.goal for other in robots}, robot.present)
                if goal is not None:
                    robot.goal = goal

    def _set_goal(self, index: int, goal: Cell) -> None:
        self.robots[index].goal = goal

    def _stuck(self) -> str | None:
        configuration = (tuple(robot.present for robot in self.robots), tuple(robot.heading for robot in self.robots))
        self._recurrences[configuration] += 1
        if self._recurrences[configuration] < self.recurrence_limit or (
            not self.scenario.lifelong and all(robot.arrived for robot in self.robots)
        ):
            return None
        return "deadlock" if self._still_since >= self.recurrence_limit - 1 else "livelock"

    def _result(self, stop_reason: str, wall_time: float) -> RunResult:
        for index, result in enumerate(self._results):
            result.time_s = sum(self._durations[index][: result.cost])
        network = self.network.stats.as_dict()
        network["dropped_by_robots"] = sum(sum(robot.dropped.values()) for robot in self.robots)
        network["stale"] = sum(robot.belief.stale_messages for robot in self.robots)
        for name in ("claims", "granted", "refused", "timed_out"):
            network[f"claims_{name}" if name != "claims" else "claims"] = sum(
                getattr(robot.safety.stats, name) for robot in self.robots
            )
        network["releases"] = sum(robot.safety.stats.releases for robot in self.robots)
        network["releases_given_up"] = sum(robot.safety.stats.releases_given_up for robot in self.robots)
        policy = self.robots[0].policy.name if self.robots else self.scenario.policy.name
        return run_result(self, self._results, policy, stop_reason, wall_time, network, message_log=self._message_log)


def message_kind(message: object) -> str:
    """The short name of a message's type, as written in a message log.

    >>> from mrmp.protocol.messages import ClaimMessage
    >>> message_kind(ClaimMessage.__new__(ClaimMessage))
    'claim'
    """
    name = type(message).__name__
    return (name[: -len("Message")] if name.endswith("Message") else name).lower()


def records_messages(scenario: Scenario, policies: Sequence[Policy] | None = None) -> bool:
    """Whether :func:`simulate` can keep a message log for ``scenario``.

    The lockstep simulator can (per-robot policies, or the ``policies`` given);
    a message-based policy's simulator can when its policy table entry says so
    (:mod:`mrmp.sim.policy_table`): the synchronous rounds of ``pibt`` exchange
    their messages inside each step, and asynchronous runs (``causal``) keep
    no log either.
    """
    entry = POLICY_TABLE.get(scenario.policy.name)
    return policies is not None or entry is None or entry.per_robot or entry.records_messages


def simulate(
    scenario: Scenario,
    record_decisions: bool = False,
    policies: Sequence[Policy] | None = None,
    *,
    record_messages: bool = False,
    on_tick: TickObserver | None = None,
) -> RunResult:
    """Run ``scenario`` in the lockstep simulator and return its result.

    A message-based policy runs in the simulator its policy table entry names
    (:mod:`mrmp.sim.policy_table`): ``pibt`` in synchronous rounds
    (:class:`mrmp.sim.rounds.RoundsSimulator`), which calls ``on_tick`` too but
    keeps no message log (its ``message_log`` stays ``None`` even with
    ``record_messages``; see :func:`records_messages`), ``causal``
    asynchronously (:class:`mrmp.sim.asynchronous.AsynchronousSimulator`),
    likewise without a message log.

    Parameters
    ----------
    scenario:
        What to run.
    record_decisions:
        Keep every robot's decisions (per-robot policies only).
    policies:
        One policy per robot, replacing the scenario's.
    record_messages:
        Keep the per-tick ``(sender, recipient, kind)`` of every message sent
        in the result's ``message_log``.
    on_tick:
        Called at the end of every tick with the tick and the robots' cells.

    Examples
    --------
    >>> from mrmp.core import Grid, RobotSpec, Scenario
    >>> swap = Scenario(Grid(1, 3), (RobotSpec("A", (0, 0), (0, 1)), RobotSpec("B", (0, 2), (0, 2))))
    >>> seen = []
    >>> result = simulate(swap, record_messages=True, on_tick=lambda tick, cells: seen.append((tick, cells)))
    >>> seen
    [(1, [(0, 1), (0, 2)])]
    >>> sorted(set(result.message_log[1]))  # doctest: +NORMALIZE_WHITESPACE
    [('A', 'B', 'claim'), ('A', 'B', 'handoff'), ('A', 'B', 'release'), ('A', 'B', 'state'),
     ('B', 'A', 'reply'), ('B', 'A', 'state')]
    """
    problem = body_problem(scenario, planned=policies is not None)
    if problem is not None:
        raise InputError(problem)
    entry = policy_entry(scenario.policy.name) if policies is None else None
    if entry is not None and not entry.per_robot:
        if record_decisions:
            raise ValueError("decisions are recorded for per-robot policies only")
        return entry.simulation(scenario, on_tick=on_tick).run()
    return LockstepSimulator(
        scenario, record_decisions=record_decisions, policies=policies, record_messages=record_messages, on_tick=on_tick
    ).run()
