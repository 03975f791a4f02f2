"""A run as ROS 2 data: an MCAP file (Foxglove, ``ros2 bag``) or a rosbag2 folder (``ros2 bag play``).

:func:`write_ros_export` writes the messages of :func:`mrmp.io.ros_messages.run_messages`
(the map on ``/map``, each robot's pose per tick, path and goal on
``/robot_<id>/...``, the robots' messages on ``/mrmp/messages``) to

* ``OUT.mcap``: an MCAP file of profile ``ros2`` with the ROS 2 message
  definitions as schemas, written with ``mcap`` and ``mcap-ros2-support``;
* ``OUT.bag`` or any path without a suffix: a rosbag2 folder (format version
  8, SQLite 3 storage, CDR messages), written with ``rosbags``.

Those packages are the optional extra ``ros2`` (``pip install -e '.[ros2]'``);
they are imported only when a file is written, and without them writing raises
an :class:`~mrmp.core.errors.InputError` saying so. Both outputs appear whole
or not at all: they are written beside the target and then moved over it. An
existing folder is replaced only when it is a rosbag2 folder (or empty).
``docs/ros2.md`` describes topics, frames, axes and times.

Examples
--------
>>> export_kind("run.mcap"), export_kind("run.bag"), export_kind("out/run"), export_kind("run.json")
('mcap', 'rosbag2', 'rosbag2', None)
>>> print(format_problem("run.json"))
not an export format: name a .mcap file, or a .bag (or suffix-less) folder for rosbag2
"""

from __future__ import annotations

import importlib.util
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any, Literal

from mrmp.core.errors import InputError, Problem
from mrmp.core.grid import Grid
from mrmp.core.result import RunResult
from mrmp.io._files import PathLike, atomic_write
from mrmp.io.ros_messages import ROS_TYPES, Topic, message_definition, run_messages, run_topics

ExportKind = Literal["mcap", "rosbag2"]
"""What an export path asks for."""

INSTALL_HINT = "pip install -e '.[ros2]'"
"""How to install the optional packages an export needs."""

REQUIRED: dict[ExportKind, tuple[tuple[str, str], ...]] = {
    "mcap": (("mcap", "mcap"), ("mcap_ros2", "mcap-ros2-support")),
    "rosbag2": (("rosbags", "rosbags"),),
}
"""For each kind of export, the modules it imports and the packages they come from."""

ROSBAG2_VERSION: Literal[8] = 8
"""The rosbag2 format version written (``offered_qos_profiles`` as a YAML string, as older ``ros2 bag`` reads)."""

_BAG_FILE_SUFFIXES = (".yaml", ".db3", ".db3-shm", ".db3-wal", ".mcap")
"""Files a rosbag2 folder holds: its ``metadata.yaml`` and its storage files."""


# -- what to write, and whether it can be ------------------------------------------------------


def export_kind(path: PathLike) -> ExportKind | None:
    """The kind of export ``path`` names: ``.mcap`` a file, ``.bag``, no suffix or an existing folder a rosbag2 folder.

    >>> export_kind("RUN.MCAP"), export_kind("swap.bag/"), export_kind("notes.txt")
    ('mcap', 'rosbag2', None)
    """
    target = Path(path)
    suffix = target.suffix.lower()
    if suffix == ".mcap":
        return "mcap"
    if suffix in (".bag", "") or target.is_dir():
        return "rosbag2"
    return None


def format_problem(path: PathLike) -> str | None:
    """Why ``path`` names no export (its suffix), or None.

    >>> format_problem("run.mcap") is None
    True
    """
    if export_kind(path) is None:
        return "not an export format: name a .mcap file, or a .bag (or suffix-less) folder for rosbag2"
    return None


def missing_packages(kind: ExportKind) -> str | None:
    """Why an export of ``kind`` cannot be written here (its packages are not installed), or None.

    The packages are looked up, not imported.
    """
    missing = [package for module, package in REQUIRED[kind] if not _installed(module)]
    if not missing:
        return None
    what = "an MCAP file" if kind == "mcap" else "a rosbag2 folder"
    return f"writing {what} needs the package{'s' if len(missing) > 1 else ''} {' and '.join(missing)}: {INSTALL_HINT}"


def _installed(module: str) -> bool:
    """Whether ``module`` can be imported (found, not imported; a broken entry in ``sys.modules`` counts as missing).

    >>> _installed("json"), _installed("no_such_module_here")
    (True, False)
    """
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError, AttributeError):
        return False


def target_problem(path: PathLike) -> str | None:
    """Why ``path`` cannot receive its export (a folder where a file goes, a folder that is no rosbag2), or None.

    >>> target_problem("/")
    'exists and is not a rosbag2 folder (it is never replaced): remove it or name another'
    """
    target = Path(path)
    kind = export_kind(target)
    if kind == "mcap" and target.is_dir():
        return "is a folder, not a file"
    if kind == "rosbag2" and target.exists() and not _replaceable_bag(target):
        return "exists and is not a rosbag2 folder (it is never replaced): remove it or name another"
    return None


def export_problem(path: PathLike) -> str | None:
    """Why a run cannot be exported to ``path``: its format, its target, or missing packages; None when it can.

    Checked before a run (``mrmp run --record``), so that no run is wasted.

    >>> export_problem("run.txt")
    'not an export format: name a .mcap file, or a .bag (or suffix-less) folder for rosbag2'
    """
    kind = export_kind(path)
    if kind is None:
        return format_problem(path)
    return target_problem(path) or missing_packages(kind)


def _replaceable_bag(folder: Path) -> bool:
    """Whether ``folder`` is empty or holds only a rosbag2's files, its ``metadata.yaml`` among them."""
    if not folder.is_dir():
        return False
    entries = list(folder.iterdir())
    if not entries:
        return True
    names = {entry.name for entry in entries}
    return "metadata.yaml" in names and all(entry.is_file() and entry.name.endswith(_BAG_FILE_SUFFIXES) for entry in entries)


def _checked(path: PathLike, kind: ExportKind) -> Path:
    """``path``, or an :class:`InputError` naming it and why it cannot be written."""
    problem = target_problem(path) or missing_packages(kind)
    if problem is not None:
        raise InputError(Problem(str(path), problem))
    return Path(path)


# -- writing ----------------------------------------------------------------------------------


def write_ros_export(
    result: RunResult, grid: Grid, path: PathLike, tick_seconds: float | None = None, cell_size: float = 1.0
) -> ExportKind:
    """Write ``result`` on ``grid`` to ``path`` as MCAP or rosbag2, by the path's name (:func:`export_kind`).

    Parameters
    ----------
    result, grid:
        The run and its map.
    path:
        ``*.mcap``: an MCAP file; ``*.bag``, a path without suffix or an
        existing rosbag2 folder: a rosbag2 folder.
    tick_seconds:
        Seconds per tick; by default the run's own (live runs), else 1
        (give a simulated run's ``timing.cell_time``).
    cell_size:
        Metres per cell (the map's resolution).

    Returns
    -------
    str
        ``"mcap"`` or ``"rosbag2"``: what was written.

    Raises
    ------
    InputError
        If the path names no export format, cannot be written, or the
        packages of the ``ros2`` extra are missing; or if ``tick_seconds`` or
        ``cell_size`` is not positive.
    """
    kind = export_kind(path)
    if kind is None:
        raise InputError(Problem(str(path), str(format_problem(path))))
    if kind == "mcap":
        write_mcap(result, grid, path, tick_seconds, cell_size)
    else:
        write_rosbag2(result, grid, path, tick_seconds, cell_size)
    return kind


def write_mcap(result: RunResult, grid: Grid, path: PathLike, tick_seconds: float | None = None, cell_size: float = 1.0) -> None:
    """Write ``result`` as an MCAP file (profile ``ros2``, CDR messages, ``ros2msg`` schemas); see :func:`write_ros_export`."""
    target = _checked(path, "mcap")
    messages = run_messages(result, grid, tick_seconds, cell_size)
    from mcap_ros2.writer import Writer

    def write(handle: IO[bytes]) -> None:
        writer = Writer(handle)
        schemas = {ros_type: writer.register_msgdef(ros_type, message_definition(ros_type)) for ros_type in ROS_TYPES}
        sequences: dict[str, int] = {}
        for message in messages:
            sequence = sequences[message.topic] = sequences.get(message.topic, -1) + 1
            writer.write_message(
                message.topic, schemas[message.ros_type], message.fields,
                log_time=message.nanoseconds, publish_time=message.nanoseconds, sequence=sequence,
            )  # fmt: skip
        writer.add_metadata("mrmp", _metadata(result, grid))
        writer.finish()

    atomic_write(target, write)


def write_rosbag2(
    result: RunResult, grid: Grid, path: PathLike, tick_seconds: float | None = None, cell_size: float = 1.0
) -> None:
    """Write ``result`` as a rosbag2 folder (version 8, SQLite 3 storage, CDR); see :func:`write_ros_export`.

    Latched topics (the map, paths, goals) are offered with durability
    ``transient_local`` and depth 1, so ``ros2 bag play`` hands them to late
    subscribers such as RViz; poses and messages with ``volatile``.
    """
    target = _checked(path, "rosbag2")
    messages = run_messages(result, grid, tick_seconds, cell_size)
    from rosbags.rosbag2 import Writer, WriterError
    from rosbags.typesys import Stores, get_typestore

    typestore = get_typestore(Stores.ROS2_HUMBLE)
    try:
        with _atomic_folder(target) as staging, Writer(staging, version=ROSBAG2_VERSION) as writer:
            for key, value in _metadata(result, grid).items():
                writer.set_custom_data(f"mrmp.{key}", value)
            connections = {
                topic.name: writer.add_connection(
                    topic.name, topic.ros_type, typestore=typestore, offered_qos_profiles=[_qos(topic)]
                )
                for topic in run_topics(result)
            }
            for message in messages:
                data = typestore.serialize_cdr(_rosbags_message(typestore, message.ros_type, message.fields), message.ros_type)
                writer.write(connections[message.topic], message.nanoseconds, data)
    except WriterError as error:
        raise InputError(Problem(str(target), f"cannot write the rosbag2 folder: {error}")) from None


def _metadata(result: RunResult, grid: Grid) -> dict[str, str]:
    """What the export says of the run besides its messages (MCAP metadata ``mrmp``, rosbag2 ``custom_data``)."""
    return {
        "scenario": result.scenario,
        "policy": result.policy,
        "seed": str(result.seed),
        "mode": result.mode,
        "ticks": str(result.ticks),
        "success": str(result.success).lower(),
        "map": grid.name,
        "axes": "map x = east = mrmp y, map y = north = mrmp x (REP 103)",
    }


def _qos(topic: Topic) -> Any:
    """The offered QoS of ``topic``: reliable; latched topics ``transient_local`` depth 1, others ``volatile`` depth 10."""
    from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime

    durability = QosDurability.TRANSIENT_LOCAL if topic.latched else QosDurability.VOLATILE
    unset = QosTime(0, 0)
    return Qos(
        QosHistory.KEEP_LAST, 1 if topic.latched else 10, QosReliability.RELIABLE, durability,
        unset, unset, QosLiveliness.AUTOMATIC, unset, False,
    )  # fmt: skip


def _rosbags_message(typestore: Any, ros_type: str, fields: dict[str, Any]) -> Any:
    """The ``rosbags`` object of type ``ros_type`` holding ``fields`` (nested dictionaries, as :class:`RosMessage` has)."""
    from rosbags.interfaces import Nodetype

    values: dict[str, Any] = {}
    for name, (node, detail) in typestore.fielddefs[ros_type][1]:
        value = fields[name]
        if node == Nodetype.NAME:
            values[name] = _rosbags_message(typestore, detail, value)
        elif node == Nodetype.SEQUENCE and detail[0][0] == Nodetype.NAME:
            values[name] = [_rosbags_message(typestore, detail[0][1], item) for item in value]
        elif node == Nodetype.SEQUENCE:
            import numpy as np

            values[name] = np.array(value, dtype=np.dtype(detail[0][1][0]))
        else:
            values[name] = value
    return typestore.types[ros_type](**values)


# -- whole or nothing -------------------------------------------------------------------------


@contextmanager
def _atomic_folder(target: Path) -> Iterator[Path]:
    """A path to create the folder at, beside ``target`` under its name, moved over ``target`` when the block ends.

    An existing ``target`` (an empty folder or a rosbag2 folder, :func:`target_problem`)
    is replaced; when the block fails nothing is left behind.

    Raises
    ------
    InputError
        If the folder cannot be written.
    """
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp"))
    except OSError as error:
        raise InputError(Problem(str(target), f"cannot write the folder: {error.strerror or error}")) from None
    try:
        yield staging / target.name
        if target.exists():
            target.rename(staging / ".replaced")
        (staging / target.name).rename(target)
    except OSError as error:
        raise InputError(Problem(str(target), f"cannot write the folder: {error.strerror or error}")) from None
    finally:
        shutil.rmtree(staging, ignore_errors=True)
