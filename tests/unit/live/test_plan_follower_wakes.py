"""A live robot following a plan does not listen before deciding, and starts its move as soon as it hears it may.

Robot 0's plan waits for robot 1 to leave (0, 1). Robot 0 decides to stay and
pauses; the state of robot 1 reporting that move comes 10 ms later: robot 0
must be moving at once, not after its ``listen_time`` (50 ms) or a pause.
"""

from __future__ import annotations

from mrmp.core import Grid, RobotSpec, Scenario
from mrmp.core.heading import Heading
from mrmp.live.agent import Agent, Phase
from mrmp.live.body import SimulatedBody
from mrmp.live.driver import AgentTiming
from mrmp.policies.plan_following import PlanFollowingPolicy
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.messages import StateMessage

KEY = b"k" * 32


class Silent:
    def send(self, data: bytes, recipient: int | None = None) -> None:
        pass

    def receive(self, timeout: float) -> bytes | None:
        return None

    def close(self) -> None:
        pass


def follower() -> Agent:
    robots = (RobotSpec("A", (0, 0), (0, 1), Heading.EAST), RobotSpec("B", (0, 1), (0, 2), Heading.EAST))
    scene = Scenario(Grid(1, 3), robots)
    body = SimulatedBody((0, 0), Heading.EAST, scene.grid, scene.timing)
    policy = PlanFollowingPolicy(moves=[(0, 1)], dependencies={0: [(1, 1)]}, dependents={})
    timing = AgentTiming(listen_time=0.05)
    return Agent(scene, 0, Silent(), body, Sealer(KEY, 1), Opener(KEY, 1), timing, guarded=False, policy=policy)


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
