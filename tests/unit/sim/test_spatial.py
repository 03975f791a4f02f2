"""The simulated radio's spatial index: every query equals a scan of the fleet, at every bucket edge."""

import random

import pytest

from mrmp.sim.spatial import SpatialIndex


def scan(cells, cell, radius):
    """What the index must answer: every robot within ``radius`` (Manhattan) of ``cell``, by index."""
    return [index for index, (x, y) in enumerate(cells) if abs(x - cell[0]) + abs(y - cell[1]) <= radius]


def check_index(make, seed):
    """Compare ``make(cells, size)`` with the scan over random fleets, moves and queries; return the first mismatch."""
    rng = random.Random(seed)
    for size in (1, 2, 3, 4, 7):
        cells = [(rng.randrange(20), rng.randrange(20)) for _ in range(60)]
        index = make(cells, size)
        for _ in range(200):
            robot = rng.randrange(len(cells))
            source = cells[robot]
            target = (max(0, min(19, source[0] + rng.choice((-1, 0, 1)))), max(0, min(19, source[1] + rng.choice((-1, 0, 1)))))
            index.move(robot, source, target)
            cells[robot] = target
            cell, radius = (rng.randrange(20), rng.randrange(20)), rng.randrange(0, 9)
            if index.within(cell, radius) != scan(cells, cell, radius):
                return size, cell, radius
    return None


@pytest.mark.parametrize("seed", range(5))
def test_every_query_equals_a_scan_of_the_fleet(seed):
    assert check_index(SpatialIndex, seed) is None


class EdgeBlind(SpatialIndex):
    """A broken index: it visits the buckets from the cell's bucket outwards but stops one short on the far side."""

    def within(self, cell, radius):
        x, y = cell
        size, found = self.size, []
        for bx in range((x - radius) // size, (x + radius) // size):
            for by in range((y - radius) // size, (y + radius) // size):
                for index in self._buckets.get((bx, by), ()):
                    cx, cy = self._cells[index]
                    if abs(cx - x) + abs(cy - y) <= radius:
                        found.append(index)
        return sorted(found)


def test_an_index_that_misses_a_bucket_edge_is_caught():
    assert check_index(EdgeBlind, 0) is not None


def test_robots_at_the_exact_radius_on_a_bucket_corner_are_found():
    index = SpatialIndex([(3, 3), (4, 4), (3, 5), (0, 0), (8, 3)], size=4)
    assert index.within((3, 3), 2) == [0, 1, 2]   # (4, 4) and (3, 5) lie in other buckets
    assert index.within((4, 3), 4) == [0, 1, 2, 4]
    assert index.within((0, 0), 0) == [3]


def test_a_bucket_is_at_least_one_cell():
    with pytest.raises(ValueError, match="bucket size 0"):
        SpatialIndex([(0, 0)], size=0)
