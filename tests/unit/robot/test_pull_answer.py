"""A plan-following robot answers, within the step, a dependent that still waits for a move it has made.

On a lossy network the state that reported a completed move (the push to its
dependents) can be lost; the dependent's next state (its pull) then reaches the
robot, which answers it at once, once per step, so that two robots waiting on
each other's moves cannot answer each other for ever within one step.
"""

from __future__ import annotations

from mrmp.core import Grid, RobotSpec
from mrmp.policies.plan_following import PlanFollowingPolicy
from mrmp.protocol.messages import StateMessage
from mrmp.robot.robot import Robot


def _leader() -> Robot:
    """Robot 0 moves (0,0) -> (0,1); robot 1's first move waits for it to have completed that move."""
    policy = PlanFollowingPolicy([(0, 1)], {}, dependents={1: [(1, 0)]})
    robot = Robot(RobotSpec("A", (0, 0), (0, 1)), 0, Grid(3, 3), policy, [(0, 0), (2, 2)], guarded=False, state_radius=0)
    robot.announce(now=1)
    robot.decide(now=1)
    assert robot.motion(now=1) == (0, 1)
    robot.arrived_at((0, 1), robot.heading)
    return robot


def _pull(progress: int, seq: int) -> StateMessage:
    return StateMessage(1, seq, (2, 2), (2, 1), progress=progress)


def test_a_dependent_that_still_waits_is_answered_within_the_step() -> None:
    leader = _leader()
    leader.announce(now=2)  # the push of the completed move: lost, say
    answers = leader.receive(_pull(progress=0, seq=1), now=2)
    assert [(type(answer.message).__name__, answer.recipients, answer.message.progress) for answer in answers] == [
        ("StateMessage", (1,), 1)
    ]


def test_one_answer_per_step_and_none_to_a_dependent_past_the_move() -> None:
    leader = _leader()
    leader.announce(now=2)
    assert leader.receive(_pull(progress=0, seq=1), now=2)
    assert leader.receive(_pull(progress=0, seq=2), now=2) == []  # the same step: answered already
    leader.announce(now=3)
    assert leader.receive(_pull(progress=1, seq=3), now=3) == []  # it has made its move: it waits no more
    assert leader.receive(_pull(progress=0, seq=4), now=3)  # a new step, still waiting: answered again
