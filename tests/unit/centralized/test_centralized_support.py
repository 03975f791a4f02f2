"""Independent oracles for the centralized planners, and tests of the oracles themselves.

* :func:`brute_force_sum_of_costs`: Dijkstra over joint states of all robots
  (every robot's cell, and which robots have "finished": settled on their goal
  for good). Each tick every unfinished robot waits or moves (or, heading-aware,
  waits, turns right or moves ahead); finishing is a free transition for a robot
  on its goal, after which it never moves. A tick costs the number of
  unfinished robots, so a plan costs the sum over robots of the first tick from
  which each stays on its goal: the standard MAPF sum of costs. Joint moves
  with a vertex or swap collision are skipped, and so are rotations (robots
  moving round a cycle of cells at one tick) unless ``rotations=True``. Shares
  no code with mrmp's planners.
* :func:`moves_round_a_cycle`: whether one joint move contains a rotation.
* :func:`assert_valid_plan`: the referee finds nothing, paths start at the
  starts, end at the goals, are 4-connected, of equal length and without
  rotations.
"""

from __future__ import annotations

import heapq
from collections.abc import Sequence
from itertools import pairwise, product

from mrmp.centralized import PlanningResult
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.sim.referee import check_paths

Cell = tuple[int, int]
_DELTAS = {1: (1, 0), 2: (0, 1), 3: (-1, 0), 4: (0, -1)}


def _free(grid: Grid, cell: Cell) -> bool:
    x, y = cell
    return 0 <= x < grid.x_size and 0 <= y < grid.y_size and not grid.is_blocked(cell)


def _options(grid: Grid, cell: Cell, facing: int, heading_aware: bool) -> list[tuple[Cell, int]]:
    if heading_aware:
        result = [(cell, facing), (cell, facing % 4 + 1)]
        dx, dy = _DELTAS[facing]
        ahead = (cell[0] + dx, cell[1] + dy)
        if _free(grid, ahead):
            result.append((ahead, facing))
        return result
    result = [(cell, 0)]
    for dx, dy in ((1, 0), (0, 1), (-1, 0), (0, -1)):
        target = (cell[0] + dx, cell[1] + dy)
        if _free(grid, target):
            result.append((target, 0))
    return result


def moves_round_a_cycle(before: Sequence[Cell], after: Sequence[Cell]) -> bool:
    """Whether some robots each move into the cell another one leaves, round a cycle back to the first."""
    occupant = {cell: robot for robot, cell in enumerate(before)}
    for first in range(len(before)):
        robot = first
        for _ in range(len(before)):
            if before[robot] == after[robot]:
                break
            robot = occupant.get(after[robot], -1)
            if robot < 0:
                break
            if robot == first:
                return True
    return False


def brute_force_sum_of_costs(
    grid: Grid,
    starts: Sequence[Cell],
    goals: Sequence[Cell],
    *,
    heading_aware: bool = False,
    headings: Sequence[int] | None = None,
    rotations: bool = False,
) -> int | None:
    """The optimal sum of costs by joint-state Dijkstra, or None if no plan exists."""
    count = len(starts)
    facing0 = tuple(headings) if heading_aware and headings is not None else ((1,) * count if heading_aware else (0,) * count)
    start_state = (tuple(starts), facing0, 0)
    full = (1 << count) - 1
    best = {start_state: 0}
    heap: list[tuple[int, int, tuple]] = [(0, 0, start_state)]
    serial = 0
    while heap:
        cost, _, state = heapq.heappop(heap)
        if best.get(state, cost + 1) < cost:
            continue
        cells, facings, finished = state
        if finished == full:
            return cost
        successors: list[tuple[int, tuple]] = []
        for i in range(count):
            if not finished >> i & 1 and cells[i] == goals[i]:
                successors.append((cost, (cells, facings, finished | 1 << i)))
        step = count - finished.bit_count()
        choices = [
            [(cells[i], facings[i])] if finished >> i & 1 else _options(grid, cells[i], facings[i], heading_aware)
            for i in range(count)
        ]
        for combo in product(*choices):
            targets = tuple(cell for cell, _ in combo)
            if len(set(targets)) < count:
                continue
            swap = any(
                targets[i] == cells[j] and targets[j] == cells[i] and cells[i] != cells[j]
                for i in range(count)
                for j in range(i + 1, count)
            )
            if swap or (not rotations and moves_round_a_cycle(cells, targets)):
                continue
            successors.append((cost + step, (targets, tuple(f for _, f in combo), finished)))
        for new_cost, new_state in successors:
            if new_cost < best.get(new_state, new_cost + 1):
                best[new_state] = new_cost
                serial += 1
                heapq.heappush(heap, (new_cost, serial, new_state))
    return None


def assert_valid_plan(grid: Grid, result: PlanningResult, starts: Sequence[Cell], goals: Sequence[Cell]) -> None:
    """The plan is solved, judged collision-free by the referee, and joins starts to goals."""
    assert result.solved, result.message
    assert result.paths is not None
    assert len(result.paths) == len(starts)
    assert len({len(path) for path in result.paths}) == 1, "paths are padded to one length"
    ids = [f"r{i}" for i in range(len(starts))]
    collisions = check_paths(grid, dict(zip(ids, result.paths)))
    assert collisions == [], [c.describe() for c in collisions]
    for path, start, goal in zip(result.paths, starts, goals):
        assert path[0] == start
        assert path[-1] == goal
        for before, after in pairwise(path):
            assert abs(before[0] - after[0]) + abs(before[1] - after[1]) <= 1
            assert grid.is_free(after)
    for tick in range(1, len(result.paths[0]) if result.paths else 0):
        before = [path[tick - 1] for path in result.paths]
        after = [path[tick] for path in result.paths]
        assert not moves_round_a_cycle(before, after), f"a rotation at tick {tick}"


def replay_headings(grid: Grid, result: PlanningResult, initial: Sequence[Heading]) -> None:
    """Every tick is a wait, one right turn in place, or one move straight ahead."""
    assert result.paths is not None and result.headings is not None
    for path, headings, first in zip(result.paths, result.headings, initial):
        assert len(path) == len(headings)
        assert headings[0] == first
        for tick in range(1, len(path)):
            before, after = path[tick - 1], path[tick]
            h_before, h_after = headings[tick - 1], headings[tick]
            if before == after:
                assert h_after in (h_before, Heading(int(h_before) % 4 + 1)), (tick, h_before, h_after)
            else:
                assert h_after == h_before, f"tick {tick}: changed direction while moving"
                assert h_before.ahead(before) == after, f"tick {tick}: moved sideways"


# -- the oracles tested on cases worked out by hand -----------------------------------


def test_brute_force_single_robot_is_its_distance() -> None:
    grid = Grid.from_rows(["...", ".@.", "..."])
    assert brute_force_sum_of_costs(grid, [(0, 0)], [(2, 2)]) == 4


def test_brute_force_without_rotations_in_a_2x3_grid() -> None:
    # four robots on a 2x2 block each want the next cell: one tick with a rotation; without, one
    # of them steps into the free column so that the three others follow one another (cost 3),
    # and it comes back round in two more ticks (cost 3): 6
    block = [(0, 0), (0, 1), (1, 1), (1, 0)]
    goals = block[1:] + block[:1]
    assert brute_force_sum_of_costs(Grid(2, 3), block, goals, rotations=True) == 4
    assert brute_force_sum_of_costs(Grid(2, 2), block, goals, rotations=True) == 4
    assert brute_force_sum_of_costs(Grid(2, 2), block, goals) is None
    assert brute_force_sum_of_costs(Grid(2, 3), block, goals) == 6


def test_moves_round_a_cycle() -> None:
    block = [(0, 0), (0, 1), (1, 1), (1, 0)]
    assert moves_round_a_cycle(block, block[1:] + block[:1])
    assert not moves_round_a_cycle(block[:3], block[1:])  # following into a free cell
    assert not moves_round_a_cycle(block, block)


def test_brute_force_swap_in_open_2x2_needs_a_detour() -> None:
    # swapping neighbours: one robot steps aside (cost 1 + 2 or rotation 1 + 2)
    grid = Grid(2, 2)
    assert brute_force_sum_of_costs(grid, [(0, 0), (0, 1)], [(0, 1), (0, 0)]) == 4


def test_brute_force_proves_corridor_swap_impossible() -> None:
    assert brute_force_sum_of_costs(Grid(1, 3), [(0, 0), (0, 2)], [(0, 2), (0, 0)]) is None


def test_brute_force_counts_leaving_the_goal() -> None:
    # B sits on A's way at its own goal: B must step aside and come back (B costs 2, A 2)
    grid = Grid.from_rows(["#.#", "..."])
    assert brute_force_sum_of_costs(grid, [(0, 0), (0, 1)], [(0, 2), (0, 1)]) == 4


def test_brute_force_heading_aware_counts_turns() -> None:
    # facing NORTH, going EAST two cells: one right turn then two moves
    assert brute_force_sum_of_costs(Grid(1, 3), [(0, 0)], [(0, 2)], heading_aware=True) == 3
    # facing NORTH, going WEST one cell: three right turns then one move
    assert brute_force_sum_of_costs(Grid(1, 2), [(0, 1)], [(0, 0)], heading_aware=True) == 4
