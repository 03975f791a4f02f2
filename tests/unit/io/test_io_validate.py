"""validate_file: every input kind, problems returned instead of raised."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from mrmp.io.validate import validate_file

SHIPPED = sorted(
    path.name for path in (Path(__file__).resolve().parents[3] / "maps").glob("*") if path.suffix in (".map", ".scen")
)


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_benchmark_files_are_clean(maps_dir: Path, name: str) -> None:
    assert validate_file(maps_dir / name) == []


def test_good_yaml(make_file) -> None:
    path = make_file("ok.yml", "map: {rows: ['..']}\nrobots: [{id: A, start: [0, 0], goal: [0, 1]}]\n")
    assert validate_file(path) == []


def test_bad_yaml_returns_every_problem(make_file) -> None:
    path = make_file("bad.yaml", "map: {rows: ['..']}\nrobots: [{id: A, start: [0, 0], goal: [0, 7]}]\nsed: 1\n")
    assert [(p.where, p.reason) for p in validate_file(path)] == [
        (f"{path}:2", "robots[0].goal: cell (0, 7) is outside the 1x2 grid"),
        (f"{path}:3", "unknown key 'sed' (did you mean 'seed'?)"),
    ]


def test_known_policies_are_passed_on(make_file) -> None:
    path = make_file(
        "p.yaml", "map: {rows: ['..']}\nrobots: [{id: A, start: [0, 0], goal: [0, 1]}]\npolicy: {name: x}\n"
    )
    assert validate_file(path) == []
    (problem,) = validate_file(path, known_policies=("thesis",))
    assert problem.where == f"{path}:3" and "known policies: thesis" in problem.reason


def test_bad_map(make_file) -> None:
    path = make_file("b.map", "type octile\nheight 1\nwidth 3\nmap\n.Q.\n")
    (problem,) = validate_file(path)
    assert problem.where == f"{path}:5" and "unknown symbol 'Q'" in problem.reason


def test_scen_with_its_map_missing(make_file) -> None:
    path = make_file("a.scen", "version 1\n\n0\tlost.map\t2\t2\t0\t0\t1\t1\t2\n")
    (problem,) = validate_file(path)
    assert problem.where == f"{path}:3"
    assert problem.reason.startswith("map file 'lost.map' not found next to the file")


def test_scen_checked_against_its_map(maps_dir: Path, tmp_path: Path) -> None:
    shutil.copy(maps_dir / "random-32-32-20.map", tmp_path)
    path = tmp_path / "mine.scen"
    path.write_text(
        "version 1\n"
        "0\trandom-32-32-20.map\t32\t32\t5\t16\t31\t24\t1\n"  # fine
        "0\trandom-32-32-20.map\t32\t32\t0\t31\t2\t31\t1\n"  # start (0, 0) is '@'
        "0\trandom-32-32-20.map\t32\t32\t5\t16\t3\t31\t1\n"  # same start as line 2
    )
    assert [(p.where, p.reason) for p in validate_file(path)] == [
        (f"{path}:3", "start: cell (0, 0) is an obstacle"),
        (f"{path}:4", "start: cell (15, 5) is also the start of the agent on line 2"),
    ]


def test_scen_size_mismatch(maps_dir: Path, tmp_path: Path) -> None:
    shutil.copy(maps_dir / "random-64-64-10.map", tmp_path)
    path = tmp_path / "mine.scen"
    path.write_text("version 1\n0\trandom-64-64-10.map\t32\t32\t0\t0\t1\t1\t1\n")
    (problem,) = validate_file(path)
    assert problem.where == f"{path}:2" and "does not match map 'random-64-64-10', which is 64x64" in problem.reason


def test_scen_without_agents(make_file) -> None:
    path = make_file("none.scen", "version 1\n")
    assert [(p.where, p.reason) for p in validate_file(path)] == [(f"{path}:1", "the file lists no agents")]


def test_malformed_scen(make_file) -> None:
    path = make_file("m.scen", "version one\n")
    (problem,) = validate_file(path)
    assert problem.where == f"{path}:1" and "bad header" in problem.reason


def test_missing_file_is_a_problem_not_an_exception(tmp_path: Path) -> None:
    (problem,) = validate_file(tmp_path / "ghost.yaml")
    assert (problem.where, problem.reason) == (str(tmp_path / "ghost.yaml"), "file not found")


def test_unknown_file_type(make_file) -> None:
    path = make_file("notes.txt", "hello")
    (problem,) = validate_file(path)
    assert problem.where == str(path) and "unknown file type '.txt'" in problem.reason
