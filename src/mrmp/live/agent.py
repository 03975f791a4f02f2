"""The live driver of one robot: the thesis's server and client threads around the sans-IO brain.

As in the thesis (section 3.5), a *receiving thread* keeps reading the
transport for the whole run (the thesis stops receiving at the destination, but
a robot that arrived still occupies its cell, so it keeps answering), and a
*client thread* (:class:`~mrmp.live.client_thread.ClientThread`) sends what the
robot queues on every update of its state. The brain itself runs in the main
thread only, fed with the messages the receiving thread queued and with the
clock:

* announce Present and Next; listen for ``listen_time``; decide (and, guarded,
  claim the chosen cell); start the body's move once allowed;
* when the body reports the new cell, announce at once (the client thread
  "sends the updated information as soon as it is updated"); after a pause,
  announce again, sending the state only when it changed or a heartbeat is due;
* send the state at least every ``heartbeat`` seconds, so that lost messages
  are repaired and silent robots are noticed: to the peers believed within the
  policy's interaction radius (widened by what each can have driven since it was
  heard), and to every peer every ``fleet_heartbeat`` seconds
  (:mod:`mrmp.live.driver`; a policy without an interaction radius, every time);
* run the safety layer's timers (resend or abandon a claim).

A robot whose body turns in place (``policy.body: turning``) turns a quarter
toward a neighbour it does not face as an action of its own
(:meth:`~mrmp.robot.robot.Robot.turn`, on a body with
:class:`~mrmp.live.body.TurnsInPlace`), and announces its new heading when the
turn ends; it claims and enters only the cell ahead.

A robot whose policy reads no peer's cells (interaction radius 0: a robot
following a plan, which waits only for its peers' progress) has nothing to
listen for: it decides at once after announcing, and the pause after a decision
to stay (it waits for a peer's move) ends as soon as a message comes, rather than
after ``listen_time``, so that it starts the move as soon as it hears that it may.
The pause after a refused claim keeps its random length (it breaks symmetry).
Such a robot also repeats its state once, ``listen_time`` after each arrival, to
the robots it names (those waiting for the move it made, and those it waits
for): its dependents hear of the move from the first state (a push), and a lost
push would otherwise cost them a pull, a heartbeat later. Measured on a LaCAM plan
for 48 turning bodies at 10% loss (``bench/live_plan.py``), a robot whose move
waited on another's decided a mean 60 ms after that one arrived without the repeat.

Before its first step a robot waits (at most ``start_wait`` seconds) until it
has heard from every peer, so that a fleet whose processes start one by one
begins together; its clock starts then.

The run ends when this robot and every peer have arrived (and a short linger
has passed so that late claims are still answered), when every peer that has
not arrived has been silent for ``give_up_after`` seconds, on timeout, or on a
stop request (a signal). The driver writes its report (and, through the body,
ground truth) to the results folder, including on interruption.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from enum import Enum

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.scenario import Scenario
from mrmp.live.body import Body
from mrmp.live.driver import AgentReport, AgentTiming, LiveDriver, believed_near, live_state_radius
from mrmp.live.transport import Transport
from mrmp.policies.base import Policy, interaction_radius
from mrmp.protocol.auth import Opener, Sealer
from mrmp.robot.robot import Outgoing, Robot
from mrmp.sim.policy_table import make_policy

__all__ = ["Agent", "AgentReport", "AgentTiming", "Phase"]


class Phase(Enum):
    """Where a live robot is in its step (module docstring)."""

    LISTEN = "announced Next; listening before deciding"
    CLAIM = "decided; waiting for the safety layer to allow the move"
    MOVING = "the body is moving"
    PAUSE = "stays this step; announces again after a pause"


class Agent(LiveDriver):
    """Runs one robot in real time (see the module docstring).

    The parameters ``scenario``, ``index``, ``transport``, ``body``,
    ``sealer``, ``opener``, ``timing`` and ``clock`` are those of
    :class:`~mrmp.live.driver.LiveDriver`.

    Parameters
    ----------
    guarded:
        Whether the safety layer guards every move.
    seed:
        Seed of the driver's own randomness (pauses that break symmetry).
    policy:
        The robot's policy, when not the scenario's (for example its share of a central plan).
    """

    def __init__(
        self,
        scenario: Scenario,
        index: int,
        transport: Transport,
        body: Body,
        sealer: Sealer,
        opener: Opener,
        timing: AgentTiming = AgentTiming(),
        guarded: bool = True,
        seed: int = 0,
        clock: Callable[[], float] = time.monotonic,
        policy: Policy | None = None,
    ) -> None:
        super().__init__(scenario, index, transport, body, sealer, opener, timing, seed, clock)
        rule = policy if policy is not None else make_policy(scenario.policy, scenario.timing)
        radius = interaction_radius(rule)
        self.robot: Robot = Robot(
            scenario.robots[index],
            index,
            scenario.grid,
            rule,
            [robot.start for robot in scenario.robots],
            guarded=guarded,
            claim_timeout=timing.claim_timeout,
            retry_interval=timing.claim_retry,
            silence_timeout=timing.silence_timeout,
            state_radius=None if radius is None else live_state_radius(radius),
            body=body_model(scenario.policy.body),
            follows_while_driving=body.follows,
        )
        self._repeat_at = math.inf  # when the state goes again after an arrival (a robot that listens for nothing)
        self._phase = Phase.LISTEN
        self._next_decision = 0.0
        self._decided_at = 0.0
        self._said: tuple[object, ...] | None = None
        self._said_at = 0.0

    # -- what the driver reads of the brain --------------------------------------------------

    def _present(self) -> Cell:
        return self.robot.present

    def _arrived(self) -> bool:
        return self.robot.arrived

    def _peers_heard(self) -> int:
        return len(self.robot.belief.peers)

    def _peer_news(self, index: int) -> tuple[float, bool] | None:
        peer = self.robot.belief.peers.get(index)
        return None if peer is None else (peer.heard_at, peer.arrived)

    def _state_messages(self, now: float) -> list[Outgoing]:
        return self.robot.announce(now)

    def _fleet_wait_messages(self) -> list[Outgoing]:
        return [Outgoing(self.robot.state_message())]

    def _believed_within(self, radius: int) -> list[int]:
        peers = ((peer.index, peer.present, peer.heard_at) for peer in self.robot.belief.peers.values())
        return believed_near(peers, self.robot.present, radius, self.clock(), self.cell_seconds)

    def _safety_counts(self) -> dict[str, int]:
        robot = self.robot
        return {**robot.safety.stats.__dict__, "stale_states": robot.belief.stale_messages}

    # -- the step ----------------------------------------------------------------------------

    def _announce_if_new(self, now: float) -> bool:
        """Announce again after a pause; send the state only when it changed or a heartbeat is due (else the peers have it)."""
        robot = self.robot
        outgoing = robot.announce(now)
        said = (robot.present, robot.intended, robot.heading, robot.arrived, robot.progress)
        if said == self._said and now - self._said_at < self.timing.heartbeat:
            return False
        self._said, self._said_at = said, now
        self._send(outgoing)
        return True

    def _listen_time(self) -> float:
        """How long to listen before deciding: ``listen_time``, or 0 for a policy that reads no peer's cells."""
        return 0.0 if interaction_radius(self.robot.policy) == 0 else self.timing.listen_time

    def _drain_inbox(self, now: float) -> None:
        """Hand the brain its messages; a robot that listens for nothing ends its pause on news (module docstring)."""
        received = self.report.messages_received
        super()._drain_inbox(now)
        if self.report.messages_received > received and self._waits_for_news():
            self._next_decision = min(self._next_decision, now)

    def _waits_for_news(self) -> bool:
        """Pausing after a decision to stay, as a robot that listens for nothing: news ends the pause."""
        decision = self.robot.last_decision
        return (
            self._phase is Phase.PAUSE
            and decision is not None
            and decision.next == self.robot.present
            and self._listen_time() == 0
        )

    def _begin(self, started: float) -> None:
        self._phase, self._next_decision, self._decided_at = Phase.LISTEN, started + self._listen_time(), started

    def _timers_idle(self) -> bool:
        """No claim pending and no release unacknowledged: the safety layer's timers have nothing to do."""
        robot = self.robot
        return not robot.guarded or (robot.safety.pending is None and robot.safety.unacknowledged_releases == 0)

    def _due(self) -> float:
        """The body's next event, the end of the listening or the pause, or at once when a claim is over."""
        due = super()._due()
        due = min(due, self._repeat_at)
        if self._phase is Phase.LISTEN or self._phase is Phase.PAUSE:
            due = min(due, self._next_decision)
        elif self._phase is Phase.CLAIM and self.robot.wanted is None and self.robot.safety.pending is None:
            due = -math.inf  # the claim is over: the next turn pauses
        return due

    def _start_turn(self, now: float) -> bool:
        """Start the quarter turn in place the robot decided, if any (module docstring); whether one started."""
        heading = self.robot.turn(now)
        if heading is None:
            return False
        self._start_turn_in_place(heading, now)
        return True

    def _step(self, now: float, started: float) -> bool:
        """Announce, listen, decide (and claim), move, or pause (module docstring)."""
        robot, body, timing, report = self.robot, self.body, self.timing, self.report
        sent_state = False
        if body.moving:
            if body.poll(now):
                if self._ended_a_turn():
                    robot.turned(body.heading)
                else:
                    robot.arrived_at(body.cell, body.heading)
                    self._record_move(now, started, robot.arrived)
                    if self._listen_time() == 0:
                        self._repeat_at = now + timing.listen_time
                self._send(robot.announce(now))
                self._said, self._said_at = (robot.present, robot.intended, robot.heading, robot.arrived, robot.progress), now
                sent_state = True
                self._phase, self._next_decision = Phase.LISTEN, now + self._listen_time()
        elif self._phase is Phase.LISTEN and now >= self._next_decision:
            self._send(robot.decide(now))
            self._phase, self._decided_at = Phase.CLAIM, now
        if self._phase is Phase.CLAIM and not body.moving:
            target = robot.motion(now)
            if target is not None:
                body.start_move(target, now)
                report.decision_latency.append(now - self._decided_at)
                self._phase = Phase.MOVING
            elif self._start_turn(now):
                self._phase = Phase.MOVING
            elif robot.wanted is None and robot.safety.pending is None:
                pause = timing.heartbeat if robot.arrived else timing.listen_time * (1 + self.random.random())
                self._phase, self._next_decision = Phase.PAUSE, now + pause
        if now >= self._repeat_at:
            self._repeat_at = math.inf
            self._send(robot.announce(now))
            sent_state = True
        if self._phase is Phase.PAUSE and now >= self._next_decision:
            sent_state = self._announce_if_new(now)
            self._phase, self._next_decision = Phase.LISTEN, now + self._listen_time()
        return sent_state
