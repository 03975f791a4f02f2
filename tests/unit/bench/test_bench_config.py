"""Benchmark configurations: one-line errors with file:line, matrix expansion, stable run ids; entries naming League of
Robot Runners problems (runs, records)."""

import json
import shutil
from pathlib import Path

import pytest

from mrmp.core.errors import InputError
from mrmp.core.scenario import NetworkFaults
from mrmp.experiments.bench_config import bench_config_from_text, load_bench_config
from mrmp.experiments.matrix import BenchRun
from mrmp.experiments.records import build_scenario, execute_run
from mrmp.io.lorr import load_lorr_scenario
from mrmp.io.report_input import record_from_dict
from mrmp.sim.simulator import simulate

ROOT = Path(__file__).resolve().parents[3]
MAPS = ROOT / "maps"

GOOD = """\
name: demo
maps:
  - map: maps/empty-32-32.map
    scen: [maps/empty-32-32-random-1.scen]
  - generate: random
    width: 16
    height: 16
    density: 0.2
    seeds: [0, 1]
    instances: 2
agents: [2, 5]
policies: [pibt, astar, cbs]
seeds: [0, 3]
faults:
  - {loss: 0.0}
  - {loss: 0.2, delay: [0, 2]}
time_limit: 5
max_ticks: 300
"""


@pytest.fixture
def folder(tmp_path):
    """A folder holding maps/ with the empty-32-32 files, and lorr/ with the LoRR example problem."""
    (tmp_path / "maps").mkdir()
    for name in ("empty-32-32.map", "empty-32-32-random-1.scen"):
        shutil.copy(MAPS / name, tmp_path / "maps" / name)
    shutil.copytree(ROOT / "examples" / "lorr", tmp_path / "lorr")
    return tmp_path


def read(folder, text, name="bench.yaml"):
    path = folder / name
    path.write_text(text)
    return load_bench_config(path)


def problems(folder, text):
    with pytest.raises(InputError) as caught:
        read(folder, text)
    return [str(problem) for problem in caught.value.problems]


def test_expansion_covers_the_whole_matrix(folder):
    config = read(folder, GOOD)
    # (1 scen + 2 map seeds x 2 instances) x 2 N x 3 methods x 2 seeds x 2 faults
    assert len(config.runs) == 5 * 2 * 3 * 2 * 2
    assert config.name == "demo" and config.notes == ()
    first = config.runs[0]
    assert first.map_name == "empty-32-32" and first.scen.endswith("empty-32-32-random-1.scen")
    assert Path(first.map_path).is_absolute() and Path(first.map_path).is_file()
    assert first.time_limit_s == 5.0 and first.max_ticks == 300 and first.bench == "demo"
    assert {run.faults for run in config.runs} == {NetworkFaults(), NetworkFaults(loss=0.2, delay_max=2)}
    generated = {run.map_name for run in config.runs if run.generator is not None}
    assert generated == {"gen:random-16x16-p0.20-s0", "gen:random-16x16-p0.20-s1"}
    assert {run.instance for run in config.runs if run.generator is not None} == {0, 1}
    assert {run.kind for run in config.runs if run.policy == "cbs"} == {"centralized"}
    assert len({run.run_id for run in config.runs}) == len(config.runs)


def test_run_ids_are_stable_across_reads_moves_and_only_change_with_parameters(folder, tmp_path_factory):
    ids = [run.run_id for run in read(folder, GOOD).runs]
    assert ids == [run.run_id for run in read(folder, GOOD).runs]
    moved = tmp_path_factory.mktemp("elsewhere")
    shutil.copytree(folder / "maps", moved / "maps")
    assert ids == [run.run_id for run in read(moved, GOOD).runs]
    # the time limit is a parameter of a run; the benchmark's name is not
    assert set(ids).isdisjoint(run.run_id for run in read(folder, GOOD.replace("time_limit: 5", "time_limit: 6")).runs)
    assert ids == [run.run_id for run in read(folder, GOOD.replace("name: demo", "name: other")).runs]
    assert ids == [run.run_id for run in load_bench_config(folder / "bench.yaml", time_limit=5).runs]
    # one known id, computed from the canonical JSON of the parameters
    run = BenchRun("empty-32-32", 2, "pibt", scen="/x/empty-32-32-random-1.scen", time_limit_s=5.0)
    assert run.run_id == BenchRun("empty-32-32", 2, "pibt", scen="/y/empty-32-32-random-1.scen", time_limit_s=5).run_id
    assert len(run.run_id) == 16 and int(run.run_id, 16) >= 0


def test_per_map_agents_and_skipped_counts_are_notes_not_errors(folder):
    text = GOOD.replace("    scen: [maps/empty-32-32-random-1.scen]\n", "    scen: [maps/empty-32-32-random-1.scen]\n    agents: [3, 5000]\n")
    text = text.replace("agents: [2, 5]", "agents: [2, 250]")
    config = read(folder, text)
    assert {run.agents for run in config.runs if run.generator is None} == {3}
    assert {run.agents for run in config.runs if run.generator is not None} == {2}
    assert any("skipped N=5000 on empty-32-32" in note and "lists" in note for note in config.notes)
    assert any("skipped N=250 on gen:random-16x16-p0.20-s0 instance 0" in note for note in config.notes)


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (("policies: [pibt, astar, cbs]", "policies: [pibt, dijkstra]"), "bench.yaml:12: policies[1]: unknown policy or planner 'dijkstra'"),
        (("time_limit: 5", "time_limit: soon"), "bench.yaml:17: time_limit: expected a number, got a string 'soon'"),
        (("max_ticks: 300", "max_tick: 300"), "bench.yaml:18: unknown key 'max_tick' (did you mean 'max_ticks'?)"),
        (("maps/empty-32-32.map", "maps/missing.map"), "bench.yaml:3: maps[0].map: map file not found"),
        (("[maps/empty-32-32-random-1.scen]", "[maps/nope.scen]"), "bench.yaml:4: maps[0].scen[0]: scenario file not found"),
        (("density: 0.2", "density: lots"), "bench.yaml:8: maps[1].density: expected a number"),
        (("generate: random", "generate: cave"), "bench.yaml:5: maps[1].generate: unknown map generator 'cave'"),
        (("density: 0.2", "corridor: 2"), "bench.yaml:8: maps[1].corridor: random maps take no 'corridor'"),
        (("agents: [2, 5]", "agents: [2, -1]"), "bench.yaml:11: agents[1]: must be at least 1, got -1"),
        (("agents: [2, 5]", "agents: 5"), "bench.yaml:11: agents: expected a non-empty list, got a number 5"),
        (("seeds: [0, 3]", "seeds: [0, 0]"), "bench.yaml:13: seeds[1]: 0 is listed twice"),
        (("{loss: 0.2, delay: [0, 2]}", "{loss: 1.5}"), "bench.yaml:16: faults[1].loss: must be a probability in [0, 1], got 1.5"),
        (("{loss: 0.2, delay: [0, 2]}", "{loss: 0.2, jitter: 1}"), "bench.yaml:16: faults[1]: unknown key 'jitter'"),
        (("max_ticks: 300", "lifelong: true"), "bench.yaml:18: lifelong: lifelong runs use decentralized policies only; remove cbs"),
        (("name: demo", "name: [demo"), "bench.yaml:2: invalid YAML"),
    ],
)
def test_errors_are_one_line_each_with_file_and_line(folder, change, expected):
    assert_reported(folder, GOOD, change, expected)


def assert_reported(folder, config, change, expected):
    """``config`` changed by ``change`` is refused with ``expected`` (``FILE:LINE: ...``, the file in ``folder``)."""
    text = config.replace(*change)
    assert text != config
    found = problems(folder, text)
    assert any(line.startswith(str(folder / expected.split(":", 1)[0]) + ":" + expected.split(":", 1)[1]) for line in found), found
    assert all("\n" not in line for line in found)


def test_missing_required_keys_and_a_warehouse_with_seeds(folder):
    found = problems(folder, "maps:\n  - {generate: warehouse, width: 30, height: 12, seeds: [1]}\n")
    assert any(line.endswith("bench.yaml:2: maps[0]: give agents: [N, ...] here or at the top level") for line in found), found
    assert any(line.endswith("bench.yaml:1: missing required key 'policies'") for line in found), found
    assert any("bench.yaml:2: maps[0].seeds: warehouse maps are not random" in line for line in found), found


def test_problems_of_a_named_scen_file_point_into_that_file(folder):
    (folder / "maps" / "bad.scen").write_text("version 1\n0\tempty-32-32.map\t32\t32\t1\t1\t2\n")
    found = problems(folder, GOOD.replace("empty-32-32-random-1.scen", "bad.scen"))
    assert any("bad.scen:2" in line for line in found), found


def test_text_without_a_folder_reads_relative_to_the_given_base():
    config = bench_config_from_text(GOOD, "demo.yaml", base_dir=ROOT)
    assert config.runs[0].map_path == str((MAPS / "empty-32-32.map").resolve())


@pytest.mark.parametrize("name", ["tiny", "standard", "generated", "lorr"])
def test_the_example_configurations_read(name):
    config = load_bench_config(ROOT / "bench" / f"{name}.yaml")
    assert config.name == name and config.runs and config.notes == ()
    methods = {run.policy for run in config.runs}
    if name == "standard":
        assert methods == {"thesis", "astar", "pibt", "causal", "cbs", "pp", "lacam"}
        assert {run.map_name for run in config.runs} == {
            "random-32-32-20", "empty-32-32", "maze-32-32-2", "room-32-32-4", "warehouse-10-20-10-2-1", "den520d"
        }
        assert any(run.faults.loss > 0 for run in config.runs) and len({run.seed for run in config.runs}) > 1
    if name == "generated":
        assert all(run.generator is not None for run in config.runs)
        assert {dict(run.generator)["kind"] for run in config.runs} == {"random", "maze", "warehouse", "room"}


LORR = """\
maps:
  - lorr: lorr/maze-example_40.json
    agents: [10, 40]
policies: [pibt]
faults:
  - {loss: 0.0}
  - {loss: 0.2}
max_ticks: 60
"""


def test_a_lorr_entry_runs_its_first_n_robots_lifelong_for_max_ticks_steps(folder):
    config = read(folder, LORR)
    assert [(run.agents, run.faults.loss) for run in config.runs] == [(10, 0.0), (10, 0.2), (40, 0.0), (40, 0.2)]
    assert all(run.lifelong and run.lorr == str(folder / "lorr" / "maze-example_40.json") for run in config.runs)
    assert {run.map_name for run in config.runs} == {"maze-example_40"}
    scenario = build_scenario(config.runs[0])
    assert len(scenario.robots) == 10 and scenario.max_ticks == 60 and scenario.policy.body == "turning"
    assert scenario.tasks is not None and scenario.tasks.reveal == 15  # numTasksReveal 1.5 x 10 robots


def test_a_lorr_run_records_the_tasks_the_simulator_finishes_on_the_same_problem(folder):
    run = read(folder, LORR).runs[2]  # all 40 robots, a perfect network
    record = execute_run(run)
    assert record["status"] == "done" and record["collisions"] == 0
    direct = simulate(load_lorr_scenario(folder / "lorr" / "maze-example_40.json", 60))
    assert direct.tasks is not None and record["tasks_finished"] == direct.tasks.finished > 0
    typed = record_from_dict(json.loads(json.dumps(record)))
    assert typed.tasks_finished == record["tasks_finished"] and typed.lorr == run.lorr


def test_without_agents_a_lorr_entry_takes_the_problems_team_and_more_robots_are_a_note(folder):
    config = read(folder, LORR.replace("    agents: [10, 40]\n", ""))
    assert {run.agents for run in config.runs} == {40}
    config = read(folder, LORR.replace("[10, 40]", "[10, 41]"))
    assert {run.agents for run in config.runs} == {10}
    assert config.notes == ("skipped N=41 on maze-example_40: its teamSize is 40",)


def test_run_ids_of_lorr_runs_name_the_problem_and_leave_other_ids_unchanged(folder, tmp_path_factory):
    ids = [run.run_id for run in read(folder, LORR).runs]
    moved = tmp_path_factory.mktemp("elsewhere")
    shutil.copytree(folder / "lorr", moved / "lorr")
    assert ids == [run.run_id for run in read(moved, LORR).runs]
    run = read(folder, LORR).runs[0]
    assert "lorr" in run.identity() and "lorr" not in run.with_changes(lorr=None).identity()


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (("policies: [pibt]", "policies: [pibt, lacam]"), "bench.yaml:2: maps[0]: LoRR problems are lifelong: lacam is a central planner"),
        (("lorr/maze-example_40.json", "lorr/missing.json"), "bench.yaml:2: maps[0].lorr: LoRR problem file not found"),
        (("    agents: [10, 40]\n", "    agents: [10, 40]\n    scen: [x.scen]\n"), "bench.yaml:4: maps[0]: unknown key 'scen'"),
    ],
)
def test_errors_of_lorr_entries_are_one_line_each_with_file_and_line(folder, change, expected):
    assert_reported(folder, LORR, change, expected)


def test_a_malformed_problem_is_reported_in_its_own_file_and_line(folder):
    problem = folder / "lorr" / "maze-example_40.json"
    data = json.loads(problem.read_text())
    data["teamSize"] = "many"
    problem.write_text(json.dumps(data, indent=4))
    found = problems(folder, LORR)
    assert any(line.startswith(str(problem)) and "teamSize" in line for line in found), found
