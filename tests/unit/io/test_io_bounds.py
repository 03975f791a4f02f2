"""File lengths, devices, nesting and map sizes: every reader refuses them with a one-line problem."""

import os
import subprocess

import pytest

from mrmp.core.errors import InputError
from mrmp.core.limits import MAX_INPUT_FILE_BYTES, MAX_YAML_DEPTH
from mrmp.io import load_scenario, validate_file
from mrmp.io.movingai import parse_map, read_map
from mrmp.io.plans import read_share
from mrmp.io.results import read_result_json
from mrmp.io.scenario_file import scenario_from_text

ONE_ROBOT = "robots:\n  - {id: A, start: [0, 0], goal: [1, 1]}\n"


def problems(error):
    return [str(problem) for problem in error.value.problems]


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom", "/dev/null"])
def test_a_device_is_refused_without_reading_it(device):
    with pytest.raises(InputError) as error:
        load_scenario(device)
    assert problems(error) == [f"{device}: is a device, not a file"]


@pytest.mark.slow
def test_a_file_one_byte_over_the_bound_is_refused_and_one_at_the_bound_is_read(tmp_path):
    path = tmp_path / "long.yaml"
    with open(path, "wb") as handle:
        handle.truncate(MAX_INPUT_FILE_BYTES + 1)
    with pytest.raises(InputError) as error:
        load_scenario(path)
    assert problems(error) == [f"{path}: longer than the bound of {MAX_INPUT_FILE_BYTES} bytes"]
    text = "map: {width: 2, height: 2}\n" + ONE_ROBOT
    path.write_text(text + "#" * (MAX_INPUT_FILE_BYTES - len(text)))
    assert load_scenario(path).robots[0].id == "A"


def test_a_pipe_is_read_up_to_the_bound(tmp_path):
    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    writer = subprocess.Popen(["sh", "-c", f"head -c {MAX_INPUT_FILE_BYTES + 65536} /dev/zero > {fifo}"], stderr=subprocess.DEVNULL)
    try:
        with pytest.raises(InputError) as error:
            load_scenario(fifo)
    finally:
        writer.wait()  # it ends once the reader has closed the pipe
    assert problems(error) == [f"{fifo}: longer than the bound of {MAX_INPUT_FILE_BYTES} bytes"]


def test_yaml_nesting_beyond_the_bound_is_refused_at_its_line():
    deep = "map: {width: 2, height: 2}\n" + ONE_ROBOT + "description: " + "[" * 20_000 + "]" * 20_000 + "\n"
    with pytest.raises(InputError) as error:
        scenario_from_text(deep, "deep.yaml")
    assert problems(error) == [f"deep.yaml:4: lists and mappings nested more than {MAX_YAML_DEPTH} levels deep"]


def test_yaml_nesting_at_the_bound_is_composed():
    nested = "[" * (MAX_YAML_DEPTH - 1) + "]" * (MAX_YAML_DEPTH - 1)
    with pytest.raises(InputError) as error:
        scenario_from_text("map: {width: 2, height: 2}\n" + ONE_ROBOT + f"description: {nested}\n", "nested.yaml")
    assert problems(error) == ["nested.yaml:4: description: expected a string, got a list"]


@pytest.mark.slow
def test_map_sizes_beyond_the_bound_are_refused_in_every_form(tmp_path):
    with pytest.raises(InputError) as error:
        scenario_from_text("map: {width: 100000, height: 100000}\n" + ONE_ROBOT, "huge.yaml")
    assert problems(error)[0].startswith("huge.yaml:1: map: a map of 100000x100000 = 10000000000 cells is larger")
    with pytest.raises(InputError) as error:
        parse_map("type octile\nheight 100000\nwidth 100000\nmap\n", "huge.map")
    assert problems(error) == [
        "huge.map:4: bad header: a map of 100000x100000 = 10000000000 cells is larger than the bound of 4194304 cells"
        " (2048 x 2048)"
    ]
    rows = "map:\n  rows:\n" + "".join(f"    - '{'.' * 3000}'\n" for _ in range(1500))
    with pytest.raises(InputError) as error:
        scenario_from_text(rows + ONE_ROBOT, "rows.yaml")
    assert problems(error)[0].startswith("rows.yaml:3: map.rows: a map of 1500x3000 = 4500000 cells is larger")


def test_a_device_named_by_a_file_is_called_a_device_and_a_missing_file_missing(tmp_path):
    with pytest.raises(InputError) as error:
        scenario_from_text("map: {file: /dev/zero}\n" + ONE_ROBOT, str(tmp_path / "zero.yaml"))
    assert problems(error) == [f"{tmp_path / 'zero.yaml'}:1: map.file: map file /dev/zero is a device, not a file"]
    with pytest.raises(InputError) as error:
        scenario_from_text("scen: /dev/zero\nagents: 1\n", str(tmp_path / "scen.yaml"))
    assert problems(error) == [f"{tmp_path / 'scen.yaml'}:1: scen: scenario file /dev/zero is a device, not a file"]
    with pytest.raises(InputError) as error:
        read_map(tmp_path)
    assert problems(error) == [f"{tmp_path}: is a folder, not a file"]
    assert [str(problem) for problem in validate_file("/dev/zero.map")] == ["/dev/zero.map: file not found"]


def test_deeply_nested_json_is_refused_with_a_problem(tmp_path):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(InputError) as error:
        read_result_json(deep)
    assert problems(error) == [f"{deep}: invalid JSON: nested too deeply"]
    with pytest.raises(InputError, match="not a robot's share of a plan"):
        read_share(deep, "A")
