"""Check any input file mrmp reads (a YAML scenario, a ``.map``, a ``.scen``, a LoRR problem ``.json``) and list its problems.

Unlike the loaders, :func:`validate_file` never raises for bad input: it
returns every problem it found (an empty list means the file is fine).

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> _ = (folder / "ok.map").write_text("type octile\\nheight 1\\nwidth 2\\nmap\\n..\\n")
>>> validate_file(folder / "ok.map")
[]
>>> _ = (folder / "bad.map").write_text("type octile\\nheight 2\\nwidth 2\\nmap\\n..\\n")
>>> [problem.reason for problem in validate_file(folder / "bad.map")]
["expected 2 map rows after 'map' (the header's height), found 1"]
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

from mrmp.core.errors import InputError, Problem
from mrmp.core.scenario import Scenario, scenario_problems
from mrmp.io._files import PathLike, file_problem
from mrmp.io.lorr import read_lorr_problem
from mrmp.io.movingai import ScenEntry, read_map, read_scen_entries, scen_map_problems
from mrmp.io.scenario_file import load_scenario

SCENARIO_SUFFIXES = (".yaml", ".yml")
"""File name endings of YAML scenarios."""

_ROBOT_FIELD = re.compile(r"^robots\[(\d+)\]\.?(.*)$")
_ROBOT_INDEX = re.compile(r"robots\[(\d+)\]")


def _agent_problems(scenario: Scenario, group: Sequence[ScenEntry], source: str) -> list[Problem]:
    """:func:`scenario_problems` of the agents in ``group``, placed at their ``.scen`` lines.

    ``robots[i].start`` becomes ``source:line`` of agent i with the reason
    ``start: ...``; a reference to another agent names that agent's line.
    """

    def line_of(match: re.Match[str]) -> str:
        return f"the agent on line {group[int(match.group(1))].line}"

    problems = []
    for problem in scenario_problems(scenario):
        match = _ROBOT_FIELD.match(problem.where)
        if match is None:
            problems.append(Problem(source, f"{problem.where}: {problem.reason}"))
            continue
        entry = group[int(match.group(1))]
        reason = _ROBOT_INDEX.sub(line_of, problem.reason)
        problems.append(Problem(f"{source}:{entry.line}", f"{match.group(2)}: {reason}"))
    return problems


def _scen_problems(path: Path) -> list[Problem]:
    """Problems of a ``.scen`` file checked against the map(s) it names, found next to it."""
    entries = read_scen_entries(path)
    source = str(path)
    if not entries:
        return [Problem(f"{source}:1", "the file lists no agents")]
    by_map: dict[str, list[ScenEntry]] = {}
    for entry in entries:
        by_map.setdefault(entry.map_name, []).append(entry)
    problems: list[Problem] = []
    for map_name, group in by_map.items():
        map_path = path.parent / map_name
        unusable = file_problem(map_path)
        if unusable is not None:
            reason = f"map file {map_name!r} not found next to the file (looked for {map_path})"
            if unusable != "file not found":
                reason = f"map file {map_name!r} next to the file ({map_path}) {unusable}"
            problems.append(Problem(f"{source}:{group[0].line}", reason))
            continue
        try:
            grid = read_map(map_path)
        except InputError as error:
            problems.extend(error.problems)
            continue
        mismatch = scen_map_problems(group, grid, source)
        if mismatch:
            problems.extend(mismatch)
            continue
        scenario = Scenario(grid, tuple(entry.robot(str(index)) for index, entry in enumerate(group)))
        problems.extend(_agent_problems(scenario, group, source))
    return problems


def validate_file(path: PathLike, known_policies: Sequence[str] | None = None) -> list[Problem]:
    """Every problem with an input file, or an empty list when it is fine.

    Parameters
    ----------
    path:
        A scenario (``.yaml`` / ``.yml``), a MovingAI map (``.map``) or a
        MovingAI agent list (``.scen``), or a League of Robot Runners problem
        (``.json``, :mod:`mrmp.io.lorr`, with the map, agents and tasks files it
        names). A ``.scen`` file is checked against the
        map each of its lines names, looked up in the ``.scen`` file's folder:
        sizes must match, and every start and goal must be a free cell, unique
        in the file, with the goal reachable from the start.
    known_policies:
        For scenarios: when given, ``policy.name`` must be one of these.

    Returns
    -------
    list[Problem]
        Each problem names ``file:line`` and says what is wrong.
    """
    file = Path(path)
    suffix = file.suffix.lower()
    try:
        if suffix in SCENARIO_SUFFIXES:
            load_scenario(file, known_policies)
            return []
        if suffix == ".map":
            read_map(file)
            return []
        if suffix == ".scen":
            return _scen_problems(file)
        if suffix == ".json":
            read_lorr_problem(file)
            return []
    except InputError as error:
        return list(error.problems)
    return [Problem(str(file), f"unknown file type {file.suffix or '(none)'!r}: expected .yaml, .yml, .map, .scen or .json")]
