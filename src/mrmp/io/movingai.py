"""MovingAI benchmark files: ``.map`` grids and ``.scen`` agent lists (Stern et al., SoCS 2019).

A ``.map`` file is a header (``type octile``, ``height H``, ``width W``,
``map``) followed by H rows of W symbols, row 0 at the top. A ``.scen`` file
is a ``version 1`` line followed by one agent per line, tab-separated: bucket,
map file, map width, map height, start column, start row, goal column, goal
row, optimal length.

MovingAI's (column, row) become thesis cells ``(x, y)`` only through
:func:`mrmp.core.grid.cell_from_movingai` and
:func:`mrmp.core.grid.movingai_from_cell`.

Every malformed input raises :class:`~mrmp.core.errors.InputError` whose
problems name ``file:line`` and say what is wrong.

Examples
--------
>>> text = "type octile\\nheight 2\\nwidth 3\\nmap\\n..@\\n...\\n"
>>> grid = parse_map(text, "tiny.map")
>>> grid.name, grid.x_size, grid.y_size, grid.is_blocked((1, 2))
('tiny', 2, 3, True)
>>> scen = "version 1\\n0\\ttiny.map\\t3\\t2\\t0\\t1\\t1\\t0\\t2.00000000\\n"
>>> entry = parse_scen(scen, "tiny.scen")[0]
>>> entry.robot("0")
RobotSpec(id='0', start=(0, 0), goal=(1, 1), heading=<Heading.NORTH: 1>)
>>> parse_map("type octile\\nheight 1\\nwidth 2\\nmap\\n.X\\n", "bad.map")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
mrmp.core.errors.InputError: bad.map:5: map row 0, column 1: unknown symbol 'X' (expected one of ...)
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from mrmp.core.cell import Cell
from mrmp.core.errors import InputError, Problem
from mrmp.core.grid import (
    BLOCKED_SYMBOLS,
    COST_SYMBOLS,
    FREE_SYMBOLS,
    Grid,
    cell_from_movingai,
    grid_size_problem,
    movingai_from_cell,
)
from mrmp.core.scenario import RobotSpec
from mrmp.io._files import PathLike, atomic_write_text, read_text

MAP_SYMBOLS = frozenset(FREE_SYMBOLS | BLOCKED_SYMBOLS | set(COST_SYMBOLS) | {"#"})
"""Every symbol a map row may hold (the ones :meth:`Grid.from_rows` understands)."""

SCEN_FIELDS = (
    "bucket",
    "map file",
    "map width",
    "map height",
    "start column",
    "start row",
    "goal column",
    "goal row",
    "optimal length",
)
"""The nine tab-separated fields of a ``.scen`` agent line, in order."""

MAX_PROBLEMS = 20
"""At most this many problems are listed for one file; the rest are counted."""

_INTEGER_FIELDS = (0, 2, 3, 4, 5, 6, 7)


@dataclass(frozen=True)
class ScenEntry:
    """One agent line of a ``.scen`` file, in MovingAI's own terms.

    ``start`` and ``goal`` are MovingAI ``(column, row)`` pairs; :meth:`robot`
    converts them to thesis cells. ``line`` is the 1-based line number in the
    file, used to point problems back at it.
    """

    line: int
    bucket: int
    map_name: str
    width: int
    height: int
    start: tuple[int, int]
    goal: tuple[int, int]
    optimal_length: float

    @property
    def start_cell(self) -> Cell:
        """The start as a thesis cell ``(x, y)``.

        >>> ScenEntry(2, 0, "m.map", 4, 3, (1, 0), (0, 2), 3.0).start_cell
        (2, 1)
        """
        return cell_from_movingai(self.start[0], self.start[1], self.height)

    @property
    def goal_cell(self) -> Cell:
        """The goal as a thesis cell ``(x, y)``.

        >>> ScenEntry(2, 0, "m.map", 4, 3, (1, 0), (0, 2), 3.0).goal_cell
        (0, 0)
        """
        return cell_from_movingai(self.goal[0], self.goal[1], self.height)

    def robot(self, robot_id: str) -> RobotSpec:
        """The robot this line describes, named ``robot_id`` and facing NORTH.

        >>> ScenEntry(2, 0, "m.map", 4, 3, (1, 0), (0, 2), 3.0).robot("7").start
        (2, 1)
        """
        return RobotSpec(robot_id, self.start_cell, self.goal_cell)


# -- helpers ---------------------------------------------------------------------------


def _stem(source: str) -> str:
    """The file name without folder and extension (``"maps/a.map"`` -> ``"a"``)."""
    return Path(source).stem


def _raise_if_any(problems: list[Problem], source: str) -> None:
    """Raise one :class:`InputError` listing ``problems`` (capped), if there are any."""
    if not problems:
        return
    if len(problems) > MAX_PROBLEMS:
        hidden = len(problems) - MAX_PROBLEMS
        problems = [*problems[:MAX_PROBLEMS], Problem(source, f"{hidden} more problems not shown")]
    raise InputError(problems)


def _positive_int(text: str) -> int | None:
    """``int(text)`` if it is a positive decimal integer, else None."""
    try:
        value = int(text)
    except ValueError:
        return None
    return value if value > 0 else None


# -- .map ------------------------------------------------------------------------------


def _parse_map_header(lines: Sequence[str], source: str) -> tuple[int, int, int]:
    """Check the header and return ``(height, width, index of the 'map' line)``.

    Raises
    ------
    InputError
        At the first bad header line (parsing cannot go on without a header).
    """
    if not lines:
        raise InputError(Problem(f"{source}:1", "bad header: the file is empty, expected 'type octile'"))
    tokens = lines[0].split()
    if len(tokens) != 2 or tokens[0] != "type":
        raise InputError(Problem(f"{source}:1", f"bad header: expected 'type octile', got {lines[0]!r}"))
    if tokens[1] != "octile":
        raise InputError(Problem(f"{source}:1", f"bad header: unsupported map type {tokens[1]!r}, expected 'octile'"))
    sizes: dict[str, int] = {}
    index = 1
    while index < len(lines) and lines[index].strip() != "map":
        tokens = lines[index].split()
        where = f"{source}:{index + 1}"
        if len(tokens) != 2 or tokens[0] not in ("height", "width"):
            raise InputError(
                Problem(where, f"bad header: expected 'height N', 'width N' or 'map', got {lines[index]!r}")
            )
        if tokens[0] in sizes:
            raise InputError(Problem(where, f"bad header: {tokens[0]} given twice"))
        value = _positive_int(tokens[1])
        if value is None:
            raise InputError(Problem(where, f"bad header: {tokens[0]} must be a positive integer, got {tokens[1]!r}"))
        sizes[tokens[0]] = value
        index += 1
    if index == len(lines):
        raise InputError(Problem(f"{source}:{len(lines)}", "bad header: missing the 'map' line before the rows"))
    for key in ("height", "width"):
        if key not in sizes:
            raise InputError(Problem(f"{source}:{index + 1}", f"bad header: missing '{key} N' before 'map'"))
    too_large = grid_size_problem(sizes["height"], sizes["width"])
    if too_large is not None:
        raise InputError(Problem(f"{source}:{index + 1}", f"bad header: {too_large}"))
    return sizes["height"], sizes["width"], index


def _row_problem(row: str, row_index: int, width: int, where: str) -> Problem | None:
    """The first thing wrong with one map row, or None."""
    if len(row) != width:
        return Problem(where, f"map row {row_index} has {len(row)} symbols, expected {width} (the header's width)")
    for column, symbol in enumerate(row):
        if symbol not in MAP_SYMBOLS:
            return Problem(
                where,
                f"map row {row_index}, column {column}: unknown symbol {symbol!r} "
                "(expected one of . G S @ O T W or a cost digit 1-9)",
            )
    return None


def parse_map(text: str, source: str = "<map>", name: str | None = None) -> Grid:
    """Build a :class:`Grid` from the text of a MovingAI ``.map`` file.

    Parameters
    ----------
    text:
        The file's content.
    source:
        The file name used in problems (``source:line``).
    name:
        The grid's name; by default the stem of ``source``.

    Returns
    -------
    Grid
        ``x_size`` = the map's height, ``y_size`` = its width; row 0 of the
        file is the northmost row (largest x).

    Raises
    ------
    InputError
        For a bad header, a row of the wrong length, an unknown symbol, or too
        few or too many rows; each problem names ``source:line``.

    Examples
    --------
    >>> parse_map("type octile\\nheight 1\\nwidth 2\\nmap\\n.@\\n", "m.map").blocked_cells()
    [(0, 1)]
    """
    lines = text.splitlines()
    height, width, map_index = _parse_map_header(lines, source)
    body = [line.rstrip() for line in lines[map_index + 1 :]]
    while body and not body[-1]:
        body.pop()
    problems: list[Problem] = []
    if len(body) < height:
        last_line = map_index + 1 + len(body)
        problems.append(
            Problem(
                f"{source}:{last_line}",
                f"expected {height} map rows after 'map' (the header's height), found {len(body)}",
            )
        )
    elif len(body) > height:
        extra_line = map_index + 2 + height
        problems.append(
            Problem(f"{source}:{extra_line}", f"extra line after the {height} map rows declared by 'height {height}'")
        )
    for row_index, row in enumerate(body[:height]):
        problem = _row_problem(row, row_index, width, f"{source}:{map_index + 2 + row_index}")
        if problem is not None:
            problems.append(problem)
    _raise_if_any(problems, source)
    try:
        return Grid.from_rows(body, name=_stem(source) if name is None else name)
    except ValueError as error:  # pragma: no cover - every case is checked above
        raise InputError(Problem(source, str(error))) from None


def read_map(path: PathLike) -> Grid:
    """Read a MovingAI ``.map`` file into a :class:`Grid` named after the file's stem.

    Parameters
    ----------
    path:
        The ``.map`` file.

    Returns
    -------
    Grid
        See :func:`parse_map`.

    Raises
    ------
    InputError
        If the file cannot be read or is malformed (problems name ``path:line``).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "column.map"
    >>> _ = path.write_text("type octile\\nheight 2\\nwidth 1\\nmap\\n@\\n.\\n")
    >>> grid = read_map(path)
    >>> grid.name, grid.blocked_cells()
    ('column', [(1, 0)])
    """
    return parse_map(read_text(path), str(path))


def map_to_text(grid: Grid) -> str:
    """The MovingAI ``.map`` text of ``grid`` (blocked cells as ``@``, cost cells as their digit).

    Raises
    ------
    ValueError
        If a cell's cost is not a whole number 1-9 (no map symbol for it).

    Examples
    --------
    >>> print(map_to_text(Grid.from_rows(["..", "@."])), end="")
    type octile
    height 2
    width 2
    map
    ..
    @.
    """
    for cell, cost in grid.costs().items():
        if cost not in COST_SYMBOLS.values():
            raise ValueError(f"cell {cell} costs {cost}: only whole costs 1-9 can be written as map symbols")
    header = ["type octile", f"height {grid.x_size}", f"width {grid.y_size}", "map"]
    return "\n".join(header + grid.to_rows()) + "\n"


def write_map(path: PathLike, grid: Grid) -> None:
    """Write ``grid`` as a MovingAI ``.map`` file (atomically).

    Parameters
    ----------
    path:
        The file to create or replace.
    grid:
        The grid to draw.

    Raises
    ------
    ValueError
        If a cell cost cannot be drawn (see :func:`map_to_text`).
    InputError
        If the file cannot be written.
    """
    atomic_write_text(path, map_to_text(grid))


# -- .scen -----------------------------------------------------------------------------


def _parse_scen_line(line: str, number: int, source: str) -> tuple[ScenEntry | None, list[Problem]]:
    """Parse one agent line; return the entry (or None) and what is wrong with it."""
    where = f"{source}:{number}"
    fields = line.split("\t")
    if len(fields) != len(SCEN_FIELDS):
        fields = line.split()
    if len(fields) != len(SCEN_FIELDS):
        expected = ", ".join(SCEN_FIELDS)
        return None, [
            Problem(where, f"expected {len(SCEN_FIELDS)} tab-separated fields ({expected}), found {len(fields)}")
        ]
    problems: list[Problem] = []
    numbers: dict[int, int] = {}
    for index in _INTEGER_FIELDS:
        try:
            numbers[index] = int(fields[index])
        except ValueError:
            problems.append(
                Problem(where, f"field {index + 1} ({SCEN_FIELDS[index]}) must be an integer, got {fields[index]!r}")
            )
    try:
        optimal = float(fields[8])
    except ValueError:
        problems.append(Problem(where, f"field 9 (optimal length) must be a number, got {fields[8]!r}"))
        optimal = 0.0
    if problems:
        return None, problems
    width, height = numbers[2], numbers[3]
    if width <= 0 or height <= 0:
        return None, [Problem(where, f"map size must be positive, got width {width} and height {height}")]
    for kind, column, row in (("start", numbers[4], numbers[5]), ("goal", numbers[6], numbers[7])):
        if not (0 <= column < width and 0 <= row < height):
            problems.append(
                Problem(
                    where, f"{kind} (column {column}, row {row}) is outside the {width}x{height} map (width x height)"
                )
            )
    if problems:
        return None, problems
    entry = ScenEntry(
        number, numbers[0], fields[1], width, height, (numbers[4], numbers[5]), (numbers[6], numbers[7]), optimal
    )
    return entry, []


def parse_scen(text: str, source: str = "<scen>") -> list[ScenEntry]:
    """Parse the text of a MovingAI ``.scen`` file into its agent lines.

    Parameters
    ----------
    text:
        The file's content.
    source:
        The file name used in problems (``source:line``).

    Returns
    -------
    list[ScenEntry]
        Every agent line, in file order (blank lines are skipped).

    Raises
    ------
    InputError
        For a missing or bad ``version 1`` header, a line without nine fields,
        a non-integer field, or a start or goal outside the map size the line
        declares; each problem names ``source:line``.

    Examples
    --------
    >>> parse_scen("version 1\\n0\\tm.map\\t2\\t2\\t0\\tx\\t1\\t1\\t1.0\\n", "m.scen")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: m.scen:2: field 6 (start row) must be an integer, got 'x'
    """
    lines = text.splitlines()
    header = lines[0].split() if lines else []
    if len(header) != 2 or header[0] != "version" or header[1] not in ("1", "1.0"):
        got = repr(lines[0]) if lines else "an empty file"
        raise InputError(Problem(f"{source}:1", f"bad header: expected 'version 1', got {got}"))
    entries: list[ScenEntry] = []
    problems: list[Problem] = []
    for index, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        entry, line_problems = _parse_scen_line(line, index, source)
        problems.extend(line_problems)
        if entry is not None:
            entries.append(entry)
    _raise_if_any(problems, source)
    return entries


def read_scen_entries(path: PathLike) -> list[ScenEntry]:
    """Read every agent line of a ``.scen`` file (see :func:`parse_scen`).

    Raises
    ------
    InputError
        If the file cannot be read or is malformed.
    """
    return parse_scen(read_text(path), str(path))


def scen_map_problems(entries: Sequence[ScenEntry], grid: Grid, source: str) -> list[Problem]:
    """Problems of ``.scen`` lines whose declared map size differs from ``grid``'s.

    Only the first mismatching line is named; the others are counted in its reason.

    Parameters
    ----------
    entries:
        Agent lines from :func:`parse_scen`.
    grid:
        The map they should use.
    source:
        The ``.scen`` file name for problems.

    Returns
    -------
    list[Problem]
        Empty if every line declares ``grid.y_size`` x ``grid.x_size`` (width x height).

    Examples
    --------
    >>> entry = ScenEntry(2, 0, "m.map", 4, 3, (0, 0), (1, 1), 2.0)
    >>> scen_map_problems([entry], Grid(3, 4, name="m"), "m.scen")
    []
    >>> [str(p) for p in scen_map_problems([entry], Grid(4, 4, name="m"), "m.scen")]
    ["m.scen:2: map size 4x3 (width x height) does not match map 'm', which is 4x4"]
    """
    wrong = [entry for entry in entries if (entry.width, entry.height) != (grid.y_size, grid.x_size)]
    if not wrong:
        return []
    first = wrong[0]
    label = f"map {grid.name!r}" if grid.name else "the map"
    more = f" (and {len(wrong) - 1} more lines)" if len(wrong) > 1 else ""
    declared = f"{first.width}x{first.height}"
    reason = f"map size {declared} (width x height) does not match {label}, which is {grid.y_size}x{grid.x_size}{more}"
    return [Problem(f"{source}:{first.line}", reason)]


def select_agents(entries: Sequence[ScenEntry], agents: int | None, source: str) -> list[ScenEntry]:
    """The first ``agents`` entries (all of them when ``agents`` is None).

    Raises
    ------
    InputError
        If ``agents`` is below 1 or the file lists fewer agents than asked
        (the problem names the last agent line).

    Examples
    --------
    >>> entry = ScenEntry(2, 0, "m.map", 4, 3, (0, 0), (1, 1), 2.0)
    >>> len(select_agents([entry], 1, "m.scen"))
    1
    >>> select_agents([entry], 3, "m.scen")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: m.scen:2: asked for 3 agents but the file lists only 1
    """
    if agents is None:
        return list(entries)
    if agents < 1:
        raise InputError(Problem(source, f"the number of agents must be at least 1, got {agents}"))
    if len(entries) < agents:
        last_line = entries[-1].line if entries else 1
        reason = f"asked for {agents} agents but the file lists only {len(entries)}"
        raise InputError(Problem(f"{source}:{last_line}", reason))
    return list(entries[:agents])


def read_scen(path: PathLike, agents: int | None = None, grid: Grid | None = None) -> list[RobotSpec]:
    """Read the first ``agents`` agents of a ``.scen`` file as robots named ``"0"``, ``"1"``, ...

    Parameters
    ----------
    path:
        The ``.scen`` file.
    agents:
        How many agents to take from the top of the file; None takes them all.
    grid:
        The map the file refers to; when given, every line's map size must match it.

    Returns
    -------
    list[RobotSpec]
        Robots in file order, facing NORTH, cells in thesis axes.

    Raises
    ------
    InputError
        If the file cannot be read, is malformed, lists fewer agents than
        asked, or declares a map size different from ``grid``'s.
    """
    source = str(path)
    entries = parse_scen(read_text(path), source)
    if grid is not None:
        _raise_if_any(scen_map_problems(entries, grid, source), source)
    chosen = select_agents(entries, agents, source)
    return [entry.robot(str(index)) for index, entry in enumerate(chosen)]


def shortest_path_length(grid: Grid, start: Cell, goal: Cell) -> int | None:
    """The number of moves of a shortest 4-connected path (breadth-first search), or None.

    Cell costs are ignored: this is the benchmark's unit-cost optimal length.

    >>> shortest_path_length(Grid.from_rows(["...", "@@.", "..."]), (0, 0), (2, 0))
    6
    >>> shortest_path_length(Grid.from_rows([".@."]), (0, 0), (0, 2)) is None
    True
    """
    if not (grid.is_free(start) and grid.is_free(goal)):
        return None
    distance = {start: 0}
    queue = deque([start])
    while queue:
        cell = queue.popleft()
        if cell == goal:
            return distance[cell]
        for neighbour in grid.neighbours(cell):
            if neighbour not in distance:
                distance[neighbour] = distance[cell] + 1
                queue.append(neighbour)
    return None


def scen_to_text(map_name: str, grid: Grid, robots: Sequence[RobotSpec]) -> str:
    """The ``.scen`` text listing ``robots`` on ``grid`` (saved as ``map_name``).

    The optimal-length column is the true 4-connected shortest path length
    and the bucket is that length divided by 4, as in the benchmark.

    Raises
    ------
    InputError
        If a robot's goal cannot be reached from its start (or either is not
        a free cell), naming ``robots[i]``.

    Examples
    --------
    >>> grid = Grid.from_rows(["...", "..."])
    >>> text = scen_to_text("m.map", grid, [RobotSpec("A", (0, 0), (1, 2))])
    >>> [line.split("\\t") for line in text.splitlines()]
    [['version 1'], ['0', 'm.map', '3', '2', '0', '1', '2', '0', '3.00000000']]
    """
    lines = ["version 1"]
    problems: list[Problem] = []
    for index, robot in enumerate(robots):
        length = shortest_path_length(grid, robot.start, robot.goal)
        if length is None:
            problems.append(Problem(f"robots[{index}]", f"no path from {robot.start} to {robot.goal} on the grid"))
            continue
        start_column, start_row = movingai_from_cell(robot.start, grid.x_size)
        goal_column, goal_row = movingai_from_cell(robot.goal, grid.x_size)
        fields = (length // 4, map_name, grid.y_size, grid.x_size, start_column, start_row, goal_column, goal_row)
        lines.append("\t".join(str(field) for field in fields) + f"\t{length:.8f}")
    if problems:
        raise InputError(problems)
    return "\n".join(lines) + "\n"


def write_scen(path: PathLike, map_name: str, grid: Grid, robots: Sequence[RobotSpec]) -> None:
    """Write ``robots`` as a MovingAI ``.scen`` file (atomically); see :func:`scen_to_text`.

    Parameters
    ----------
    path:
        The file to create or replace.
    map_name:
        The map file name written in every line (for example ``"random-32-32-20.map"``).
    grid:
        The map, for its size and for the shortest path lengths.
    robots:
        The agents, in order. Names and headings are not stored by the format.

    Raises
    ------
    InputError
        If a goal is unreachable or the file cannot be written.
    """
    atomic_write_text(path, scen_to_text(map_name, grid, robots))
