"""A live ``pibt`` robot's fleet heartbeat: to the peers its beacons did not reach since the last, to all once settled;
and what a beacon tells of whether its sender is settled."""

from __future__ import annotations

from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
from mrmp.live.body import SimulatedBody
from mrmp.live.pibt_agent import PibtAgent
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.messages import BeaconMessage, StateMessage
from mrmp.robot.messaging import Outgoing


class Silent:
    """A transport that keeps what is sent and receives nothing."""

    def __init__(self) -> None:
        self.sent: list[tuple[bytes, int | None]] = []

    def send(self, data: bytes, recipient: int | None = None) -> None:
        self.sent.append((data, recipient))

    def receive(self, timeout: float) -> bytes | None:
        return None

    def close(self) -> None:
        pass


def agent(
    index: int = 0, starts=((0, 0), (1, 0), (2, 0), (3, 0)), goals=((0, 0), (3, 0), (2, 0), (1, 0)), kind=PibtAgent
) -> PibtAgent:
    robots = tuple(RobotSpec(f"r{i}", start, goal) for i, (start, goal) in enumerate(zip(starts, goals, strict=True)))
    scenario = Scenario(Grid(4, 2), robots, policy=PolicyOptions(name="pibt"))
    body = SimulatedBody(robots[index].start, robots[index].heading, scenario.grid, scenario.timing)
    return kind(scenario, index, Silent(), body, Sealer(b"k", 1), Opener(b"k", 1))


def heartbeat_recipients(robot: PibtAgent) -> list[tuple[int, ...] | None]:
    return [item.recipients for item in robot._fleet_heartbeat(0.0)]


def test_the_heartbeat_of_a_robot_under_way_skips_the_peers_its_beacons_reached_since_the_last():
    robot = agent(index=1)  # off its goal
    robot._send([Outgoing(BeaconMessage(1, 1, 1, (1, 0), (3, 0), 0, 1), (0, 2))])
    assert heartbeat_recipients(robot) == [(3,)]
    assert heartbeat_recipients(robot) == [None]  # no beacon since: every peer


def test_a_settled_robot_tells_every_peer_whatever_its_beacons_reached():
    robot = agent(index=0)  # on its goal from the start
    assert robot.robot.settled
    robot._send([Outgoing(BeaconMessage(0, 1, 1, (0, 0), (0, 0), 0, 1), (1, 2, 3))])
    assert heartbeat_recipients(robot) == [None]


def test_a_beacon_off_its_goal_takes_a_settled_peer_for_under_way_and_only_a_state_says_settled_again():
    robot = agent(index=2)
    brain = robot.robot
    brain.receive(StateMessage(0, 1, (0, 0), (0, 0), arrived=True, progress=1), now=1.0)
    assert brain.heard[0] == (1.0, True)
    brain.receive(BeaconMessage(0, 2, 1, (0, 0), (0, 0), 0, 1), now=2.0)  # on its goal: still settled
    assert brain.heard[0] == (2.0, True)
    brain.receive(BeaconMessage(0, 3, 2, (0, 1), (0, 0), 0, 1), now=3.0)  # pushed off it
    assert brain.heard[0] == (3.0, False)
    brain.receive(BeaconMessage(0, 4, 3, (0, 0), (0, 0), 0, 1), now=4.0)  # back on it: a beacon does not say settled
    assert brain.heard[0] == (4.0, False)
