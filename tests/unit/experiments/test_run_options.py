"""One function applies a run's options for ``mrmp run`` and ``mrmp.with_options``; only the field names differ."""

from __future__ import annotations

import pytest

from mrmp.core.errors import InputError
from mrmp.experiments.run_options import FIELD_NAMES, FLAG_NAMES, apply_run_options
from mrmp.io import load_scenario


@pytest.fixture
def swap():
    return load_scenario("examples/thesis-swap.yaml")


def _problems(swap, names, **options) -> list[str]:
    with pytest.raises(InputError) as caught:
        apply_run_options(swap, names=names, **options)
    return [str(problem) for problem in caught.value.problems]


def test_every_problem_is_gathered_under_the_callers_names(swap) -> None:
    options = {"policy": "teleport", "policy_settings": {"radius": 1}, "loss": 2.0}
    flags = _problems(swap, FLAG_NAMES, **options)
    fields = _problems(swap, FIELD_NAMES, **options)
    assert len(flags) == 3 and [text.replace("--policy", "policy") for text in flags] == fields
    assert flags[-1].startswith("--policy: unknown policy 'teleport'")


@pytest.mark.parametrize("delay", ["3..1", "x", (3, 1), -1, 1.5])
def test_a_bad_delay_is_named_as_the_caller_names_it(swap, delay) -> None:
    assert _problems(swap, FLAG_NAMES, delay=delay)[0].startswith("--delay: expected")
    assert _problems(swap, FIELD_NAMES, delay=delay)[0].startswith("delay: expected")


def test_options_given_replace_the_scenarios_and_none_leaves_them(swap) -> None:
    updated = apply_run_options(
        swap, "astar", {"heading_aware": True, "radius": None}, loss=0.1, delay="1..2", seed=9, max_ticks=None, safety=False
    )
    assert (updated.policy.name, updated.policy.heading_aware, updated.policy.radius) == ("astar", True, swap.policy.radius)
    assert (updated.network.loss, updated.network.delay_min, updated.network.delay_max) == (0.1, 1, 2)
    assert (updated.seed, updated.max_ticks, updated.safety) == (9, swap.max_ticks, False)


def test_an_unknown_option_is_a_programming_error(swap) -> None:
    with pytest.raises(TypeError, match="speed"):
        apply_run_options(swap, speed=2)
