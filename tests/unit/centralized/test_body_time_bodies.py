"""The execution bound per body: at most the makespan of a plan the body can carry out, equal when the last robot never waits."""

from __future__ import annotations

import random

import pytest

from mrmp.centralized.body_time import execution_seconds
from mrmp.centralized.dependencies import PlanDeadlockError
from mrmp.centralized.registry import plan_with
from mrmp.core import Grid, RobotSpec, Scenario, Timing
from mrmp.core.body import body_model
from mrmp.core.heading import HEADINGS, Heading
from mrmp.sim.referee import Referee, check_paths

N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST
OMNI, THESIS, TURNING = body_model("omni"), body_model("thesis"), body_model("turning")
ONE = Timing(cell_time=1.0, turn_time=0.0)
SLOW_TURNS = Timing(cell_time=2.0, turn_time=0.5)


def proposal(body, rng, grid, cell, heading):
    """One action the body can make from ``cell`` facing ``heading``: (cell, heading) after it."""
    if body.turns_in_place:  # forward, a quarter turn either way, or wait
        choice = rng.randrange(4)
        if choice == 0:
            return heading.ahead(cell), heading
        if choice in (1, 2):
            return cell, body.turned(heading, 1 if choice == 1 else -1)
        return cell, heading
    neighbours = grid.neighbours(cell)
    if neighbours and rng.random() < 0.8:
        target = rng.choice(neighbours)
        return target, Heading.between(cell, target)
    return cell, rng.choice(HEADINGS) if body.headed else heading


def legal_plan(body, seed, grid=None, robots=5, ticks=8):
    """A random plan every tick of which the real referee accepts for ``body``: proposals, reverted to waits until legal."""
    rng = random.Random(seed)
    grid = grid or Grid.from_rows(["....", ".@..", "...."])
    starts = rng.sample(grid.free_cells(), robots)
    ids = [f"r{i}" for i in range(robots)]
    paths = [[cell] for cell in starts]
    headings = [[rng.choice(HEADINGS)] for _ in starts]
    for tick in range(1, ticks + 1):
        before, facing = [p[-1] for p in paths], [h[-1] for h in headings]
        after, faced = map(list, zip(*(proposal(body, rng, grid, c, h) for c, h in zip(before, facing))))
        while found := Referee(grid, ids, body).check_tick(tick, before, after, facing, faced):
            for collision in found:
                for robot in collision.robots:
                    index = ids.index(robot)
                    after[index], faced[index] = before[index], facing[index]
        for path, cell in zip(paths, after):
            path.append(cell)
        for turns, heading in zip(headings, faced):
            turns.append(heading)
    assert check_paths(grid, dict(zip(ids, paths)), dict(zip(ids, headings)), body) == []
    return paths, headings


def acts(body, path, turns, tick):
    """Whether the robot does something at ``tick``: a move, or (a body that turns in place) a turn."""
    return path[tick] != path[tick - 1] or (body.turns_in_place and turns[tick] != turns[tick - 1])


def makespan_and_busy(body, paths, headings):
    """The plan's makespan (its last action) and whether a robot acting then never waited before."""
    last = [max((t for t in range(1, len(p)) if acts(body, p, h, t)), default=0) for p, h in zip(paths, headings)]
    makespan = max(last)
    busy = any(
        end == makespan and all(acts(body, p, h, t) for t in range(1, end + 1)) for p, h, end in zip(paths, headings, last)
    )
    return makespan, busy


@pytest.mark.parametrize("name", ["omni", "turning", "thesis"])
def test_a_plan_the_body_can_carry_out_takes_at_most_its_makespan_and_exactly_that_when_its_last_robot_never_waits(name):
    body = body_model(name)
    equal = 0
    for seed in range(300):
        paths, headings = legal_plan(body, seed, robots=1 + seed % 5, ticks=2 + seed % 7)
        makespan, busy = makespan_and_busy(body, paths, headings)
        starts = [h[0] for h in headings]
        for scale in (1.0, 4.0):
            bound = makespan * SLOW_TURNS.cell_time / scale
            seconds = execution_seconds(paths, starts, ONE if name == "thesis" else SLOW_TURNS, scale, body, headings)
            if name == "thesis":  # right turns lengthen a move beyond its cell time: only without them is it the makespan
                bound = makespan * ONE.cell_time / scale
                worst = makespan * (SLOW_TURNS.cell_time + 3 * SLOW_TURNS.turn_time) / scale
                assert execution_seconds(paths, starts, SLOW_TURNS, scale, body) <= worst
            assert seconds <= bound + 1e-9
            if busy:
                assert seconds == pytest.approx(bound)
        equal += busy
        if name == "turning":  # turns derived from the cells are the fewest, so the bound holds without headings too
            assert execution_seconds(paths, starts, SLOW_TURNS, 1.0, body) <= makespan * SLOW_TURNS.cell_time + 1e-9
    assert equal >= 30  # the equality was tested


def test_no_body_is_the_thesis_body():
    for seed in range(40):
        paths, headings = legal_plan(THESIS, seed)
        starts = [h[0] for h in headings]
        assert execution_seconds(paths, starts, SLOW_TURNS) == execution_seconds(paths, starts, SLOW_TURNS, body=THESIS)
        assert execution_seconds(paths, starts, SLOW_TURNS, body=THESIS, heading_paths=headings) == execution_seconds(
            paths, starts, SLOW_TURNS
        )


def test_a_train_that_never_waits_takes_its_makespan():
    """Three robots in a column drive north four cells: omni and turning bodies all start at once."""
    paths = [[(x + t, 0) for t in range(5)] for x in (2, 1, 0)]
    for body in (OMNI, TURNING):
        assert check_paths(Grid(7, 1), dict(zip("ABC", paths)), body=body) == []
        assert execution_seconds(paths, [N] * 3, SLOW_TURNS, body=body) == 4 * 2.0
    assert execution_seconds(paths, [N] * 3, ONE, body=THESIS) == 6.0  # one after the other: the thesis body cannot follow


def test_a_thesis_train_with_one_cell_gaps_takes_its_makespan():
    paths = [[(x + t, 0) for t in range(4)] for x in (2, 0)]
    assert check_paths(Grid(6, 1), dict(zip("AB", paths)), body=THESIS) == []
    assert execution_seconds(paths, [N] * 2, ONE, body=THESIS) == 3.0


def test_a_turning_body_turns_one_tick_per_quarter_read_from_its_headings_or_derived():
    paths = [[(0, 0), (0, 0), (0, 1), (0, 2)]]  # turn east in place, then two cells east
    turns = [[N, E, E, E]]
    assert check_paths(Grid(1, 3), {"A": paths[0]}, {"A": turns[0]}, TURNING) == []
    assert execution_seconds(paths, [N], SLOW_TURNS, body=TURNING, heading_paths=turns) == 3 * 2.0
    assert execution_seconds(paths, [N], SLOW_TURNS, body=TURNING) == 3 * 2.0  # derived: one quarter, N to E
    assert execution_seconds([[(0, 0), (0, 1)]], [S], SLOW_TURNS, body=TURNING) == 2 * 2.0  # S to E: one quarter left
    assert execution_seconds([[(0, 0), (0, 1)]], [W], SLOW_TURNS, body=TURNING) == 3 * 2.0  # a half turn: two quarters
    wasteful = [[N, E, N, E, E, E]]  # turns east, back, east again: read from the headings, three turns
    assert execution_seconds([[(0, 0)] * 4 + [(0, 1)]], [N], ONE, body=TURNING, heading_paths=wasteful) == 4.0
    after_arrival = [[N, N, E, S]]  # drives a cell north, then turns twice on its goal
    assert execution_seconds([[(0, 0), (1, 0)]], [N], ONE, body=TURNING, heading_paths=after_arrival) == 3.0


def test_following_counts_from_the_leader_s_start_not_its_readiness():
    """The leader turns first (one tick), then drives north; the follower enters its cell as it starts out."""
    paths = [[(1, 0), (1, 0), (2, 0)], [(0, 0), (0, 0), (1, 0)]]
    headings = [[E, N, N], [N, N, N]]
    ids = {"L": paths[0], "F": paths[1]}
    assert check_paths(Grid(3, 1), ids, dict(zip(ids, headings)), TURNING) == []
    assert execution_seconds(paths, [E, N], ONE, body=TURNING, heading_paths=headings) == 2.0
    assert execution_seconds(paths, [E, N], ONE, body=OMNI) == 1.0  # no turn: both start at once


def test_waits_cost_nothing():
    """B waits three ticks in the plan for A to leave (0, 1); its body starts as A starts out."""
    paths = [[(0, 1), (1, 1), (1, 1), (1, 1)], [(0, 0), (0, 0), (0, 0), (0, 1)]]
    assert execution_seconds(paths, [N, E], ONE, body=OMNI) == 1.0
    assert execution_seconds(paths, [N, E], ONE, body=TURNING) == 1.0
    assert execution_seconds(paths, [N, E], ONE, body=THESIS) == 2.0


def test_an_omni_rotation_starts_together_and_a_turning_one_deadlocks():
    block = [(0, 0), (0, 1), (1, 1), (1, 0)]
    paths = [[block[i], block[(i + 1) % 4], block[(i + 2) % 4]] for i in range(4)]  # twice round
    assert check_paths(Grid(2, 2), dict(zip("ABCD", paths)), body=OMNI) == []
    assert execution_seconds(paths, [N] * 4, ONE, body=OMNI) == 2.0
    approach = [[(2, 0), (2, 0), (1, 0)], [(0, 0), (0, 1), (1, 1)], [(0, 1), (1, 1), (1, 0)]]
    assert execution_seconds(approach, [N] * 3, ONE, body=OMNI) == 2.0  # a robot entering a cell left in a rotation
    with pytest.raises(PlanDeadlockError, match="rotation"):
        execution_seconds(paths, [N] * 4, ONE, body=TURNING)
    with pytest.raises(PlanDeadlockError, match="swap"):
        execution_seconds([[(0, 0), (0, 1)], [(0, 1), (0, 0)]], [E, W], ONE, body=OMNI)


def test_a_heading_path_must_start_with_the_start_heading():
    with pytest.raises(ValueError, match="start heading"):
        execution_seconds([[(0, 0), (1, 0)]], [N], ONE, body=TURNING, heading_paths=[[E, N]])


def test_the_omni_plan_of_a_scenario_with_turns_costs_more_than_its_makespan_for_turning_bodies():
    grid = Grid.from_rows(["......", ".@@.@.", "......", ".@..@.", "......"])
    robots = (
        RobotSpec("A", (0, 0), (4, 5)),
        RobotSpec("B", (4, 0), (0, 5), Heading.EAST),
        RobotSpec("C", (2, 5), (2, 0), Heading.WEST),
        RobotSpec("D", (0, 3), (4, 2)),
    )
    scenario = Scenario(grid, robots)
    plan = plan_with("lacam", scenario, time_limit_s=10)
    assert plan.paths is not None
    assert check_paths(grid, {r.id: p for r, p in zip(robots, plan.paths)}) == []  # an omni plan
    makespan = max(len(path) for path in plan.paths) - 1
    starts = [robot.heading for robot in robots]
    assert execution_seconds(plan.paths, starts, ONE, body=OMNI) <= makespan
    assert execution_seconds(plan.paths, starts, ONE, body=TURNING) > makespan
