"""One check of reachability for the property tests of every policy with a progress guarantee."""

from collections.abc import Callable
from typing import Any


def assert_every_robot_reaches_its_goal(simulator: Any, within: int, unit: str, elapsed: Callable[[int], int]) -> None:
    """Step ``simulator`` until every robot has stood on its goal at least once, at most ``within`` ``unit``
    (``elapsed(steps)`` says how many have passed after ``steps`` steps); no collision on the way."""
    count = len(simulator.robots)
    reached = {robot.index for robot in simulator.robots if robot.at_goal}
    steps = 0
    while elapsed(steps) < within and len(reached) < count:
        simulator.step()
        steps += 1
        reached |= {robot.index for robot in simulator.robots if robot.at_goal}
    assert simulator.referee.collisions == []
    assert reached == set(range(count)), f"not at their goals within {within} {unit}: {set(range(count)) - reached}"
