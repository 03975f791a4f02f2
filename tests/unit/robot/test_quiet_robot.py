"""One quiet robot, step by step: when its state goes out, whom it answers, and a claim that stands.

Two robots on a perfect network under the lockstep rule (``state_refresh`` and
``lossy=False``, as the lockstep simulator makes them there). Every message of
one goes to the other (a fleet of two).
"""

from __future__ import annotations

from mrmp.core import Grid, RobotSpec
from mrmp.policies.thesis import ThesisPolicy
from mrmp.robot.robot import Outgoing, Robot

STARTS = [(2, 2), (1, 2)]


def fleet() -> list[Robot]:
    """A at (2, 2) heading for (0, 2) outranks B, parked on (1, 2): A claims B's cell every step, refused."""
    specs = [RobotSpec("A", (2, 2), (0, 2)), RobotSpec("B", (1, 2), (1, 2))]
    return [
        Robot(spec, index, Grid(5, 5), ThesisPolicy(), STARTS, following=True, state_radius=2, knowledge_lease=0,
              state_refresh=4, lossy=False)
        for index, spec in enumerate(specs)
    ]


def deliver(robots: list[Robot], sender: int, outgoing: list[Outgoing], now: int, log: list[str]) -> None:
    """Deliver everything ``sender`` sent to the other robot, and its answers, recursively."""
    other = 1 - sender
    for item in outgoing:
        log.append(f"{sender}:{type(item.message).__name__}")
        deliver(robots, other, robots[other].receive(item.message, now), now, log)


def step(robots: list[Robot], now: int) -> list[str]:
    """One lockstep tick; returns the messages sent, as ``sender:type``."""
    log: list[str] = []
    for phase in ("announce", "decide", "retry"):
        sent = [getattr(robot, phase)(now) for robot in robots]
        for index, outgoing in enumerate(sent):
            deliver(robots, index, outgoing, now, log)
    for robot in robots:
        cell = robot.motion(now)
        if cell is not None:
            robot.arrived_at(cell, robot.heading)
    for index, robot in enumerate(robots):
        deliver(robots, index, robot.expire(now), now, log)
    return log


def test_a_refused_claim_stands_and_unchanged_states_wait_for_the_refresh() -> None:
    robots = fleet()
    first = step(robots, 1)
    assert first == ["0:StateMessage", "1:StateMessage", "0:ClaimMessage", "1:ReplyMessage"]
    a = robots[0]
    assert a.last_decision is not None and a.last_decision.reason == "priority" and a.safety.standing
    assert [step(robots, now) for now in (2, 3, 4)] == [[], [], []]  # nothing changed: nothing is sent
    assert a.safety.standing and a.safety.stats.claims == 1
    assert step(robots, 5) == ["0:StateMessage", "1:StateMessage"]  # the refresh, four ticks on


def test_a_robot_that_gives_its_standing_claim_up_releases_it_before_it_claims_again() -> None:
    robots = fleet()
    step(robots, 1)
    a = robots[0]
    a.goal = (2, 3)  # it now wants another cell, free
    log = step(robots, 2)
    assert log == [
        "0:StateMessage",  # its Next changed: its state goes at once
        "0:ReleaseMessage", "1:ReleaseAckMessage",  # the standing claim given up, before the new claim
        "0:ClaimMessage", "1:ReplyMessage", "0:HandoffMessage",
        "0:ReleaseMessage", "1:ReleaseAckMessage",  # the cell it left
    ]
    assert a.present == (2, 3)


def test_a_robot_coming_near_is_answered_by_a_robot_that_kept_its_state_to_itself() -> None:
    far = [(4, 4), (0, 0)]
    specs = [RobotSpec("A", (4, 4), (4, 4)), RobotSpec("B", (0, 0), (4, 2))]
    robots = [
        Robot(spec, index, Grid(5, 5), ThesisPolicy(), far, following=True, state_radius=2, knowledge_lease=0,
              state_refresh=100, lossy=False)
        for index, spec in enumerate(specs)
    ]
    step(robots, 1)
    logs = [step(robots, now) for now in range(2, 10)]
    b = robots[1]
    assert b.present == (4, 2) and 0 in b.belief.peers  # B, two cells from A now, knows it
    answers = [log for log in logs if "0:StateMessage" in log]
    assert len(answers) == 1  # A, parked, spoke once: to B, come within its radius
    assert b.situation().peers[0].present == (4, 4)
