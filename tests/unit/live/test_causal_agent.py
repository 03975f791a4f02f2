"""The Causal-PIBT live driver's step, polled by hand: what it reports of the body's moves."""

from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
from mrmp.core.heading import Heading
from mrmp.live.causal_agent import CausalAgent
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.messages import LockReleaseMessage, LockRequestMessage
from mrmp.robot.causal_pibt import EXTENDED, CausalRobot


class RecordingTransport:
    """Keeps what is sent; delivers nothing."""

    def __init__(self):
        self.sent = []

    def send(self, data, recipient=None):
        self.sent.append((data, recipient))

    def receive(self, timeout):
        return None

    def close(self):
        pass


class OneSecondBody:
    """A body whose every move takes one second."""

    def __init__(self, cell):
        self.cell, self.heading, self.moving, self.follows = cell, Heading.NORTH, False, False

    def start_move(self, target, now):
        self.target, self.ends_at, self.moving = target, now + 1.0, True

    def next_event(self):
        return self.ends_at if self.moving else float("inf")

    def poll(self, now):
        if self.moving and now >= self.ends_at:
            self.cell, self.moving = self.target, False
            return True
        return False


def exchange(robots, sender, outgoing, now):
    """Deliver ``outgoing`` of robot ``sender`` and every answer, at once (a perfect network)."""
    queue = [(sender, item) for item in outgoing]
    while queue:
        origin, item = queue.pop(0)
        for recipient in item.recipients if item.recipients is not None else range(len(robots)):
            if recipient != origin:
                queue.extend((recipient, answer) for answer in robots[recipient].receive(item.message, now))


def test_arrival_on_the_goal_counts_when_the_body_arrives_even_if_a_peer_holds_the_lock():
    """The body reaches the goal while a peer's activation locks the robot: it contracts later, arrived on time."""
    grid = Grid(1, 6)
    robots = (RobotSpec("a", (0, 0), (0, 1)), RobotSpec("b", (0, 5), (0, 5)))
    scenario = Scenario(grid, robots, policy=PolicyOptions(name="causal"), name="late-contraction")
    agent = CausalAgent(scenario, 0, RecordingTransport(), OneSecondBody((0, 0)), Sealer(b"", 1), Opener(b"", 1, fleet_size=2))
    robot, peer = agent.robot, CausalRobot(1, grid, [(0, 0), (0, 5)], (0, 5))
    fleet = [robot, peer]
    robot.receive(peer.state_message(), now=0.0)
    peer.receive(robot.state_message(), now=0.0)
    exchange(fleet, 0, robot.activate(now=0.0), now=0.0)  # requesting (0, 1)
    exchange(fleet, 0, robot.activate(now=0.0), now=0.0)  # extended into it, claimed and granted
    assert robot.mode == EXTENDED
    agent._begin(0.0)
    agent._next_activation = float("inf")  # activations are run by hand above
    agent._step(1.0, started=0.0)
    assert agent.body.moving
    assert robot.receive(LockRequestMessage(1, 1, 1), now=1.5)  # the peer's activation locks this robot
    agent._step(2.0, started=0.0)  # the body stands on the goal; contracting waits for the release
    assert robot.mode == EXTENDED and not robot.at_goal
    robot.receive(LockReleaseMessage(1, 2, 1), now=2.5)
    agent._step(3.0, started=0.0)
    assert robot.at_goal and agent.report.steps == 1
    assert agent.report.arrival_time == 2.0
