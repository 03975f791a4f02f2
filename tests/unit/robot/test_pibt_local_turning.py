"""PIBT sequenced by the robots for bodies that turn in place, and two rules of local sequencing over faulty networks.

With ``turning`` bodies a robot of local sequencing decides for the cell ahead
(it drives) or for its own (it stays, turning toward the neighbour it chose), so
a decision for good is never cancelled: the *ahead-or-stay* rule
(:attr:`~mrmp.robot.pibt_robot.PibtRobot.turns_by_staying`). Its asks and
answers carry the central rule's chain of robots that stay (an answer "stays,
turns to leave"). The central generator's rule, whose decisions a later
:class:`StayMessage` cancels, is caught colliding under local sequencing; so
is a fleet whose robots follow one another round a loop.

Two rules of local sequencing hold for every body and are each broken on
purpose: a claim decided for good beats a provisional one even when the
claimant's beacon has not come in yet, and a robot whose reservation lost while
it waited for an answer waits for that answer before its next cell.
"""

from __future__ import annotations

import dataclasses
import itertools
import random
from pathlib import Path

import pytest
from test_pibt_local import crowd as omni_crowd

from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.core.heading import Heading
from mrmp.io.scenario_file import load_scenario
from mrmp.protocol.codec import DecodeError, decode, encode
from mrmp.protocol.messages import AnswerMessage, BeaconMessage
from mrmp.protocol.pibt_local import CallReserveMessage
from mrmp.robot.pibt_local import LocalPibtRobot
from mrmp.search.flat_map import FlatMap
from mrmp.sim.local_rounds import LocalRoundsSimulator
from mrmp.sim.policy_table import pibt_simulator

N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST
EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
FAULTS = NetworkFaults(loss=0.3, delay_max=2, duplicate=0.2, reorder=0.3)


def local_turning(synchronizer: str = "clock", radius: int = 2) -> PolicyOptions:
    return PolicyOptions(name="pibt", radius=radius, swap=False, body="turning", sequencing="local", synchronizer=synchronizer)


def crowd(seed: int, faults: NetworkFaults | None = None, synchronizer: str = "clock", density: float = 0.5) -> Scenario:
    """``test_pibt_local``'s random crowd at ``density``, every robot facing a heading drawn with ``seed``."""
    scenario = omni_crowd(seed, density=density, swap=False, max_ticks=3000)
    rng = random.Random(seed)
    robots = tuple(dataclasses.replace(robot, heading=Heading(rng.randint(1, 4))) for robot in scenario.robots)
    return scenario.with_changes(robots=robots, network=faults or NetworkFaults(), policy=local_turning(synchronizer))


def assert_legal_actions(result) -> None:
    """Every tick is one action: a forward move that keeps the heading, or a quarter turn in place, or a wait."""
    for robot in result.robots:
        states = list(zip(robot.path, robot.headings))
        for (cell, heading), (after, turned) in itertools.pairwise(states):
            if after != cell:
                assert turned == heading and after == heading.ahead(cell)
            else:
                assert (int(turned) - int(heading)) % 4 in (0, 1, 3)


@pytest.mark.parametrize("synchronizer", ["clock", "local"])
def test_a_fleet_on_a_standard_map_arrives_with_legal_actions_only(synchronizer: str) -> None:
    scenario = load_scenario(EXAMPLES / "causal-32.yaml").with_changes(policy=local_turning(synchronizer))
    result = pibt_simulator(scenario).run()
    assert result.success and result.collisions == []
    assert_legal_actions(result)
    driver_policy = PolicyOptions(name="pibt", swap=False, body="turning", sequencing="driver")
    driver = pibt_simulator(scenario.with_changes(policy=driver_policy)).run()
    assert result.makespan <= 1.2 * driver.makespan  # the robots' own order costs little against the driver's


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(12))
def test_crowds_arrive_without_collision_on_perfect_and_faulty_networks(seed: int) -> None:
    for faults in (None, FAULTS):
        result = pibt_simulator(crowd(seed, faults, synchronizer="local" if seed % 2 else "clock")).run()
        assert result.collisions == [], (faults, result.collisions[:3])
        assert_legal_actions(result)
        if faults is None:
            assert result.success


def test_the_central_rule_with_cancellations_collides_under_local_sequencing(monkeypatch: pytest.MonkeyPatch) -> None:
    """A decision for good that a later StayMessage would cancel: the robot has moved already."""
    short = [crowd(seed).with_changes(max_ticks=60) for seed in range(8)]
    assert all(not pibt_simulator(scenario).run().collisions for scenario in short)
    monkeypatch.setattr(LocalPibtRobot, "turns_by_staying", False)
    assert any(pibt_simulator(scenario).run().collisions for scenario in short)


def test_no_cycle_of_robots_follows_round_a_loop_and_the_referee_catches_one(monkeypatch: pytest.MonkeyPatch) -> None:
    # four robots on a 2x2 loop, each facing the next one's cell, which is its goal
    cells = [(0, 0), (0, 1), (1, 1), (1, 0)]
    robots = tuple(
        RobotSpec(f"r{i}", cell, cells[(i + 1) % 4], heading=heading) for i, (cell, heading) in enumerate(zip(cells, [E, N, W, S]))
    )
    scenario = Scenario(Grid(2, 2), robots, policy=local_turning(), max_ticks=8)
    simulator = LocalRoundsSimulator(scenario, random_ties=False)
    simulator.step()
    assert simulator.referee.collisions == []
    monkeypatch.setattr(LocalPibtRobot, "_may_rotate", lambda self: True)  # the broken rule: follow one of its own call
    broken = LocalRoundsSimulator(scenario, random_ties=False)
    broken.step()
    assert [collision.kind for collision in broken.referee.collisions] == ["rotation"]


def test_a_robot_asked_to_leave_turns_to_leave_and_the_asker_waits_behind_it() -> None:
    # r0 at (0, 0) faces EAST toward r1 at (0, 1); r1 faces EAST into the wall, its way out is NORTH to (1, 1)
    grid = Grid(2, 2, {(1, 0)})
    robots = (
        RobotSpec("r0", (0, 0), (0, 1), heading=E),
        RobotSpec("r1", (0, 1), (1, 1), heading=E),
    )
    simulator = LocalRoundsSimulator(Scenario(grid, robots, policy=local_turning(), max_ticks=10), random_ties=False)
    simulator.robots[0].elapsed = 3  # r0 outranks r1: it asks r1 to leave
    simulator.step()
    r0, r1 = simulator.robots
    assert [simulator.flat.cell(robot.present) for robot in (r0, r1)] == [(0, 0), (0, 1)]
    assert (r0.heading, r1.heading) == (E, N) and simulator.referee.collisions == []
    simulator.step()  # r1 faces its way out: it drives, and r0 follows it into its cell
    assert [simulator.flat.cell(robot.present) for robot in (r0, r1)] == [(0, 1), (1, 1)]
    assert simulator.referee.collisions == []


def test_answers_carry_whether_the_robot_turns_to_leave() -> None:
    for answer in (AnswerMessage(1, 2, 3, True), AnswerMessage(1, 2, 3, False, turns=True), AnswerMessage(1, 2, 3, False)):
        assert decode(encode(answer)) == answer
    moved_and_turns = bytearray(encode(AnswerMessage(1, 2, 3, True)))
    moved_and_turns[-1] = 3
    with pytest.raises(DecodeError):
        decode(bytes(moved_and_turns))
    with pytest.raises(ValueError, match="not both"):
        AnswerMessage(1, 2, 3, True, turns=True)


def occupant_first(self: LocalPibtRobot, claimant: int, holder: int, cell: int) -> bool:
    """The rule before: staying on one's cell, as far as the beacons heard tell, then the call's rank."""
    occupant = self._occupants.get(cell)
    if (occupant == claimant) != (occupant == holder):
        return occupant == claimant
    return self._claims.get(claimant, (0, 0, 0)) > self._claims.get(holder, (0, 0, 0))


@pytest.mark.parametrize("broken", [False, True])
def test_a_claim_decided_for_good_holds_before_its_claimants_beacon_comes_in(broken: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """In a corridor of cells 0-1-2-3, robot 2 on cell 2 asked robot 1, on cell 1, to leave; robot 1 could not.

    Robot 0, on cell 0, heard robot 2's claim of cell 1, then robot 1's claim of
    it decided for good (it stays), then robot 2's next claim, all before robot
    1's beacon: cell 1 is robot 1's, and robot 0 must not claim it.
    """
    if broken:
        monkeypatch.setattr(LocalPibtRobot, "_outranks", occupant_first)
        monkeypatch.setattr(LocalPibtRobot, "_restore_holder", lambda self, cell: None)
    flat = FlatMap(Grid(1, 4))
    robot = LocalPibtRobot(0, flat.index((0, 0)), flat.index((0, 3)), flat, tie=3)
    robot.begin_step(1)
    robot.receive_beacons([BeaconMessage(2, 1, 1, (0, 2), (0, 0), 9, 0, W)])  # robot 2, higher priority, at cell 2
    for message in (
        CallReserveMessage(2, 2, 1, (0, 1), 2, 9, 0, False),  # robot 2 claims cell 1, asking its occupant
        CallReserveMessage(1, 1, 1, (0, 1), 2, 9, 0, True),  # robot 1, its occupant, stays: decided for good
        CallReserveMessage(2, 3, 1, (0, 2), 2, 9, 0, True),  # robot 2 stays on its cell instead
    ):
        robot.receive(message)
    robot.act()
    assert (robot.target == flat.index((0, 1))) == broken  # the broken rule claims the cell robot 1 stays on


def drop_the_answer(self: LocalPibtRobot, out: list) -> None:
    """The rule before: on a lost reservation, forget the robot asked and try the next cell at once."""
    self._waiting = None
    self._next_cell(out)


@pytest.mark.parametrize("broken", [False, True])
def test_a_robot_whose_reservation_lost_waits_for_the_answer_of_the_robot_it_asked(
    broken: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Robot 0 at (1, 1) asked robot 1 to leave (1, 2); robot 2's call, of higher rank, then claimed (1, 2) too.

    Robot 1 may have taken robot 0's request and be deciding within robot 0's
    call: robot 0 tries its next cell only once robot 1 has answered, so that no
    two branches of its call claim cells side by side (their claims carry one
    rank: both could stand). The broken rule goes on at once.
    """
    if broken:
        monkeypatch.setattr(LocalPibtRobot, "_withdraw", drop_the_answer)
    flat = FlatMap(Grid(3, 3))
    robot = LocalPibtRobot(0, flat.index((1, 1)), flat.index((1, 2)), flat, tie=1, swap=False)
    robot.begin_step(1)
    robot.receive_beacons(
        [BeaconMessage(1, 1, 1, (1, 2), (0, 2), 0, 0, N), BeaconMessage(2, 1, 1, (2, 2), (2, 1), 0, 0, N)]
    )
    asked = [type(item.message).__name__ for item in robot.act()]
    assert asked == ["CallReserveMessage", "CallInheritMessage"]
    robot.receive(CallReserveMessage(2, 2, 1, (1, 2), 5, 9, 0, False))  # a call of higher rank claims (1, 2)
    reservations = [item.message for item in robot.act() if isinstance(item.message, CallReserveMessage)]
    assert bool(reservations) == broken  # the broken rule claims its next cell while robot 1 still decides
    robot.receive(AnswerMessage(1, 3, 1, True))
    after = [item.message for item in robot.act() if isinstance(item.message, CallReserveMessage)]
    assert (after or broken) and robot.target != flat.index((1, 2))  # then, and only then, its next cell
