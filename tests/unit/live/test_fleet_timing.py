"""A live fleet's heartbeats do not grow with it: fleet heartbeats spaced by the fleet's size, no radius for plans.

Sent to every peer once a second, fleet heartbeats cost each of ``N`` robot
processes ``N - 1`` datagrams a second to receive; a robot following a plan
(its policy reads no peer's cells) sent its state every heartbeat to every peer
it believed near, a set that grows with the age of what it knows.
"""

from __future__ import annotations

import pytest

from mrmp.core import Grid, RobotSpec, Scenario
from mrmp.live.agent import Agent
from mrmp.live.body import SimulatedBody
from mrmp.live.driver import AgentTiming
from mrmp.live.process import FLEET_STATES_PER_SECOND, fleet_timing
from mrmp.policies.plan_following import PlanFollowingPolicy
from mrmp.protocol.auth import Opener, Sealer

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
    for index in range(1, len(robot.scenario.robots)):
        peer = Agent(robot.scenario, index, _Silent(), robot.body, Sealer(KEY, 1), Opener(KEY, 1))
        robot.robot.receive(peer.robot.state_message(), now)


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
