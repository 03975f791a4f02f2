"""Benchmark configurations that name League of Robot Runners problems: runs, records, errors with file:line."""

import json
import shutil
from pathlib import Path

import pytest

from mrmp.core.errors import InputError
from mrmp.experiments.bench_config import load_bench_config
from mrmp.experiments.records import build_scenario, execute_run
from mrmp.io.lorr import load_lorr_scenario
from mrmp.io.report_input import record_from_dict
from mrmp.sim.simulator import simulate

ROOT = Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "examples" / "lorr"

CONFIG = """\
maps:
  - lorr: lorr/maze-example_40.json
    agents: [10, 40]
policies: [pibt]
faults:
  - {loss: 0.0}
  - {loss: 0.2}
max_ticks: 60
"""


@pytest.fixture
def folder(tmp_path):
    shutil.copytree(EXAMPLE, tmp_path / "lorr")
    return tmp_path


def read(folder, text):
    path = folder / "bench.yaml"
    path.write_text(text)
    return load_bench_config(path)


def problems(folder, text):
    with pytest.raises(InputError) as caught:
        read(folder, text)
    return [str(problem) for problem in caught.value.problems]


def test_a_lorr_entry_runs_its_first_n_robots_lifelong_for_max_ticks_steps(folder):
    config = read(folder, CONFIG)
    assert [(run.agents, run.faults.loss) for run in config.runs] == [(10, 0.0), (10, 0.2), (40, 0.0), (40, 0.2)]
    assert all(run.lifelong and run.lorr == str(folder / "lorr" / "maze-example_40.json") for run in config.runs)
    assert {run.map_name for run in config.runs} == {"maze-example_40"}
    scenario = build_scenario(config.runs[0])
    assert len(scenario.robots) == 10 and scenario.max_ticks == 60 and scenario.policy.body == "turning"
    assert scenario.tasks is not None and scenario.tasks.reveal == 15  # numTasksReveal 1.5 x 10 robots


def test_a_lorr_run_records_the_tasks_the_simulator_finishes_on_the_same_problem(folder):
    run = read(folder, CONFIG).runs[2]  # all 40 robots, a perfect network
    record = execute_run(run)
    assert record["status"] == "done" and record["collisions"] == 0
    direct = simulate(load_lorr_scenario(folder / "lorr" / "maze-example_40.json", 60))
    assert direct.tasks is not None and record["tasks_finished"] == direct.tasks.finished > 0
    typed = record_from_dict(json.loads(json.dumps(record)))
    assert typed.tasks_finished == record["tasks_finished"] and typed.lorr == run.lorr


def test_without_agents_a_lorr_entry_takes_the_problems_team_and_more_robots_are_a_note(folder):
    config = read(folder, CONFIG.replace("    agents: [10, 40]\n", ""))
    assert {run.agents for run in config.runs} == {40}
    config = read(folder, CONFIG.replace("[10, 40]", "[10, 41]"))
    assert {run.agents for run in config.runs} == {10}
    assert config.notes == ("skipped N=41 on maze-example_40: its teamSize is 40",)


def test_run_ids_of_lorr_runs_name_the_problem_and_leave_other_ids_unchanged(folder, tmp_path_factory):
    ids = [run.run_id for run in read(folder, CONFIG).runs]
    moved = tmp_path_factory.mktemp("elsewhere")
    shutil.copytree(folder / "lorr", moved / "lorr")
    assert ids == [run.run_id for run in read(moved, CONFIG).runs]
    run = read(folder, CONFIG).runs[0]
    assert "lorr" in run.identity() and "lorr" not in run.with_changes(lorr=None).identity()


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (("policies: [pibt]", "policies: [pibt, lacam]"), "bench.yaml:2: maps[0]: LoRR problems are lifelong: lacam is a central planner"),
        (("lorr/maze-example_40.json", "lorr/missing.json"), "bench.yaml:2: maps[0].lorr: LoRR problem file not found"),
        (("    agents: [10, 40]\n", "    agents: [10, 40]\n    scen: [x.scen]\n"), "bench.yaml:4: maps[0]: unknown key 'scen'"),
    ],
)
def test_errors_are_one_line_each_with_file_and_line(folder, change, expected):
    text = CONFIG.replace(*change)
    assert text != CONFIG
    found = problems(folder, text)
    assert any(line.startswith(str(folder / expected.split(":", 1)[0]) + ":" + expected.split(":", 1)[1]) for line in found), found
    assert all("\n" not in line for line in found)


def test_a_malformed_problem_is_reported_in_its_own_file_and_line(folder):
    problem = folder / "lorr" / "maze-example_40.json"
    data = json.loads(problem.read_text())
    data["teamSize"] = "many"
    problem.write_text(json.dumps(data, indent=4))
    found = problems(folder, CONFIG)
    assert any(line.startswith(str(problem)) and "teamSize" in line for line in found), found
