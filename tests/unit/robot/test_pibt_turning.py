"""Decentralized PIBT for bodies that turn in place: the robots decide as the central generator, by messages.

The robots of policy ``pibt`` with ``body: turning`` (LoRR's MAPF_T) rank their
neighbours with the turns toward them, drive only to the cell ahead, and cancel
a forward move into a robot that stays by a chain of :class:`StayMessage`s. Step
by step their configuration and headings equal those of
:class:`mrmp.centralized.pibt_step.PIBT` with ``turning_y_size``; the referee
judges every run in the turning model; and the two rules that keep steps legal
(the stay chain; a pushed robot never takes the cell of a moving one) are each
broken on purpose and caught.
"""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from mrmp.centralized.pibt_step import NO_CELL, PIBT
from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.core.grid import connected_regions
from mrmp.core.heading import Heading
from mrmp.io.scenario_file import load_scenario
from mrmp.policies.pibt_rules import DEAD_END_BONUS
from mrmp.protocol.codec import decode, encode
from mrmp.protocol.messages import StayMessage
from mrmp.robot.pibt_robot import PibtRobot
from mrmp.sim import rounds
from mrmp.sim.rounds import RoundsSimulator

N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST
EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def turning_policy(radius: int = 2) -> PolicyOptions:
    return PolicyOptions(name="pibt", radius=radius, swap=False, body="turning", sequencing="driver")


def random_scenario(seed: int, radius: int = 2, faults: NetworkFaults | None = None) -> Scenario:
    rng = random.Random(seed)
    x_size, y_size = rng.randint(3, 9), rng.randint(3, 9)
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    blocked = set(rng.sample(cells, k=rng.randint(0, len(cells) // 5)))
    grid = Grid(x_size, y_size, blocked)
    free = sorted(max(connected_regions(grid, grid.free_cells())[1], key=len))
    count = rng.randint(1, max(1, len(free) // 2))
    starts, goals = rng.sample(free, count), rng.sample(free, count)
    robots = tuple(
        RobotSpec(f"r{i}", start, goal, heading=Heading(rng.randint(1, 4)))
        for i, (start, goal) in enumerate(zip(starts, goals))
    )
    return Scenario(grid, robots, network=faults or NetworkFaults(), policy=turning_policy(radius), seed=seed)


def central_next(simulator: RoundsSimulator) -> tuple[list[int], list[int]]:
    """The central generator's next cells and headings, from the robots' cells, headings and priorities."""
    robots, flat = simulator.robots, simulator.flat
    pibt = PIBT(
        flat.neighbours,
        [flat.heading_distances(robot.goal, 1.0, both_ways=True) for robot in robots],
        [robot.goal for robot in robots],
        rotations=False,
        turning_y_size=flat.y_size,
    )
    order = [robot.index for robot in sorted(robots, key=lambda robot: robot.priority, reverse=True)]
    target, headings = [NO_CELL] * len(robots), [0] * len(robots)
    assert pibt.generate([robot.present for robot in robots], target, order, [int(r.heading) for r in robots], headings)
    return target, headings


def state(simulator: RoundsSimulator) -> tuple[list[int], list[int]]:
    return [robot.present for robot in simulator.robots], [int(robot.heading) for robot in simulator.robots]


@pytest.mark.slow
@pytest.mark.parametrize("radius", [2, 32])
@pytest.mark.parametrize("seed", range(40))
def test_decisions_equal_the_central_turning_generator(seed: int, radius: int) -> None:
    simulator = RoundsSimulator(random_scenario(seed, radius), random_ties=False)
    for _ in range(30):
        expected = central_next(simulator)
        simulator.step()
        assert state(simulator) == expected
    assert simulator.referee.collisions == []


@pytest.mark.parametrize("seed", range(10))
def test_faults_change_timing_not_decisions(seed: int) -> None:
    faults = NetworkFaults(loss=0.3, delay_min=0, delay_max=2, duplicate=0.2, reorder=0.3)
    perfect = RoundsSimulator(random_scenario(seed))
    faulty = RoundsSimulator(random_scenario(seed, faults=faults))
    for _ in range(20):
        perfect.step()
        faulty.step()
        assert state(faulty) == state(perfect)
    assert faulty.referee.collisions == []


def test_a_fleet_on_a_standard_map_arrives_with_legal_actions_only() -> None:
    scenario = load_scenario(EXAMPLES / "causal-32.yaml")
    scenario = scenario.with_changes(policy=turning_policy())
    result = RoundsSimulator(scenario).run()
    assert result.success and result.collisions == []
    # every tick is one action: a forward move keeps the heading; a turn is a quarter, in place
    for robot in result.robots:
        for (cell, heading), (after, turned) in zip(zip(robot.path, robot.headings), zip(robot.path[1:], robot.headings[1:])):
            if after != cell:
                assert turned == heading and after == heading.ahead(cell)
            else:
                assert (int(turned) - int(heading)) % 4 in (0, 1, 3)


def test_the_lower_bound_counts_the_turns() -> None:
    grid = Grid(1, 3)
    scenario = Scenario(grid, (RobotSpec("A", (0, 0), (0, 2), heading=N),), policy=turning_policy())
    result = RoundsSimulator(scenario).run()
    assert result.lower_bound == 3  # a quarter turn, then two cells
    assert result.sum_of_costs == 3 and result.robots[0].turns == 1


def test_a_robot_that_turns_stops_the_robot_behind_it_and_the_referee_catches_a_fleet_that_does_not(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # r0 faces EAST toward r1, whose goal lies NORTH of it: r1 must turn first, so r0 must wait
    grid = Grid(2, 3)
    robots = (RobotSpec("r0", (0, 0), (0, 2), heading=E), RobotSpec("r1", (0, 1), (1, 1), heading=E))
    scenario = Scenario(grid, robots, policy=turning_policy())
    simulator = RoundsSimulator(scenario, random_ties=False)
    simulator.step()
    assert [simulator.flat.cell(robot.present) for robot in simulator.robots] == [(0, 0), (0, 1)]
    assert simulator.robots[1].heading == N and simulator.referee.collisions == []
    monkeypatch.setattr(PibtRobot, "_tell_taker", lambda self, out: None)  # the broken fleet: no stay chain
    broken = RoundsSimulator(scenario, random_ties=False)
    broken.step()
    assert [collision.kind for collision in broken.referee.collisions] == ["vertex"]


def test_no_cycle_of_robots_follows_round_a_loop_and_the_referee_catches_one(monkeypatch: pytest.MonkeyPatch) -> None:
    # four robots on a 2x2 loop, each facing the next one's cell, which is its goal
    cells = [(0, 0), (0, 1), (1, 1), (1, 0)]
    robots = tuple(
        RobotSpec(f"r{i}", cell, cells[(i + 1) % 4], heading=heading) for i, (cell, heading) in enumerate(zip(cells, [E, N, W, S]))
    )
    scenario = Scenario(Grid(2, 2), robots, policy=turning_policy())
    simulator = RoundsSimulator(scenario, random_ties=False)
    simulator.step()
    assert simulator.referee.collisions == []
    monkeypatch.setattr(PibtRobot, "_closes_cycle", lambda self, occupant, cell: False)  # the broken rule
    broken = RoundsSimulator(scenario, random_ties=False)
    broken.step()
    assert [collision.kind for collision in broken.referee.collisions] == ["rotation"]


def test_stay_messages_round_trip_the_codec_and_turning_refuses_swap() -> None:
    message = StayMessage(3, 17, 9)
    assert decode(encode(message)) == message
    with pytest.raises(ValueError, match="no swap technique"):
        PibtRobot(0, 0, 1, RoundsSimulator(random_scenario(0)).flat, swap=True, turning=True)


@pytest.mark.parametrize("bonus", [DEAD_END_BONUS, 0])
def test_a_robot_shut_in_a_dead_end_outranks_the_one_waiting_at_its_mouth(bonus: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """Without the swap technique, B (at the mouth, for the dead end) and A (in it, for outside) wait for each other
    for ever while B outranks A; the Start-Kit's dead-end bonus lets A go first. The variant without it never ends."""
    monkeypatch.setattr(rounds, "DEAD_END_BONUS", bonus)
    grid = Grid.from_rows(["...", "#.#"])
    dead_end, mouth, outside = (0, 1), (1, 1), (1, 0)
    scenario = Scenario(
        grid,
        (RobotSpec("A", dead_end, outside), RobotSpec("B", mouth, dead_end)),
        policy=PolicyOptions(name="pibt", body="turning", sequencing="driver"),
        max_ticks=60,
    )
    simulator = RoundsSimulator(scenario)
    simulator.robots[1].elapsed = 5  # B has waited longer: it outranks A
    result = simulator.run()
    assert not result.collisions
    if bonus:
        assert result.stop_reason == "all arrived" and result.makespan <= 10
    else:
        assert result.stop_reason == "tick limit"
