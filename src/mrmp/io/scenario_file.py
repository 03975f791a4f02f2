"""The YAML scenario format, read strictly: every problem is reported with its file and line.

A scenario file looks like this (only ``map`` and ``robots`` are required)::

    name: thesis-swap                 # default: the file's stem
    description: two robots swap ends of a column
    map:                              # exactly one of: rows / file / width + height
      rows: [".....", ".....", "..@..", ".....", "....."]   # first row is the NORTHMOST
      # file: ../maps/random-32-32-20.map   (relative to this file's folder)
      # width: 5     (number of y values, east-west)
      # height: 5    (number of x values, north-south)
      # obstacles: [[2, 2], [3, 1]]   (with width and height: blocked cells [x, y])
    robots:                           # or, at top level: scen: file.scen + agents: N
      - id: A
        start: [0, 2]                 # [x, y]: x grows NORTH, y grows EAST
        goal: [4, 2]
        heading: NORTH                # optional: a name or 1-4
    timing: {cell_time: 1.0, turn_time: 0.5}
    network:                          # delay: N, "A..B" or [A, B] ticks
      loss: 0.0
      delay: 0
      duplicate: 0.0
      reorder: 0.0
      links:                          # optional: faults of particular directed links
        - {from: A, to: B, loss: 0.5} # unset settings are the network's
    policy: {name: thesis, resolve: divert, heading_aware: false}
    safety: true                      # false: no safety layer, the policy as written
    lifelong: false                   # true: a robot that reaches its goal gets a new one
    seed: 0
    max_ticks: 100

With ``scen:`` and ``agents:`` the robots are the first N agents of a MovingAI
``.scen`` file (named ``"0"``, ``"1"``, ...); ``map:`` may then be left out, and
the map named in the ``.scen`` file is read from the ``.scen`` file's folder.

The file is read with PyYAML's node API (:func:`yaml.compose`) so that every
value keeps its line. All problems are collected -- unknown keys, wrong types,
missing keys, conflicting map forms, malformed map files, and the meaning
checks of :func:`mrmp.core.scenario.scenario_problems` -- and raised together
as one :class:`~mrmp.core.errors.InputError`, each as ``file:line`` and
``field.path: reason``.

Examples
--------
>>> text = '''
... map: {rows: ["...", "...", "..."]}
... robots:
...   - {id: A, start: [0, 0], goal: [2, 2]}
... '''
>>> scenario = scenario_from_text(text, "demo.yaml")
>>> scenario.name, scenario.grid.x_size, scenario.robots[0].goal
('demo', 3, (2, 2))
>>> scenario_from_text(text.replace("goal", "gaol"), "demo.yaml")
Traceback (most recent call last):
...
mrmp.core.errors.InputError: demo.yaml:4: robots[0]: unknown key 'gaol' (did you mean 'goal'?)
demo.yaml:4: robots[0]: missing required key 'goal'
"""

from __future__ import annotations

import difflib
import json
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml
from yaml.constructor import SafeConstructor
from yaml.events import MappingStartEvent, SequenceStartEvent
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from mrmp.core.cell import Cell
from mrmp.core.errors import InputError, Problem
from mrmp.core.grid import COST_SYMBOLS, Grid, grid_size_problem
from mrmp.core.heading import Heading
from mrmp.core.limits import MAX_YAML_DEPTH
from mrmp.core.options import setting_types, settings
from mrmp.core.scenario import (
    LinkFaults,
    NetworkFaults,
    PolicyOptions,
    RobotSpec,
    Scenario,
    Timing,
    scenario_problems,
)
from mrmp.io._files import PathLike, atomic_write_text, file_problem, read_text
from mrmp.io.movingai import (
    MAP_SYMBOLS,
    ScenEntry,
    parse_scen,
    read_map,
    scen_map_problems,
    select_agents,
)

TOP_KEYS = (
    "name",
    "description",
    "map",
    "robots",
    "scen",
    "agents",
    "timing",
    "network",
    "policy",
    "seed",
    "max_ticks",
    "safety",
    "lifelong",
)
"""Keys allowed at the top level of a scenario file."""
MAP_KEYS = ("rows", "file", "width", "height", "obstacles")
"""Keys allowed under ``map``."""
ROBOT_KEYS = ("id", "start", "goal", "heading")
"""Keys allowed in each item of ``robots``."""
TIMING_KEYS = ("cell_time", "turn_time")
"""Keys allowed under ``timing``."""
FAULT_KEYS = ("loss", "delay", "duplicate", "reorder")
"""Fault settings, allowed under ``network`` and in each of its ``links``."""
NETWORK_KEYS = (*FAULT_KEYS, "links")
"""Keys allowed under ``network``."""
LINK_KEYS = ("from", "to", *FAULT_KEYS)
"""Keys allowed in each entry of ``network.links``; unset faults are the network's."""
POLICY_SETTINGS = settings(PolicyOptions)
"""The settings of the ``policy`` section, with their YAML keys (:mod:`mrmp.core.options`)."""
POLICY_KEYS = ("name", *(setting.yaml_key for _, setting in POLICY_SETTINGS))
"""Keys allowed under ``policy``."""

_BAD: Any = object()
"""Returned by a value reader when the value was wrong (a problem has been recorded)."""
_FLOAT_TEXT = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")
_DELAY_RANGE = re.compile(r"^\s*(-?\d+)\s*\.\.\s*(-?\d+)\s*$")
_ROBOT_INDEX = re.compile(r"robots\[(\d+)\]")
_PARENT_SUFFIX = re.compile(r"(\.[^.\[\]]+|\[\d+\])$")


def _line(node: Node) -> int:
    """The 1-based line where ``node`` starts."""
    return int(node.start_mark.line) + 1


def _describe(node: Node, value: Any = None) -> str:
    """A short description of what a node holds, for "expected X, got Y" messages."""
    if isinstance(node, MappingNode):
        return "a mapping"
    if isinstance(node, SequenceNode):
        return "a list"
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return f"a boolean {node.value!r}"
    if isinstance(value, (int, float)):
        return f"a number {node.value}"
    return f"a string {str(value)!r}" if isinstance(value, str) else f"{node.value!r}"


@dataclass
class _Entry:
    """A key of a mapping with its value node and line."""

    key_line: int
    value: Node


@dataclass
class _Reader:
    """Walks the YAML nodes of one scenario file, collecting problems and field lines."""

    source: str
    base_dir: Path
    known_policies: tuple[str, ...] | None
    problems: list[Problem] = field(default_factory=list)
    lines: dict[str, int] = field(default_factory=dict)
    robot_sources: dict[int, str] = field(default_factory=dict)
    robot_trouble: bool = False
    constructor: SafeConstructor = field(default_factory=SafeConstructor)
    obstacles: dict[Cell, int] = field(default_factory=dict)
    """The cells of ``map.obstacles``, each with its index there."""

    # -- recording ---------------------------------------------------------------------

    def report(self, line: int, path: str, reason: str) -> None:
        """Record a problem at ``line`` about the field ``path``."""
        text = f"{path}: {reason}" if path else reason
        self.problems.append(Problem(f"{self.source}:{line}", text))
        if path.startswith("robots") or path in ("scen", "agents"):
            self.robot_trouble = True

    def where(self, path: str) -> str:
        """``file:line`` of the field ``path`` (or of its closest recorded parent)."""
        match = _ROBOT_INDEX.match(path)
        if match and int(match.group(1)) in self.robot_sources:
            return self.robot_sources[int(match.group(1))]
        candidate = path
        while candidate:
            if candidate in self.lines:
                return f"{self.source}:{self.lines[candidate]}"
            parent = _PARENT_SUFFIX.sub("", candidate)
            candidate = parent if parent != candidate else ""
        return f"{self.source}:{self.lines.get('', 1)}"

    # -- structure ---------------------------------------------------------------------

    def mapping(
        self, node: Node, path: str, allowed: Sequence[str], required: Sequence[str] = ()
    ) -> dict[str, _Entry] | None:
        """Check that ``node`` is a mapping of known, unique keys; return its entries or None."""
        if not isinstance(node, MappingNode):
            self.report(
                _line(node),
                path,
                f"expected a mapping of {', '.join(allowed)}, got {_describe(node, self.scalar(node))}",
            )
            return None
        entries: dict[str, _Entry] = {}
        for key_node, value_node in node.value:
            key_line = _line(key_node)
            if not isinstance(key_node, ScalarNode):
                self.report(key_line, path, "keys must be plain names")
                continue
            key = str(key_node.value)
            if key not in allowed:
                close = difflib.get_close_matches(key, allowed, n=1)
                hint = f"did you mean {close[0]!r}?" if close else f"allowed: {', '.join(allowed)}"
                self.report(key_line, path, f"unknown key {key!r} ({hint})")
                continue
            if key in entries:
                self.report(key_line, path, f"key {key!r} is given twice (first at line {entries[key].key_line})")
                continue
            entries[key] = _Entry(key_line, value_node)
            self.lines[f"{path}.{key}" if path else key] = key_line
        for key in required:
            if key not in entries:
                self.report(_line(node), path, f"missing required key {key!r}")
        return entries

    def scalar(self, node: Node) -> Any:
        """The Python value of a scalar node (None for non-scalars or unreadable scalars)."""
        if not isinstance(node, ScalarNode):
            return None
        try:
            return self.constructor.construct_object(node, deep=True)
        except yaml.YAMLError:
            return node.value

    # -- typed values ------------------------------------------------------------------

    def integer(self, node: Node, path: str) -> Any:
        """An int (not a bool), or ``_BAD``."""
        value = self.scalar(node)
        if isinstance(node, ScalarNode) and isinstance(value, int) and not isinstance(value, bool):
            return value
        self.report(_line(node), path, f"expected an integer, got {_describe(node, value)}")
        return _BAD

    def number(self, node: Node, path: str) -> Any:
        """A float from an int or float (or a plain ``1e-3``), or ``_BAD``."""
        value = self.scalar(node)
        if isinstance(node, ScalarNode):
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                return float(value)
            if isinstance(value, str) and node.style is None and _FLOAT_TEXT.match(value):
                return float(value)
        self.report(_line(node), path, f"expected a number, got {_describe(node, value)}")
        return _BAD

    def boolean(self, node: Node, path: str) -> Any:
        """A bool, or ``_BAD``."""
        value = self.scalar(node)
        if isinstance(node, ScalarNode) and isinstance(value, bool):
            return value
        self.report(_line(node), path, f"expected true or false, got {_describe(node, value)}")
        return _BAD

    def text(self, node: Node, path: str) -> Any:
        """A string, or ``_BAD``."""
        value = self.scalar(node)
        if isinstance(node, ScalarNode) and isinstance(value, str):
            return value
        self.report(_line(node), path, f"expected a string, got {_describe(node, value)}")
        return _BAD

    def label(self, node: Node, path: str) -> Any:
        """A name: a string, or an integer turned into its text as written; else ``_BAD``."""
        value = self.scalar(node)
        if isinstance(node, ScalarNode) and isinstance(value, (str, int)) and not isinstance(value, bool):
            return str(node.value)
        self.report(_line(node), path, f"expected a string or an integer, got {_describe(node, value)} (quote it)")
        return _BAD

    def cell(self, node: Node, path: str) -> Any:
        """A cell from a list of two integers ``[x, y]``, or ``_BAD``."""
        if isinstance(node, SequenceNode) and len(node.value) == 2:
            values = [self.scalar(item) for item in node.value]
            if all(isinstance(v, int) and not isinstance(v, bool) for v in values):
                return (values[0], values[1])
        got = (
            f"a list of {len(node.value)} items"
            if isinstance(node, SequenceNode)
            else _describe(node, self.scalar(node))
        )
        if isinstance(node, SequenceNode) and len(node.value) == 2:
            got = (
                "[" + ", ".join(str(item.value) if isinstance(item, ScalarNode) else "..." for item in node.value) + "]"
            )
        self.report(_line(node), path, f"expected a list of two integers [x, y], got {got}")
        return _BAD

    def heading(self, node: Node, path: str) -> Any:
        """A :class:`Heading` from a name or 1-4, or ``_BAD``."""
        value = self.scalar(node)
        if isinstance(node, ScalarNode) and isinstance(value, (str, int)) and not isinstance(value, bool):
            try:
                return Heading.parse(value)
            except ValueError:
                pass
        self.report(_line(node), path, f"unknown heading {_describe(node, value)}: use NORTH, EAST, SOUTH, WEST or 1-4")
        return _BAD

    def delay(self, node: Node, path: str) -> Any:
        """A delay range ``(min, max)`` from ``N``, ``"A..B"`` or ``[A, B]``, or ``_BAD``."""
        value = self.scalar(node)
        if isinstance(node, ScalarNode):
            if isinstance(value, int) and not isinstance(value, bool):
                return (value, value)
            if isinstance(value, str):
                match = _DELAY_RANGE.match(value)
                if match:
                    return (int(match.group(1)), int(match.group(2)))
        if isinstance(node, SequenceNode) and len(node.value) == 2:
            values = [self.scalar(item) for item in node.value]
            if all(isinstance(v, int) and not isinstance(v, bool) for v in values):
                return (values[0], values[1])
        self.report(_line(node), path, f'expected ticks as N, "A..B" or [A, B], got {_describe(node, value)}')
        return _BAD

    def optional(self, entries: dict[str, _Entry] | None, key: str, path: str, read: Callable[[Node, str], Any]) -> Any:
        """Read ``entries[key]`` with ``read``; None when absent or null, ``_BAD`` when wrong."""
        if entries is None or key not in entries:
            return None
        node = entries[key].value
        if isinstance(node, ScalarNode) and node.tag.endswith(":null"):
            return None
        return read(node, path)

    # -- sections ----------------------------------------------------------------------

    def read_map_section(self, node: Node, name: str) -> Grid | None:
        """The grid of the ``map`` section, or None if it is wrong (problems recorded)."""
        entries = self.mapping(node, "map", MAP_KEYS)
        if entries is None:
            return None
        forms = [
            form
            for form, keys in (("rows", ("rows",)), ("file", ("file",)), ("width and height", ("width", "height")))
            if any(k in entries for k in keys)
        ]
        if len(forms) != 1:
            reason = (
                "needs rows, file, or width and height"
                if not forms
                else f"give exactly one of rows, file, or width and height; got {' and '.join(forms)}"
            )
            self.report(_line(node), "map", reason)
            return None
        if "obstacles" in entries and "width and height" not in forms:
            reason = f"goes with width and height; draw obstacles in the map's {forms[0]}"
            self.report(entries["obstacles"].key_line, "map.obstacles", reason)
            return None
        if "rows" in entries:
            return self.read_rows(entries["rows"].value, name)
        if "file" in entries:
            return self.read_map_file(entries["file"].value)
        missing = [key for key in ("width", "height") if key not in entries]
        if missing:
            self.report(_line(node), "map", f"missing required key {missing[0]!r} (width and height go together)")
            return None
        width = self.integer(entries["width"].value, "map.width")
        height = self.integer(entries["height"].value, "map.height")
        for key, value in (("width", width), ("height", height)):
            if value is not _BAD and value <= 0:
                self.report(entries[key].key_line, f"map.{key}", f"must be a positive integer, got {value}")
                return None
        if width is _BAD or height is _BAD:
            return None
        too_large = grid_size_problem(height, width)
        if too_large is not None:
            self.report(_line(node), "map", too_large)
            return None
        obstacles = self.read_obstacles(entries["obstacles"].value, Grid(height, width)) if "obstacles" in entries else []
        if obstacles is None:
            return None
        return Grid(height, width, obstacles, name=name)

    def read_obstacles(self, node: Node, bounds: Grid) -> list[Cell] | None:
        """The blocked cells of ``map.obstacles`` (a list of ``[x, y]`` inside ``bounds``), or None if any is wrong."""
        if not isinstance(node, SequenceNode):
            got = _describe(node, self.scalar(node))
            self.report(_line(node), "map.obstacles", f"expected a list of cells [x, y], got {got}")
            return None
        ok = True
        for index, item in enumerate(node.value):
            path = f"map.obstacles[{index}]"
            self.lines[path] = _line(item)
            cell = self.cell(item, path)
            if cell is _BAD:
                ok = False
            elif not bounds.in_bounds(cell):
                size = f"{bounds.x_size}x{bounds.y_size}"
                reason = f"cell {cell} is outside the {size} map (x from 0 to {bounds.x_max}, y from 0 to {bounds.y_max})"
                self.report(_line(item), path, reason)
                ok = False
            elif cell in self.obstacles:
                self.report(_line(item), path, f"cell {cell} is already map.obstacles[{self.obstacles[cell]}]")
                ok = False
            else:
                self.obstacles[cell] = index
        return list(self.obstacles) if ok else None

    def read_rows(self, node: Node, name: str) -> Grid | None:
        """A grid from ``map.rows`` (first row northmost), or None."""
        if not isinstance(node, SequenceNode) or not node.value:
            got = "an empty list" if isinstance(node, SequenceNode) else _describe(node, self.scalar(node))
            self.report(_line(node), "map.rows", f"expected a non-empty list of rows of symbols, got {got}")
            return None
        first = node.value[0]
        if isinstance(first, ScalarNode):
            too_large = grid_size_problem(len(node.value), len(str(first.value)))
            if too_large is not None:
                self.report(_line(node), "map.rows", too_large)
                return None
        rows: list[str] = []
        ok = True
        for index, item in enumerate(node.value):
            path = f"map.rows[{index}]"
            self.lines[path] = _line(item)
            if not isinstance(item, ScalarNode):
                self.report(_line(item), path, f"expected a row of symbols, got {_describe(item)}")
                ok = False
                continue
            row = str(item.value)
            rows.append(row)
            if len(row) != len(rows[0]):
                self.report(_line(item), path, f"has {len(row)} symbols, expected {len(rows[0])} like map.rows[0]")
                ok = False
            unknown = [(column, symbol) for column, symbol in enumerate(row) if symbol not in MAP_SYMBOLS]
            if unknown:
                column, symbol = unknown[0]
                self.report(
                    _line(item),
                    path,
                    f"column {column}: unknown symbol {symbol!r} (use . for free, @ for blocked, 1-9 for a cost)",
                )
                ok = False
        return Grid.from_rows(rows, name=name) if ok else None

    def read_map_file(self, node: Node) -> Grid | None:
        """A grid from ``map.file`` (relative to the scenario's folder), or None."""
        relative = self.text(node, "map.file")
        if relative is _BAD:
            return None
        path = self.base_dir / relative
        problem = file_problem(path)
        if problem is not None:
            self.report(_line(node), "map.file", _unusable("map file", path, problem))
            return None
        try:
            return read_map(path)
        except InputError as error:
            self.problems.extend(error.problems)
            return None

    def read_robots(self, node: Node) -> list[tuple[int, RobotSpec]]:
        """The robots that are well formed, each with its index in the file."""
        if not isinstance(node, SequenceNode):
            self.report(_line(node), "robots", f"expected a list of robots, got {_describe(node, self.scalar(node))}")
            return []
        robots: list[tuple[int, RobotSpec]] = []
        for index, item in enumerate(node.value):
            path = f"robots[{index}]"
            self.lines[path] = _line(item)
            entries = self.mapping(item, path, ROBOT_KEYS, required=("id", "start", "goal"))
            if entries is None:
                continue
            values = {
                "id": self.optional(entries, "id", f"{path}.id", self.label),
                "start": self.optional(entries, "start", f"{path}.start", self.cell),
                "goal": self.optional(entries, "goal", f"{path}.goal", self.cell),
                "heading": self.optional(entries, "heading", f"{path}.heading", self.heading),
            }
            for key in ("id", "start", "goal"):
                if key in entries and values[key] is None:
                    self.report(entries[key].key_line, f"{path}.{key}", "missing value")
            if (
                any(values[key] is None or values[key] is _BAD for key in ("id", "start", "goal"))
                or values["heading"] is _BAD
            ):
                self.robot_trouble = True
                continue
            heading = values["heading"] if values["heading"] is not None else Heading.NORTH
            robots.append((index, RobotSpec(values["id"], values["start"], values["goal"], heading)))
        return robots

    def read_scen_robots(
        self, entries: dict[str, _Entry], grid: Grid | None
    ) -> tuple[Grid | None, list[tuple[int, RobotSpec]]]:
        """The robots (and, without a ``map`` section, the grid) of ``scen`` + ``agents``."""
        relative = self.optional(entries, "scen", "scen", self.text)
        agents = self.optional(entries, "agents", "agents", self.integer)
        if "agents" not in entries:
            self.report(entries["scen"].key_line, "scen", "needs agents: N next to it")
        elif agents is not _BAD and agents is not None and agents < 1:
            self.report(entries["agents"].key_line, "agents", f"must be at least 1, got {agents}")
            agents = _BAD
        if relative is None or relative is _BAD or agents is None or agents is _BAD:
            return grid, []
        path = self.base_dir / relative
        problem = file_problem(path)
        if problem is not None:
            self.report(entries["scen"].key_line, "scen", _unusable("scenario file", path, problem))
            return grid, []
        try:
            scen_entries = parse_scen(read_text(path), str(path))
            if grid is None and "map" not in self.lines:
                grid = self.grid_next_to(path, scen_entries, entries["scen"].key_line)
            if grid is None:
                return None, []
            problems = scen_map_problems(scen_entries, grid, str(path))
            if problems:
                raise InputError(problems)
            chosen = select_agents(scen_entries, agents, str(path))
        except InputError as error:
            self.problems.extend(error.problems)
            self.robot_trouble = True
            return grid, []
        for index, entry in enumerate(chosen):
            self.robot_sources[index] = f"{path}:{entry.line}"
        return grid, [(index, entry.robot(str(index))) for index, entry in enumerate(chosen)]

    def grid_next_to(self, scen_path: Path, entries: Sequence[ScenEntry], line: int) -> Grid | None:
        """The map a ``.scen`` file names, read from the ``.scen`` file's folder."""
        if not entries:
            self.report(line, "scen", f"{scen_path} lists no agents")
            return None
        map_path = scen_path.parent / entries[0].map_name
        problem = file_problem(map_path)
        if problem is not None:
            named = f"map file {entries[0].map_name!r} named by {scen_path}"
            reason = f"{named} not found (looked for {map_path})" if problem == "file not found" else f"{named} {problem}"
            self.report(line, "scen", reason)
            return None
        return read_map(map_path)

    def read_settings(self, top: dict[str, _Entry]) -> tuple[Timing, NetworkFaults, tuple[LinkFaults, ...], PolicyOptions]:
        """The ``timing``, ``network`` and ``policy`` sections (defaults where absent or wrong)."""
        timing_entries = self.section(top, "timing", TIMING_KEYS)
        timing_values = {key: self.optional(timing_entries, key, f"timing.{key}", self.number) for key in TIMING_KEYS}
        timing = Timing(**_given(timing_values))
        network_entries = self.section(top, "network", NETWORK_KEYS)
        network = self.faults(network_entries, "network", NetworkFaults())
        links = self.links(network_entries, network)
        policy_values = self.policy_values(self.section(top, "policy", POLICY_KEYS))
        policy = self.policy_options(_given(policy_values))
        if (
            self.known_policies is not None
            and policy_values["name"] not in (None, _BAD)
            and policy.name not in self.known_policies
        ):
            known = ", ".join(self.known_policies)
            self.report(
                self.lines["policy.name"], "policy.name", f"unknown policy {policy.name!r}; known policies: {known}"
            )
        return timing, network, links, policy

    def policy_values(self, entries: dict[str, _Entry] | None) -> dict[str, Any]:
        """The ``policy`` section's values by field name: its name, then each setting read by its type."""
        readers: dict[type, Callable[[Node, str], Any]] = {str: self.text, bool: self.boolean, int: self.integer}
        types = setting_types(PolicyOptions)
        values = {"name": self.optional(entries, "name", "policy.name", self.text)}
        for option, setting in POLICY_SETTINGS:
            values[option.name] = self.optional(entries, setting.yaml_key, setting.path, readers[types[option.name]])
        return values

    def policy_options(self, given: dict[str, Any]) -> PolicyOptions:
        """The policy options of the well-formed ``given`` values.

        A setting out of range is reported at its line and left at its default.
        """
        try:
            return PolicyOptions(**given)
        except InputError as error:
            wrong = {problem.where for problem in error.problems}
            for problem in error.problems:
                self.problems.append(Problem(self.where(problem.where), f"{problem.where}: {problem.reason}"))
        paths = {option.name: setting.path for option, setting in POLICY_SETTINGS}
        return PolicyOptions(**{key: value for key, value in given.items() if paths.get(key) not in wrong})

    def faults(self, entries: dict[str, _Entry] | None, path: str, defaults: NetworkFaults) -> NetworkFaults:
        """Fault settings under ``path``; the ones not given keep their value in ``defaults``."""
        values = {key: self.optional(entries, key, f"{path}.{key}", self.number) for key in ("loss", "duplicate", "reorder")}
        delay = self.optional(entries, "delay", f"{path}.delay", self.delay)
        if delay is not None and delay is not _BAD:
            values["delay_min"], values["delay_max"] = delay
        return replace(defaults, **_given(values))

    def links(self, network_entries: dict[str, _Entry] | None, network: NetworkFaults) -> tuple[LinkFaults, ...]:
        """The ``network.links`` list: faults of particular directed links between robots."""
        if network_entries is None or "links" not in network_entries:
            return ()
        node = network_entries["links"].value
        if not isinstance(node, SequenceNode):
            self.report(_line(node), "network.links", f"expected a list of links, got {_describe(node, self.scalar(node))}")
            return ()
        links = []
        for index, item in enumerate(node.value):
            path = f"network.links[{index}]"
            self.lines[path] = _line(item)
            entries = self.mapping(item, path, LINK_KEYS, required=("from", "to"))
            if entries is None:
                continue
            ends = [self.optional(entries, key, f"{path}.{key}", self.label) for key in ("from", "to")]
            faults = self.faults(entries, path, network)
            if all(end is not None and end is not _BAD for end in ends):
                links.append(LinkFaults(ends[0], ends[1], faults))
        return tuple(links)

    def section(self, top: dict[str, _Entry], key: str, allowed: Sequence[str]) -> dict[str, _Entry] | None:
        """The entries of an optional sub-mapping (None when absent, null or wrong)."""
        if key not in top:
            return None
        node = top[key].value
        if isinstance(node, ScalarNode) and node.tag.endswith(":null"):
            return None
        return self.mapping(node, key, allowed)

    # -- whole file --------------------------------------------------------------------

    def read(self, root: Node) -> Scenario | None:
        """Build the scenario from the root node; None if anything was wrong."""
        self.lines[""] = _line(root)
        top = self.mapping(root, "", TOP_KEYS)
        if top is None:
            return None
        name = self.optional(top, "name", "name", self.label)
        name = Path(self.source).stem if name is None or name is _BAD else name
        description = self.optional(top, "description", "description", self.text)
        has_scen = "scen" in top
        if has_scen and "robots" in top:
            self.report(top["scen"].key_line, "scen", "give either robots or scen + agents, not both")
        if not has_scen and "agents" in top:
            self.report(top["agents"].key_line, "agents", "only allowed together with scen")
        for key in ("map", "robots"):
            if key not in top and not has_scen:
                self.report(_line(root), "", f"missing required key {key!r}")
                self.robot_trouble = self.robot_trouble or key == "robots"
        grid = self.read_map_section(top["map"].value, name) if "map" in top else None
        robots: list[tuple[int, RobotSpec]] = []
        if has_scen:
            grid, robots = self.read_scen_robots(top, grid)
        elif "robots" in top:
            robots = self.read_robots(top["robots"].value)
        timing, network, links, policy = self.read_settings(top)
        safety = self.optional(top, "safety", "safety", self.boolean)
        lifelong = self.optional(top, "lifelong", "lifelong", self.boolean)
        seed = self.optional(top, "seed", "seed", self.integer)
        max_ticks = self.optional(top, "max_ticks", "max_ticks", self.integer)
        scenario = Scenario(
            grid=grid if grid is not None else Grid(1, 1),
            robots=tuple(robot for _, robot in robots),
            timing=timing,
            network=network,
            links=links,
            policy=policy,
            safety=True if safety is None or safety is _BAD else safety,
            lifelong=False if lifelong is None or lifelong is _BAD else lifelong,
            seed=0 if seed is None or seed is _BAD else seed,
            max_ticks=None if max_ticks is _BAD else max_ticks,
            name=name,
            description="" if description is None or description is _BAD else description,
        )
        self.check_meaning(scenario, grid is not None, [index for index, _ in robots])
        return None if self.problems else scenario

    def check_meaning(self, scenario: Scenario, have_grid: bool, indices: list[int]) -> None:
        """Add :func:`scenario_problems`, placed at the lines of their fields."""

        def original(text: str) -> str:
            return _ROBOT_INDEX.sub(lambda m: f"robots[{indices[int(m.group(1))]}]", text)

        for problem in scenario_problems(scenario):
            if problem.where.startswith("robots") and (
                not have_grid or (problem.where == "robots" and self.robot_trouble)
            ):
                continue
            path = original(problem.where)
            reason = original(problem.reason) + self.obstacle_named(scenario, problem)
            self.problems.append(Problem(self.where(path), f"{path}: {reason}"))

    def obstacle_named(self, scenario: Scenario, problem: Problem) -> str:
        """For a robot's start or goal on a cell of ``map.obstacles``, which entry (and line) blocks it; else ``""``."""
        match = re.fullmatch(r"robots\[(\d+)\]\.(start|goal)", problem.where)
        if match is None or not problem.reason.endswith("is an obstacle"):
            return ""
        robot = scenario.robots[int(match.group(1))]
        cell = robot.start if match.group(2) == "start" else robot.goal
        if cell not in self.obstacles:
            return ""
        entry = f"map.obstacles[{self.obstacles[cell]}]"
        return f" ({entry}, line {self.lines[entry]}; cells are [x, y], x growing north)"


def _unusable(what: str, path: Path, problem: str) -> str:
    """Why the file a field names cannot be read, e.g. ``map file not found: x.map``.

    >>> _unusable("map file", Path("/dev/zero"), "is a device, not a file")
    'map file /dev/zero is a device, not a file'
    """
    return f"{what} not found: {path}" if problem == "file not found" else f"{what} {path} {problem}"


def _given(values: dict[str, Any]) -> dict[str, Any]:
    """The values that were given and well formed."""
    return {key: value for key, value in values.items() if value is not None and value is not _BAD}


def _yaml_error_problem(error: yaml.YAMLError, text: str, source: str) -> Problem:
    """One problem, with file and line, for a YAML syntax error."""
    if isinstance(error, yaml.MarkedYAMLError):
        mark = error.problem_mark or error.context_mark
        line = mark.line + 1 if mark is not None else 1
        reason = error.problem or error.context or "malformed YAML"
        if error.context and error.problem:
            started = error.context_mark
            at = f" started at line {started.line + 1}" if started is not None and started.line + 1 != line else ""
            reason = f"{error.problem} ({error.context}{at})"
        return Problem(f"{source}:{line}", f"invalid YAML: {reason}")
    position = getattr(error, "position", None)
    line = text.count("\n", 0, position) + 1 if isinstance(position, int) else 1
    reason = getattr(error, "reason", None) or str(error).splitlines()[0]
    return Problem(f"{source}:{line}", f"invalid YAML: {reason}")


class _TooDeep(yaml.MarkedYAMLError):
    """Lists and mappings nested deeper than :data:`~mrmp.core.limits.MAX_YAML_DEPTH`."""


class _DepthBoundedLoader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing to compose lists and mappings nested deeper than :data:`MAX_YAML_DEPTH`.

    PyYAML's parser is iterative, but its composer recurses once per level, so
    without a bound a deep file overflows the stack.
    """

    _depth = 0

    def compose_node(self, parent: Node | None, index: int) -> Node | None:
        if not self.check_event(SequenceStartEvent, MappingStartEvent):
            return super().compose_node(parent, index)
        self._depth += 1
        try:
            if self._depth > MAX_YAML_DEPTH:
                mark = self.peek_event().start_mark
                raise _TooDeep(problem=f"lists and mappings nested more than {MAX_YAML_DEPTH} levels deep", problem_mark=mark)
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


def _compose(text: str, source: str, expected: str) -> Node:
    """The YAML node tree of ``text``; invalid YAML, or an empty file (that should hold ``expected``), is an InputError.

    >>> _compose("a: " + "[" * 40 + "]" * 40, "deep.yaml", "a mapping")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: deep.yaml:1: lists and mappings nested more than 32 levels deep
    """
    try:
        root = yaml.compose(text, Loader=_DepthBoundedLoader)
    except _TooDeep as error:
        line = error.problem_mark.line + 1 if error.problem_mark is not None else 1
        raise InputError(Problem(f"{source}:{line}", str(error.problem))) from None
    except yaml.YAMLError as error:
        raise InputError(_yaml_error_problem(error, text, source)) from None
    if root is None:
        raise InputError(Problem(f"{source}:1", f"the file is empty: expected {expected}"))
    return root


def _problem_order(problem: Problem, source: str) -> tuple[bool, str, int]:
    """Sort key: problems of ``source`` first, then other files, each by line."""
    file, _, line = problem.where.rpartition(":")
    if not line.isdigit():
        file, line = problem.where, "0"
    return (file != source, file, int(line))


def _in_order(problems: Sequence[Problem], source: str) -> list[Problem]:
    """Problems of ``source`` first, by line, then those of the files it names (see :func:`_problem_order`)."""
    return sorted(problems, key=lambda problem: _problem_order(problem, source))


def scenario_from_text(
    text: str,
    source_name: str = "<scenario>",
    known_policies: Sequence[str] | None = None,
    base_dir: PathLike | None = None,
) -> Scenario:
    """Read a scenario from YAML text, strictly.

    Parameters
    ----------
    text:
        The YAML document.
    source_name:
        The file name used in problems and as the default scenario name (its stem).
    known_policies:
        When given, ``policy.name`` must be one of these.
    base_dir:
        The folder relative ``map.file`` and ``scen`` paths start from; by
        default the folder of ``source_name``.

    Returns
    -------
    Scenario
        The scenario, which also passes :func:`scenario_problems`.

    Raises
    ------
    InputError
        Listing every problem as ``source_name:line`` and ``field.path: reason``.

    Examples
    --------
    >>> text = "map: {width: 5, height: 5}\\nrobots:\\n  - {id: A, start: [0, 2], goal: [9, 2]}\\n"
    >>> scenario_from_text(text, "swap.yaml")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: swap.yaml:3: robots[0].goal: cell (9, 2) is outside the 5x5 grid
    """
    folder = Path(source_name).parent if base_dir is None else Path(base_dir)
    root = _compose(text, source_name, "a mapping with map and robots")
    if not isinstance(root, MappingNode):
        kind = "a list" if isinstance(root, SequenceNode) else f"a single value {root.value!r}"
        raise InputError(
            Problem(
                f"{source_name}:{_line(root)}", f"the top level must be a mapping (name, map, robots, ...), got {kind}"
            )
        )
    policies = tuple(known_policies) if known_policies is not None else None
    reader = _Reader(source_name, folder, policies)
    scenario = reader.read(root)
    if scenario is None:
        raise InputError(_in_order(reader.problems, source_name))
    return scenario


def load_scenario(path: PathLike, known_policies: Sequence[str] | None = None) -> Scenario:
    """Read a YAML scenario file, strictly (see :func:`scenario_from_text`).

    Parameters
    ----------
    path:
        The ``.yaml`` file; ``map.file`` and ``scen`` are relative to its folder.
    known_policies:
        When given, ``policy.name`` must be one of these.

    Returns
    -------
    Scenario
        The checked scenario; its name defaults to the file's stem.

    Raises
    ------
    InputError
        If the file cannot be read or anything in it is wrong (every problem
        listed as ``file:line: field.path: reason``).
    """
    return scenario_from_text(read_text(path), str(path), known_policies, Path(path).parent)


def load_movingai_scenario(map_path: PathLike, scen_path: PathLike, agents: int | None) -> Scenario:
    """The first ``agents`` agents of a MovingAI ``.scen`` file on its ``.map``, as a scenario.

    Robots are named ``"0"``, ``"1"``, ... and face NORTH; the scenario is named
    after the ``.scen`` file and uses default timing, network and policy.

    Parameters
    ----------
    map_path:
        The ``.map`` file.
    scen_path:
        The ``.scen`` file.
    agents:
        How many agents to take from the top of the ``.scen`` file (None: all).

    Returns
    -------
    Scenario
        The checked scenario.

    Raises
    ------
    InputError
        If a file is missing or malformed, the sizes differ, the file lists fewer
        agents than asked, or a robot's cells are wrong on the map (named by the
        ``.scen`` line of that agent).
    """
    grid = read_map(map_path)
    source = str(scen_path)
    entries = parse_scen(read_text(scen_path), source)
    mismatch = scen_map_problems(entries, grid, source)
    if mismatch:
        raise InputError(mismatch)
    chosen = select_agents(entries, agents, source)
    scenario = Scenario(
        grid=grid,
        robots=tuple(entry.robot(str(index)) for index, entry in enumerate(chosen)),
        name=Path(scen_path).stem,
        description=f"first {agents} agents of {Path(scen_path).name} on {Path(map_path).name}",
    )
    problems = []
    for problem in scenario_problems(scenario):
        match = _ROBOT_INDEX.match(problem.where)
        where = f"{source}:{chosen[int(match.group(1))].line}" if match else source
        problems.append(Problem(where, f"{problem.where}: {problem.reason}"))
    if problems:
        raise InputError(problems)
    return scenario


# -- writing ---------------------------------------------------------------------------


def _yaml_float(value: float) -> str:
    """A float as text that PyYAML's YAML 1.1 resolver reads back as the same float.

    >>> _yaml_float(0.5), _yaml_float(1e-05), _yaml_float(float("inf"))
    ('0.5', '1.0e-05', '.inf')
    """
    if math.isnan(value):
        return ".nan"
    if math.isinf(value):
        return ".inf" if value > 0 else "-.inf"
    text = repr(float(value))
    if "e" in text:
        mantissa, exponent = text.split("e")
        if "." not in mantissa:
            mantissa += ".0"
        if exponent[0] not in "+-":
            exponent = "+" + exponent
        text = f"{mantissa}e{exponent}"
    return text


def _quote(text: str) -> str:
    """A YAML double-quoted string (JSON's quoting is valid YAML)."""
    return json.dumps(text, ensure_ascii=False)


def _cell_text(cell: Cell) -> str:
    """``[x, y]``."""
    return f"[{cell[0]}, {cell[1]}]"


def _faults_text(faults: NetworkFaults) -> str:
    """Fault settings as YAML flow-mapping entries."""
    delay = (
        str(faults.delay_min) if faults.delay_min == faults.delay_max else _quote(f"{faults.delay_min}..{faults.delay_max}")
    )
    return (
        f"loss: {_yaml_float(faults.loss)}, delay: {delay}, "
        f"duplicate: {_yaml_float(faults.duplicate)}, reorder: {_yaml_float(faults.reorder)}"
    )


def _setting_text(value: object) -> str:
    """A policy setting's value as YAML: a quoted text, true or false, a number."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return _quote(value) if isinstance(value, str) else str(value)


def _policy_text(policy: PolicyOptions) -> str:
    """The ``policy`` section's items: its name, then every setting by its YAML key.

    >>> _policy_text(PolicyOptions())  # doctest: +NORMALIZE_WHITESPACE
    'name: "thesis", resolve: "divert", heading_aware: false, radius: 2, swap: true, search: "default",
     sequencing: "local", synchronizer: "clock", body: "omni", guidance: "none"'
    """
    items = [f"name: {_quote(policy.name)}"]
    items += [f"{setting.yaml_key}: {_setting_text(getattr(policy, option.name))}" for option, setting in POLICY_SETTINGS]
    return ", ".join(items)


def scenario_to_yaml(scenario: Scenario, map_file: str | None = None) -> str:
    """The YAML text of ``scenario``, readable by :func:`scenario_from_text`.

    Parameters
    ----------
    scenario:
        The scenario to write.
    map_file:
        When given, the map is written as ``map: {file: map_file}`` instead of
        inline rows (the caller keeps that file next to the YAML).

    Returns
    -------
    str
        The YAML document. With inline rows, loading it gives back an equal scenario.

    Raises
    ------
    ValueError
        If a cell cost cannot be drawn as a map symbol (only whole costs 1-9 can).

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> scenario = Scenario(Grid.from_rows(["..", ".@"]), (RobotSpec("A", (0, 0), (1, 0)),), name="tiny")
    >>> scenario_from_text(scenario_to_yaml(scenario), "x.yaml") == scenario
    True
    """
    grid = scenario.grid
    lines = [f"name: {_quote(scenario.name)}"]
    if scenario.description:
        lines.append(f"description: {_quote(scenario.description)}")
    if map_file is not None:
        lines += ["map:", f"  file: {_quote(map_file)}"]
    else:
        for cell, cost in grid.costs().items():
            if cost not in COST_SYMBOLS.values():
                raise ValueError(f"cell {cell} costs {cost}: only whole costs 1-9 can be written as map symbols")
        lines += ["map:", "  rows:"] + [f"    - {_quote(row)}" for row in grid.to_rows()]
    lines.append("robots:")
    for robot in scenario.robots:
        start, goal = _cell_text(robot.start), _cell_text(robot.goal)
        lines.append(f"  - {{id: {_quote(robot.id)}, start: {start}, goal: {goal}, heading: {robot.heading.name}}}")
    timing, network, policy = scenario.timing, scenario.network, scenario.policy
    lines.append(f"timing: {{cell_time: {_yaml_float(timing.cell_time)}, turn_time: {_yaml_float(timing.turn_time)}}}")
    lines.append(f"network: {{{_faults_text(network)}}}")
    if scenario.links:
        lines[-1] = "network:"
        lines += [f"  {setting}" for setting in _faults_text(network).split(", ")]
        lines.append("  links:")
        for link in scenario.links:
            ends = f"from: {_quote(link.sender)}, to: {_quote(link.recipient)}"
            lines.append(f"    - {{{ends}, {_faults_text(link.faults)}}}")
    lines.append(f"policy: {{{_policy_text(policy)}}}")
    if not scenario.safety:
        lines.append("safety: false")
    if scenario.lifelong:
        lines.append("lifelong: true")
    lines.append(f"seed: {scenario.seed}")
    if scenario.max_ticks is not None:
        lines.append(f"max_ticks: {scenario.max_ticks}")
    return "\n".join(lines) + "\n"


def save_scenario(scenario: Scenario, path: PathLike, map_file: str | None = None) -> None:
    """Write ``scenario`` as a YAML file (atomically); see :func:`scenario_to_yaml`.

    Raises
    ------
    ValueError
        If a cell cost cannot be drawn as a map symbol.
    InputError
        If the file cannot be written.
    """
    atomic_write_text(path, scenario_to_yaml(scenario, map_file))
