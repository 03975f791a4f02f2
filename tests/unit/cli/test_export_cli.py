"""``mrmp export RESULT OUT`` and ``mrmp run --record OUT``: files ROS 2 tools read, and one-line refusals.

The files written are read back with ``mcap`` (and its ROS 2 decoder) and
``rosbags``; those tests skip, saying why, without the ``ros2`` extra. Every
refusal is a real ``python -m mrmp`` process: exit code 2, one line
``error: <file>: <reason>``, no traceback.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from mrmp.cli import app
from mrmp.io import ros_export

ROOT = Path(__file__).resolve().parents[3]
SWAP = ROOT / "examples" / "thesis-swap.yaml"
EXTRA = "needs the ros2 extra: pip install -e '.[ros2]'"
runner = CliRunner()


def invoke(*args: object):
    return runner.invoke(app, [str(arg) for arg in args])


def mrmp(*args: object) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "mrmp", *map(str, args)], capture_output=True, text=True, timeout=120, check=False
    )


def assert_refused(completed: subprocess.CompletedProcess[str], where: object, reason: str) -> None:
    """Exit code 2 and exactly one error line, ``error: <where>: ...<reason>...``."""
    assert completed.returncode == 2, completed.stdout + completed.stderr
    assert "Traceback" not in completed.stdout + completed.stderr
    lines = [line for line in completed.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, completed.stderr
    assert lines[0].startswith(f"error: {where}: "), lines[0]
    assert reason in lines[0], lines[0]


def need_extra() -> None:
    for module in ("mcap", "mcap_ros2", "rosbags"):
        pytest.importorskip(module, reason=EXTRA)


def mcap_poses(path: Path, topic: str) -> list[tuple[int, tuple[int, int]]]:
    """``(log time, mrmp cell)`` of each message on ``topic`` (ROS x is east = mrmp y, ROS y north = mrmp x)."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    with path.open("rb") as handle:
        reader = make_reader(handle, decoder_factories=[DecoderFactory()])
        return [
            (message.log_time, (int(decoded.pose.position.y), int(decoded.pose.position.x)))
            for _, _, message, decoded in reader.iter_decoded_messages(topics=[topic])
        ]


def bag_poses(path: Path, topic: str) -> list[tuple[int, tuple[int, int]]]:
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    typestore = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(path) as reader:
        connections = [connection for connection in reader.connections if connection.topic == topic]
        poses = []
        for connection, timestamp, raw in reader.messages(connections=connections):
            pose = typestore.deserialize_cdr(raw, connection.msgtype).pose
            poses.append((timestamp, (int(pose.position.y), int(pose.position.x))))
        return poses


def expected_poses(result_file: Path, index: int, seconds: float) -> list[tuple[int, tuple[int, int]]]:
    robot = json.loads(result_file.read_text())["robots"][index]
    return [(round(tick * seconds * 1e9), (x, y)) for tick, (x, y) in enumerate(robot["path"])]


# -- what is written ------------------------------------------------------------------------------


@pytest.mark.parametrize(("name", "read"), [("swap.mcap", mcap_poses), ("swap.bag", bag_poses)])
def test_run_record_writes_the_run_at_its_scenarios_cell_time(tmp_path, name, read) -> None:
    need_extra()
    out, saved = tmp_path / name, tmp_path / "swap.json"
    result = invoke("run", SWAP, "--json", saved, "--record", out)
    assert result.exit_code == 0, result.output
    kind = "mcap" if name.endswith(".mcap") else "rosbag2"
    assert f"{kind} written to {out}" in result.output.replace("\n", "")
    for index, robot in enumerate(("A", "B")):
        assert read(out, f"/robot_{robot}/pose") == expected_poses(saved, index, 2.0)  # cell_time: 2 s


@pytest.mark.parametrize(("name", "read"), [("out.mcap", mcap_poses), ("out.bag", bag_poses), ("out", bag_poses)])
def test_export_writes_a_saved_run(tmp_path, name, read) -> None:
    need_extra()
    saved = tmp_path / "swap.json"
    assert invoke("run", SWAP, "--json", saved).exit_code == 0
    out = tmp_path / name
    result = invoke("export", saved, out, "--tick-seconds", 2)
    assert result.exit_code == 0, result.output
    assert read(out, "/robot_A/pose") == expected_poses(saved, 0, 2.0)
    assert invoke("export", saved, out).exit_code == 0, "an export replaces its own earlier export"
    assert read(out, "/robot_B/pose") == expected_poses(saved, 1, 1.0)  # a simulated run saved without timing: 1 s a tick


def test_export_has_help() -> None:
    result = invoke("export", "-h")
    assert result.exit_code == 0
    for text in ("RESULT", "OUT", "--tick-seconds", "--cell-size", "rosbag2"):
        assert text in result.output


# -- what is refused ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run saved with its map."""
    path = tmp_path_factory.mktemp("saved") / "swap.json"
    assert invoke("run", SWAP, "--json", path).exit_code == 0
    return path


@pytest.mark.slow
def test_a_missing_result_file_is_named(tmp_path) -> None:
    missing = tmp_path / "nothing.json"
    assert_refused(mrmp("export", missing, tmp_path / "out.mcap"), missing, "file not found")


@pytest.mark.slow
def test_malformed_json_names_its_line(tmp_path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text('{\n  "scenario": \n')
    assert_refused(mrmp("export", bad, tmp_path / "out.mcap"), f"{bad}:3", "invalid JSON")


def test_json_that_is_no_run_is_refused(tmp_path) -> None:
    other = tmp_path / "list.json"
    other.write_text("[1, 2]\n")
    assert_refused(mrmp("export", other, tmp_path / "out.mcap"), other, "expected a JSON object describing a run")


def test_a_run_saved_without_its_map_is_refused(tmp_path, saved) -> None:
    data = json.loads(saved.read_text())
    del data["map"]
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps(data))
    assert_refused(mrmp("export", bare, tmp_path / "out.mcap"), bare, "no map is stored with this run")


@pytest.mark.parametrize("name", ["out.json", "out.db3", "out.MCAP.txt"])
def test_export_refuses_an_unknown_suffix(tmp_path, saved, name) -> None:
    out = tmp_path / name
    assert_refused(mrmp("export", saved, out), out, "not an export format: name a .mcap file, or a .bag")
    assert not out.exists()


def test_run_record_refuses_an_unknown_suffix_before_the_run(tmp_path) -> None:
    out, saved = tmp_path / "swap.zip", tmp_path / "swap.json"
    assert_refused(mrmp("run", SWAP, "--json", saved, "--record", out), out, "not an export format")
    assert not saved.exists(), "nothing ran"


def test_a_folder_that_is_no_rosbag2_is_refused(tmp_path, saved) -> None:
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("keep me")
    assert_refused(mrmp("export", saved, folder), folder, "exists and is not a rosbag2 folder")
    assert (folder / "notes.txt").read_text() == "keep me"


def test_a_bad_tick_is_refused(tmp_path, saved) -> None:
    assert_refused(
        mrmp("export", saved, tmp_path / "out.mcap", "--tick-seconds", 0), "--tick-seconds", "must be a positive number"
    )


def test_without_the_extra_export_and_record_say_how_to_install_it(tmp_path, saved, monkeypatch) -> None:
    monkeypatch.setattr(ros_export.importlib.util, "find_spec", lambda module, *args: None)
    out = tmp_path / "out.mcap"
    for result in (invoke("export", saved, out), invoke("run", SWAP, "--record", out)):
        assert result.exit_code == 2, result.output
        assert f"error: {out}: writing an MCAP file needs the packages mcap and mcap-ros2-support: pip install -e '.[ros2]'" in (
            result.output.replace("\n", "")
        )
        assert not out.exists()
