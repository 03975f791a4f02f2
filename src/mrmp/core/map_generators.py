"""Seeded map generators and random instances for benchmarks (pure: no I/O).

Four families, after the map types of the MovingAI MAPF benchmark (Stern et
al., "Multi-Agent Pathfinding: Definitions, Variants, and Benchmarks", SoCS
2019; maps by Sturtevant, "Benchmarks for Grid-Based Pathfinding", IEEE TCIAIG
2012):

* :func:`random_map` -- each cell an obstacle with a given probability, then
  only the largest 4-connected free region kept (the rest is blocked);
* :func:`maze_map` -- a perfect maze of corridors of a given width, carved by
  the randomized depth-first search ("recursive backtracker", J. Buck,
  *Mazes for Programmers*, 2015, chapter 5);
* :func:`warehouse_map` -- rectangular shelf blocks in rows and columns
  separated by aisles, with a free margin (the MovingAI ``warehouse`` maps);
* :func:`room_map` -- square rooms separated by one-cell walls, each wall
  between two neighbouring rooms pierced by seeded doors (the MovingAI
  ``room`` maps).

Every generator returns a :class:`~mrmp.core.grid.Grid` named like
``gen:random-32x32-p0.20-s3`` (see :func:`generated_name`), whose free cells
form one 4-connected region. A generator spec is a plain dictionary
(``{"kind": "random", "width": 32, "height": 32, "density": 0.2, "seed": 3}``);
:func:`generate` builds its grid. :func:`random_instance` draws seeded distinct
starts and goals in a grid's largest connected region.

Sizes follow MovingAI: ``width`` is the number of columns (the grid's
``y_size``), ``height`` the number of rows (``x_size``).

Examples
--------
>>> grid = generate({"kind": "random", "width": 8, "height": 6, "density": 0.2, "seed": 1})
>>> grid.name, grid.x_size, grid.y_size
('gen:random-8x6-p0.20-s1', 6, 8)
>>> scenario = random_instance(grid, agents=3, seed=0)
>>> len(scenario.robots), len({robot.start for robot in scenario.robots})
(3, 3)
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid, connected_regions
from mrmp.core.scenario import RobotSpec, Scenario
from mrmp.core.seeds import Stream, stream_random


def largest_region(grid: Grid) -> list[Cell]:
    """The largest 4-connected region of free cells (the first one found among equals).

    >>> largest_region(Grid.from_rows(["..@.", "..@."]))
    [(0, 0), (1, 0), (0, 1), (1, 1)]
    """
    _, regions = connected_regions(grid, grid.free_cells())
    return max(regions, key=len) if regions else []


def _keep_largest_region(x_size: int, y_size: int, free: set[Cell], name: str) -> Grid:
    """A grid whose only free cells are the largest connected region of ``free``."""
    everything = [(x, y) for x in range(x_size) for y in range(y_size)]
    draft = Grid(x_size, y_size, [cell for cell in everything if cell not in free])
    kept = set(largest_region(draft))
    return Grid(x_size, y_size, [cell for cell in everything if cell not in kept], name=name)


def _check_size(width: int, height: int, smallest: int = 1) -> None:
    if width < smallest or height < smallest:
        raise ValueError(f"a map needs width and height of at least {smallest}, got {width}x{height}")


def random_map(width: int, height: int, density: float, seed: int) -> Grid:
    """Obstacles drawn independently with probability ``density``; only the largest free region kept.

    Parameters
    ----------
    width, height:
        Columns and rows.
    density:
        Probability that a cell is an obstacle, in ``[0, 1)``. Cells outside
        the largest connected region are blocked too, so the share of blocked
        cells is at least about ``density``.
    seed:
        Seed of the draw.

    Raises
    ------
    ValueError
        If a size is not positive or ``density`` is outside ``[0, 1)``.

    Examples
    --------
    >>> grid = random_map(16, 16, 0.3, seed=2)
    >>> grid == random_map(16, 16, 0.3, seed=2), grid.name
    (True, 'gen:random-16x16-p0.30-s2')
    """
    _check_size(width, height)
    if not 0.0 <= density < 1.0:
        raise ValueError(f"density must be in [0, 1), got {density}")
    rng = stream_random(seed, Stream.MAP)
    free = {(x, y) for x in range(height) for y in range(width) if rng.random() >= density}
    if not free:
        free = {(0, 0)}
    name = generated_name({"kind": "random", "width": width, "height": height, "density": density, "seed": seed})
    return _keep_largest_region(height, width, free, name)


def maze_map(width: int, height: int, corridor: int, seed: int) -> Grid:
    """A perfect maze (one way between any two places) of corridors ``corridor`` cells wide.

    The grid is tiled by rooms of ``corridor x corridor`` cells with one-cell
    walls between them and around them; a randomized depth-first search from
    the first room knocks down walls to unvisited neighbours (Buck 2015).
    Columns or rows that do not fit a whole room stay blocked.

    Raises
    ------
    ValueError
        If ``corridor`` is below 1 or the map is too small for one room
        (``corridor + 2`` in each direction).

    Examples
    --------
    >>> maze_map(7, 7, corridor=1, seed=0).to_rows()[0]
    '@@@@@@@'
    >>> len(largest_region(maze_map(9, 9, 1, seed=4))) == len(maze_map(9, 9, 1, seed=4).free_cells())
    True
    """
    if corridor < 1:
        raise ValueError(f"corridor width must be at least 1, got {corridor}")
    _check_size(width, height, corridor + 2)
    pitch = corridor + 1
    rows, columns = (height - 1) // pitch, (width - 1) // pitch
    free: set[Cell] = set()

    def carve(x0: int, y0: int, x_extent: int, y_extent: int) -> None:
        free.update((x, y) for x in range(x0, x0 + x_extent) for y in range(y0, y0 + y_extent))

    rng = stream_random(seed, Stream.MAP)
    visited = {(0, 0)}
    stack = [(0, 0)]
    carve(1, 1, corridor, corridor)
    while stack:
        i, j = stack[-1]
        options = [
            (i + di, j + dj)
            for di, dj in ((1, 0), (0, 1), (-1, 0), (0, -1))
            if 0 <= i + di < rows and 0 <= j + dj < columns and (i + di, j + dj) not in visited
        ]
        if not options:
            stack.pop()
            continue
        ni, nj = rng.choice(options)
        carve(1 + ni * pitch, 1 + nj * pitch, corridor, corridor)
        # the wall between the two rooms
        carve(1 + min(i, ni) * pitch + (corridor if ni != i else 0), 1 + min(j, nj) * pitch + (corridor if nj != j else 0),
              1 if ni != i else corridor, 1 if nj != j else corridor)
        visited.add((ni, nj))
        stack.append((ni, nj))
    name = generated_name({"kind": "maze", "width": width, "height": height, "corridor": corridor, "seed": seed})
    return _keep_largest_region(height, width, free, name)


def warehouse_map(width: int, height: int, shelf_length: int, shelf_depth: int, aisle: int, margin: int) -> Grid:
    """Shelf blocks ``shelf_depth`` rows by ``shelf_length`` columns, ``aisle`` cells apart, inside a free margin.

    Deterministic (no seed): as many whole blocks as fit inside the margin,
    centred.

    Raises
    ------
    ValueError
        If a size is below 1, ``aisle`` or ``margin`` below 1, or not one shelf fits.

    Examples
    --------
    >>> warehouse_map(8, 5, shelf_length=2, shelf_depth=1, aisle=1, margin=1).to_rows()
    ['........', '.@@.@@..', '........', '.@@.@@..', '........']
    """
    if min(shelf_length, shelf_depth, aisle, margin) < 1:
        raise ValueError("shelf_length, shelf_depth, aisle and margin must each be at least 1")
    _check_size(width, height)
    if width < 2 * margin + shelf_length or height < 2 * margin + shelf_depth:
        raise ValueError(f"no {shelf_depth}x{shelf_length} shelf fits in {width}x{height} with margin {margin}")

    def starts(extent: int, size: int) -> range:
        inside = extent - 2 * margin
        count = (inside + aisle) // (size + aisle)
        first = margin + (inside - (count * size + (count - 1) * aisle)) // 2
        return range(first, first + count * (size + aisle), size + aisle)

    shelves: list[Cell] = []
    for row in starts(height, shelf_depth):
        for column in starts(width, shelf_length):
            shelves += [(height - 1 - r, c) for r in range(row, row + shelf_depth) for c in range(column, column + shelf_length)]
    blocked = set(shelves)
    free = {(x, y) for x in range(height) for y in range(width) if (x, y) not in blocked}
    spec = {"kind": "warehouse", "width": width, "height": height, "shelf_length": shelf_length,
            "shelf_depth": shelf_depth, "aisle": aisle, "margin": margin}
    return _keep_largest_region(height, width, free, generated_name(spec))


def room_map(width: int, height: int, room_size: int, doors: int, seed: int) -> Grid:
    """Rooms ``room_size`` cells square behind one-cell walls; ``doors`` seeded openings per shared wall.

    Walls run after every ``room_size`` rows and columns (the map's edge
    closes the last rooms); where two walls cross the cell stays blocked.
    Every wall between two neighbouring rooms gets ``min(doors, its length)``
    distinct openings, so all rooms are connected.

    Raises
    ------
    ValueError
        If ``room_size`` or ``doors`` is below 1, or the map is smaller than one room.

    Examples
    --------
    >>> grid = room_map(7, 7, room_size=3, doors=1, seed=0)
    >>> grid.name, len(grid.blocked_cells())
    ('gen:room-7x7-r3-d1-s0', 9)
    """
    if room_size < 1 or doors < 1:
        raise ValueError(f"room_size and doors must be at least 1, got {room_size} and {doors}")
    _check_size(width, height, room_size)
    pitch = room_size + 1
    rng = stream_random(seed, Stream.MAP)

    def walls(extent: int) -> list[int]:
        return [index for index in range(room_size, extent - 1, pitch)]

    wall_rows, wall_columns = set(walls(height)), set(walls(width))
    blocked = {(height - 1 - r, c) for r in range(height) for c in range(width) if r in wall_rows or c in wall_columns}

    def spans(extent: int, cut: set[int]) -> list[range]:
        starts = [0] + [index + 1 for index in sorted(cut)]
        return [range(start, min(start + room_size, extent)) for start in starts if start < extent]

    for row in sorted(wall_rows):
        for span in spans(width, wall_columns):
            for column in rng.sample(list(span), min(doors, len(span))):
                blocked.discard((height - 1 - row, column))
    for column in sorted(wall_columns):
        for span in spans(height, wall_rows):
            for row in rng.sample(list(span), min(doors, len(span))):
                blocked.discard((height - 1 - row, column))
    free = {(x, y) for x in range(height) for y in range(width) if (x, y) not in blocked}
    spec = {"kind": "room", "width": width, "height": height, "room_size": room_size, "doors": doors, "seed": seed}
    return _keep_largest_region(height, width, free, generated_name(spec))


@dataclass(frozen=True)
class Parameter:
    """One setting of a generator: its name, type, default (None: required) and smallest value."""

    name: str
    kind: type
    default: Any
    minimum: float


@dataclass(frozen=True)
class Generator:
    """A map family: its function, settings (besides width and height) and whether it uses a seed."""

    build: Callable[..., Grid]
    parameters: tuple[Parameter, ...]
    seeded: bool


GENERATORS: dict[str, Generator] = {
    "random": Generator(random_map, (Parameter("density", float, 0.2, 0.0),), seeded=True),
    "maze": Generator(maze_map, (Parameter("corridor", int, 1, 1),), seeded=True),
    "warehouse": Generator(
        warehouse_map,
        (
            Parameter("shelf_length", int, 10, 1),
            Parameter("shelf_depth", int, 2, 1),
            Parameter("aisle", int, 1, 1),
            Parameter("margin", int, 2, 1),
        ),
        seeded=False,
    ),
    "room": Generator(room_map, (Parameter("room_size", int, 4, 1), Parameter("doors", int, 1, 1)), seeded=True),
}
"""Every map family by name, with its settings."""

_NAME_PARTS: dict[str, Callable[[Mapping[str, Any]], str]] = {
    "random": lambda spec: f"p{spec['density']:.2f}",
    "maze": lambda spec: f"c{spec['corridor']}",
    "warehouse": lambda spec: f"l{spec['shelf_length']}-d{spec['shelf_depth']}-a{spec['aisle']}-m{spec['margin']}",
    "room": lambda spec: f"r{spec['room_size']}-d{spec['doors']}",
}


def complete_spec(spec: Mapping[str, Any]) -> dict[str, Any]:
    """``spec`` with every setting of its family, defaults filled in, in a fixed key order.

    Raises
    ------
    ValueError
        If the family is unknown, a setting is unknown or missing, or a seed is
        given to an unseeded family (or missing from a seeded one).

    >>> complete_spec({"kind": "maze", "width": 9, "height": 9, "seed": 1})
    {'kind': 'maze', 'width': 9, 'height': 9, 'corridor': 1, 'seed': 1}
    """
    kind = spec.get("kind")
    if kind not in GENERATORS:
        raise ValueError(f"unknown map generator {kind!r}; known: {', '.join(GENERATORS)}")
    generator = GENERATORS[kind]
    allowed = {"kind", "width", "height", *(p.name for p in generator.parameters)} | ({"seed"} if generator.seeded else set())
    unknown = sorted(set(spec) - allowed)
    if unknown:
        raise ValueError(f"{kind} maps take no setting {unknown[0]!r}")
    complete: dict[str, Any] = {"kind": kind, "width": spec.get("width"), "height": spec.get("height")}
    for parameter in generator.parameters:
        complete[parameter.name] = spec.get(parameter.name, parameter.default)
    if generator.seeded:
        complete["seed"] = spec.get("seed", 0)
    missing = [key for key, value in complete.items() if value is None]
    if missing:
        raise ValueError(f"{kind} maps need {missing[0]!r}")
    return complete


def generated_name(spec: Mapping[str, Any]) -> str:
    """The map name of a generator spec: ``gen:KIND-WIDTHxHEIGHT-SETTINGS[-sSEED]``.

    >>> generated_name({"kind": "random", "width": 32, "height": 32, "density": 0.2, "seed": 3})
    'gen:random-32x32-p0.20-s3'
    """
    seed = f"-s{spec['seed']}" if "seed" in spec else ""
    return f"gen:{spec['kind']}-{spec['width']}x{spec['height']}-{_NAME_PARTS[spec['kind']](spec)}{seed}"


def generate(spec: Mapping[str, Any]) -> Grid:
    """Build the grid of a generator spec (see :func:`complete_spec` for its keys).

    Raises
    ------
    ValueError
        If the spec or one of its values is wrong.

    >>> generate({"kind": "warehouse", "width": 16, "height": 8}).name
    'gen:warehouse-16x8-l10-d2-a1-m2'
    """
    complete = complete_spec(spec)
    arguments = {key: value for key, value in complete.items() if key != "kind"}
    return GENERATORS[complete["kind"]].build(**arguments)


def random_instance(grid: Grid, agents: int, seed: int, name: str | None = None) -> Scenario:
    """``agents`` seeded distinct random starts and distinct goals in the grid's largest connected region.

    Robots are named ``"0"``, ``"1"``, ...; the scenario's seed is ``seed`` and
    its name defaults to ``GRIDNAME-seed-SEED``.

    Raises
    ------
    ValueError
        If the region has fewer than ``agents`` cells.

    Examples
    --------
    >>> scenario = random_instance(Grid(4, 4), agents=2, seed=7)
    >>> scenario == random_instance(Grid(4, 4), agents=2, seed=7), scenario.name
    (True, '-seed-7')
    """
    region = largest_region(grid)
    if agents > len(region):
        raise ValueError(f"{agents} robots do not fit in a connected region of {len(region)} free cells")
    rng = stream_random(seed, Stream.INSTANCE)
    starts, goals = rng.sample(region, agents), rng.sample(region, agents)
    robots = tuple(RobotSpec(str(index), start, goal) for index, (start, goal) in enumerate(zip(starts, goals)))
    return Scenario(grid, robots, name=name if name is not None else f"{grid.name}-seed-{seed}", seed=seed)
