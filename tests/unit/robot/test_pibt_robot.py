"""The message-driven PIBT robots decide exactly as the central PIBT generator, step by step."""

import random

import pytest

from mrmp.centralized.pibt_step import PIBT
from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.core.grid import connected_regions
from mrmp.protocol.codec import decode, encode
from mrmp.protocol.messages import AnswerMessage, BeaconMessage, InheritMessage, PullMessage, ReserveMessage
from mrmp.robot.pibt_robot import PibtRobot
from mrmp.search.flat_map import FlatMap
from mrmp.sim.rounds import RoundsSimulator


def random_scenario(seed, swap, radius=2, faults=None):
    rng = random.Random(seed)
    x_size, y_size = rng.randint(3, 9), rng.randint(3, 9)
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    blocked = set(rng.sample(cells, k=rng.randint(0, len(cells) // 5)))
    grid = Grid(x_size, y_size, blocked)
    region = max(connected_regions(grid, grid.free_cells())[1], key=len)
    free = sorted(region)
    count = rng.randint(1, max(1, len(free) // 2))
    starts, goals = rng.sample(free, count), rng.sample(free, count)
    robots = tuple(RobotSpec(f"r{i}", s, g) for i, (s, g) in enumerate(zip(starts, goals)))
    return Scenario(grid, robots, network=faults or NetworkFaults(), policy=PolicyOptions(name="pibt", radius=radius, swap=swap), seed=seed)


def central_next(simulator, swap, tie_penalties=False):
    robots = simulator.robots
    flat = simulator.flat
    pibt = PIBT(
        flat.neighbours,
        [flat.distances(robot.goal) for robot in robots],
        [robot.goal for robot in robots],
        swap=swap,
        tie_penalties=tie_penalties,
    )
    order = [robot.index for robot in sorted(robots, key=lambda robot: robot.priority, reverse=True)]
    return pibt.step([robot.present for robot in robots], order)


@pytest.mark.parametrize("swap", [False, True])
@pytest.mark.parametrize("seed", range(40))
def test_decisions_equal_central_pibt(seed, swap):
    scenario = random_scenario(seed, swap, radius=32)  # the radius covers the map: nothing is unknown
    simulator = RoundsSimulator(scenario, random_ties=False)
    for _ in range(30):
        expected = central_next(simulator, swap)
        simulator.step()
        assert [robot.present for robot in simulator.robots] == expected
    assert simulator.referee.collisions == []


@pytest.mark.parametrize("seed", range(40))
def test_radius_two_without_swap_is_exact(seed):
    scenario = random_scenario(seed, swap=False, radius=2)
    simulator = RoundsSimulator(scenario, random_ties=False)
    for _ in range(30):
        expected = central_next(simulator, swap=False)
        simulator.step()
        assert [robot.present for robot in simulator.robots] == expected


@pytest.mark.parametrize(("swap", "radius"), [(False, 2), (False, 32), (True, 32)])  # swap walks may leave radius 2
@pytest.mark.parametrize("seed", range(20))
def test_tie_penalties_are_applied_alike_by_robots_and_central_pibt(seed, swap, radius):
    simulator = RoundsSimulator(random_scenario(seed, swap, radius=radius), random_ties=False, tie_penalties=True)
    for _ in range(30):
        expected = central_next(simulator, swap, tie_penalties=True)
        simulator.step()
        assert [robot.present for robot in simulator.robots] == expected
    assert simulator.referee.collisions == []


def test_tie_penalties_change_decisions():
    changed = 0
    for seed in range(10):
        simulator = RoundsSimulator(random_scenario(seed, swap=True), random_ties=False, tie_penalties=True)
        for _ in range(15):
            changed += central_next(simulator, True, tie_penalties=True) != central_next(simulator, True)
            simulator.step()
    assert changed > 0


def test_a_robot_passes_by_a_robot_standing_on_its_goal():
    # from (0, 0) to (2, 2): (1, 0) and (0, 1) are equally near; a robot stands on its goal (1, 0)
    flat = FlatMap(Grid(3, 3))
    for tie_penalties, expected in ((False, (1, 0)), (True, (0, 1))):
        robot = PibtRobot(0, flat.index((0, 0)), flat.index((2, 2)), flat, tie_penalties=tie_penalties)
        robot.begin_step(1)
        assert not robot.receive(BeaconMessage(1, 1, 1, (1, 0), (1, 0), 0, 0))
        robot.start()
        assert flat.cell(robot.target) == expected  # the plain order (NORTH first) would push it off


@pytest.mark.parametrize("seed", range(20))
def test_faults_change_timing_not_decisions(seed):
    faulty = NetworkFaults(loss=0.3, delay_min=0, delay_max=2, duplicate=0.2, reorder=0.3)
    clean = RoundsSimulator(random_scenario(seed, swap=True))
    noisy = RoundsSimulator(random_scenario(seed, swap=True, faults=faulty).with_changes(max_ticks=10**5))
    for _ in range(25):
        clean.step()
        noisy.step()
        assert [robot.present for robot in noisy.robots] == [robot.present for robot in clean.robots]
    assert noisy.referee.collisions == [] and clean.referee.collisions == []
    assert noisy.tick >= clean.tick == 25
    if noisy.stats["tries"] > 100:
        assert noisy.stats["retransmissions"] > 0 and noisy.stats["extra_copies"] > 0
        assert sum(sum(robot.dropped.values()) for robot in noisy.robots) > 0  # second copies dropped


def test_a_cut_link_abandons_steps_and_nobody_moves():
    scenario = random_scenario(5, swap=True, faults=NetworkFaults(loss=1.0)).with_changes(max_ticks=5)
    result = RoundsSimulator(scenario).run()
    assert result.network["abandoned_steps"] == 5
    assert all(set(robot.path) == {robot.start} for robot in result.robots)


def test_messages_round_trip_the_codec():
    for message in (
        BeaconMessage(3, 9, 4, (1, 2), (5, 6), 7, 8),
        InheritMessage(3, 10, 4, (1, 3)),
        AnswerMessage(3, 11, 4, True),
        ReserveMessage(3, 12, 4, (2, 2)),
        PullMessage(3, 13, 4, (1, 2)),
    ):
        assert decode(encode(message)) == message


def test_duplicates_and_stale_messages_are_dropped():
    flat = FlatMap(Grid(1, 3))
    robot = PibtRobot(0, 0, 2, flat)
    robot.begin_step(2)
    reserve = ReserveMessage(1, 5, 2, (0, 1))
    robot.receive(reserve)
    robot.receive(reserve)
    robot.receive(ReserveMessage(1, 6, 1, (0, 2)))
    assert robot.dropped == {"duplicate": 1, "stale": 1}
    assert robot.start() and robot.target == 0  # (0, 1) is reserved: it stays


def test_radius_below_two_is_refused():
    with pytest.raises(ValueError, match="radius 1"):
        PibtRobot(0, 0, 1, FlatMap(Grid(1, 2)), radius=1)


def test_heading_aware_robot_goes_straight_among_equal_cells():
    from mrmp.core.heading import Heading

    scenario = Scenario(
        Grid(4, 4),
        (RobotSpec("A", (0, 0), (3, 3), heading=Heading.EAST),),
        policy=PolicyOptions(name="pibt", heading_aware=True),
    )
    result = RoundsSimulator(scenario).run()
    assert result.success and result.robots[0].path[1] == (0, 1)  # EAST first: no turn
    plain = RoundsSimulator(scenario.with_changes(policy=PolicyOptions(name="pibt")), random_ties=False).run()
    assert plain.robots[0].path[1] == (1, 0)  # NORTH first in the plain order: a turn
    assert result.robots[0].turns < plain.robots[0].turns


def test_lifelong_pibt_keeps_reaching_new_goals():
    scenario = random_scenario(11, swap=True).with_changes(lifelong=True, max_ticks=120)
    result = RoundsSimulator(scenario).run()
    assert result.stop_reason == "time up" and result.collisions == []
    assert sum(robot.goals_reached for robot in result.robots) > 2 * len(result.robots)
    assert result.throughput > 0


def test_a_run_leaves_no_garbage_cycles_and_restores_the_collector():
    import gc

    scenario = random_scenario(3, swap=True, faults=NetworkFaults(loss=0.2, delay_max=1, duplicate=0.1, reorder=0.2))
    gc.collect()
    result = RoundsSimulator(scenario.with_changes(max_ticks=10**4)).run()
    assert gc.isenabled()
    gc.set_debug(gc.DEBUG_SAVEALL)  # keep what the collector finds, to look at it
    try:
        gc.collect()
        ours = [item for item in gc.garbage if type(item).__module__.startswith("mrmp")]
    finally:
        gc.set_debug(0)
        gc.garbage.clear()
    assert ours == []  # the collector was paused during the run: nothing of the run needed it
    assert result.collisions == []


@pytest.mark.parametrize("seed", range(6))
def test_heading_aware_robot_alone_takes_a_cheapest_turning_way(seed):
    """Alone, a heading-aware robot descends its heading-aware table: its time equals heading-aware A*'s cost."""
    from mrmp.core.heading import HEADINGS
    from mrmp.core.scenario import Timing
    from mrmp.search import astar

    rng = random.Random(seed)
    base = random_scenario(seed, swap=False)
    free = sorted(max(connected_regions(base.grid, base.grid.free_cells())[1], key=len))
    start, goal = rng.sample(free, 2)
    heading = rng.choice(HEADINGS)
    timing = Timing(1.0, 0.5)
    scenario = Scenario(
        base.grid, (RobotSpec("A", start, goal, heading=heading),), timing=timing,
        policy=PolicyOptions(name="pibt", heading_aware=True, swap=False), seed=seed,
    )  # fmt: skip
    result = RoundsSimulator(scenario).run()
    assert result.success
    assert result.robots[0].time_s == pytest.approx(astar(base.grid, start, goal, heading=heading, timing=timing).cost)
