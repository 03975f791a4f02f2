"""The live driver of one Causal-PIBT robot (policy ``causal``): real time around the sans-IO brain.

The brain is :class:`mrmp.robot.causal_pibt.CausalRobot` (Okumura, Tamura and
Défago, AAAI 2021), the same object the asynchronous simulator runs. As in
:mod:`mrmp.live.agent`, a receiving thread queues what the transport delivers
and the brain runs in the main thread only, fed with those messages and the
clock. Every turn of the driver's loop (:mod:`mrmp.live.driver`):

* hand the brain the queued messages and send its answers (lock grants,
  acknowledgements, claim replies);
* when the body reports the end of its move, tell the brain (it contracts on
  its head and announces its state); else start the move the safety layer
  allows, if any; a body that turns in place (``turning``) and does not face
  that head first turns toward it, a quarter at a time (each end told to the
  brain, which announces its heading), on the tail it still holds;
* when the robot's next activation is due, activate it (an activation locks
  the robots within two cells, runs one Causal-PIBT transition and releases
  them); activations come every ``listen_time`` seconds, times a random factor
  in [0.5, 1.5), so robots interleave differently in every run;
* run the brain's timers (resend lock requests, releases and claims) and send
  the state every ``heartbeat`` seconds, to the peers believed within its state
  radius, and to every peer every ``fleet_heartbeat`` seconds
  (:mod:`mrmp.live.driver`).

Before its first activation a robot waits (at most ``start_wait`` seconds)
until it has heard every peer. The run ends as :class:`~mrmp.live.agent.Agent`'s
does: when this robot and every peer stand on their goals (then a short linger,
so that late requests are still answered), when the peers that have not arrived
have been silent for ``give_up_after`` seconds, on timeout or on a stop
request. The report (:class:`~mrmp.live.driver.AgentReport`) is written by the
caller, through ``on_progress`` while running and at the end.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.core.scenario import Scenario
from mrmp.core.seeds import Stream, stream_random
from mrmp.live.body import Body
from mrmp.live.driver import AgentTiming, LiveDriver, believed_near, fleet_wide, live_state_radius
from mrmp.live.transport import Transport
from mrmp.protocol.auth import Opener, Sealer
from mrmp.robot.causal_pibt import LOCK_RADIUS, CausalRobot
from mrmp.robot.robot import Outgoing
from mrmp.search.flat_map import FlatMap


class CausalAgent(LiveDriver):
    """Runs one Causal-PIBT robot in real time (see the module docstring).

    The parameters ``scenario``, ``index``, ``transport``, ``body``,
    ``sealer``, ``opener``, ``timing`` and ``clock`` are those of
    :class:`~mrmp.live.driver.LiveDriver`.

    Parameters
    ----------
    seed:
        Seed of the robot's randomness (ties between cells, activation times).
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
        seed: int = 0,
        clock: Callable[[], float] = time.monotonic,
        flat: FlatMap | None = None,
    ) -> None:
        super().__init__(scenario, index, transport, body, sealer, opener, timing, seed, clock)
        spec = scenario.robots[index]
        retry = timing.claim_retry  # lock requests and releases are resent as often as claims
        self.robot: CausalRobot = CausalRobot(
            index,
            scenario.grid,
            [robot.start for robot in scenario.robots],
            spec.goal,
            rng=stream_random(seed, Stream.TIES, index),
            retry_interval=retry,
            lock_timeout=max(1.0, 20 * retry),
            claim_timeout=timing.claim_timeout,
            heading=spec.heading,
            state_radius=live_state_radius(LOCK_RADIUS),
            body=body_model(scenario.policy.body),
            flat=flat,
        )
        self._next_activation = 0.0
        self._extended_at: float | None = None

    # -- what the driver reads of the brain --------------------------------------------------

    def _present(self) -> Cell:
        return self.robot.tail

    def _arrived(self) -> bool:
        return self.robot.at_goal

    def _settled(self) -> bool:
        """On the goal, with no activation of its own under way and not locked by another robot's."""
        robot = self.robot
        return robot.at_goal and robot.idle and robot.locked_by is None

    def _peers_heard(self) -> int:
        return len(self.robot.heard)

    def _peer_news(self, index: int) -> tuple[float, bool] | None:
        return self.robot.heard.get(index)

    def _state_messages(self, now: float) -> list[Outgoing]:
        return self.robot.heartbeat()

    def _fleet_wait_messages(self) -> list[Outgoing]:
        return fleet_wide(self.robot.heartbeat())

    def _believed_within(self, radius: int) -> list[int]:
        now, peers = self.clock(), self.robot.peers
        known = (
            (index, peer.cells[0], peers.heard.get(index, (self.report.started_at, False))[0])
            for index, peer in peers.known.items()
        )
        return believed_near(known, self.robot.tail, radius, now, self.cell_seconds)

    def _safety_counts(self) -> dict[str, int]:
        robot = self.robot
        return {**robot.safety.stats.__dict__, **{f"causal_{name}": count for name, count in robot.stats.items()}}

    # -- the step ----------------------------------------------------------------------------

    def _begin(self, started: float) -> None:
        self._next_activation = started + self.timing.listen_time * self.random.random()
        self._extended_at = None

    def _due(self) -> float:
        """The body's next event and the next activation (the driver sleeps until then)."""
        return min(super()._due(), self._next_activation)

    def _step(self, now: float, started: float) -> bool:
        """Finish or start the body's move, and activate the robot when due (module docstring)."""
        robot, body, timing, report = self.robot, self.body, self.timing, self.report
        sent_state = False
        if body.moving:
            if body.poll(now):
                sent_state = True
                if self._ended_a_turn():
                    self._send(robot.turned(body.heading))
                    head = robot.head
                    assert head is not None  # a robot turns only toward the head it may enter
                    self._drive_toward(head, now)
                else:
                    self._send(robot.arrived_at(body.cell, now, body.heading))
                    self._record_move(now, started, robot.body_on_goal)
        else:
            if robot.mode_name == "extended" and self._extended_at is None:
                self._extended_at = now
            target = robot.motion(now)
            if target is not None:
                self._drive_toward(target, now)
                if self._extended_at is not None:
                    report.decision_latency.append(now - self._extended_at)
                self._extended_at = None
        if now >= self._next_activation:
            self._send(robot.activate(now))
            self._next_activation = now + timing.listen_time * (0.5 + self.random.random())
        if not robot.body_on_goal:
            report.arrival_time = None
        return sent_state

    def _drive_toward(self, target: Cell, now: float) -> None:
        """Start the body's next action toward ``target``: a quarter turn when it turns in place and does not face it."""
        body = self.body
        turn = self.robot.body.first_turn(body.heading, Heading.between(body.cell, target))
        if turn is not None:
            self._start_turn_in_place(turn, now)
        else:
            body.start_move(target, now)
