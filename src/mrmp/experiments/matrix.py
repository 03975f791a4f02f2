"""The parameters of one benchmark run, and its stable identity.

A benchmark is a matrix: maps (MovingAI files or generated) x instances x
numbers of robots x methods (decentralized policies and central planners) x
seeds x network faults. Each cell of the matrix is a :class:`BenchRun`, a
frozen record of plain values that can cross process boundaries as JSON. Its
:attr:`~BenchRun.run_id` is the first 16 hex digits of the SHA-256 of the
canonical JSON of its parameters (sorted keys, no spaces), so the same run in
a later invocation -- or on another machine -- has the same id, which is how
an interrupted benchmark resumes. Paths enter the id only by file name, so a
checkout moved elsewhere keeps its ids.

Examples
--------
>>> run = BenchRun(map_name="empty-32-32", map_path="maps/empty-32-32.map",
...                scen="maps/empty-32-32-random-1.scen", agents=10, policy="pibt")
>>> run.kind, len(run.run_id), run.run_id == BenchRun.from_dict(run.to_dict()).run_id
('decentralized', 16, True)
>>> run.with_changes(seed=1).run_id != run.run_id
True
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field, replace
from pathlib import PurePath
from typing import Any

from mrmp.centralized.registry import PLANNER_NAMES
from mrmp.core.scenario import NetworkFaults


def faults_to_dict(faults: NetworkFaults) -> dict[str, Any]:
    """The record form of network faults: ``{loss, delay: [min, max], duplicate, reorder}``.

    >>> faults_to_dict(NetworkFaults(loss=0.1, delay_max=2))
    {'loss': 0.1, 'delay': [0, 2], 'duplicate': 0.0, 'reorder': 0.0}
    """
    return {
        "loss": faults.loss,
        "delay": [faults.delay_min, faults.delay_max],
        "duplicate": faults.duplicate,
        "reorder": faults.reorder,
    }


def faults_from_dict(data: dict[str, Any]) -> NetworkFaults:
    """The inverse of :func:`faults_to_dict`.

    >>> faults_from_dict({"loss": 0.1, "delay": [0, 2], "duplicate": 0.0, "reorder": 0.0}).delay_max
    2
    """
    low, high = data["delay"]
    return NetworkFaults(float(data["loss"]), int(low), int(high), float(data["duplicate"]), float(data["reorder"]))


@dataclass(frozen=True)
class BenchRun:
    """One run of a benchmark matrix.

    Attributes
    ----------
    map_name:
        The map's name: a MovingAI file's stem, or a generated map's
        ``gen:...`` name.
    map_path, scen:
        The MovingAI ``.map`` and ``.scen`` files (as the runner opens them),
        or None for a generated map.
    generator:
        A generated map's spec as sorted ``(key, value)`` pairs
        (:mod:`mrmp.core.map_generators`), or None.
    instance:
        A generated map's instance number: the seed of its random starts and goals.
    agents:
        How many robots (the first N of the ``.scen`` file, or N random ones).
    policy:
        A decentralized policy or a central planner's name.
    seed:
        The run's seed (the simulated network's, and LaCAM's).
    faults:
        The simulated network's faults.
    lorr:
        A League of Robot Runners problem file (:mod:`mrmp.io.lorr`), whose map, robots (the first
        ``agents``) and task stream the run takes, or None. Such a run is lifelong and lasts
        ``max_ticks`` steps.
    lifelong, max_ticks:
        As in a scenario file.
    time_limit_s:
        Wall-clock seconds the run may take (a central planner's own limit too).
    bench:
        The name of the benchmark the run belongs to (not part of its identity).
    """

    map_name: str
    agents: int
    policy: str
    map_path: str | None = None
    scen: str | None = None
    generator: tuple[tuple[str, Any], ...] | None = None
    instance: int | None = None
    lorr: str | None = None
    seed: int = 0
    faults: NetworkFaults = field(default_factory=NetworkFaults)
    lifelong: bool = False
    max_ticks: int | None = None
    time_limit_s: float = 60.0
    bench: str = ""

    @property
    def kind(self) -> str:
        """``"centralized"`` for a central planner, else ``"decentralized"``."""
        return "centralized" if self.policy in PLANNER_NAMES else "decentralized"

    @property
    def generator_spec(self) -> dict[str, Any] | None:
        """The generator spec as a dictionary, or None."""
        return dict(self.generator) if self.generator is not None else None

    def identity(self) -> dict[str, Any]:
        """The parameters that make the run what it is (files by name only; ``lorr`` only when set, so
        that the ids of the other runs do not change)."""
        lorr = {"lorr": PurePath(self.lorr).name} if self.lorr is not None else {}
        return lorr | {
            "map": self.map_name,
            "scen": PurePath(self.scen).name if self.scen is not None else None,
            "generator": self.generator_spec,
            "instance": self.instance,
            "agents": self.agents,
            "policy": self.policy,
            "seed": self.seed,
            "faults": faults_to_dict(self.faults),
            "lifelong": self.lifelong,
            "max_ticks": self.max_ticks,
            "time_limit_s": float(self.time_limit_s),
        }

    @property
    def run_id(self) -> str:
        """16 hex digits of the SHA-256 of the canonical JSON of :meth:`identity`."""
        canonical = json.dumps(self.identity(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(canonical.encode("utf-8")).hexdigest()[:16]

    def describe(self) -> str:
        """One line for a person.

        >>> BenchRun("empty-32-32", 10, "cbs", seed=2).describe()
        'empty-32-32 N=10 cbs seed 2'
        """
        instance = f" instance {self.instance}" if self.instance is not None else ""
        faults = "" if self.faults.is_perfect else f" faults {faults_to_dict(self.faults)}"
        return f"{self.map_name}{instance} N={self.agents} {self.policy} seed {self.seed}{faults}"

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dictionary (the inverse of :meth:`from_dict`)."""
        data = asdict(self)
        data["faults"] = faults_to_dict(self.faults)
        data["generator"] = self.generator_spec
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> BenchRun:
        """Rebuild a run from :meth:`to_dict`'s output."""
        values = dict(data)
        values["faults"] = faults_from_dict(values["faults"])
        if values.get("generator") is not None:
            values["generator"] = tuple(sorted(values["generator"].items()))
        return cls(**values)

    def with_changes(self, **changes: Any) -> BenchRun:
        """A copy with some fields replaced."""
        return replace(self, **changes)
