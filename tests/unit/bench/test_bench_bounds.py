"""Bounds of a benchmark configuration: refused while reading it, before any map is generated or any run starts."""

import pytest

from mrmp.core.errors import InputError
from mrmp.experiments.bench_config import bench_config_from_text


def problems(text):
    with pytest.raises(InputError) as error:
        bench_config_from_text(text, "bench.yaml")
    return [str(problem) for problem in error.value.problems]


def test_a_generated_map_beyond_the_bound_is_refused_before_it_is_generated():
    text = "maps:\n  - {generate: random, width: 100000, height: 100000, density: 0.1}\nagents: [2]\npolicies: [pibt]\n"
    assert problems(text) == [
        "bench.yaml:2: maps[0]: a map of 100000x100000 = 10000000000 cells is larger than the bound of 4194304 cells"
        " (2048 x 2048)"
    ]


def test_instances_and_matrices_beyond_the_bound_are_refused():
    many = "maps:\n  - {generate: random, width: 8, height: 8, instances: 1000000000}\nagents: [2]\npolicies: [pibt]\n"
    assert problems(many) == ["bench.yaml:2: maps[0].instances: must be at most 100000, got 1000000000"]
    seeds = ", ".join(str(seed) for seed in range(1000))
    wide = f"maps:\n  - {{generate: maze, width: 8, height: 8, instances: 200}}\nagents: [2]\npolicies: [pibt]\nseeds: [{seeds}]\n"
    assert problems(wide) == ["bench.yaml:1: the matrix has 200000 runs, more than the bound of 100000"]


def test_more_generated_maps_than_the_bound_are_refused():
    seeds = ", ".join(str(seed) for seed in range(1001))
    text = f"maps:\n  - {{generate: random, width: 8, height: 8, seeds: [{seeds}]}}\nagents: [2]\npolicies: [pibt]\n"
    assert problems(text) == ["bench.yaml:2: maps[0].seeds: at most 1000 maps, got 1001 seeds"]


@pytest.mark.parametrize(
    ("setting", "expected"),
    [
        ("time_limit: 1e9", "bench.yaml:5: time_limit: must be at most 86400, got 1000000000.0"),
        ("time_limit: .nan", "bench.yaml:5: time_limit: must be at least 0.001, got nan"),
        ("max_ticks: 1000000001", "bench.yaml:5: max_ticks: must be at most 1000000, got 1000000001"),
        ("faults: [{delay: 5000}]", "bench.yaml:5: faults[0].delay: must be at most 1000 ticks, got 5000"),
    ],
)
def test_settings_beyond_their_bounds_are_refused(setting, expected):
    text = "maps:\n  - {generate: random, width: 8, height: 8}\nagents: [2]\npolicies: [pibt]\n" + setting + "\n"
    assert expected in problems(text)


def test_numbers_of_robots_beyond_the_bound_are_refused():
    text = "maps:\n  - {generate: random, width: 8, height: 8, agents: [20000]}\nagents: [2, 10001]\npolicies: [pibt]\n"
    assert problems(text) == [
        "bench.yaml:2: maps[0].agents[0]: must be at most 10000, got 20000",
        "bench.yaml:3: agents[1]: must be at most 10000, got 10001",
    ]
