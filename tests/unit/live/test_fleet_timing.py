"""A live fleet's heartbeats do not grow with it: fleet heartbeats spaced by the fleet's size, no radius for plans.

Sent to every peer once a second, fleet heartbeats cost each of ``N`` robot
processes ``N - 1`` datagrams a second to receive; a robot following a plan
(its policy reads no peer's cells) sent its state every heartbeat to every peer
it believed near, a set that grows with the age of what it knows, and listened
before every decision for states it does not read.
"""

from __future__ import annotations

import pytest

from mrmp.core import Grid, RobotSpec, Scenario
from mrmp.core.heading import Heading
from mrmp.live.agent import Agent, Phase
from mrmp.live.body import SimulatedBody
from mrmp.live.driver import AgentTiming
from mrmp.live.process import FLEET_STATES_PER_SECOND, fleet_timing
from mrmp.policies.plan_following import PlanFollowingPolicy
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.messages import StateMessage

KEY = b"k" * 32


@pytest.mark.parametrize("robots", [2, 8, 21, 22, 48, 100, 400, 1000])
def test_a_robot_sends_a_bounded_number_of_fleet_heartbeats_a_second_and_judges_silence_over_three(robots):
    timing = fleet_timing(AgentTiming(), robots)
    assert (robots - 1) / timing.fleet_heartbeat <= FLEET_STATES_PER_SECOND + 1e-9
    assert timing.fleet_heartbeat >= AgentTiming().fleet_heartbeat
    assert timing.give_up_after == pytest.approx(3 * timing.fleet_heartbeat)
    assert timing.silence_timeout == pytest.approx(1.5 * timing.fleet_heartbeat)


def test_a_small_fleet_keeps_the_timing_it_was_given():
    timing = AgentTiming(start_wait=20.0)
    assert fleet_timing(timing, 21) == timing


def line(robots: int) -> Scenario:
    """``robots`` robots on one row, each on its goal."""
    specs = tuple(RobotSpec(f"R{index}", (0, index), (0, index)) for index in range(robots))
    return Scenario(Grid(1, robots), specs)


def agent(scene: Scenario, policy: PlanFollowingPolicy | None = None, timing: AgentTiming = AgentTiming()) -> Agent:
    spec = scene.robots[0]
    body = SimulatedBody(spec.start, spec.heading, scene.grid, scene.timing)
    transport = _Silent()
    return Agent(scene, 0, transport, body, Sealer(KEY, 1), Opener(KEY, 1), timing=timing, policy=policy, clock=lambda: 0.0)


class _Silent:
    def send(self, data: bytes, recipient: int | None = None) -> None:
        pass

    def receive(self, timeout: float) -> bytes | None:
        return None

    def close(self) -> None:
        pass


def hear_everyone(robot: Agent, now: float) -> None:
    """Robot 0 hears every peer's state, each from its own cell, at ``now``."""
    for index, spec in enumerate(robot.scenario.robots[1:], start=1):
        robot.robot.receive(StateMessage(index, 1, spec.start, spec.start, spec.heading, True), now)


def test_a_robot_following_a_plan_sends_its_state_only_to_the_peers_it_names():
    scene = line(8)
    follower = agent(scene, PlanFollowingPolicy([], {}, dependents={}))
    hear_everyone(follower, now=0.0)
    outgoing = follower.robot.announce(0.0)
    assert [item.radius for item in outgoing] == [0]
    follower._send(outgoing)
    follower._send([item._replace(recipients=(5,)) for item in outgoing])
    assert follower.report.datagrams_sent == 1  # nobody by radius, robot 5 by name


def test_a_robot_whose_policy_reads_its_peers_cells_still_sends_its_state_to_those_near():
    scene = line(8)
    thesis = agent(scene)  # the scenario's policy, the thesis's: interaction radius 2, live radius 4
    hear_everyone(thesis, now=0.0)
    thesis._send(thesis.robot.announce(0.0))
    assert thesis.report.datagrams_sent == 4  # robots 1 to 4, within four cells of robot 0


def test_news_of_an_arrival_counts_for_as_long_as_a_silence_does():
    """In a fleet of 101 the fleet heartbeat comes every 5 s: a far peer's arrival, heard 4 s ago, still ends the run."""
    scene = line(101)
    robot = agent(scene, timing=fleet_timing(AgentTiming(), 101))
    robot._peer_news = lambda index: (96.0, True)  # type: ignore[method-assign]
    assert robot._peer_state(7, now=100.0) == "done"
    assert robot._everyone_done(now=100.0)
    robot._peer_news = lambda index: (84.0, True)  # type: ignore[method-assign]
    assert robot._peer_state(7, now=100.0) == "silent"


# A robot following a plan does not listen before deciding, and starts its move as soon as it hears it may:
# robot 0's plan waits for robot 1 to leave (0, 1); robot 0 decides to stay and pauses; the state of robot 1
# reporting that move comes 10 ms later: robot 0 must be moving at once, not after its listen_time (50 ms).


def follower() -> Agent:
    robots = (RobotSpec("A", (0, 0), (0, 1), Heading.EAST), RobotSpec("B", (0, 1), (0, 2), Heading.EAST))
    scene = Scenario(Grid(1, 3), robots)
    body = SimulatedBody((0, 0), Heading.EAST, scene.grid, scene.timing)
    policy = PlanFollowingPolicy(moves=[(0, 1)], dependencies={0: [(1, 1)]}, dependents={})
    timing = AgentTiming(listen_time=0.05)
    return Agent(scene, 0, _Silent(), body, Sealer(KEY, 1), Opener(KEY, 1), timing, guarded=False, policy=policy)


def test_a_robot_following_a_plan_moves_as_soon_as_the_robot_it_waits_for_reports_its_move():
    agent = follower()
    agent._begin(0.0)
    agent._step(0.0, 0.0)  # decides at once (nothing to listen for): robot 1 has not left (0, 1), so it stays
    assert agent._phase is Phase.PAUSE and not agent.body.moving
    assert agent._due() >= 0.05  # on its own it would decide again only after a pause
    agent._inbox.put(StateMessage(1, 1, (0, 2), (0, 2), Heading.EAST, True, progress=1))
    agent._drain_inbox(0.01)
    assert agent._due() == 0.01
    agent._step(0.01, 0.0)  # the pause ends: announce
    agent._step(0.01, 0.0)  # decide and move
    assert agent.body.moving


def test_a_robot_following_a_plan_does_not_listen_before_deciding():
    agent = follower()
    agent._begin(0.0)
    assert agent._phase is Phase.LISTEN and agent._due() == 0.0
