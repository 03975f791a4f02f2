"""Run results as JSON: the dictionary's content, the way back, atomic files and stdout."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from mrmp.core import Collision, Grid, Heading, InputError, RobotResult, RunResult
from mrmp.io import results
from mrmp.io.results import (
    read_result_json,
    result_from_dict,
    result_to_dict,
    write_result_json,
)

N, E = Heading.NORTH, Heading.EAST


def make_run() -> RunResult:
    """Two robots: A arrives at tick 3 after a wait, B never arrives; one referee finding."""
    robot_a = RobotResult(
        "A",
        (0, 0),
        (1, 1),
        path=[(0, 0), (1, 0), (1, 0), (1, 1), (1, 1)],
        headings=[N, N, E, E, E],
        turns=1,
        messages_sent=4,
        bytes_sent=96,
        time_s=3.5,
    )
    robot_b = RobotResult(
        "B", (2, 2), (0, 2), path=[(2, 2), (1, 2), (1, 2), (1, 2), (1, 2)], headings=[N] * 5, time_s=1.0
    )
    return RunResult(
        scenario="demo",
        policy="thesis",
        seed=7,
        robots=[robot_a, robot_b],
        collisions=[Collision("vertex", 2, ("A", "B"), ((1, 2),)), Collision("swap", 3, ("A", "B"), ((0, 1), (1, 1)))],
        stop_reason="max_ticks",
        ticks=4,
        lower_bound=4,
        wall_time_s=0.125,
        network={"sent": 4, "delivered": 3, "lost": 1},
    )


def test_dict_has_the_summary_metrics() -> None:
    data = result_to_dict(make_run())
    assert data["success"] is False
    assert data["stop_reason"] == "max_ticks"
    assert (data["makespan"], data["sum_of_costs"], data["lower_bound"]) == (4, 7, 4)
    assert data["time_makespan_s"] == 3.5
    assert data["messages"] == 4
    assert data["network"] == {"sent": 4, "delivered": 3, "lost": 1}
    assert (data["wall_time_s"], data["ticks"], data["scenario"], data["policy"], data["seed"]) == (
        0.125,
        4,
        "demo",
        "thesis",
        7,
    )
    assert data["collisions"][1] == {"kind": "swap", "tick": 3, "robots": ["A", "B"], "cells": [[0, 1], [1, 1]]}


def test_dict_has_the_robot_details() -> None:
    robot_a, robot_b = result_to_dict(make_run())["robots"]
    assert robot_a == {
        "id": "A",
        "start": [0, 0],
        "goal": [1, 1],
        "arrived": True,
        "arrival_tick": 3,
        "cost": 3,
        "steps": 2,
        "turns": 1,
        "waits": 1,
        "messages_sent": 4,
        "bytes_sent": 96,
        "time_s": 3.5,
        "goals_reached": 0,
        "path": [[0, 0], [1, 0], [1, 0], [1, 1], [1, 1]],
        "headings": ["NORTH", "NORTH", "EAST", "EAST", "EAST"],
    }
    assert (robot_b["arrived"], robot_b["arrival_tick"], robot_b["cost"]) == (False, None, 4)


def test_dict_is_json_serialisable_and_round_trips() -> None:
    run = make_run()
    data = json.loads(json.dumps(result_to_dict(run)))
    assert result_from_dict(data) == run


def test_map_is_stored_when_a_grid_is_given() -> None:
    grid = Grid.from_rows(["..@", "...", "..."], name="tiny")
    data = result_to_dict(make_run(), grid)
    assert data["map"] == {"name": "tiny", "x_size": 3, "y_size": 3, "rows": ["..@", "...", "..."]}
    assert results.grid_from_result_dict(data) == grid
    assert "map" not in result_to_dict(make_run())


def test_file_round_trip_with_grid(tmp_path: Path) -> None:
    grid = Grid.from_rows(["..@", "...", "..."], name="tiny")
    path = tmp_path / "out" / "run.json"
    write_result_json(make_run(), path, grid)
    run, stored_grid = read_result_json(path)
    assert run == make_run()
    assert stored_grid == grid and stored_grid.name == "tiny"


def test_dash_writes_to_stdout(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    write_result_json(make_run(), "-")
    out = capsys.readouterr().out
    assert json.loads(out)["scenario"] == "demo"
    assert list(tmp_path.iterdir()) == []  # no file called "-"


def test_writing_replaces_the_file_and_leaves_no_temporary(tmp_path: Path) -> None:
    path = tmp_path / "run.json"
    path.write_text("old")
    write_result_json(make_run(), path)
    assert json.loads(path.read_text())["policy"] == "thesis"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.json"]


def test_interrupted_write_keeps_the_old_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "run.json"
    path.write_text('{"old": true}')

    def interrupted(source: str, target: str) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_result_json(make_run(), path)
    assert path.read_text() == '{"old": true}'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.json"]


def test_written_file_is_readable_by_others(tmp_path: Path) -> None:
    path = tmp_path / "run.json"
    write_result_json(make_run(), path)
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask


def test_unwritable_target_is_an_input_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(InputError) as error:
        write_result_json(make_run(), blocker / "run.json")
    assert error.value.problems[0].where == str(blocker / "run.json")


def test_from_dict_names_a_missing_field() -> None:
    data = result_to_dict(make_run())
    del data["policy"]
    with pytest.raises(InputError, match="policy: expected a string, got nothing"):
        result_from_dict(data, "run.json")


def test_from_dict_names_a_bad_cell() -> None:
    data = result_to_dict(make_run())
    data["robots"][1]["path"][2] = [1]
    with pytest.raises(InputError) as error:
        result_from_dict(data, "run.json")
    assert str(error.value) == "run.json: robots[1].path[2]: expected a cell [x, y], got [1]"


def test_invalid_json_names_its_line(tmp_path: Path) -> None:
    path = tmp_path / "broken.json"
    path.write_text('{\n  "scenario": "x",\n  "policy": \n}\n')
    with pytest.raises(InputError) as error:
        read_result_json(path)
    (problem,) = error.value.problems
    assert problem.where == f"{path}:4" and problem.reason.startswith("invalid JSON")
