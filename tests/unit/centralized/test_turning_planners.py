"""PIBT and LaCAM planned for ``turning`` bodies (LoRR's MAPF_T): legal, collision-free, and as long as they say.

Every plan is judged by the one referee in the turning model (forward only to
the cell ahead, quarter turns in place, following only behind a robot that
drives on, no rotation), and its execution bound on turning bodies is compared
with its makespan. The two rules that keep the generator's steps safe (a
forward move into the cell of a robot that stays is cancelled; no cycle of
robots follows round a loop) are each broken on purpose, and the referee must
catch the result.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mrmp.centralized.body_time import execution_seconds
from mrmp.centralized.cbs import cbs
from mrmp.centralized.lacam import lacam
from mrmp.centralized.pibt_plan import pibt_plan
from mrmp.centralized.pibt_step import NO_CELL, PIBT
from mrmp.centralized.plan import PlanningResult, as_problem
from mrmp.centralized.prioritized import prioritized
from mrmp.core.body import body_model
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Timing
from mrmp.io.movingai import read_map, read_scen
from mrmp.search.flat_grid import flat_grid
from mrmp.search.heading_distance import heading_distances
from mrmp.sim.referee import check_paths

TURNING = body_model("turning")
TICK = Timing(cell_time=1.0, turn_time=1.0)
MAPS = Path(__file__).resolve().parents[3] / "maps"
N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST


def judged(grid: Grid, plan: PlanningResult) -> list[tuple[str, int]]:
    """The referee's findings on ``plan`` in the turning model, as (kind, tick)."""
    assert plan.paths is not None and plan.headings is not None
    ids = [str(robot) for robot in range(len(plan.paths))]
    found = check_paths(grid, dict(zip(ids, plan.paths)), dict(zip(ids, plan.headings)), TURNING)
    return [(collision.kind, collision.tick) for collision in found]


def turning_ticks(plan: PlanningResult, starts: list[Heading]) -> float:
    assert plan.paths is not None
    return execution_seconds(plan.paths, starts, TICK, body=TURNING, heading_paths=plan.headings)


@pytest.fixture(scope="module")
def random_fifty() -> tuple[Grid, list[tuple[int, int]], list[tuple[int, int]]]:
    grid = read_map(MAPS / "random-32-32-20.map")
    robots = read_scen(MAPS / "random-32-32-20-random-1.scen", 50, grid)
    return grid, [robot.start for robot in robots], [robot.goal for robot in robots]


@pytest.mark.parametrize(("planner", "count"), [(lacam, 50), (pibt_plan, 50), (prioritized, 40)])  # pp fails at 50
def test_turning_plans_on_a_standard_map_are_legal_and_executable_as_planned(planner, count, random_fifty) -> None:
    grid, starts, goals = random_fifty
    starts, goals = starts[:count], goals[:count]
    plan = planner(grid, starts, goals, body="turning")
    assert plan.solved and plan.headings is not None
    assert judged(grid, plan) == []
    # driven by turning bodies, the plan takes no longer than its makespan (waits it holds may be skipped)
    assert turning_ticks(plan, [N] * len(starts)) <= plan.makespan()
    # and no plan can beat the (cell, heading) lower bound of any robot
    for robot, (start, goal) in enumerate(zip(starts, goals)):
        table = heading_distances(grid, goal, 1.0, both_ways=True)
        assert plan.costs()[robot] >= table[4 * (start[0] * grid.y_size + start[1]) + int(N) - 1]


def test_cbs_for_turning_bodies_is_optimal_among_them(random_fifty) -> None:
    grid, starts, goals = random_fifty
    starts, goals = starts[:10], goals[:10]
    best = cbs(grid, starts, goals, body="turning", time_limit_s=60)
    assert best.solved and judged(grid, best) == []
    for other in (prioritized, lacam, pibt_plan):
        plan = other(grid, starts, goals, body="turning")
        assert plan.solved and best.sum_of_costs() <= plan.sum_of_costs()
    # facing NORTH at the start, the optimum pays for turns an omni plan ignores
    assert best.sum_of_costs() > cbs(grid, starts, goals, time_limit_s=60).sum_of_costs()


def test_an_omni_plan_is_stretched_on_turning_bodies_a_turning_plan_is_not(random_fifty) -> None:
    grid, starts, goals = random_fifty
    omni = lacam(grid, starts, goals)
    turning = lacam(grid, starts, goals, body="turning")
    assert omni.solved and turning.solved
    assert turning_ticks(omni, [N] * len(starts)) > omni.makespan()  # the turns it ignored
    assert turning_ticks(turning, [N] * len(starts)) <= turning.makespan()


def test_a_robot_turns_before_it_drives_and_its_follower_waits_for_it() -> None:
    # robot 0 faces EAST along the bottom row toward robot 1, whose goal is NORTH of it (x + 1)
    grid = Grid(2, 3)
    problem = as_problem(grid, [(0, 0), (0, 1)], [(0, 2), (1, 1)], headings=[E, E])
    plan = lacam(problem, body="turning")
    assert plan.solved and plan.paths is not None and plan.headings is not None
    assert judged(grid, plan) == []
    # robot 1 must turn NORTH before it leaves (0, 1): a tick in which robot 0 may not enter (0, 1)
    assert plan.headings[1][1] == N and plan.paths[1][1] == (0, 1)
    assert plan.paths[0][1] == (0, 0)


def _one_step(grid: Grid, cells: list[tuple[int, int]], goals: list[tuple[int, int]], headings: list[Heading]) -> PIBT:
    flat = flat_grid(grid)
    tables = [heading_distances(grid, goal, 1.0, both_ways=True) for goal in goals]
    return PIBT(flat.neighbours, tables, [flat.index(goal) for goal in goals], rotations=False, turning_y_size=flat.y_size)


def _step_plan(grid: Grid, pibt: PIBT, cells: list[tuple[int, int]], headings: list[Heading]) -> PlanningResult:
    """One generator step as a two-tick plan."""
    flat = flat_grid(grid)
    current = [flat.index(cell) for cell in cells]
    target, next_headings = [NO_CELL] * len(cells), [0] * len(cells)
    assert pibt.generate(current, target, list(range(len(cells))), [int(h) for h in headings], next_headings)
    paths = tuple((cell, flat.cell(index)) for cell, index in zip(cells, target))
    turns = tuple((heading, Heading(after)) for heading, after in zip(headings, next_headings))
    return PlanningResult("solved", paths, 0.0, "pibt", headings=turns)


def test_a_forward_move_into_a_robot_that_only_turns_is_cancelled_and_the_referee_catches_it_when_not(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    grid = Grid(2, 3)
    cells, goals, headings = [(0, 0), (0, 1)], [(0, 2), (1, 1)], [E, E]
    pibt = _one_step(grid, cells, goals, headings)
    plan = _step_plan(grid, pibt, cells, headings)
    assert plan.paths == (((0, 0), (0, 0)), ((0, 1), (0, 1)))  # robot 1 turns NORTH, robot 0 waits behind it
    assert judged(grid, plan) == []
    monkeypatch.setattr(PIBT, "_cancel_blocked", lambda self, current, target, constrained: True)
    broken = _step_plan(grid, pibt, cells, headings)
    assert broken.paths is not None and broken.paths[0][1] == (0, 1)
    assert ("vertex", 1) in judged(grid, broken)


def test_no_rotation_round_a_loop_and_the_referee_catches_one_when_allowed(monkeypatch: pytest.MonkeyPatch) -> None:
    # four robots on a 2x2 loop, each facing the next one's cell, which is its goal
    grid = Grid(2, 2)
    cells = [(0, 0), (0, 1), (1, 1), (1, 0)]
    goals = cells[1:] + cells[:1]
    headings = [E, N, W, S]
    pibt = _one_step(grid, cells, goals, headings)
    plan = _step_plan(grid, pibt, cells, headings)
    assert judged(grid, plan) == []
    assert plan.paths is not None and any(path[0] == path[1] for path in plan.paths)
    pibt.rotations = True  # PIBT may close the cycle: the pushed robots' rule and the cancellation still refuse it
    assert judged(grid, _step_plan(grid, pibt, cells, headings)) == []
    monkeypatch.setattr(PIBT, "_closes_cycle", lambda self, occupant, cell, target: False)
    assert judged(grid, _step_plan(grid, pibt, cells, headings)) == []  # the cancellation refuses a chain that loops
    monkeypatch.setattr(PIBT, "_cancel_blocked", lambda self, current, target, constrained: True)
    broken = _step_plan(grid, pibt, cells, headings)  # every rule broken
    assert broken.paths is not None and all(path[1] == goal for path, goal in zip(broken.paths, goals))
    assert ("rotation", 1) in judged(grid, broken)


def test_the_planners_know_their_bodies_and_turning_needs_rotations_off() -> None:
    with pytest.raises(ValueError, match="not 'thesis'"):
        lacam(Grid(1, 2), [(0, 0)], [(0, 1)], body="thesis")
    for planner in (pibt_plan, prioritized, cbs):
        with pytest.raises(ValueError, match="not 'thesis'"):
            planner(Grid(1, 2), [(0, 0)], [(0, 1)], body="thesis")
    with pytest.raises(ValueError, match="swap and rotations off"):
        PIBT([(1,), (0,)], [[0.0] * 8], [1], rotations=True, turning_y_size=2)
    with pytest.raises(ValueError, match="no swap technique"):
        pibt_plan(Grid(1, 2), [(0, 0)], [(0, 1)], body="turning", swap=True)
