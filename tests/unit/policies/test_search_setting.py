"""``policy.search`` and ``mrmp run --search``: each search reaches the per-robot policies, by YAML and by flag."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from mrmp.cli import app
from mrmp.core.errors import InputError
from mrmp.core.scenario import PolicyOptions
from mrmp.io.scenario_file import scenario_from_text, scenario_to_yaml
from mrmp.policies.astar import AstarPolicy
from mrmp.policies.thesis import ThesisPolicy
from mrmp.search.choices import SEARCH_TABLE
from mrmp.sim import policy_table
from mrmp.sim.policy_table import make_policy

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

TRAP_YAML = """\
name: trap
map:
  rows:
    - "......."
    - "......."
    - ".@@@@@."
    - ".@...@."
    - ".@...@."
    - "......."
    - "......."
robots:
  - {id: A, start: [2, 0], goal: [3, 3]}
policy: {name: astar, search: SEARCH}
max_ticks: 60
"""
"""One robot into a pocket open to the south: A* and Dijkstra take 6 moves, greedy best-first 18, and the
update coordinate method's L is blocked at (3, 1)."""

SUM_OF_COSTS = {"dijkstra": 6, "astar": 6, "best-first": 18}


@pytest.mark.parametrize("policy", ["thesis", "astar"])
@pytest.mark.parametrize("name", list(SEARCH_TABLE))
def test_each_search_reaches_each_per_robot_policy(policy, name):
    assert make_policy(PolicyOptions(name=policy, search=name)).search is SEARCH_TABLE[name].planner


def test_default_is_each_policys_own_search():
    assert make_policy(PolicyOptions(name="thesis")).search is SEARCH_TABLE[ThesisPolicy.own_search].planner
    assert make_policy(PolicyOptions(name="astar")).search is SEARCH_TABLE[AstarPolicy.own_search].planner
    assert (ThesisPolicy.own_search, AstarPolicy.own_search) == ("update-coordinate", "astar")


@pytest.mark.parametrize("name", list(SEARCH_TABLE))
def test_yaml_key_reads_and_writes_back(name):
    scenario = scenario_from_text(TRAP_YAML.replace("SEARCH", name), "trap.yaml")
    assert scenario.policy.search == name
    assert scenario_from_text(scenario_to_yaml(scenario), "again.yaml").policy.search == name


def test_yaml_unknown_search_is_one_line_naming_file_line_and_field():
    with pytest.raises(InputError) as error:
        scenario_from_text(TRAP_YAML.replace("SEARCH", "bfs"), "trap.yaml")
    message = str(error.value)
    assert "\n" not in message
    assert message.startswith("trap.yaml:13: policy.search: must be one of default, update-coordinate,")
    assert message.endswith("got 'bfs'")


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SEARCH_TABLE))
def test_flag_reaches_the_policy_table_and_changes_the_run(name, tmp_path, monkeypatch):
    scenario_file = tmp_path / "trap.yaml"
    scenario_file.write_text(TRAP_YAML.replace("SEARCH", "default"))
    asked = []

    def spy(search, own):
        asked.append((search, own))
        return SEARCH_TABLE[search if search != "default" else own]

    monkeypatch.setattr(policy_table, "chosen_search", spy)
    out = tmp_path / "run.json"
    result = CliRunner().invoke(app, ["run", str(scenario_file), "--search", name, "--json", str(out)])
    assert asked == [(name, "astar")]
    data = json.loads(out.read_text())
    if name in SUM_OF_COSTS:
        assert result.exit_code == 0, result.output
        assert data["sum_of_costs"] == SUM_OF_COSTS[name]
    else:  # the L is blocked and the update coordinate method never detours: the robot stays
        assert result.exit_code == 1
        assert data["robots"][0]["arrived"] is False and data["stop_reason"] == "deadlock"


def test_flag_unknown_search_exits_2_with_one_line():
    result = CliRunner().invoke(app, ["run", str(EXAMPLES / "thesis-swap.yaml"), "--search", "bfs"])
    assert result.exit_code == 2
    assert "policy.search: must be one of default, update-coordinate, dijkstra, best-first, astar, got 'bfs'" in (
        result.output
    )


@pytest.mark.slow
@pytest.mark.parametrize("name", ["dijkstra", "best-first", "astar"])
def test_thesis_rule_with_a_search_trades_places_along_the_row(name):
    """The row swap livelocks with the update coordinate method; searches replanned at each step do not."""
    result = CliRunner().invoke(app, ["run", str(EXAMPLES / "thesis-swap-row.yaml"), "--search", name])
    assert result.exit_code == 0, result.output
    default = CliRunner().invoke(app, ["run", str(EXAMPLES / "thesis-swap-row.yaml")])
    assert default.exit_code == 1 and "livelock" in default.output
