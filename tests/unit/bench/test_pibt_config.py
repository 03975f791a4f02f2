"""``bench/pibt.yaml`` runs exactly the instances of ``bench/pibt_scale.py``, so it reproduces the pibt table.

The table in ``docs/algorithms.md`` is printed by ``bench/pibt_scale.py``; the
benchmark configuration must run the same scenarios (robots, starts, goals,
seed) for every map and number of robots, including the seeded random
instances of the maps without a ``.scen`` file.
"""

from __future__ import annotations

import importlib.util
from collections import defaultdict
from pathlib import Path

import pytest

from mrmp.experiments.bench_config import load_bench_config
from mrmp.experiments.records import build_scenario

ROOT = Path(__file__).resolve().parents[3]


def _pibt_scale():
    spec = importlib.util.spec_from_file_location("pibt_scale", ROOT / "bench" / "pibt_scale.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _robots(scenario) -> tuple:
    return tuple((robot.start, robot.goal) for robot in scenario.robots), scenario.seed, scenario.policy.name


@pytest.mark.slow
def test_the_bench_config_runs_the_scale_scripts_instances() -> None:
    pibt_scale = _pibt_scale()
    config = load_bench_config(ROOT / "bench" / "pibt.yaml")
    by_row: dict[tuple[str, int], list] = defaultdict(list)
    for run in config.runs:
        by_row[(run.map_name, run.agents)].append(_robots(build_scenario(run)))
    expected_rows = {(name, agents) for name, counts in pibt_scale.AGENTS.items() for agents in counts}
    assert set(by_row) == expected_rows
    for (name, agents), runs in sorted(by_row.items()):
        scale = [
            _robots(scenario.with_changes(policy=scenario.policy.__class__(name="pibt")))
            for scenario in pibt_scale.instances(ROOT / "maps", name, agents)
        ]
        assert runs == scale, (name, agents)
