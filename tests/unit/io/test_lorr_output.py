"""A LoRR problem run by mrmp and written as LoRR's output JSON, checked by replaying it under LoRR's own rules."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from mrmp.cli import app
from mrmp.core.errors import MrmpError
from mrmp.core.heading import Heading
from mrmp.io.lorr import load_lorr_scenario
from mrmp.io.lorr_output import lorr_actions, lorr_output
from mrmp.sim.simulator import simulate

PROBLEM = Path(__file__).resolve().parents[3] / "examples" / "lorr" / "maze-example_40.json"
STEPS = 150
# LoRR orientations: 0 east, 1 south, 2 west, 3 north; a move forward adds these (row, column)
FORWARD = {0: (0, 1), 1: (1, 0), 2: (0, -1), 3: (-1, 0)}
LETTERS = {"E": 0, "S": 1, "W": 2, "N": 3}


def replay(output: dict, map_rows: list[str]) -> tuple[int, list[list[int]]]:
    """Tasks finished and events, re-derived from the output by LoRR's rules (Start-Kit ``ActionModel``, ``TaskManager``).

    Every step: apply each robot's action; refuse a move off the map, into an
    obstacle, two robots on one cell or two robots swapping cells; then every
    robot with a task on that task's next errand advances it.
    """
    states = [(row, column, LETTERS[facing]) for row, column, facing in output["start"]]
    actions = [path.split(",") for path in output["actualPaths"]]
    errands = {task: list(zip(cells[::2], cells[1::2], strict=True)) for task, _, cells in output["tasks"]}
    given = [[tuple(map(int, item.split(":"))) for item in schedule.split(",") if item] for schedule in output["actualSchedule"]]
    progress = dict.fromkeys(errands, 0)
    task_of: list[int | None] = [None] * len(states)
    finished, events = 0, []
    for step in range(1, len(actions[0]) + 1):
        before = states
        states = []
        for (row, column, facing), path in zip(before, actions, strict=True):
            action = path[step - 1]
            if action == "F":
                row, column = row + FORWARD[facing][0], column + FORWARD[facing][1]
                assert 0 <= row < len(map_rows) and 0 <= column < len(map_rows[0]) and map_rows[row][column] != "@"
            elif action in "RC":
                facing = (facing + (1 if action == "R" else -1)) % 4
            else:
                assert action == "W"
            states.append((row, column, facing))
        cells = [(row, column) for row, column, _ in states]
        assert len(set(cells)) == len(cells), f"vertex conflict at step {step}"
        edges = {((a[0], a[1]), (b[0], b[1])) for a, b in zip(before, states, strict=True) if a[:2] != b[:2]}
        assert not any((after, source) in edges for source, after in edges), f"edge conflict at step {step}"
        for robot, schedule in enumerate(given):
            for start, task in schedule:
                if start == step:
                    task_of[robot] = task
        for robot, task in enumerate(task_of):
            if task is not None and cells[robot] == errands[task][progress[task]]:
                progress[task] += 1
                events.append([step, robot, task, progress[task]])
                if progress[task] == len(errands[task]):
                    finished += 1
                    task_of[robot] = None
    return finished, events


@pytest.fixture(scope="module")
def output() -> dict:
    result = simulate(load_lorr_scenario(PROBLEM, steps=STEPS))
    return lorr_output(result, load_lorr_scenario(PROBLEM).grid)


def test_the_output_replayed_by_lorr_rules_finishes_the_tasks_it_claims(output: dict) -> None:
    map_rows = (PROBLEM.parent / "maps" / "maze-32-32-2.map").read_text().splitlines()[4:]
    finished, events = replay(output, map_rows)
    assert output["numTaskFinished"] == finished > 30
    assert output["events"] == events
    assert output["numPlannerErrors"] == 0 and output["errors"] == []


def test_the_output_has_the_start_kit_s_fields(output: dict) -> None:
    assert output["actionModel"] == "MAPF_T" and output["teamSize"] == 40
    assert all(len(path.split(",")) == STEPS for path in output["actualPaths"])
    assert output["start"][0] == [31, 13, "E"]  # location 1005 of the agents file, facing east
    assert output["makespan"] == STEPS and output["sumOfCost"] == 40 * STEPS  # every robot always holds a task here
    assert [task for task, _, _ in output["tasks"]][:3] == [0, 1, 2]
    assert output["tasks"][0][2] == [6, 11, 14, 5]  # task file line "203,453": rows and columns of both errands


def test_actions_name_each_tick_and_a_move_a_turning_body_cannot_make_is_an_error() -> None:
    assert lorr_actions([(0, 0), (0, 0), (1, 0)], [Heading.EAST, Heading.NORTH, Heading.NORTH]) == "C,F"
    with pytest.raises(MrmpError, match="tick 1: the move"):
        lorr_actions([(0, 0), (1, 0)], [Heading.EAST, Heading.EAST])
    with pytest.raises(MrmpError, match="more than a quarter"):
        lorr_actions([(0, 0), (0, 0)], [Heading.EAST, Heading.WEST])


def test_mrmp_run_takes_a_lorr_problem_and_writes_its_output(tmp_path: Path) -> None:
    out = tmp_path / "out.json"
    result = CliRunner().invoke(app, ["run", str(PROBLEM), "--steps", "40", "--lorr-output", str(out)])
    assert result.exit_code == 0, result.output
    assert "tasks finished" in result.output
    written = json.loads(out.read_text())
    assert len(written["actualPaths"][0].split(",")) == 40 and len(written["plannerTimes"]) == 40


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--steps", "0"], "--steps: must be between 1 and"),
        (["--lorr-output", "x.json", "--body", "omni"], "--lorr-output: LoRR's actions are those of turning bodies"),
        (["--live", "--policy", "causal"], "--policy: causal does not take tasks live"),
        (["--live", "--transport", "multicast"], "--transport: a lifelong robot reaches its task desk over udp"),
        (["--live", "--lorr-output", "x.json"], "--lorr-output: writes a simulated run"),
        (["--planner", "lacam"], "--lifelong: lifelong runs are decentralized"),
        (["--lorr-output", "x.json", "--loss", "0.1"], "--lorr-output: LoRR's output has one action a step"),
    ],
)
def test_bad_lorr_runs_get_one_line(arguments: list[str], message: str) -> None:
    result = CliRunner().invoke(app, ["run", str(PROBLEM), *arguments])
    assert result.exit_code == 2
    assert message in result.output and "Traceback" not in result.output


def test_lorr_output_and_steps_belong_to_lorr_problems() -> None:
    swap = str(PROBLEM.parents[1] / "thesis-swap.yaml")
    for arguments, message in ((["--lorr-output", "x.json"], "writes the run of a LoRR problem"), (["--steps", "5"], "--steps")):
        result = CliRunner().invoke(app, ["run", swap, *arguments])
        assert result.exit_code == 2 and message in result.output
