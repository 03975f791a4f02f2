"""Map generators: connected free space, seeded determinism, density, family shapes, random instances."""

import pytest

from mrmp.core.grid import Grid, connected_regions
from mrmp.core.map_generators import (
    complete_spec,
    generate,
    generated_name,
    largest_region,
    maze_map,
    random_instance,
    random_map,
    room_map,
    warehouse_map,
)

SPECS = [
    {"kind": "random", "width": 32, "height": 24, "density": 0.3, "seed": 5},
    {"kind": "maze", "width": 33, "height": 21, "corridor": 2, "seed": 5},
    {"kind": "warehouse", "width": 40, "height": 20, "shelf_length": 6, "shelf_depth": 2, "aisle": 2, "margin": 1},
    {"kind": "room", "width": 30, "height": 30, "room_size": 4, "doors": 2, "seed": 5},
]


def one_region(grid: Grid) -> bool:
    free = grid.free_cells()
    _, regions = connected_regions(grid, free)
    return len(regions) == 1 and len(regions[0]) == len(free)


@pytest.mark.parametrize("spec", SPECS, ids=lambda spec: spec["kind"])
def test_free_cells_form_one_connected_region_with_the_given_size(spec):
    grid = generate(spec)
    assert (grid.y_size, grid.x_size) == (spec["width"], spec["height"])
    assert one_region(grid)
    assert 0 < len(grid.free_cells()) < grid.x_size * grid.y_size
    assert grid.name == generated_name(complete_spec(spec))


@pytest.mark.parametrize("spec", [spec for spec in SPECS if "seed" in spec], ids=lambda spec: spec["kind"])
def test_same_seed_same_map_other_seed_other_map(spec):
    assert generate(spec) == generate(dict(spec))
    assert generate(spec) != generate({**spec, "seed": spec["seed"] + 1})


@pytest.mark.parametrize("seed", range(4))
def test_random_many_seeds_stay_connected(seed):
    assert one_region(random_map(24, 24, 0.35, seed))


def test_random_density_is_respected():
    for density in (0.0, 0.1, 0.25):
        grid = random_map(64, 64, density, seed=1)
        blocked = len(grid.blocked_cells()) / (64 * 64)
        # obstacles drawn with probability density, plus the cut-off pockets
        assert density - 0.03 <= blocked <= density + 0.05, (density, blocked)
    assert random_map(64, 64, 0.0, seed=1).blocked_cells() == []
    assert random_map(16, 16, 0.2, seed=3).name == "gen:random-16x16-p0.20-s3"


def test_maze_corridors_are_as_wide_as_asked_and_the_maze_is_perfect():
    for corridor in (1, 2, 3):
        grid = maze_map(33, 33, corridor, seed=2)
        free = set(grid.free_cells())
        # every free cell lies in a corridor x corridor block of free cells (no thinner passage)
        for x, y in free:
            assert any(
                all((x - dx + i, y - dy + j) in free for i in range(corridor) for j in range(corridor))
                for dx in range(corridor)
                for dy in range(corridor)
            ), (corridor, (x, y))
    # corridor 1: rooms form a spanning tree, so free cells = rooms + (rooms - 1) walls knocked down
    grid = maze_map(21, 21, 1, seed=7)
    rooms = 10 * 10
    assert len(grid.free_cells()) == rooms + rooms - 1


def test_warehouse_places_whole_shelf_blocks_inside_the_margin():
    grid = warehouse_map(40, 20, shelf_length=6, shelf_depth=2, aisle=2, margin=1)
    blocked = grid.blocked_cells()
    # blocks per row: (38 + 2) // 8 = 5, rows of blocks: (18 + 2) // 4 = 5
    assert len(blocked) == 5 * 5 * 6 * 2
    assert all(1 <= x <= 18 and 1 <= y <= 38 for x, y in blocked)
    assert warehouse_map(40, 20, 6, 2, 2, 1) == warehouse_map(40, 20, 6, 2, 2, 1)
    with pytest.raises(ValueError, match="no 2x50 shelf fits"):
        warehouse_map(40, 20, 50, 2, 1, 1)


def test_rooms_get_their_doors():
    one = room_map(29, 29, room_size=4, doors=1, seed=0)
    two = room_map(29, 29, room_size=4, doors=2, seed=0)
    # 5 wall lines each way; 6 rooms along each wall line: 2 * 5 * 6 wall segments
    segments = 2 * 5 * 6
    assert len(two.free_cells()) - len(one.free_cells()) == segments
    assert one_region(one)


def test_bad_generator_settings_are_refused():
    with pytest.raises(ValueError, match="density"):
        random_map(8, 8, 1.0, 0)
    with pytest.raises(ValueError, match="unknown map generator"):
        generate({"kind": "cave", "width": 8, "height": 8})
    with pytest.raises(ValueError, match="take no setting 'seed'"):
        generate({"kind": "warehouse", "width": 30, "height": 10, "seed": 1})
    with pytest.raises(ValueError, match="at least 4"):
        maze_map(3, 9, 2, 0)


def test_random_instance_distinct_cells_in_one_region_and_seeded():
    grid = Grid.from_rows(["....@..", "....@..", "....@.."], name="split")
    scenario = random_instance(grid, agents=6, seed=3)
    region = set(largest_region(grid))
    assert {robot.start for robot in scenario.robots} <= region and {robot.goal for robot in scenario.robots} <= region
    assert len({robot.start for robot in scenario.robots}) == 6 == len({robot.goal for robot in scenario.robots})
    assert scenario == random_instance(grid, agents=6, seed=3)
    assert scenario != random_instance(grid, agents=6, seed=4)
    assert scenario.name == "split-seed-3" and scenario.seed == 3
    with pytest.raises(ValueError, match="do not fit"):
        random_instance(grid, agents=13, seed=0)
