"""Hand-made runs for the visualization tests: no simulator involved."""

from __future__ import annotations

import random

import pytest

from mrmp.core import Collision, Grid, Heading, RobotResult, RunResult

N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST


def make_run(robots: list[RobotResult], collisions: list[Collision] | None = None, name: str = "test") -> RunResult:
    ticks = max(len(robot.path) for robot in robots) - 1
    return RunResult(name, "thesis", 0, robots, collisions or [], "done", ticks, 0, 0.0)


@pytest.fixture
def swap() -> tuple[Grid, RunResult]:
    """Two robots trading places on a 5x5 grid: A goes north around B, B comes south."""
    a = RobotResult(
        "A",
        (0, 2),
        (4, 2),
        path=[(0, 2), (1, 2), (1, 3), (2, 3), (3, 3), (4, 3), (4, 2)],
        headings=[N, N, E, N, N, N, W],
    )
    b = RobotResult(
        "B", (4, 2), (0, 2), path=[(4, 2), (3, 2), (2, 2), (1, 2), (0, 2), (0, 2), (0, 2)], headings=[N] + [S] * 6
    )
    return Grid(5, 5, name="swap"), make_run([a, b], name="swap")


@pytest.fixture
def walled() -> tuple[Grid, RunResult]:
    """A 4x6 grid with obstacles, a costly cell and a vertex collision at tick 2."""
    grid = Grid.from_rows(["..@...", "..@.5.", "......", "......"], name="walled")
    a = RobotResult("A", (0, 0), (0, 3), path=[(0, 0), (0, 1), (0, 2), (0, 3)], headings=[E, E, E, E])
    b = RobotResult("B", (1, 3), (0, 2), path=[(1, 3), (1, 2), (0, 2), (0, 2)], headings=[W, W, S, S])
    collision = Collision("vertex", 2, ("A", "B"), ((0, 2),))
    return grid, make_run([a, b], [collision], name="walled")


def random_crowd(robots: int, size: int, ticks: int, seed: int = 0) -> tuple[Grid, RunResult]:
    """``robots`` robots wandering on a ``size`` x ``size`` grid, never sharing a cell."""
    rng = random.Random(seed)
    grid = Grid(size, size, name=f"random-{size}")
    cells = grid.free_cells()
    rng.shuffle(cells)
    where = cells[:robots]
    taken = set(where)
    headings = [N] * robots
    paths = [[cell] for cell in where]
    turns = [[N] for _ in where]
    for _ in range(ticks):
        for index in range(robots):
            options = [cell for cell in grid.neighbours(where[index]) if cell not in taken]
            if options and rng.random() < 0.7:
                step = rng.choice(options)
                taken.discard(where[index])
                taken.add(step)
                headings[index] = Heading.between(where[index], step)
                where[index] = step
            paths[index].append(where[index])
            turns[index].append(headings[index])
    results = [
        RobotResult(f"r{index}", paths[index][0], paths[index][-1], path=paths[index], headings=turns[index])
        for index in range(robots)
    ]
    return grid, make_run(results, name=f"random-{size}")


@pytest.fixture
def crowd():
    """The :func:`random_crowd` maker, for tests that need a big fleet."""
    return random_crowd
