"""Files of a live run: ground-truth traces, agent reports, the referee's verdict.

* ``trace-<index>.jsonl``: one JSON object per line,
  ``{"robot": i, "event": "enter"|"leave", "cell": [x, y], "t": seconds}``, and for
  a body that turns in place ``{"robot": i, "event": "heading", "cell": [x, y],
  "heading": "EAST", "t": seconds}`` when a turn ends, appended and flushed as
  events happen, so that nothing is lost if a process dies;
* ``agent-<index>.json``, ``referee.json``: JSON objects, written atomically.

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> writer = TraceWriter(folder / "trace-0.jsonl", robot=0)
>>> writer.write("enter", (1, 2), 3.5)
>>> writer.write_heading((1, 2), Heading.NORTH, 4.5)
>>> writer.close()
>>> TraceReader(folder / "trace-0.jsonl").read_new()
[(0, 'enter', (1, 2), 3.5, None), (0, 'heading', (1, 2), 4.5, <Heading.NORTH: 1>)]
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import IO, Any

from mrmp.core.cell import Cell
from mrmp.core.errors import InputError, Problem
from mrmp.core.heading import Heading
from mrmp.core.limits import MIN_KEY_BYTES
from mrmp.io._files import PathLike, atomic_write_text, read_bytes, read_text

TraceEvent = tuple[int, str, Cell, float, Heading | None]
"""A trace's event: robot, ``"enter"``, ``"leave"`` or ``"heading"``, cell, time, and the heading of a ``"heading"``."""


class TraceWriter:
    """Appends occupancy events of one robot to a JSON-lines file, flushing each line."""

    def __init__(self, path: PathLike, robot: int) -> None:
        self.robot = robot
        self._file: IO[str] | None = open(path, "a", encoding="utf-8")  # noqa: SIM115 (kept open while the robot runs; closed by close())

    def write(self, event: str, cell: Cell, t: float) -> None:
        """Append one event."""
        if self._file is not None:
            self._file.write(json.dumps({"robot": self.robot, "event": event, "cell": list(cell), "t": t}) + "\n")
            self._file.flush()

    def write_heading(self, cell: Cell, heading: Heading, t: float) -> None:
        """Append that the body, on ``cell``, ended a turn in place facing ``heading``."""
        if self._file is not None:
            item = {"robot": self.robot, "event": "heading", "cell": list(cell), "heading": heading.name, "t": t}
            self._file.write(json.dumps(item) + "\n")
            self._file.flush()

    def close(self) -> None:
        """Close the file."""
        if self._file is not None:
            self._file.close()
            self._file = None


class TraceReader:
    """Reads a trace file incrementally while its writer appends to it (a partial last line waits)."""

    def __init__(self, path: PathLike) -> None:
        self.path = Path(path)
        self._offset = 0
        self._pending = b""

    def read_new(self) -> list[TraceEvent]:
        """Events appended since the last call; malformed lines are skipped."""
        try:
            with open(self.path, "rb") as handle:
                handle.seek(self._offset)
                chunk = handle.read()
        except FileNotFoundError:
            return []
        self._offset += len(chunk)
        data = self._pending + chunk
        lines = data.split(b"\n")
        self._pending = lines.pop()
        events = []
        for line in lines:
            try:
                item = json.loads(line)
                cell = (int(item["cell"][0]), int(item["cell"][1]))
                heading = Heading[item["heading"]] if "heading" in item else None
                events.append((int(item["robot"]), str(item["event"]), cell, float(item["t"]), heading))
            except (ValueError, KeyError, TypeError, IndexError, RecursionError):
                continue
        return events


def prepare_folder(path: PathLike) -> Path:
    """Make ``path`` a folder to write a run's files in (created with its parents if missing).

    Raises
    ------
    InputError
        If it is a file, or cannot be created or written to (naming the folder).

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> prepare_folder(folder / "run") == folder / "run"
    True
    >>> (folder / "note").write_text("x") and prepare_folder(folder / "note")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: ...note: is a file, not a folder
    """
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise InputError(Problem(str(path), "is a file, not a folder"))
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise InputError(Problem(str(path), f"cannot create the folder: {error.strerror or error}")) from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(Problem(str(path), "cannot write in this folder"))
    return folder


def write_json(path: PathLike, data: Any, compact: bool = False) -> None:
    """Write ``data`` as JSON, atomically; ``compact``: on one line, for a file written again and again (a live
    robot's progress), which the C encoder writes several times faster than an indented one."""
    atomic_write_text(path, json.dumps(data, indent=None if compact else 1) + "\n")


def read_json(path: PathLike) -> Any:
    """Read a JSON file.

    Raises
    ------
    InputError
        If the file is missing or not JSON (naming the file and line).
    """
    text = read_text(path)
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise InputError(Problem(f"{path}:{error.lineno}", f"not valid JSON: {error.msg}")) from None
    except RecursionError:
        raise InputError(Problem(str(path), "not valid JSON: nested too deeply")) from None


def read_key_file(path: PathLike) -> bytes:
    """Read a fleet key: the file's bytes, less surrounding white space; at least :data:`MIN_KEY_BYTES` bytes.

    Raises
    ------
    InputError
        If the file cannot be read or the key is shorter than 16 bytes.
    """
    try:
        key = read_bytes(path).strip()
    except InputError as error:
        reason = error.problems[0].reason
        raise InputError(Problem(str(path), f"cannot read the fleet key: {reason}")) from None
    return checked_key(key, str(path))


def key_from_environment(value: str | None) -> bytes:
    """The fleet key given by ``MRMP_FLEET_KEY`` (``value``): empty when unset or empty, else at least 16 bytes.

    The key is the variable's bytes as they are; white space around them does
    not count towards the 16 bytes.

    Raises
    ------
    InputError
        If the variable holds a key shorter than 16 bytes (naming ``MRMP_FLEET_KEY``).

    >>> key_from_environment(None), key_from_environment(""), key_from_environment("k" * 16)
    (b'', b'', b'kkkkkkkkkkkkkkkk')
    >>> key_from_environment(" ")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: MRMP_FLEET_KEY: a fleet key needs at least 16 bytes, this one has 0
    """
    if not value:
        return b""
    key = value.encode()
    checked_key(key.strip(), "MRMP_FLEET_KEY")
    return key


def checked_key(key: bytes, where: str) -> bytes:
    """``key`` if it has at least :data:`MIN_KEY_BYTES` bytes.

    Raises
    ------
    InputError
        If it is shorter (the problem names ``where``).
    """
    if len(key) < MIN_KEY_BYTES:
        raise InputError(Problem(where, f"a fleet key needs at least {MIN_KEY_BYTES} bytes, this one has {len(key)}"))
    return key


def write_key_file(path: PathLike, key: bytes) -> None:
    """Write a fleet key readable by its owner only."""
    target = Path(path)
    target.touch(mode=0o600, exist_ok=True)
    target.chmod(0o600)
    target.write_bytes(key)
