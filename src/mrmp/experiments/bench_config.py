"""The YAML benchmark configuration of ``mrmp bench``, read strictly and expanded into runs.

A configuration looks like this (``maps`` and ``policies`` are required, and ``agents`` where a map entry
has none)::

    name: standard                     # default: the file's stem
    maps:                              # MovingAI files (paths relative to this file) ...
      - map: ../maps/random-32-32-20.map
        scen: [../maps/random-32-32-20-random-1.scen]
        agents: [10, 20]               # optional: this map's own numbers of robots
      - map: ../maps/empty-32-32.map   # ... or a map with K seeded random instances
        instances: 2
      - generate: random               # ... or generated maps: random, maze, warehouse, room
        width: 32
        height: 32
        density: 0.2                   # the family's settings (mrmp.core.map_generators)
        seeds: [0, 1]                  # one map per seed (not for warehouse: it has none)
        instances: 2                   # seeded random starts and goals per map
      - lorr: ../../examples/lorr/maze-example_40.json   # ... or a League of Robot Runners problem:
        agents: [20, 40]               # its first N robots (default: its teamSize), lifelong, max_ticks steps
    agents: [10, 50]                   # numbers of robots
    policies: [thesis, astar, pibt, cbs, pp, lacam]   # decentralized policies and central planners
    seeds: [0, 1]                      # each run's seed (the simulated network's; LaCAM's)
    faults:                            # optional; default: one perfect network
      - {loss: 0.0}
      - {loss: 0.1, delay: [0, 2], duplicate: 0.0, reorder: 0.0}
    time_limit: 30                     # wall-clock seconds per run (default 60)
    max_ticks: 500                     # optional tick limit (a LoRR problem's steps; default 5000)
    lifelong: false                    # true: new goals on arrival (decentralized policies only)

The file is read with the node reader of :mod:`mrmp.io.scenario_file`, so
every problem -- an unknown key, a wrong type, a missing file, an unknown
policy -- is reported as ``file:line: field: reason``, all of them together in
one :class:`~mrmp.core.errors.InputError`. A number of robots larger than a
``.scen`` file lists, or than a map's largest connected region holds, is not
an error: that combination is left out, with a note.

Examples
--------
>>> text = '''
... maps:
...   - {generate: random, width: 8, height: 8, density: 0.1, seeds: [1]}
... agents: [2, 3]
... policies: [pibt, pp]
... '''
>>> config = bench_config_from_text(text, "demo.yaml")
>>> config.name, len(config.runs), config.runs[0].map_name, config.runs[-1].policy
('demo', 4, 'gen:random-8x8-p0.10-s1', 'pp')
>>> bench_config_from_text(text.replace("policies", "policy"), "demo.yaml")
Traceback (most recent call last):
...
mrmp.core.errors.InputError: demo.yaml:2: missing required key 'policies'
demo.yaml:5: unknown key 'policy' (did you mean 'policies'?)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from mrmp.centralized.registry import PLANNER_NAMES
from mrmp.core.errors import InputError
from mrmp.core.grid import Grid, grid_size_problem
from mrmp.core.limits import MAX_BENCH_MAPS, MAX_BENCH_RUNS, MAX_ROBOTS, MAX_RUN_SECONDS, MAX_TICKS, shown
from mrmp.core.map_generators import GENERATORS, complete_spec, generate, largest_region
from mrmp.core.scenario import NetworkFaults, _fault_problems
from mrmp.experiments.matrix import BenchRun
from mrmp.io._files import PathLike, file_problem, read_text
from mrmp.io.lorr import read_lorr_problem
from mrmp.io.movingai import read_map, read_scen_entries, scen_map_problems
from mrmp.io.scenario_file import (
    _BAD,
    FAULT_KEYS,
    _compose,
    _describe,
    _in_order,
    _line,
    _Reader,
    _unusable,
)
from mrmp.sim.policy_table import policy_names

TOP_KEYS = ("name", "maps", "agents", "policies", "seeds", "faults", "time_limit", "max_ticks", "lifelong")
"""Keys allowed at the top level of a benchmark configuration."""
FILE_MAP_KEYS = ("map", "scen", "instances", "agents")
"""Keys allowed in a ``maps`` entry naming a MovingAI map."""
_GENERATOR_SETTINGS = tuple(dict.fromkeys(p.name for g in GENERATORS.values() for p in g.parameters))
GENERATED_MAP_KEYS = ("generate", "width", "height", *_GENERATOR_SETTINGS, "seeds", "instances", "agents")
"""Keys allowed in a ``maps`` entry describing generated maps."""
LORR_MAP_KEYS = ("lorr", "agents")
"""Keys allowed in a ``maps`` entry naming a League of Robot Runners problem."""
DEFAULT_TIME_LIMIT_S = 60.0
"""Wall-clock seconds a run may take when the configuration sets no ``time_limit``."""


def method_names() -> tuple[str, ...]:
    """Every name ``policies`` accepts: the policy table's policies, then the central planners.

    >>> method_names()
    ('thesis', 'astar', 'pibt', 'causal', 'cbs', 'pp', 'lacam')
    """
    return (*policy_names(), *PLANNER_NAMES)



@dataclass(frozen=True)
class BenchConfig:
    """A benchmark configuration, expanded.

    Attributes
    ----------
    name:
        The benchmark's name.
    runs:
        Every run of the matrix, in the configuration's order (maps, their
        instances, numbers of robots, policies, seeds, faults).
    notes:
        One line per combination left out (more robots than an instance offers).
    """

    name: str
    runs: tuple[BenchRun, ...]
    notes: tuple[str, ...] = field(default=())


@dataclass(frozen=True)
class _Instance:
    """One instance family of a map: where it comes from and how many robots it can hold."""

    map_name: str
    capacity: int
    capacity_reason: str
    agents: tuple[int, ...] | None
    map_path: str | None = None
    scen: str | None = None
    generator: tuple[tuple[str, Any], ...] | None = None
    instance: int | None = None
    lorr: str | None = None
    """A League of Robot Runners problem file."""


class _BenchReader(_Reader):
    """The scenario reader's value checks, applied to a benchmark configuration."""

    def items(self, entries: dict[str, Any], key: str, path: str) -> list[Node] | None:
        """The item nodes of a non-empty list at ``key`` (None when absent, null or wrong)."""
        if key not in entries:
            return None
        node = entries[key].value
        if isinstance(node, ScalarNode) and node.tag.endswith(":null"):
            return None
        if not isinstance(node, SequenceNode) or not node.value:
            got = "an empty list" if isinstance(node, SequenceNode) else _describe(node, self.scalar(node))
            self.report(_line(node), path, f"expected a non-empty list, got {got}")
            return None
        return list(node.value)

    def positive_list(
        self, entries: dict[str, Any], key: str, path: str, smallest: int = 1, largest: int | None = None
    ) -> list[int] | None:
        """A list of distinct integers, each at least ``smallest`` (and at most ``largest`` when given)."""
        nodes = self.items(entries, key, path)
        if nodes is None:
            return None
        values: list[int] = []
        for index, node in enumerate(nodes):
            value = self.integer(node, f"{path}[{index}]")
            if value is _BAD:
                continue
            if value < smallest:
                self.report(_line(node), f"{path}[{index}]", f"must be at least {smallest}, got {value}")
            elif largest is not None and value > largest:
                self.report(_line(node), f"{path}[{index}]", f"must be at most {largest}, got {value}")
            elif value in values:
                self.report(_line(node), f"{path}[{index}]", f"{value} is listed twice")
            else:
                values.append(value)
        return values

    def bounded(
        self, entries: dict[str, Any], key: str, path: str, read: Any, smallest: float, largest: float | None = None
    ) -> Any:
        """An optional number read with ``read`` that must be at least ``smallest`` (and at most ``largest``)."""
        value = self.optional(entries, key, path, read)
        if value is not None and value is not _BAD and not value >= smallest:
            self.report(entries[key].key_line, path, f"must be at least {smallest:g}, got {value}")
            return _BAD
        if value is not None and value is not _BAD and largest is not None and not value <= largest:
            self.report(entries[key].key_line, path, f"must be at most {shown(largest)}, got {value}")
            return _BAD
        return value

    def file(self, node: Node, path: str, what: str) -> Path | None:
        """An existing file named relative to the configuration's folder."""
        relative = self.text(node, path)
        if relative is _BAD:
            return None
        file = (self.base_dir / relative).resolve()
        problem = file_problem(file)
        if problem is not None:
            self.report(_line(node), path, _unusable(what, self.base_dir / relative, problem))
            return None
        return file

    # -- maps --------------------------------------------------------------------------

    def map_entry(self, node: Node, path: str) -> list[_Instance]:
        """The instance families of one ``maps`` entry."""
        keys = {key.value for key, _ in node.value if isinstance(key, ScalarNode)} if isinstance(node, MappingNode) else set()
        if "generate" in keys:
            return self.generated_entry(node, path)
        if "lorr" in keys:
            return self.lorr_entry(node, path)
        entries = self.mapping(node, path, FILE_MAP_KEYS, required=("map",))
        if entries is None or "map" not in entries:
            return []
        agents = self.positive_list(entries, "agents", f"{path}.agents", largest=MAX_ROBOTS)
        agents_given = tuple(agents) if agents else None
        map_file = self.file(entries["map"].value, f"{path}.map", "map file")
        if ("scen" in entries) == ("instances" in entries):
            self.report(_line(node), path, "give either scen: [files] or instances: K next to map")
            return []
        grid: Grid | None = None
        if map_file is not None:
            try:
                grid = read_map(map_file)
            except InputError as error:
                self.problems.extend(error.problems)
        if "instances" in entries:
            count = self.bounded(entries, "instances", f"{path}.instances", self.integer, 1, MAX_BENCH_RUNS)
            if map_file is None or grid is None or count is _BAD or count is None:
                return []
            capacity = len(largest_region(grid))
            return [
                _Instance(map_file.stem, capacity, f"its largest connected region has {capacity} free cells",
                          agents_given, map_path=str(map_file), instance=index)
                for index in range(count)
            ]  # fmt: skip
        instances = []
        for index, scen_node in enumerate(self.items(entries, "scen", f"{path}.scen") or []):
            scen_file = self.file(scen_node, f"{path}.scen[{index}]", "scenario file")
            if scen_file is None or map_file is None or grid is None:
                continue
            try:
                scen_entries = read_scen_entries(scen_file)
                problems = scen_map_problems(scen_entries, grid, str(scen_file))
            except InputError as error:
                problems = list(error.problems)
            if problems:
                self.problems.extend(problems)
                continue
            reason = f"{scen_file.name} lists {len(scen_entries)} agents"
            instances.append(
                _Instance(map_file.stem, len(scen_entries), reason, agents_given, str(map_file), str(scen_file))
            )
        return instances

    def generated_entry(self, node: Node, path: str) -> list[_Instance]:
        """The instance families of one ``generate:`` entry."""
        entries = self.mapping(node, path, GENERATED_MAP_KEYS, required=("generate", "width", "height"))
        if entries is None or "generate" not in entries:
            return []
        kind = self.text(entries["generate"].value, f"{path}.generate")
        if kind is _BAD:
            return []
        if kind not in GENERATORS:
            self.report(entries["generate"].key_line, f"{path}.generate",
                        f"unknown map generator {kind!r}; known: {', '.join(GENERATORS)}")  # fmt: skip
            return []
        generator = GENERATORS[kind]
        allowed = {p.name for p in generator.parameters}
        for key in _GENERATOR_SETTINGS:
            if key in entries and key not in allowed:
                self.report(entries[key].key_line, f"{path}.{key}",
                            f"{kind} maps take no {key!r} (their settings: {', '.join(sorted(allowed)) or 'none'})")  # fmt: skip
        spec: dict[str, Any] = {"kind": kind}
        ok = True
        for key in ("width", "height"):
            value = self.bounded(entries, key, f"{path}.{key}", self.integer, 1)
            ok = ok and value is not _BAD and value is not None
            spec[key] = value
        if ok:
            too_large = grid_size_problem(spec["height"], spec["width"])
            if too_large is not None:
                self.report(_line(node), path, too_large)
                ok = False
        for parameter in generator.parameters:
            read = self.integer if parameter.kind is int else self.number
            value = self.bounded(entries, parameter.name, f"{path}.{parameter.name}", read, parameter.minimum)
            if value is _BAD:
                ok = False
            elif value is not None:
                spec[parameter.name] = value
        seeds: list[int | None] = [None]
        if generator.seeded:
            given = self.positive_list(entries, "seeds", f"{path}.seeds", smallest=0)
            seeds = list(given) if given else [0]
        elif "seeds" in entries:
            self.report(entries["seeds"].key_line, f"{path}.seeds", f"{kind} maps are not random: leave seeds out")
        count = self.bounded(entries, "instances", f"{path}.instances", self.integer, 1, MAX_BENCH_RUNS)
        agents = self.positive_list(entries, "agents", f"{path}.agents", largest=MAX_ROBOTS)
        if ok and len(seeds) > MAX_BENCH_MAPS:
            self.report(entries["seeds"].key_line, f"{path}.seeds", f"at most {MAX_BENCH_MAPS} maps, got {len(seeds)} seeds")
            ok = False
        if not ok or count is _BAD:
            return []
        instances = []
        for seed in seeds:
            seeded = dict(spec, seed=seed) if seed is not None else dict(spec)
            try:
                grid = generate(seeded)
            except ValueError as error:
                self.report(_line(node), path, str(error))
                return []
            capacity = len(largest_region(grid))
            generator_key = tuple(sorted(complete_spec(seeded).items()))
            for index in range(count or 1):
                instances.append(
                    _Instance(grid.name, capacity, f"it has {capacity} free cells", tuple(agents) if agents else None,
                              generator=generator_key, instance=index)
                )  # fmt: skip
        return instances

    def lorr_entry(self, node: Node, path: str) -> list[_Instance]:
        """The one instance of a ``lorr:`` entry: the problem, its first N robots for each of ``agents`` (default:
        its ``teamSize``)."""
        entries = self.mapping(node, path, LORR_MAP_KEYS, required=("lorr",))
        if entries is None or "lorr" not in entries:
            return []
        agents = self.positive_list(entries, "agents", f"{path}.agents", largest=MAX_ROBOTS)
        problem_file = self.file(entries["lorr"].value, f"{path}.lorr", "LoRR problem file")
        if problem_file is None:
            return []
        try:
            problem = read_lorr_problem(problem_file)
        except InputError as error:
            self.problems.extend(error.problems)
            return []
        reason = f"its teamSize is {problem.team_size}"
        counts = tuple(agents) if agents else (problem.team_size,)
        return [_Instance(problem.name, problem.team_size, reason, counts, lorr=str(problem_file))]

    def lorr_policy_problems(self, policies: list[str], node: Node, path: str) -> None:
        """Report each central planner among ``policies``: a LoRR problem is lifelong."""
        for policy in policies:
            if policy in PLANNER_NAMES:
                self.report(_line(node), path, f"LoRR problems are lifelong: {policy} is a central planner")

    # -- whole file --------------------------------------------------------------------

    def read_config(self, root: Node, time_limit_override: float | None) -> BenchConfig | None:
        """Expand the configuration into runs; None if anything was wrong."""
        top = self.mapping(root, "", TOP_KEYS, required=("maps", "policies"))
        if top is None:
            return None
        name = self.optional(top, "name", "name", self.label)
        name = Path(self.source).stem if name is None or name is _BAD else name
        instances: list[_Instance] = []
        map_nodes = self.items(top, "maps", "maps") or []
        if len(map_nodes) > MAX_BENCH_MAPS:
            self.report(top["maps"].key_line, "maps", f"at most {MAX_BENCH_MAPS} maps, got {len(map_nodes)}")
            map_nodes = []
        entry_of: dict[int, tuple[Node, str]] = {}
        for index, node in enumerate(map_nodes):
            self.lines[f"maps[{index}]"] = _line(node)
            found = self.map_entry(node, f"maps[{index}]")
            entry_of.update((id(family), (node, f"maps[{index}]")) for family in found)
            instances += found
            if len({instance.generator or instance.map_path or instance.lorr for instance in instances}) > MAX_BENCH_MAPS:
                self.report(_line(node), f"maps[{index}]", f"the configuration reaches more than {MAX_BENCH_MAPS} maps")
                break
        agents = self.positive_list(top, "agents", "agents", largest=MAX_ROBOTS) or []
        if "agents" not in top:
            for family in instances:
                if family.agents is None:
                    node, path = entry_of[id(family)]
                    self.report(_line(node), path, "give agents: [N, ...] here or at the top level")
                    break
        policies = self.policies(top)
        seeds = self.positive_list(top, "seeds", "seeds", smallest=0) or [0]
        faults = self.fault_list(top)
        time_limit = self.bounded(top, "time_limit", "time_limit", self.number, 0.001, MAX_RUN_SECONDS)
        max_ticks = self.bounded(top, "max_ticks", "max_ticks", self.integer, 1, MAX_TICKS)
        lifelong = self.optional(top, "lifelong", "lifelong", self.boolean)
        for family in instances:
            if family.lorr is not None:
                self.lorr_policy_problems(policies, *entry_of[id(family)])
        if lifelong is True:
            central = [policy for policy in policies if policy in PLANNER_NAMES]
            if central:
                self.report(top["lifelong"].key_line, "lifelong",
                            f"lifelong runs use decentralized policies only; remove {', '.join(central)}")  # fmt: skip
        matrix = sum(len(family.agents or agents) for family in instances) * len(policies) * len(seeds) * len(faults)
        if matrix > MAX_BENCH_RUNS:
            self.report(_line(root), "", f"the matrix has {matrix} runs, more than the bound of {MAX_BENCH_RUNS}")
        if self.problems:
            return None
        limit = time_limit_override or (time_limit if time_limit is not None else DEFAULT_TIME_LIMIT_S)
        runs: list[BenchRun] = []
        notes: list[str] = []
        for family in instances:
            for count in family.agents or tuple(agents):
                if count > family.capacity:
                    label = family.map_name + (f" instance {family.instance}" if family.instance is not None else "")
                    notes.append(f"skipped N={count} on {label}: {family.capacity_reason}")
                    continue
                for policy in policies:
                    for seed in seeds:
                        for network in faults:
                            runs.append(
                                BenchRun(
                                    map_name=family.map_name, agents=count, policy=policy, map_path=family.map_path,
                                    scen=family.scen, generator=family.generator, instance=family.instance,
                                    lorr=family.lorr,
                                    seed=seed, faults=network, lifelong=bool(lifelong) or family.lorr is not None,
                                    max_ticks=max_ticks,
                                    time_limit_s=float(limit), bench=name,
                                )
                            )  # fmt: skip
        unique: dict[str, BenchRun] = {}
        for run in runs:
            unique.setdefault(run.run_id, run)
        return BenchConfig(name, tuple(unique.values()), tuple(dict.fromkeys(notes)))

    def policies(self, top: dict[str, Any]) -> list[str]:
        """The ``policies`` list: known, distinct method names."""
        names: list[str] = []
        for index, node in enumerate(self.items(top, "policies", "policies") or []):
            value = self.text(node, f"policies[{index}]")
            if value is _BAD:
                continue
            known = method_names()
            if value not in known:
                self.report(_line(node), f"policies[{index}]",
                            f"unknown policy or planner {value!r}; known: {', '.join(known)}")  # fmt: skip
            elif value in names:
                self.report(_line(node), f"policies[{index}]", f"{value!r} is listed twice")
            else:
                names.append(value)
        return names

    def fault_list(self, top: dict[str, Any]) -> list[NetworkFaults]:
        """The ``faults`` list (default: one perfect network)."""
        nodes = self.items(top, "faults", "faults")
        if nodes is None:
            return [NetworkFaults()]
        networks: list[NetworkFaults] = []
        for index, node in enumerate(nodes):
            path = f"faults[{index}]"
            entries = self.mapping(node, path, FAULT_KEYS)
            if entries is None:
                continue
            before = len(self.problems)
            network = self.faults(entries, path, NetworkFaults())
            if len(self.problems) > before:
                continue
            for problem in _fault_problems(network, path):
                key = problem.where.rpartition(".")[2]
                line = entries[key].key_line if key in entries else _line(node)
                self.report(line, problem.where, problem.reason)
            if network in networks:
                self.report(_line(node), path, f"the same faults as faults[{networks.index(network)}]")
            networks.append(network)
        return networks


def bench_config_from_text(
    text: str, source_name: str = "<bench>", base_dir: PathLike | None = None, time_limit: float | None = None
) -> BenchConfig:
    """Read a benchmark configuration from YAML text, strictly, and expand it into runs.

    Parameters
    ----------
    text:
        The YAML document.
    source_name:
        The file name used in problems and as the default benchmark name (its stem).
    base_dir:
        The folder relative paths start from; by default the folder of ``source_name``.
    time_limit:
        When given, replaces the configuration's ``time_limit``.

    Returns
    -------
    BenchConfig
        The runs, and notes about combinations left out.

    Raises
    ------
    InputError
        Listing every problem as ``source_name:line: field: reason``.
    """
    folder = Path(source_name).parent if base_dir is None else Path(base_dir)
    root = _compose(text, source_name, "a mapping with maps, agents, policies")
    reader = _BenchReader(source_name, folder, None)
    config = reader.read_config(root, time_limit)
    if config is None:
        raise InputError(_in_order(reader.problems, source_name))
    return config


def load_bench_config(path: PathLike, time_limit: float | None = None) -> BenchConfig:
    """Read a benchmark configuration file (see :func:`bench_config_from_text`); paths are relative to it.

    Raises
    ------
    InputError
        If the file cannot be read or anything in it is wrong.
    """
    return bench_config_from_text(read_text(path), str(path), Path(path).parent, time_limit)
