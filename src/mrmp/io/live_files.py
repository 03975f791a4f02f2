"""Files of a live run: ground-truth traces, agent reports, the referee's verdict.

* ``trace-<index>.jsonl``: one JSON object per line,
  ``{"robot": i, "event": "enter"|"leave", "cell": [x, y], "t": seconds}``,
  appended and flushed as events happen, so that nothing is lost if a process dies;
* ``agent-<index>.json``, ``referee.json``: JSON objects, written atomically.

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> writer = TraceWriter(folder / "trace-0.jsonl", robot=0)
>>> writer.write("enter", (1, 2), 3.5)
>>> writer.close()
>>> TraceReader(folder / "trace-0.jsonl").read_new()
[(0, 'enter', (1, 2), 3.5)]
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import IO, Any

from mrmp.core.cell import Cell
from mrmp.core.errors import InputError, Problem
from mrmp.io._files import PathLike, atomic_write_text, read_text

TraceEvent = tuple[int, str, Cell, float]


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
                events.append((int(item["robot"]), str(item["event"]), cell, float(item["t"])))
            except (ValueError, KeyError, TypeError, IndexError):
                continue
        return events


def write_json(path: PathLike, data: Any) -> None:
    """Write ``data`` as JSON, atomically."""
    atomic_write_text(path, json.dumps(data, indent=1) + "\n")


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


def read_key_file(path: PathLike) -> bytes:
    """Read a fleet key: the file's bytes, less surrounding white space; at least 16 bytes.

    Raises
    ------
    InputError
        If the file cannot be read or the key is shorter than 16 bytes.
    """
    try:
        key = Path(path).read_bytes().strip()
    except OSError as error:
        raise InputError(Problem(str(path), f"cannot read the fleet key: {error.strerror or error}")) from None
    if len(key) < 16:
        raise InputError(Problem(str(path), f"a fleet key needs at least 16 bytes, this one has {len(key)}"))
    return key


def write_key_file(path: PathLike, key: bytes) -> None:
    """Write a fleet key readable by its owner only."""
    target = Path(path)
    target.touch(mode=0o600, exist_ok=True)
    target.chmod(0o600)
    target.write_bytes(key)
