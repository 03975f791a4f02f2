"""Plans for turning bodies executed by turning bodies (LoRR's ``MAPF_T``): the plan's cells at the plan's ticks.

A robot whose body turns in place turns toward its next cell while it waits
(``Robot.turn``) and moves only to the cell ahead; the lockstep simulator's
referee judges every tick in the turning model (an ``action`` is a move to a
cell the robot does not face, or a turn with a move).
"""

from pathlib import Path

import pytest

from mrmp.centralized.execution import plan_policies
from mrmp.centralized.plan import PlanningResult
from mrmp.centralized.registry import plan_with
from mrmp.core import Heading, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.core.body import body_model
from mrmp.core.grid import Grid
from mrmp.experiments.execution import execute_in_simulator
from mrmp.io.scenario_file import load_movingai_scenario
from mrmp.robot.robot import Robot

MAPS = Path(__file__).resolve().parents[3] / "maps"
TURNING = PolicyOptions(body="turning")


def instance(map_name: str, agents: int) -> Scenario:
    scenario = load_movingai_scenario(MAPS / f"{map_name}.map", MAPS / f"{map_name}-random-1.scen", agents)
    return scenario.with_changes(policy=TURNING)


def settled(path):
    """A path without the waits at its goal after its last move."""
    path = list(path)
    while len(path) > 1 and path[-1] == path[-2]:
        path.pop()
    return path


def cells(path):
    """The cells a path enters, in order, without its waits."""
    return [cell for tick, cell in enumerate(path) if tick == 0 or cell != path[tick - 1]]


@pytest.mark.parametrize(
    ("planner", "map_name", "agents"),
    [("cbs", "random-32-32-20", 6), ("pp", "random-32-32-20", 20), ("lacam", "random-32-32-20", 48)],
)
def test_a_turning_plan_is_executed_in_its_ticks(planner: str, map_name: str, agents: int) -> None:
    scenario = instance(map_name, agents)
    plan = plan_with(planner, scenario, time_limit_s=60)
    assert plan.solved and plan.paths is not None, plan.message
    result = execute_in_simulator(scenario, plan)
    assert result.success and result.collisions == [] and result.body == "turning"
    assert [settled(robot.path) for robot in result.robots] == [settled(path) for path in plan.paths]
    assert result.makespan == plan.makespan() and result.sum_of_costs == plan.sum_of_costs()
    assert sum(robot.turns for robot in result.robots) > 0


def test_an_omni_plan_driven_by_turning_bodies_takes_longer_but_never_collides() -> None:
    scenario = instance("random-32-32-20", 48)
    plan = plan_with("lacam", scenario.with_changes(policy=PolicyOptions()), time_limit_s=60)
    result = execute_in_simulator(scenario, plan)
    assert result.success and result.collisions == []
    assert result.makespan > plan.makespan()


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_over_a_faulty_network_a_turning_plan_is_late_not_colliding(seed: int) -> None:
    scenario = instance("random-32-32-20", 30).with_changes(
        network=NetworkFaults(loss=0.2, delay_max=2, duplicate=0.1, reorder=0.1), seed=seed
    )
    plan = plan_with("lacam", scenario, time_limit_s=60)
    result = execute_in_simulator(scenario, plan)
    assert result.success and result.collisions == [], result.stop_reason
    assert [cells(robot.path) for robot in result.robots] == [cells(path) for path in plan.paths]
    assert result.makespan > plan.makespan()


def test_robots_that_do_not_turn_before_moving_are_caught_by_the_referee(monkeypatch: pytest.MonkeyPatch) -> None:
    """A broken variant: robots that drive to any neighbour (no turn in place) break the turning model."""
    monkeypatch.setattr(Robot, "_turn_toward", lambda self, cell: None)
    monkeypatch.setattr(Robot, "_faces", lambda self, cell: True)
    scenario = instance("random-32-32-20", 20)
    plan = plan_with("lacam", scenario, time_limit_s=60)
    result = execute_in_simulator(scenario, plan)
    assert {collision.kind for collision in result.collisions} == {"action"}


def test_claiming_while_turning_under_the_lockstep_rule_collides(monkeypatch: pytest.MonkeyPatch) -> None:
    """A broken variant: under the lockstep rule a granted claim hands the robot's cell to its follower within the
    tick; a robot that claims as it starts to turn is still there when the follower drives in."""
    monkeypatch.setattr(Robot, "_claims_while_turning", lambda self: True)
    scenario = instance("random-32-32-20", 48)
    plan = plan_with("lacam", scenario.with_changes(policy=PolicyOptions()), time_limit_s=60)
    result = execute_in_simulator(scenario, plan)
    assert "vertex" in {collision.kind for collision in result.collisions}


def test_a_robot_waiting_for_its_peers_turns_toward_its_next_cell_meanwhile() -> None:
    """A's first move (east) waits until B has left (0, 1); A turns east meanwhile and claims nothing yet."""
    robots = (
        RobotSpec("A", (0, 0), (0, 1), heading=Heading.NORTH),
        RobotSpec("B", (0, 1), (1, 1), heading=Heading.NORTH),
    )
    scenario = Scenario(Grid(2, 2), robots, policy=TURNING)
    plan = PlanningResult("solved", [[(0, 0), (0, 0), (0, 1)], [(0, 1), (1, 1), (1, 1)]], 0.0, "hand")
    policy = plan_policies(plan)[0]
    robot = Robot(robots[0], 0, scenario.grid, policy, [(0, 0), (0, 1)], body=body_model("turning"))
    robot.announce(now=1)
    assert robot.decide(now=1) == [] and robot.motion(now=1) is None
    assert robot.turn(now=1) == Heading.EAST and robot.moving
    robot.turned(Heading.EAST)
    assert robot.heading == Heading.EAST and not robot.moving and robot.turn(now=2) is None


def test_a_live_robot_claims_as_it_turns_and_makes_both_quarters_of_a_half_turn() -> None:
    """Without the lockstep rule (live bodies) the claim's round trip overlaps the turn; a cell behind the robot
    takes two quarter turns, the second one started while the claim is still pending."""
    spec = RobotSpec("A", (1, 0), (0, 0), heading=Heading.NORTH)
    policy = plan_policies(PlanningResult("solved", [[(1, 0), (0, 0)]], 0.0, "hand"))[0]
    robot = Robot(spec, 0, Grid(2, 1), policy, [(1, 0)], body=body_model("turning"))
    robot.announce(now=1)
    sends = robot.decide(now=1)
    assert [outgoing.message.cell for outgoing in sends] == [(0, 0)]  # claimed at once, while it turns
    assert robot.motion(now=1) is None and robot.turn(now=1) == Heading.EAST
    robot.turned(Heading.EAST)
    assert robot.decide(now=2) == [] and robot.motion(now=2) is None  # the claim pending: no new decision
    assert robot.turn(now=2) == Heading.SOUTH
    robot.turned(Heading.SOUTH)
    assert robot.motion(now=3) == (0, 0)  # a fleet of one is its own majority
