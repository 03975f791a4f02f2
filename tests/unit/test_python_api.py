"""The Python API (:mod:`mrmp.api`): ``docs/python.md`` runs as written, and the API's errors name the field."""

from __future__ import annotations

import doctest
from pathlib import Path

import pytest

import mrmp
from mrmp.core.errors import InputError

ROOT = Path(__file__).resolve().parents[2]


def test_the_python_page_runs_as_written(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    outcome = doctest.testfile(str(ROOT / "docs" / "python.md"), module_relative=False, optionflags=doctest.ELLIPSIS)
    assert outcome.attempted > 10 and outcome.failed == 0


def test_run_with_a_planner_executes_its_plan() -> None:
    result = mrmp.run(ROOT / "examples" / "thesis-swap.yaml", planner="cbs")
    assert result.success and result.plan is not None
    assert result.summary()["plan sum of costs"] == result.plan.sum_of_costs() == 10 == result.sum_of_costs


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"policy": "teleport"}, "policy: unknown policy 'teleport'"),
        ({"planner": "magic"}, "planner: unknown planner 'magic'"),
        ({"speed": 3}, "speed: unknown option"),
        ({"delay": (3, 1)}, "delay: expected ticks"),
        ({"loss": 1.5}, "loss"),
        ({"time_limit": 0}, "time_limit: must be positive"),
    ],
)
def test_bad_options_are_refused_naming_the_field(options: dict[str, object], message: str) -> None:
    with pytest.raises(InputError, match=message):
        mrmp.run(ROOT / "examples" / "thesis-swap.yaml", **options)  # type: ignore[arg-type]


def test_load_names_the_file_of_a_missing_scenario(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"nothing\.yaml"):
        mrmp.load(tmp_path / "nothing.yaml")


def test_a_result_shows_its_table_and_animation_in_a_notebook() -> None:
    page = mrmp.run(ROOT / "examples" / "thesis-swap.yaml")._repr_html_()
    assert page.count("<tr>") == 10 and "<svg" in page and "<animate" in page


def test_the_api_is_loaded_only_when_used() -> None:
    with pytest.raises(AttributeError, match="no attribute 'simulate'"):
        mrmp.simulate  # noqa: B018
