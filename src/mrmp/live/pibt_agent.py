"""The live driver of one ``pibt`` robot: locally sequenced PIBT, steps on a clock or ended by the robot, bodies guarded.

No driver can order live processes, so a live ``pibt`` robot sequences its
PIBT calls itself: its brain is :class:`~mrmp.robot.pibt_live.LivePibtRobot`
(local sequencing over a faulty network, with acknowledgements and timers,
knowing instead of sensing which robots can be near). :class:`PibtBrain` wraps
it with what a live robot adds, sans-IO (fed with the clock, never reading it):

* **steps on a common clock**: step ``k`` (from 1) begins at ``t0 + (k - 1) *
  step`` seconds, ``t0`` being the moment the robot has heard every peer (the
  fleet's start: a robot answers a peer it hears of for the first time at once,
  so every robot gets there at about the same moment when nothing is lost). A
  robot that receives a PIBT message of a later step than its own begins that
  step at once (ending the steps in between undecided; a fleet heartbeat
  naming step ``p`` counts as a message of step ``p - 1``), and keeps that
  schedule: the fleet keeps the schedule of its earliest robot, each robot
  within a message's delay of it. The first
  ``decide`` seconds of a step are its decision phase, at whose end a robot
  that has not decided for good stays (an abandoned step);
* **moves queued as soon as decided, decisions overlapping moves**: a robot
  queues its move the moment it decides for good (a decision for good never
  changes), not at the end of the decision phase, and the next step begins
  while the body still performs it: the step lasts a move with one right turn
  (:meth:`PibtTiming.for_body`), not the decision phase and a move one after
  the other. Step ``k + 1`` is decided from the cells the fleet decided in step
  ``k``, whether the bodies have reached them or not (the decisions never
  depended on the bodies);
* **bodies through the safety layer**: a queued move is claimed from the
  cell's replicas (:class:`~mrmp.protocol.safety.SafetyLayer`); the body starts
  only once a majority registered the cell to it, and its old cell is
  released once the body has left it. Live bodies cover both cells while they
  move, so a robot following another into its cell enters only once the
  leader has cleared it: a chain of followers moves one after the other, and
  its tail may still be moving when the next step begins;
* **held robots**: a robot whose queued move has not been granted when a step
  begins takes part in no call in that step, until the grant arrives, and
  stays at its turn (``LivePibtRobot.held``): a robot leaves a cell only once its
  body owns it, which keeps the execution free of deadlocks (``docs/protocol.md``,
  "Local sequencing", "Live");
* **or steps ended by the robots** (``synchronizer: local``): no step clock;
  the brain is :class:`~mrmp.robot.pibt_synchronized.SynchronizedPibtRobot`,
  which begins its next step the moment its step is done (it and every robot
  within 2 cells decided for good), held while its last move is not granted;
  a held robot gives up after ``hold`` seconds from its step's start, as on the
  clock, and no step ends undecided (``docs/protocol.md``, "Live", "Steps
  ended by the robots"); a settled robot whose neighbours are all on their
  goals *rests*, beginning no step until a peer's message of a later step
  comes, and a settled robot behind its peers catches up at once
  (:attr:`PibtBrain.resting`);
* a peer silent for ``crash_after`` seconds is taken for crashed (an obstacle
  on its last known cell, no longer waited for), until it is heard again;
* **lifelong**: a robot of a lifelong run takes its tasks from the task desk
  (:class:`~mrmp.robot.task_taker.TaskTaker`, :mod:`mrmp.live.task_desk`):
  its goal, set as a step begins, is its task's next errand; an errand counts
  as soon as the robot decides for good to end a step on it; after its last
  step (the scenario's ``max_ticks``) its goal is its cell and it is done;
* the brain's timers run in whole milliseconds since ``t0``.

:class:`PibtAgent` is the process around it (:class:`~mrmp.live.driver.LiveDriver`):
the receiving and client threads, the body (its step timing by default
:meth:`PibtTiming.for_body` of the body's cell and turn times), the fleet heartbeat
(a :class:`~mrmp.protocol.messages.StateMessage`, for discovery, for the end
of the run, and to keep every robot's knowledge of the far robots fresh: its
``present`` is the cell the robot stands on at the start of step ``progress``).
A PIBT message sent again by its brain keeps its sequence number
(the brain recognises second copies by it), which the envelope's replay window
rejects; :func:`open_repeat` lets such a datagram through, once its MAC and
session are checked, to be acknowledged again and otherwise ignored by the brain.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.core.scenario import Scenario
from mrmp.core.seeds import Stream, stream_random
from mrmp.live.body import Body
from mrmp.live.driver import AgentTiming, LiveDriver, Sending, fleet_wide
from mrmp.live.transport import Transport
from mrmp.policies.pibt_rules import DEAD_END_BONUS
from mrmp.protocol.auth import OVERHEAD, TAG_BYTES, Opener, Sealer
from mrmp.protocol.codec import DecodeError, decode
from mrmp.protocol.messages import (
    BeaconMessage,
    ClaimMessage,
    FarewellMessage,
    Message,
    PibtMessage,
    ReleaseAckMessage,
    ReleaseMessage,
    ReplyMessage,
    StateMessage,
)
from mrmp.protocol.pibt_local import CallAckMessage
from mrmp.protocol.safety import SafetyLayer
from mrmp.protocol.tasks import TaskMessage
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_live import LivePibtRobot
from mrmp.robot.pibt_synchronized import SynchronizedPibtRobot
from mrmp.robot.task_taker import TaskTaker
from mrmp.search.flat_map import FlatMap

__all__ = ["PibtAgent", "PibtBrain", "PibtTiming", "open_repeat"]

M = TypeVar("M", bound=Message)

TASK_RETRY = 0.1
"""Seconds between two sends of a lifelong robot's task report that the desk has not answered."""

POLL = 0.01
"""Seconds between two polls of a live ``pibt`` robot at least: two thirds of its retransmission interval
(a process per robot, many of them on a few cores: each poll costs CPU time the others wait for)."""

LONGEST_ASK_GAP_TOGETHER = 2
"""Over a transport that sends a turn's messages together (multicast), a robot asks for a missing beacon one
retry after its step's beacon, then every two retries (``LivePibtRobot.longest_beacon_gap``). Most asks go to a
peer that has not begun the step yet, which answers once it has; there each ask is a datagram of its own, and
asking every retry cost 2 datagrams per move more at the same makespan. Over unicast the slower asks cost 0.19
s of 6.27 for 0.9 messages per move fewer (24 robots of ``causal-32`` at 20% loss, 24 seeds on the virtual
clock: ``docs/protocol.md``, "Sent again, and when")."""

CLAIM_RETRY = 0.02
"""Seconds between two sends of a robot's claim of a cell, or of its release, that no replica has answered yet:
over a lossy network a move waits for its grant, and each follower's grant for its leader's release; 50 ms
instead made 24 turning robots at 20% loss 0.4 s slower (``docs/protocol.md``, "Steps begun as the body runs
out of work")."""


@dataclass(frozen=True)
class PibtTiming:
    """A live ``pibt`` robot's step, in seconds of wall-clock time (module docstring)."""

    decide: float
    """The decision phase at the start of every step (a robot not decided for good by its end stays)."""
    step: float
    """The step's length (a step's decisions overlap the moves of the step before)."""
    retry: float
    """How long the brain waits for an acknowledgement before it sends a message again (but the beacon)."""
    hold: float
    """How long, from the step's start, a held robot waits for its grant before it stays."""
    pace: float = 0.0
    """With a local synchronizer, the least time from a step's start to the next's: one action of the body (a
    step of the simulator is one action; a robot whose steps are shorter only waits for its body, or spends
    beacons on steps in which it stays), but for :attr:`lead`."""
    lead: float = 0.0
    """With a local synchronizer, a robot off its goal may begin its next step sooner than :attr:`pace`, once
    its body has at most this long left of the actions it was given (each counted as :attr:`pace`): the next
    decision then comes as the body finishes, and a step whose decisions took long is caught up on (0: never)."""
    beacon_retry: float | None = None
    """How long the brain waits for a beacon it still misses before it sends its own again, asking for it (None:
    :attr:`retry`; ``ReliablePibtRobot``'s ``beacon_retry`` says why it may differ)."""

    @classmethod
    def for_body(
        cls,
        cell_seconds: float,
        turn_seconds: float = 0.0,
        decide: float = 0.3,
        grace: float = 0.05,
        retry: float = 0.015,
        hold: float = 0.4,
        lead: float = 0.5,
        beacon_retry: float = 0.015,
    ) -> PibtTiming:
        """Steps as long as a move with one right turn (the next step's decisions overlap it), or as ``decide``
        seconds of decisions and a ``grace`` for the grant when the moves are shorter.

        The decision phase is all of the step but the grace: a robot's move is
        queued the moment it decides for good, so a long phase costs nothing to
        the robots that decided and gives the others time. A held robot waits
        for its grant for the fraction ``hold`` of the decision phase. Steps
        ended by the robots last at least one action (``pace``: a move with
        one right turn, or a cell time for a body that turns in place), unless
        the robot is off its goal and its body is within the fraction ``lead``
        of an action of running out of work (:attr:`lead`). A call's messages are
        sent again after 15 ms without an acknowledgement, and the beacon, to ask
        for a beacon still missing, after 15 ms too (:attr:`beacon_retry`;
        ``docs/protocol.md``, "Sent again, and when").

        >>> PibtTiming.for_body(0.5, 0.25)
        PibtTiming(decide=0.7, step=0.75, retry=0.015, hold=0.28, pace=0.75, lead=0.375, beacon_retry=0.015)
        >>> PibtTiming.for_body(0.1, 0.05)   # moves shorter than the decisions: the decisions set the clock's pace
        PibtTiming(decide=0.3, step=0.35, retry=0.015, hold=0.12, pace=0.15, lead=0.075, beacon_retry=0.015)
        """
        action = cell_seconds + turn_seconds
        phase = max(decide, action - grace)
        return cls(
            round(phase, 6), round(phase + grace, 6), retry, round(phase * hold, 6), round(action, 6), round(action * lead, 6),
            beacon_retry,
        )  # fmt: skip


def open_repeat(opener: Opener, data: bytes) -> Message | None:
    """Open ``data``; a PIBT message (not an acknowledgement) the replay window rejects as replayed is returned too.

    Its MAC and session were checked before the replay window
    (:mod:`mrmp.protocol.auth`); a repeat of a brain's message reaches the
    brain, which acknowledges it again and takes nothing else from it.

    >>> from mrmp.protocol.messages import BeaconMessage
    >>> sealer, opener = Sealer(b"k", 1), Opener(b"k", 1)
    >>> data = sealer.seal(BeaconMessage(0, 5, 1, (0, 0), (1, 0), 0, 1))
    >>> open_repeat(opener, data).seq, open_repeat(opener, data).seq, dict(opener.rejected)
    (5, 5, {'replayed': 1})
    >>> open_repeat(opener, sealer.seal(StateMessage(0, 5, (0, 0), (0, 0)))) is None   # a state is no repeat
    True
    """
    replayed = opener.rejected["replayed"]
    message = opener.open(data)
    if message is not None or opener.rejected["replayed"] == replayed:
        return message
    try:
        repeat = decode(data[OVERHEAD - TAG_BYTES : -TAG_BYTES])
    except DecodeError:
        return None
    if isinstance(repeat, PibtMessage) and not isinstance(repeat, CallAckMessage):
        return repeat
    return None


class PibtBrain:
    """One live ``pibt`` robot's decisions: the PIBT brain, the step clock, the move queue, the safety layer.

    Sans-IO: fed with messages and the time (seconds, the driver's clock).

    Parameters
    ----------
    scenario:
        The whole scenario (every robot loads the same one).
    index:
        Which robot this is.
    timing:
        The step's timing.
    claim_retry:
        Seconds between two sends of a claim or a release.
    crash_after:
        A peer silent for this long is taken for crashed (an obstacle where it was last known), until heard again.
    follows:
        Whether its body may be followed while it drives (:attr:`mrmp.live.body.Body.follows`): its cell is
        released as the body starts out of it (:class:`~mrmp.protocol.safety.SafetyLayer`, ``releases_on_start``).
    """

    def __init__(
        self,
        scenario: Scenario,
        index: int,
        timing: PibtTiming,
        claim_retry: float = CLAIM_RETRY,
        crash_after: float = 6.0,
        flat: FlatMap | None = None,
        follows: bool = False,
    ) -> None:
        spec = scenario.robots[index]
        flat = self.flat = flat if flat is not None else FlatMap(scenario.grid)
        goal, start = flat.index(spec.goal), flat.index(spec.start)
        distance = flat.distances(goal)[start]
        options = scenario.policy
        self.index = index
        self.timing = timing
        self.synchronized = options.synchronizer == "local"
        """Whether the robot ends its steps itself (``synchronizer: local``) instead of on the common clock."""
        self.turning = body_model(options.body).turns_in_place
        """Whether the body turns in place (``turning``): the brain plans its turns, and the queue holds them."""
        brain_type = SynchronizedPibtRobot if self.synchronized else LivePibtRobot
        self.robot: LivePibtRobot = brain_type(
            index, start, goal, flat,
            tie=int(distance) if distance != math.inf else 0,
            heading=spec.heading,
            radius=options.radius,
            swap=options.swap and not self.turning,
            turning=self.turning,
            dead_end_bonus=DEAD_END_BONUS if self.turning else 0,
            guidance=options.guidance,
            heading_aware=options.heading_aware,
            turn_cost=scenario.timing.turn_time / scenario.timing.cell_time,
            rng=stream_random(scenario.seed, Stream.TIES, index),
            retry=max(1, round(timing.retry * 1000)),
            beacon_retry=None if timing.beacon_retry is None else max(1, round(timing.beacon_retry * 1000)),
            starts=[flat.index(robot.start) for robot in scenario.robots],
        )  # fmt: skip
        self.safety = SafetyLayer(
            index,
            [robot.start for robot in scenario.robots],
            claim_timeout=math.inf,
            retry_interval=claim_retry,
            waits_for_release=True,
            releases_on_start=follows,
        )
        self.dropped = self.robot.dropped
        self.queue: list[Cell | Heading] = []
        """Actions decided and not yet begun, in order: a cell to enter (claimed first, once the body stands
        still) or, for a body that turns in place, a heading to turn to."""
        self.moving = False
        self.moves: list[tuple[int, Cell]] = []
        """Every step's decided cell, as ``(step, cell)`` (the brain's path)."""
        self.heard: dict[int, tuple[float, bool]] = {}
        self._silence_check_at = -math.inf
        """No peer can have been silent for ``crash_after`` seconds before this time (:meth:`_crash_silent`)."""
        """Per peer: when it was last heard, and whether it said it stood on its goal."""
        self.t0: float | None = None
        self.step = 0
        self._deciding = False
        self._decided: int | None = None
        """The cell the robot decided for good on in this step (its move queued already), if it has."""
        self._act = False
        self._claimed_at = -math.inf
        self._began = 0.0
        self._action_began = 0.0
        """When the body began its current action (:meth:`work_left`)."""
        self.crash_after = crash_after
        self.tasks = TaskTaker(index, len(scenario.robots), TASK_RETRY) if scenario.lifelong else None
        """A lifelong robot's tasks, from the task desk (one past the last robot on the wire); None: one goal."""
        self.last_step = scenario.max_ticks if scenario.lifelong else None
        """A lifelong robot's last step: its run is done once it is over (it still takes part until its fleet's is)."""
        self._goals = [flat.index(robot.goal) for robot in scenario.robots]
        """Every robot's goal, as the scenario gives it (:attr:`resting`)."""
        self._rested_after = 0

    # -- time -------------------------------------------------------------------------------

    def start(self, t0: float) -> None:
        """The fleet starts at ``t0`` (step 1 begins)."""
        self.t0 = t0

    def _ms(self, now: float) -> int:
        assert self.t0 is not None
        return round((now - self.t0) * 1000)

    def expire(self, now: float) -> list[Outgoing]:
        """Run the step clock and every timer: begin and end steps, act, resend, claim; return what to send."""
        if self.t0 is None:
            return []
        out = self._task_reports(now)
        if self.synchronized:
            return out + self._expire_synchronized(now)
        robot, timing = self.robot, self.timing
        begins = self.t0 + self.step * timing.step  # when the next step begins
        if self._deciding and now >= begins - timing.step + timing.hold:
            robot.give_up()
        if self._deciding and now >= begins - timing.step + timing.decide:
            self._finish_step()
        if now >= begins:
            if self._deciding:
                self._finish_step()
            self._begin_next_step(now, out)
        self._crash_silent(now)
        if self._deciding:
            self._run_brain(now, out)
        out.extend(self._stamped(self.safety.expire(now)))
        return out

    def _run_brain(self, now: float, out: list[Outgoing]) -> None:
        """The brain's timers, its act when something is to act on, and its move queued once decided for good."""
        robot = self.robot
        resent = robot.on_tick(self._ms(now))
        out.extend(resent)
        if self._act or robot.wake or resent:
            self._act = False
            out.extend(robot.act())
        if robot.final and self._decided is None:
            self._queue_decided()

    def _expire_synchronized(self, now: float) -> list[Outgoing]:
        """:meth:`expire` with a local synchronizer: the robot ends its step when its brain says so, not on a clock.

        Step 1 begins at ``t0``; step ``k + 1`` at once when step ``k`` is done
        (:attr:`~mrmp.robot.pibt_synchronized.SynchronizedPibtRobot.step_done`),
        held while the move decided in step ``k`` is not granted, and no sooner
        than ``pace`` after step ``k`` began, unless the robot is off its goal
        and its body has no more than ``lead`` seconds of work left
        (:meth:`work_left`). A held robot that has not been
        granted ``hold`` seconds after its step began gives up and, at its
        turn, stays, as on the clock; no step ends undecided.
        """
        robot = self.robot
        assert isinstance(robot, SynchronizedPibtRobot)
        out: list[Outgoing] = []
        if self.step == 0:
            self._begin_next_step(now, out)
        if now - self._began >= self.timing.hold:
            robot.give_up()
        self._crash_silent(now)
        self._run_brain(now, out)
        if robot.step_done and self._may_begin_next_step(now) and not self._rests():
            self._finish_step()
            self._begin_next_step(now, out)
            self._run_brain(now, out)
        out.extend(self._stamped(self.safety.expire(now)))
        return out

    @property
    def resting(self) -> bool:
        """With a local synchronizer, whether the robot begins no next step: it is settled, every peer that can
        stand within its radius and lookout was last known on its own goal, and no peer is in a later step.

        Nobody near would move in such a step unless a peer comes: its
        beacons and their acknowledgements were most of what a fleet sent
        once its robots had arrived. A message of a later step ends the rest
        (a peer steps on, coming near or pushed off its goal, and the robot
        follows; rule 4 counts a robot that rests as decided for good, to stay,
        in the steps it has not begun); a lifelong robot never rests
        (``docs/protocol.md``, "Live", "Resting, and catching up").

        >>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
        >>> robots = [RobotSpec("A", (0, 0), (0, 0)), RobotSpec("B", (2, 0), (3, 0))]
        >>> scenario = Scenario(Grid(6, 1), robots, policy=PolicyOptions(name="pibt", synchronizer="local"))
        >>> brain = PibtBrain(scenario, 0, PibtTiming.for_body(0.5))
        >>> brain.resting  # robot B, 2 cells away, is not on its goal
        False
        >>> brain.robot.learn(1, brain.flat.index((3, 0)), 1)
        >>> brain.resting
        True
        """
        if not self.settled or self.tasks is not None or self.robot.heard_later_step:
            return False
        robot, goals = self.robot, self._goals
        known = robot.known
        return all(known[peer][0] == goals[peer] for peer in robot.possibly_within(robot.radius + robot.lookout))

    def _rests(self) -> bool:
        """:attr:`resting`, counting the steps after which the robot rested (``rested``)."""
        if not self.resting:
            return False
        if self._rested_after != self.step:
            self._rested_after = self.step
            self.robot.stats["rested"] += 1
        return True

    def _may_begin_next_step(self, now: float) -> bool:
        """With a local synchronizer, the step done: ``pace`` has passed since it began, the robot is settled and
        behind its peers (:meth:`_behind`), or it is off its goal and its body is within ``lead`` of running out
        of work (a robot on its goal does not hurry, unless a peer waits for it)."""
        timing, robot = self.timing, self.robot
        if now - self._began >= timing.pace or self._behind():
            return True
        return timing.lead > 0 and robot.present != robot.goal and self.work_left(now) <= timing.lead

    def _behind(self) -> bool:
        """Settled, and a peer is in a later step: the robot catches up at once, without the pace (it stays in
        every step, and a peer coming near waits for it in each)."""
        return self.settled and self.robot.heard_later_step

    def work_left(self, now: float) -> float:
        """Seconds of work the body has left at ``now``: the rest of its action, and ``pace`` for each queued one.

        >>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
        >>> scenario = Scenario(Grid(3, 1), [RobotSpec("A", (0, 0), (2, 0))], policy=PolicyOptions(name="pibt"))
        >>> brain = PibtBrain(scenario, 0, PibtTiming(decide=0.3, step=0.35, retry=0.03, hold=0.1, pace=0.2))
        >>> brain.queue.append((1, 0))
        >>> brain.work_left(0.0)
        0.2
        """
        pace = self.timing.pace
        left = max(0.0, self._action_began + pace - now) if self.moving else 0.0
        return left + pace * len(self.queue)

    def _begin_next_step(self, now: float, out: list[Outgoing]) -> None:
        """Begin the next step, held while a queued move is not granted; the brain acts on it at its next run."""
        self.step += 1
        self._began = now
        self._follow_tasks()
        out.extend(self.robot.begin_step(self.step, now=self._ms(now), held=self._move_queued()))
        self._deciding = True
        self._act = True

    def _follow_tasks(self) -> None:
        """A lifelong robot, as a step begins: its goal becomes its task's next errand, or, free, its cell (as the
        simulator's task book hands them out at the end of a tick). Once its last step is over, its goal is its
        cell: it stays, moving only when a peer whose steps are not over pushes it."""
        tasks, robot = self.tasks, self.robot
        if tasks is None:
            return
        present = self.flat.cells[robot.present]
        over = self.last_step is not None and self.step > self.last_step
        goal = robot.present if over else self.flat.index(tasks.goal(present))
        if goal != robot.goal:
            robot.goal = goal
            robot.elapsed = 0

    def _step_ends_on(self, cell: int) -> None:
        """The step ends with the robot on ``cell``, as it has decided for good: an errand reached there counts
        now, and the desk hears of it at once, so that the robot's next task can be there when its next step
        begins."""
        if self.tasks is not None:
            self.tasks.step_ended(self.step, self.flat.cells[cell])

    def _task_reports(self, now: float) -> list[Outgoing]:
        """A lifelong robot's report to the task desk, when one is due (:class:`~mrmp.robot.task_taker.TaskTaker`)."""
        tasks = self.tasks
        if tasks is None:
            return []
        reports = tasks.due(now, self.flat.cells[self.robot.present], self.step)
        return [Outgoing(self._stamp(report), (tasks.desk,)) for report in reports]

    def _crash_silent(self, now: float) -> None:
        """Take every peer silent for ``crash_after`` seconds for crashed.

        The peers are looked at only once the one heard from least recently
        can have been silent that long (:attr:`_silence_check_at`): news only
        gets fresher, and a peer heard of for the first time, or again, is
        heard now; so a turn costs no look at every peer of a large fleet.
        """
        if now < self._silence_check_at:
            return
        robot = self.robot
        least_recent = math.inf
        for peer, (heard_at, _) in self.heard.items():
            if peer in robot.crashed:
                continue
            if now - heard_at > self.crash_after:
                robot.crash(peer)
            else:
                least_recent = min(least_recent, heard_at)
        self._silence_check_at = least_recent + self.crash_after

    def _move_queued(self) -> bool:
        """Whether a move (not a turn) waits in the queue: the robot is held until its claim is granted."""
        return any(not isinstance(action, Heading) for action in self.queue)

    def _queue_decided(self) -> None:
        """The robot decided for good: its move or turn is queued now, before the decision phase ends (it cannot change)."""
        robot = self.robot
        assert robot.target is not None
        self._decided = robot.target
        self._step_ends_on(robot.target)
        if robot.target != robot.present:
            cell = self.flat.cells[robot.target]
            self.queue.append(cell)
            self.moves.append((self.step, cell))
        elif self.turning and robot.next_heading != robot.heading:
            self.queue.append(robot.next_heading)

    def _finish_step(self) -> None:
        self._deciding = False
        robot = self.robot
        decided, self._decided = self._decided, None
        before, heading = robot.present, robot.heading
        after = robot.finish_step()
        assert decided is None or decided == after, "a robot's decision for good changed"
        self._step_ends_on(after)
        if decided is None and after != before:
            cell = self.flat.cells[after]
            self.queue.append(cell)
            self.moves.append((self.step, cell))
        elif decided is None and robot.heading != heading:
            self.queue.append(robot.heading)

    # -- the body ---------------------------------------------------------------------------

    def motion(self, now: float) -> tuple[Cell | Heading | None, list[Outgoing]]:
        """What the standing body may start now, if anything, and the claims to send.

        A cell to enter, once its claim won; or a heading to turn to in place,
        at once (the body stays on the cell it owns).
        """
        if self.moving or not self.queue:
            return None, []
        safety, cell = self.safety, self.queue[0]
        if isinstance(cell, Heading):
            self.queue.pop(0)
            self.moving, self._action_began = True, now
            return cell, []
        if safety.pending is None or safety.pending.cell != cell:
            if now - self._claimed_at < safety.retry_interval:
                return None, []  # refused a moment ago: claim again after the retry interval
            self._claimed_at = now
            claim = safety.start_claim(cell, now)
            if claim is None:
                return None, []  # a peer still owns it here: claim again later
            return None, [Outgoing(self._stamp(claim), safety.claim_recipients(cell))]
        if not safety.may_enter(cell):
            return None, []
        safety.begin_move(cell)
        self.queue.pop(0)
        self.moving, self._action_began = True, now
        if not self._move_queued():
            self.robot.release()
            self._act = True
        return cell, []

    def arrived_at(self, cell: Cell) -> None:
        """The body stands on ``cell``: the cell it left is released."""
        self.safety.end_move(cell)
        self.moving = False

    def turned(self) -> None:
        """The body ended its turn in place."""
        self.moving = False

    @property
    def settled(self) -> bool:
        """On its goal, decided and there in body; a lifelong robot: its last step over, and still in body."""
        if self.last_step is not None:
            return self.step > self.last_step and not self.queue and not self.moving
        return self.robot.at_goal and not self.queue and not self.moving

    # -- messages ---------------------------------------------------------------------------

    def state(self) -> StateMessage:
        """The fleet heartbeat: where the robot stands at the start of a step (``progress``: that step) and
        whether it is settled on its goal."""
        robot = self.robot
        cell = self.flat.cells[robot.present]
        step = self.step if self._deciding else self.step + 1  # decided: its cell is the next step's
        return self._stamp(StateMessage(self.index, 0, cell, cell, robot.heading, self.settled, progress=step))

    def receive(self, message: Message, now: float) -> list[Outgoing]:
        """Take in one message; return the answers to send at once."""
        sender = message.sender
        if isinstance(message, TaskMessage):
            self._take_task(message)
            return []
        if sender == self.index or not 0 <= sender < self.safety.fleet_size:
            self.dropped["own" if sender == self.index else "unknown_sender"] += 1
            return []
        if sender in self.robot.departed:
            self.dropped["departed"] += 1  # a late copy: its run is over
            return []
        safety = self.safety
        if sender in self.robot.crashed:
            self.robot.revive(sender)
        if isinstance(message, PibtMessage):
            if self.t0 is not None and message.step > self.step and not self.synchronized:
                self.t0 = min(self.t0, now - (message.step - 1) * self.timing.step)  # a peer is ahead: catch it up
            if isinstance(message, BeaconMessage):  # alive; settled only if it was and still stands on its goal
                old = self.heard.get(sender)
                self.heard[sender] = (now, old is not None and old[1] and message.present == message.goal)
            self._act = self.robot.receive(message) or self._act
            return []
        if isinstance(message, StateMessage):
            first = sender not in self.heard
            self.heard[sender] = (now, message.arrived)
            if message.progress > 0:
                self.robot.learn(sender, self.flat.index(message.present), message.progress)
                if self.t0 is not None and message.progress - 1 > self.step and not self.synchronized:  # a later step
                    self.t0 = min(self.t0, now - (message.progress - 2) * self.timing.step)
            if first and self.t0 is None:
                return [Outgoing(self.state(), (sender,))]  # so that it hears of us as soon as we heard of it
            return []
        if isinstance(message, ClaimMessage):
            reply = safety.handle_claim(message, claimant_outranks=False)
            return [] if reply is None else [Outgoing(self._stamp(reply), (sender,))]
        if isinstance(message, ReplyMessage):
            return self._stamped(safety.handle_reply(message, now))
        if isinstance(message, ReleaseMessage):
            acknowledgement = Outgoing(self._stamp(safety.handle_release(message)), (sender,))
            return [acknowledgement, *self._stamped(safety.take_granted_on_release())]
        if isinstance(message, ReleaseAckMessage):
            safety.handle_release_ack(message)
            return []
        if isinstance(message, FarewellMessage):
            self._take_farewell(message)
            return []
        self.dropped["other_type"] += 1
        return []

    def _take_task(self, message: TaskMessage) -> None:
        """The task desk's answer: a task to take at the next step, or an acknowledgement (from the desk only)."""
        if self.tasks is None or message.sender != self.tasks.desk:
            self.dropped["unknown_sender"] += 1
            return
        if not all(self.flat.grid.in_bounds(cell) and self.flat.grid.is_free(cell) for cell in message.errands):
            self.dropped["off_map"] += 1  # not a cell this robot can reach: no desk of its fleet sent it
            return
        self.tasks.take(message)

    def _take_farewell(self, message: FarewellMessage) -> None:
        """A peer's run is over: an obstacle on its cell for good, and done for the end of the run (it is heard
        of for good: never silent)."""
        cell = self.flat.index_on_grid(message.cell)
        if cell is None:
            self.dropped["off_map"] += 1
            return
        self.robot.depart(message.sender, cell)
        self.heard[message.sender] = (math.inf, True)

    def farewell(self) -> FarewellMessage:
        """What this robot tells every peer as its run ends: the cell it stays on for good."""
        return self._stamp(FarewellMessage(self.index, 0, self.flat.cells[self.robot.present]))

    def next_seq(self) -> int:
        """The next number of the robot's sequence (every message it sends has a fresh one)."""
        return self.robot._seq()

    def _stamp(self, message: M) -> M:
        """``message`` numbered in the robot's sequence (the safety layer leaves it 0)."""
        return dataclasses.replace(message, seq=self.next_seq())  # type: ignore[type-var]

    def _stamped(self, sends: list[tuple[Message, tuple[int, ...]]]) -> list[Outgoing]:
        return [Outgoing(self._stamp(message), recipients) for message, recipients in sends]


class PibtAgent(LiveDriver):
    """Runs one ``pibt`` robot in real time (see the module docstring).

    The parameters ``scenario``, ``index``, ``transport``, ``body``,
    ``sealer``, ``opener``, ``timing``, ``seed`` and ``clock`` are those of
    :class:`~mrmp.live.driver.LiveDriver`; ``pibt``: the step's timing (by
    default :meth:`PibtTiming.for_body` of the body's cell and turn times).
    """

    robot: PibtBrain

    wakes_while_polling = True
    """A message wakes the robot at once: each is a hop of a call or of an acknowledgement, which would otherwise
    wait up to a poll (10 ms) at every robot on its way."""

    def __init__(
        self,
        scenario: Scenario,
        index: int,
        transport: Transport,
        body: Body,
        sealer: Sealer,
        opener: Opener,
        timing: AgentTiming = AgentTiming(),
        seed: int = 0,
        clock: Callable[[], float] = time.monotonic,
        pibt: PibtTiming | None = None,
        flat: FlatMap | None = None,
    ) -> None:
        timing = dataclasses.replace(timing, poll=max(timing.poll, POLL))
        super().__init__(scenario, index, transport, body, sealer, opener, timing, seed, clock)
        turns_in_place = body_model(scenario.policy.body).turns_in_place  # a turn is a step of its own
        turn_seconds = 0.0 if turns_in_place else scenario.timing.turn_time / scenario.timing.cell_time * self.cell_seconds
        self.pibt_timing = pibt if pibt is not None else PibtTiming.for_body(self.cell_seconds, turn_seconds)
        self.robot = PibtBrain(
            scenario, index, self.pibt_timing, claim_retry=min(timing.claim_retry, CLAIM_RETRY),
            crash_after=2 * timing.give_up_after, flat=flat, follows=body.follows,
        )  # fmt: skip
        self._beaconed: set[int] = set()
        """The peers sent a beacon since the last fleet heartbeat (:meth:`_fleet_heartbeat`)."""
        self._ask_as_fits(self._client)

    def send_through(self, client: Sending) -> None:
        super().send_through(client)
        self._ask_as_fits(client)

    def _ask_as_fits(self, client: Sending) -> None:
        """Over a transport that reaches several peers at once, ask for a missing beacon every two retries after the
        first ask (:data:`LONGEST_ASK_GAP_TOGETHER`); over unicast, every retry."""
        self.robot.robot.longest_beacon_gap = LONGEST_ASK_GAP_TOGETHER if client.reaches_several else 1

    # -- what the driver reads of the brain --------------------------------------------------

    def _present(self) -> Cell:
        return self.body.cell

    def _arrived(self) -> bool:
        return self.robot.settled

    def _peers_heard(self) -> int:
        return len(self.robot.heard)

    def _peer_news(self, index: int) -> tuple[float, bool] | None:
        return self.robot.heard.get(index)

    def _state_messages(self, now: float) -> list[Outgoing]:
        return [Outgoing(self.robot.state(), ())]  # beacons tell the near peers; the fleet heartbeat tells everyone

    def _fleet_wait_messages(self) -> list[Outgoing]:
        return fleet_wide([Outgoing(self.robot.state())])

    def _fleet_heartbeat(self, now: float) -> list[Outgoing]:
        """The state to every peer not sent a beacon since the last fleet heartbeat, or to every peer once settled.

        A beacon tells its recipient what the state would (where the robot
        stands at the start of a step; and it is alive), but for whether it is
        settled: a peer takes a beacon off its goal for "not settled"
        (:meth:`PibtBrain.receive`), and only a state says "settled", so a
        settled robot tells every peer every fleet heartbeat, as before
        (``tests/unit/live/test_pibt_fleet_heartbeat.py``).
        """
        beaconed, self._beaconed = self._beaconed, set()
        if self.robot.settled or not beaconed:
            return fleet_wide([Outgoing(self.robot.state())])
        others = tuple(peer for peer in range(len(self.scenario.robots)) if peer != self.index and peer not in beaconed)
        return [Outgoing(self.robot.state(), others)] if others else []

    def _send(self, outgoing: list[Outgoing]) -> None:
        """Send as every driver does, noting to whom this robot's beacons went (:meth:`_fleet_heartbeat`)."""
        for item in outgoing:
            if isinstance(item.message, BeaconMessage) and item.recipients:
                self._beaconed.update(item.recipients)
        super()._send(outgoing)

    def _farewell_messages(self, now: float) -> list[Outgoing]:
        return fleet_wide([Outgoing(self.robot.farewell())])

    def _believed_within(self, radius: int) -> list[int]:
        return self.robot.robot.possibly_within(radius)

    def _safety_counts(self) -> dict[str, int]:
        brain = self.robot
        counts = {**brain.safety.stats.__dict__, **{f"pibt_{name}": count for name, count in brain.robot.stats.items()}}
        counts["pibt_steps"] = brain.step
        if brain.tasks is not None:
            counts.update({f"task_{name}": count for name, count in brain.tasks.stats.items()})
        return counts

    # -- the receiving thread: repeats of PIBT messages pass --------------------------------

    def take_datagram(self, data: bytes) -> None:
        """Open a datagram that arrived (a repeat of a PIBT message too: :func:`open_repeat`) and queue its message."""
        with self._lock:
            message = open_repeat(self.opener, data)
        if message is not None:
            self._inbox.put(message)

    # -- the step ----------------------------------------------------------------------------

    def _begin(self, started: float) -> None:
        self.robot.start(started)

    def _step(self, now: float, started: float) -> bool:
        """Finish the body's move, and start its next action (or claim its next cell) in the same turn (the
        brain's clock runs in ``expire``)."""
        brain, body = self.robot, self.body
        if body.moving:
            if not body.poll(now):
                return False
            if self._ended_a_turn():
                brain.turned()
            else:
                brain.arrived_at(body.cell)  # the brain may have decided the steps beyond already: the body's cell says
                self._record_move(now, started, body.cell == self.scenario.robots[self.index].goal)
        if not body.moving:
            action, out = brain.motion(now)
            self._send(out)
            if isinstance(action, Heading):
                self._start_turn_in_place(action, now)
            elif action is not None:
                body.start_move(action, now)
        return False
