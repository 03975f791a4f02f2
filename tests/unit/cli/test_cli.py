"""The mrmp command: exit codes, outputs, JSON keys, validation messages."""

import json
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from mrmp.cli import app

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"
MAPS = ROOT / "maps"
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(arg) for arg in args])


def test_thesis_swap_prints_table_and_summary_and_exits_0():
    result = invoke("run", EXAMPLES / "thesis-swap.yaml")
    assert result.exit_code == 0, result.output
    for text in ("robot", "start", "goal", "arrived", "steps", "turns", "waits", "messages", "(0,2)", "(4,2)"):
        assert text in result.output
    assert "success" in result.output and "collisions: 0" in result.output
    assert "makespan 6" in result.output and "sum of costs 10" in result.output and "lower bound 8" in result.output


def test_json_result_has_the_documented_keys(tmp_path):
    out = tmp_path / "swap.json"
    result = invoke("run", EXAMPLES / "thesis-swap.yaml", "--json", out)
    assert result.exit_code == 0
    data = json.loads(out.read_text())
    for key in ("success", "collisions", "makespan", "sum_of_costs", "lower_bound", "messages", "wall_time_s", "robots"):
        assert key in data
    assert data["success"] is True and data["collisions"] == [] and data["makespan"] == 6
    a = data["robots"][0]
    assert (a["id"], a["start"], a["goal"], a["arrived"]) == ("A", [0, 2], [4, 2], True)
    assert a["path"] == [[0, 2], [1, 2], [1, 3], [2, 3], [3, 3], [4, 3], [4, 2]]


def test_json_to_stdout_is_pure_json():
    completed = subprocess.run(
        [sys.executable, "-m", "mrmp", "run", str(EXAMPLES / "thesis-cross.yaml"), "--json", "-"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert completed.returncode == 0, completed.stderr
    assert json.loads(completed.stdout)["makespan"] == 8
    assert "success" in completed.stderr


def test_failed_run_exits_1_and_still_writes_the_result(tmp_path):
    out = tmp_path / "partial.json"
    result = invoke("run", EXAMPLES / "thesis-swap.yaml", "--max-ticks", 2, "--json", out)
    assert result.exit_code == 1
    assert "did not arrive: A, B" in result.output
    data = json.loads(out.read_text())
    assert data["success"] is False and data["stop_reason"] == "tick limit"


def test_collision_exits_1_and_is_printed():
    result = invoke("run", EXAMPLES / "thesis-swap.yaml", "--delay", "1", "--unsafe")
    assert result.exit_code == 1
    assert "collision of A, B" in result.output
    guarded = invoke("run", EXAMPLES / "thesis-swap.yaml", "--delay", "1")
    assert guarded.exit_code == 0 and "collisions: 0" in guarded.output


def test_movingai_run():
    result = invoke(
        "run", "--map", MAPS / "random-32-32-20.map", "--scen", MAPS / "random-32-32-20-random-1.scen",
        "--agents", 20, "--policy", "astar",
    )
    assert result.exit_code == 0, result.output
    assert "success" in result.output


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--policy", "nope"], "unknown policy 'nope'"),
        (["--loss", "1.5"], "network.loss: must be a probability"),
        (["--delay", "x"], "--delay: expected N or A..B"),
        (["--animate", "out.avi"], "unsupported suffix '.avi'"),
    ],
)
def test_bad_options_exit_2_with_one_line(args, fragment):
    result = invoke("run", EXAMPLES / "thesis-swap.yaml", *args)
    assert result.exit_code == 2
    assert fragment in result.output
    assert "Traceback" not in result.output


def test_missing_file_exits_2_without_traceback(tmp_path):
    result = invoke("run", tmp_path / "nowhere.yaml")
    assert result.exit_code == 2
    assert "nowhere.yaml" in result.output and "Traceback" not in result.output


def test_validate_reports_every_problem(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "map:\n  width: 5\n  height: 5\nrobots:\n"
        "  - {id: A, start: [0, 0], goal: [9, 9]}\n"
        "  - {id: B, start: [0, 0], goal: [1, 1]}\n"
        "colour: red\n"
    )
    result = invoke("validate", bad)
    assert result.exit_code == 2
    lines = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert len(lines) >= 3
    assert any("bad.yaml:5" in line and "outside" in line for line in lines)
    assert any("bad.yaml:6" in line and "start" in line for line in lines)
    assert any("bad.yaml:7" in line and "colour" in line for line in lines)


def test_validate_accepts_examples_and_maps():
    result = invoke("validate", *sorted(EXAMPLES.glob("*.yaml")), MAPS / "random-32-32-20.map",
                    MAPS / "random-32-32-20-random-1.scen")
    assert result.exit_code == 0, result.output
    assert result.output.count(": ok") == len(list(EXAMPLES.glob("*.yaml"))) + 2


def test_animations(tmp_path):
    for suffix in (".gif", ".svg"):
        target = tmp_path / f"swap{suffix}"
        result = invoke("run", EXAMPLES / "thesis-swap.yaml", "--animate", target)
        assert result.exit_code == 0, result.output
        assert target.stat().st_size > 1000


@pytest.mark.parametrize("planner", ["cbs", "pp", "lacam"])
def test_run_with_a_central_planner(planner, tmp_path):
    out = tmp_path / "plan.json"
    result = invoke("run", EXAMPLES / "thesis-cross.yaml", "--planner", planner, "--json", out)
    assert result.exit_code == 0, result.output
    assert f"{planner}: planned in" in result.output
    data = json.loads(out.read_text())
    assert data["success"] is True and data["planning_time_s"] >= 0 and data["plan_bytes"] > 0
    assert data["policy"] == planner


def test_unknown_planner_and_unsolvable_plan(tmp_path):
    result = invoke("run", EXAMPLES / "thesis-swap.yaml", "--planner", "magic")
    assert result.exit_code == 2 and "unknown planner 'magic'" in result.output
    corridor = tmp_path / "corridor.yaml"
    corridor.write_text("map: {rows: ['..']}\nrobots:\n  - {id: A, start: [0, 0], goal: [0, 1]}\n  - {id: B, start: [0, 1], goal: [0, 0]}\n")
    result = invoke("run", corridor, "--planner", "lacam", "--time-limit", "2")
    assert result.exit_code == 1 and "lacam: no plan" in result.output and "infeasible" in result.output


def test_compare_prints_every_method(tmp_path):
    out = tmp_path / "rows.json"
    result = invoke("compare", EXAMPLES / "thesis-cross.yaml", "--json", out)
    assert result.exit_code == 0, result.output
    rows = json.loads(out.read_text())
    assert [row["method"] for row in rows] == ["thesis", "astar", "pibt", "causal", "cbs", "pp", "lacam"]
    assert all(row["success"] for row in rows)
    cbs = next(row for row in rows if row["method"] == "cbs")
    assert cbs["sum_of_costs"] == 16 == cbs["lower_bound"]  # optimal: the lower bound is reached
    assert cbs["plan_bytes"] > 0 and cbs["planning_time_s"] >= 0
