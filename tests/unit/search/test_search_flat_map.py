"""A FlatMap's distance lists: kept within their byte budget, least recently used dropped, exact when compacted."""

import random

from mrmp.core.grid import Grid
from mrmp.search.distance import distance_table
from mrmp.search.flat_map import FlatMap
from mrmp.search.heading_distance import heading_distances


def test_the_lists_kept_never_exceed_the_budget_and_a_dropped_list_comes_back_equal():
    grid = Grid.from_rows(["." * 12] * 10)
    table_bytes = 4 * grid.x_size * grid.y_size  # whole numbers: kept in single precision
    flat = FlatMap(grid, budget_bytes=3 * table_bytes)
    goals = list(range(0, flat.size, 7))
    first = {goal: list(flat.distances(goal)) for goal in goals}
    assert flat.tables_kept == 3 and flat.tables_computed == len(goals)
    assert flat._kept_bytes <= flat.budget_bytes
    flat.distances(goals[-3])  # still kept: used again, so the last to go
    flat.distances(goals[0])  # dropped long ago: computed again
    assert flat.tables_computed == len(goals) + 1
    flat.distances(goals[-3])
    assert flat.tables_computed == len(goals) + 1
    assert all(list(flat.distances(goal)) == first[goal] for goal in goals)


def test_compacted_lists_hold_exactly_the_searched_values_and_costed_ones_stay_double():
    rng = random.Random(3)
    rows = ["".join("@" if rng.random() < 0.25 else "." for _ in range(20)) for _ in range(15)]
    plain = Grid.from_rows(rows)
    goal = rng.choice(plain.free_cells())
    flat = FlatMap(plain)
    kept = flat.heading_distances(flat.index(goal), 1.0, both_ways=True)
    assert kept.typecode == "f"
    assert list(kept) == list(heading_distances(plain, goal, 1.0, both_ways=True))
    assert list(flat.distances(flat.index(goal))) == distance_table(plain, goal).as_list()
    costed = Grid(plain.x_size, plain.y_size, plain.blocked_cells(), {cell: 1.3 for cell in plain.free_cells()})
    costed_flat = FlatMap(costed)
    assert costed_flat.distances(costed_flat.index(goal)).typecode == "d"
    assert list(costed_flat.distances(costed_flat.index(goal))) == distance_table(costed, goal).as_list()
