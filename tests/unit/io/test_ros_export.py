"""A run exported for ROS 2 tools and read back with the same libraries: every pose, tick by tick, cell by cell.

A run of a real scenario goes to an MCAP file (read with ``mcap``'s reader and
the ``mcap_ros2`` decoder) and to a rosbag2 folder (read with ``rosbags``'
Reader and ``deserialize_cdr``); both must hold the map's occupancy, each
robot's pose at every tick (its cell and its heading's quaternion), its path
and its goal, and the robots' messages, at ``tick * tick_seconds``. The tests
that write files skip, saying why, without the ``ros2`` extra.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

import mrmp
from mrmp.core import Grid, Heading, InputError, RobotResult, RunResult
from mrmp.core.scenario import Scenario
from mrmp.io import ros_export
from mrmp.io.ros_export import export_kind, export_problem, missing_packages, write_ros_export
from mrmp.io.ros_messages import ROS_TYPES, message_definition, robot_headings, run_messages
from mrmp.sim.simulator import simulate

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"
EXTRA = "needs the ros2 extra: pip install -e '.[ros2]'"
FORMATS = ("mcap", "rosbag2")

Decoded = dict[str, list[tuple[int, Any]]]
"""Messages read back: for each topic, ``(log time in ns, decoded message)`` in file order."""


def need(module: str) -> Any:
    return pytest.importorskip(module, reason=EXTRA)


# -- runs and reading back ---------------------------------------------------------------------


def simulated(name: str) -> tuple[Scenario, RunResult]:
    scenario = mrmp.load(EXAMPLES / name)
    return scenario, simulate(scenario, record_messages=True)


@pytest.fixture(scope="module")
def warehouse() -> tuple[Scenario, RunResult]:
    """Six robots around shelves on a 7 x 11 map (not square: x and y cannot be confused), with turns and messages."""
    return simulated("warehouse-astar.yaml")


@pytest.fixture(scope="module")
def swap() -> tuple[Scenario, RunResult]:
    """The thesis's head-on swap: 2 s a cell."""
    return simulated("thesis-swap.yaml")


def read_mcap(path: Path) -> Decoded:
    need("mcap")
    decoder = need("mcap_ros2.decoder")
    from mcap.reader import make_reader

    topics: Decoded = {}
    with path.open("rb") as handle:
        reader = make_reader(handle, decoder_factories=[decoder.DecoderFactory()])
        for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=False):
            assert schema is not None and schema.encoding == "ros2msg"
            assert channel.message_encoding == "cdr"
            topics.setdefault(channel.topic, []).append((message.log_time, decoded))
    return topics


def read_rosbag2(path: Path) -> Decoded:
    need("rosbags")
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    typestore = get_typestore(Stores.ROS2_HUMBLE)
    topics: Decoded = {}
    with Reader(path) as reader:
        for connection, timestamp, raw in reader.messages():
            topics.setdefault(connection.topic, []).append((timestamp, typestore.deserialize_cdr(raw, connection.msgtype)))
    return topics


def mcap_types(path: Path) -> dict[str, str]:
    need("mcap")
    from mcap.reader import make_reader

    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None
    return {channel.topic: summary.schemas[channel.schema_id].name for channel in summary.channels.values()}


def rosbag2_types(path: Path) -> dict[str, str]:
    need("rosbags")
    from rosbags.rosbag2 import Reader

    with Reader(path) as reader:
        return {connection.topic: connection.msgtype for connection in reader.connections}


READERS: dict[str, Callable[[Path], Decoded]] = {"mcap": read_mcap, "rosbag2": read_rosbag2}
TYPES: dict[str, Callable[[Path], dict[str, str]]] = {"mcap": mcap_types, "rosbag2": rosbag2_types}
SUFFIXES = {"mcap": ".mcap", "rosbag2": ".bag"}


def exported(tmp_path: Path, kind: str, scenario: Scenario, result: RunResult, **options: Any) -> Decoded:
    """``result`` written as ``kind`` and read back."""
    for module in ("mcap", "mcap_ros2") if kind == "mcap" else ("rosbags",):
        need(module)
    path = tmp_path / f"run{SUFFIXES[kind]}"
    assert write_ros_export(result, scenario.grid, path, **options) == kind
    return READERS[kind](path)


# -- what a decoded message says -----------------------------------------------------------------


def nanoseconds(header: Any) -> int:
    return header.stamp.sec * 1_000_000_000 + header.stamp.nanosec


def cell_of(pose: Any, cell_size: float = 1.0) -> tuple[int, int]:
    """The mrmp cell whose centre a ROS pose stands on: ROS x is east (mrmp y), ROS y north (mrmp x)."""
    east, north = pose.position.x / cell_size - 0.5, pose.position.y / cell_size - 0.5
    assert east == round(east) and north == round(north), "a pose is at a cell's centre"
    assert pose.position.z == 0.0
    return (round(north), round(east))


YAWS = {Heading.EAST: 0.0, Heading.NORTH: math.pi / 2, Heading.WEST: math.pi, Heading.SOUTH: -math.pi / 2}


def heading_of(pose: Any) -> Heading:
    """The heading of a pose's quaternion, which must be a unit rotation about z only."""
    q = pose.orientation
    assert q.x == q.y == 0.0
    assert math.isclose(q.z * q.z + q.w * q.w, 1.0, abs_tol=1e-12)
    yaw = math.atan2(2 * q.w * q.z, 1 - 2 * q.z * q.z)
    [heading] = [h for h, angle in YAWS.items() if math.isclose(math.cos(yaw - angle), 1.0, abs_tol=1e-9)]
    return heading


def tick_ns(tick: int, seconds: float) -> int:
    return round(tick * seconds * 1e9)


# -- both formats hold the run -----------------------------------------------------------------


@pytest.mark.parametrize("kind", FORMATS)
def test_every_pose_is_the_robots_cell_and_heading_at_its_tick(tmp_path, warehouse, kind) -> None:
    scenario, result = warehouse
    seconds = scenario.timing.cell_time
    topics = exported(tmp_path, kind, scenario, result, tick_seconds=seconds)
    for robot in result.robots:
        poses = topics[f"/robot_{robot.id}/pose"]
        assert len(poses) == len(robot.path) == result.ticks + 1
        assert robot.headings, "the simulator records headings"
        for tick, (log_time, message) in enumerate(poses):
            assert log_time == nanoseconds(message.header) == tick_ns(tick, seconds)
            assert message.header.frame_id == "map"
            assert cell_of(message.pose) == robot.path[tick], (robot.id, tick)
            assert heading_of(message.pose) == robot.headings[tick], (robot.id, tick)


@pytest.mark.parametrize("kind", FORMATS)
def test_the_map_is_the_grid_occupied_100_free_0(tmp_path, warehouse, kind) -> None:
    scenario, result = warehouse
    grid = scenario.grid
    [(log_time, occupancy)] = exported(tmp_path, kind, scenario, result)["/map"]
    assert log_time == 0 and nanoseconds(occupancy.header) == 0 and occupancy.header.frame_id == "map"
    info = occupancy.info
    assert (info.width, info.height, info.resolution) == (grid.y_size, grid.x_size, 1.0)
    assert (info.origin.position.x, info.origin.position.y, info.origin.orientation.w) == (0.0, 0.0, 1.0)
    data = list(occupancy.data)
    assert len(data) == grid.x_size * grid.y_size
    for x in range(grid.x_size):
        for y in range(grid.y_size):
            assert data[x * info.width + y] == (100 if grid.is_blocked((x, y)) else 0), (x, y)
    assert data.count(100) == len(grid.blocked_cells()) > 0


@pytest.mark.parametrize("kind", FORMATS)
def test_paths_hold_every_tick_and_goals_their_cell(tmp_path, warehouse, kind) -> None:
    scenario, result = warehouse
    topics = exported(tmp_path, kind, scenario, result, tick_seconds=0.25)
    for robot in result.robots:
        [(path_time, path)] = topics[f"/robot_{robot.id}/path"]
        assert path_time == 0 and path.header.frame_id == "map"
        assert len(path.poses) == len(robot.path)
        assert [cell_of(pose.pose) for pose in path.poses] == robot.path
        assert [heading_of(pose.pose) for pose in path.poses] == robot.headings
        assert [nanoseconds(pose.header) for pose in path.poses] == [tick_ns(tick, 0.25) for tick in range(len(robot.path))]
        [(goal_time, goal)] = topics[f"/robot_{robot.id}/goal"]
        assert goal_time == 0 and cell_of(goal.pose) == robot.goal and heading_of(goal.pose) == Heading.NORTH


@pytest.mark.parametrize("kind", FORMATS)
def test_the_robots_messages_are_json_lines_at_their_tick(tmp_path, swap, kind) -> None:
    scenario, result = swap
    assert result.message_log is not None
    expected = [
        (tick_ns(tick, 2.0), {"tick": tick, "type": kind_, "sender": sender, "receiver": receiver})
        for tick, entries in enumerate(result.message_log)
        for sender, receiver, kind_ in entries
    ]
    assert len(expected) == result.messages > 0
    messages = exported(tmp_path, kind, scenario, result, tick_seconds=scenario.timing.cell_time)["/mrmp/messages"]
    assert [(log_time, json.loads(message.data)) for log_time, message in messages] == expected


@pytest.mark.parametrize("kind", FORMATS)
def test_each_topic_has_its_ros2_type(tmp_path, swap, kind) -> None:
    scenario, result = swap
    exported(tmp_path, kind, scenario, result)
    expected = {"/map": "nav_msgs/msg/OccupancyGrid", "/mrmp/messages": "std_msgs/msg/String"}
    for robot in ("A", "B"):
        expected |= {
            f"/robot_{robot}/pose": "geometry_msgs/msg/PoseStamped",
            f"/robot_{robot}/goal": "geometry_msgs/msg/PoseStamped",
        }
        expected[f"/robot_{robot}/path"] = "nav_msgs/msg/Path"
    assert TYPES[kind](tmp_path / f"run{SUFFIXES[kind]}") == expected


@pytest.mark.parametrize("kind", FORMATS)
def test_times_start_at_0_and_follow_the_tick(tmp_path, swap, kind) -> None:
    scenario, result = swap
    topics = exported(tmp_path, kind, scenario, result, tick_seconds=scenario.timing.cell_time)
    times = [log_time for messages in topics.values() for log_time, _ in messages]
    assert min(times) == 0 and max(times) == tick_ns(result.ticks, 2.0) == 12_000_000_000


@pytest.mark.parametrize("kind", FORMATS)
def test_a_live_run_keeps_its_own_tick_and_a_cell_size_scales_positions(tmp_path, swap, kind) -> None:
    scenario, result = swap
    live = replace(result, mode="live", tick_seconds=0.05)
    topics = exported(tmp_path, kind, scenario, live, cell_size=0.5)
    assert topics["/map"][0][1].info.resolution == 0.5
    robot = live.robots[0]
    poses = topics[f"/robot_{robot.id}/pose"]
    assert [log_time for log_time, _ in poses] == [tick_ns(tick, 0.05) for tick in range(len(robot.path))]
    assert [cell_of(message.pose, cell_size=0.5) for _, message in poses] == robot.path


# -- definitions, names, files ------------------------------------------------------------------


def test_the_definitions_are_those_of_ros2() -> None:
    need("rosbags")
    from rosbags.typesys import Stores, get_typestore

    for store in (Stores.ROS2_HUMBLE, Stores.ROS2_JAZZY):
        typestore = get_typestore(store)
        for ros_type in ROS_TYPES:
            assert message_definition(ros_type) == typestore.generate_msgdef(ros_type, ros_version=2)[0], (store, ros_type)


def test_latched_topics_are_offered_transient_local(tmp_path, swap) -> None:
    need("rosbags")
    from rosbags.interfaces import QosDurability
    from rosbags.rosbag2 import Reader

    scenario, result = swap
    write_ros_export(result, scenario.grid, tmp_path / "run.bag")
    with Reader(tmp_path / "run.bag") as reader:
        durability = {c.topic: c.ext.offered_qos_profiles[0].durability for c in reader.connections}
    assert durability["/map"] == durability["/robot_A/path"] == durability["/robot_A/goal"] == QosDurability.TRANSIENT_LOCAL
    assert durability["/robot_A/pose"] == durability["/mrmp/messages"] == QosDurability.VOLATILE


def test_ids_a_topic_cannot_hold_are_spelled_with_underscores(tmp_path) -> None:
    need("mcap_ros2")
    robot = RobotResult("r-1.x", (0, 0), (0, 1), path=[(0, 0), (0, 1)])
    run = RunResult("s", "astar", 0, [robot], [], "all_arrived", 1, 1, 0.0)
    write_ros_export(run, Grid(1, 2), tmp_path / "run.mcap")
    assert set(read_mcap(tmp_path / "run.mcap")) == {"/map", "/robot_r_1_x/pose", "/robot_r_1_x/path", "/robot_r_1_x/goal"}


def test_a_run_without_headings_faces_the_way_it_moves() -> None:
    robot = RobotResult("A", (0, 0), (1, 1), path=[(0, 0), (0, 1), (0, 1), (1, 1), (0, 1)])
    assert robot_headings(robot) == [Heading.NORTH, Heading.EAST, Heading.EAST, Heading.NORTH, Heading.SOUTH]
    grid = Grid(2, 2)
    run = RunResult("s", "p", 0, [robot], [], "done", 4, 2, 0.0)
    poses = [message for message in run_messages(run, grid) if message.topic == "/robot_A/pose"]
    assert [message.fields["pose"]["orientation"]["z"] for message in poses][:2] == [math.sqrt(0.5), 0.0]


@pytest.mark.parametrize("kind", FORMATS)
def test_an_export_replaces_its_own_kind_and_leaves_nothing_beside_it(tmp_path, swap, kind) -> None:
    scenario, result = swap
    first = exported(tmp_path, kind, scenario, result)
    shorter = replace(result, robots=result.robots[:1], message_log=None)
    again = exported(tmp_path, kind, scenario, shorter)
    assert len(first) == 8 and sorted(again) == ["/map", "/robot_A/goal", "/robot_A/path", "/robot_A/pose"]
    assert [entry.name for entry in tmp_path.iterdir()] == [f"run{SUFFIXES[kind]}"]


def test_a_folder_that_is_no_rosbag2_is_never_replaced(tmp_path, swap) -> None:
    scenario, result = swap
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("keep me")
    with pytest.raises(InputError, match="exists and is not a rosbag2 folder"):
        write_ros_export(result, scenario.grid, folder)
    assert (folder / "notes.txt").read_text() == "keep me"
    assert export_kind(folder) == "rosbag2" and export_problem(folder) is not None


def test_an_mcap_target_that_is_a_folder_is_refused(tmp_path, swap) -> None:
    scenario, result = swap
    (tmp_path / "run.mcap").mkdir()
    with pytest.raises(InputError, match=r"run\.mcap: is a folder, not a file"):
        write_ros_export(result, scenario.grid, tmp_path / "run.mcap")


def test_an_unknown_suffix_names_the_formats(tmp_path, swap) -> None:
    scenario, result = swap
    with pytest.raises(InputError, match=r"run\.json: not an export format: name a \.mcap file"):
        write_ros_export(result, scenario.grid, tmp_path / "run.json")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    ("name", "reason"),
    [
        ("run.mcap", "writing an MCAP file needs the packages mcap and mcap-ros2-support: pip install -e '.[ros2]'"),
        ("run.bag", "writing a rosbag2 folder needs the package rosbags: pip install -e '.[ros2]'"),
    ],
)
def test_without_the_extra_the_error_says_how_to_install_it(tmp_path, swap, monkeypatch, name, reason) -> None:
    scenario, result = swap
    monkeypatch.setattr(ros_export.importlib.util, "find_spec", lambda module, *args: None)
    with pytest.raises(InputError) as raised:
        write_ros_export(result, scenario.grid, tmp_path / name)
    assert str(raised.value) == f"{tmp_path / name}: {reason}"
    assert export_problem(tmp_path / name) == missing_packages(export_kind(name) or "mcap") == reason
    assert not list(tmp_path.iterdir())


def test_bad_numbers_are_refused() -> None:
    run = RunResult("s", "p", 0, [], [], "done", 0, 0, 0.0)
    with pytest.raises(InputError, match="--tick-seconds: must be a positive"):
        run_messages(run, Grid(1, 1), tick_seconds=float("inf"))
    with pytest.raises(InputError, match="--cell-size: must be a positive"):
        run_messages(run, Grid(1, 1), cell_size=-1.0)
