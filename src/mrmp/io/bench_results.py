"""Benchmark results on disk: ``results.jsonl`` (one record per finished run) and ``results.csv``.

``results.jsonl`` holds one JSON object per line, appended, flushed and
fsynced as each run ends, so that whatever finished is on disk even if the
benchmark is killed. A run that was run again (``--only-missing`` retries
failed runs) has several records; the last one counts
(:func:`latest_records`). A line cut short by a kill in mid-write is dropped
when the file is next opened for appending (:func:`read_records` with
``repair=True``).

``results.csv`` is regenerated from the JSON lines: the scalar fields of each
latest record, in :data:`CSV_COLUMNS` order, the faults spread over
``loss``, ``delay_min``, ``delay_max``, ``duplicate`` and ``reorder`` columns.

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> append_record(folder / "results.jsonl", {"run_id": "a1", "status": "done"})
>>> append_record(folder / "results.jsonl", {"run_id": "a1", "status": "error"})
>>> [record["status"] for record in latest_records(read_records(folder / "results.jsonl"))]
['error']
"""

from __future__ import annotations

import csv
import io
import json
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from mrmp.core.errors import InputError, Problem
from mrmp.io._files import PathLike, atomic_write_text

RECORD_FORMAT = "mrmp-bench-1"
"""The ``format`` of every record (the contract between ``mrmp bench`` and ``mrmp report``)."""
RESULTS_JSONL = "results.jsonl"
"""The records file inside a benchmark's output folder."""
RESULTS_CSV = "results.csv"
"""The table inside a benchmark's output folder."""

RESULT_FIELDS: tuple[str, ...] = (
    "success", "stop_reason", "ticks", "makespan", "sum_of_costs", "lower_bound", "time_makespan_s",
    "time_sum_of_costs_s", "messages",
    "network", "wall_time_s", "planning_time_s", "plan_bytes", "throughput", "collisions", "soc_over_lb",
    "robots_arrived", "goals_reached", "steps", "wall_time_per_step_s", "messages_per_robot_move", "tasks_finished",
)  # fmt: skip
"""The fields of a record that come from the run's result (null for a timeout or an error)."""

CSV_COLUMNS: tuple[str, ...] = (
    "run_id", "bench", "status", "error", "map", "map_path", "scen", "instance", "lorr", "agents", "policy", "kind",
    "seed", "loss", "delay_min", "delay_max", "duplicate", "reorder", "lifelong", "max_ticks", "time_limit_s",
    *(name for name in RESULT_FIELDS if name != "network"),
)  # fmt: skip
"""The columns of ``results.csv``: the run's parameters (faults spread out), then its scalar result fields."""


def append_record(path: PathLike, record: Mapping[str, Any]) -> None:
    """Append one record as a JSON line, then flush and fsync the file.

    Raises
    ------
    InputError
        If the file cannot be written.
    """
    line = json.dumps(record, separators=(",", ":")) + "\n"
    try:
        with open(path, "a", encoding="utf-8") as stream:
            stream.write(line)
            stream.flush()
            os.fsync(stream.fileno())
    except OSError as error:
        raise InputError(Problem(str(path), f"cannot append to the file: {error.strerror or error}")) from None


def read_records(path: PathLike, repair: bool = False) -> list[dict[str, Any]]:
    """Every record of a ``results.jsonl`` file, in file order (none if the file does not exist).

    Parameters
    ----------
    path:
        The file.
    repair:
        Cut off a last line left incomplete by a kill in mid-write, so that
        the next append starts on a line of its own.

    Raises
    ------
    InputError
        If a complete line is not a JSON object (naming its line), or the file
        cannot be read.
    """
    file = Path(path)
    if not file.exists():
        return []
    try:
        data = file.read_bytes()
    except OSError as error:
        raise InputError(Problem(str(path), f"cannot read the file: {error.strerror or error}")) from None
    complete_end = data.rfind(b"\n") + 1
    if complete_end < len(data) and repair:
        with open(file, "r+b") as stream:
            stream.truncate(complete_end)
            stream.flush()
            os.fsync(stream.fileno())
    records: list[dict[str, Any]] = []
    for number, raw in enumerate(data[:complete_end].decode("utf-8", errors="replace").splitlines(), start=1):
        if not raw.strip():
            continue
        try:
            record = json.loads(raw)
        except json.JSONDecodeError as error:
            raise InputError(Problem(f"{path}:{number}", f"not a JSON record: {error.msg}")) from None
        except RecursionError:
            raise InputError(Problem(f"{path}:{number}", "not a JSON record: nested too deeply")) from None
        if not isinstance(record, dict) or not isinstance(record.get("run_id"), str):
            raise InputError(Problem(f"{path}:{number}", "expected a JSON object with a run_id"))
        records.append(record)
    return records


def latest_records(records: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """One record per run_id, the last one written, in order of first appearance.

    >>> [r["n"] for r in latest_records([{"run_id": "a", "n": 1}, {"run_id": "b", "n": 2}, {"run_id": "a", "n": 3}])]
    [3, 2]
    """
    latest: dict[str, dict[str, Any]] = {}
    for record in records:
        latest[record["run_id"]] = dict(record)
    return list(latest.values())


def csv_row(record: Mapping[str, Any]) -> dict[str, Any]:
    """The flat scalar fields of one record, keyed by :data:`CSV_COLUMNS`.

    >>> row = csv_row({"run_id": "a", "faults": {"loss": 0.1, "delay": [0, 2], "duplicate": 0, "reorder": 0}})
    >>> row["loss"], row["delay_max"], row["success"]
    (0.1, 2, None)
    """
    faults = record.get("faults") or {}
    delay = faults.get("delay") or [None, None]
    flat = dict(record)
    flat.update(
        loss=faults.get("loss"),
        delay_min=delay[0],
        delay_max=delay[1],
        duplicate=faults.get("duplicate"),
        reorder=faults.get("reorder"),
    )
    return {column: flat.get(column) for column in CSV_COLUMNS}


def records_to_csv(records: Iterable[Mapping[str, Any]]) -> str:
    """The CSV text of records (header first; null as an empty cell).

    >>> records_to_csv([{"run_id": "a", "agents": 5}]).splitlines()[1].split(",")[:11]
    ['a', '', '', '', '', '', '', '', '', '5', '']
    """
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=CSV_COLUMNS, lineterminator="\n")
    writer.writeheader()
    for record in records:
        writer.writerow({key: "" if value is None else value for key, value in csv_row(record).items()})
    return buffer.getvalue()


def write_csv(path: PathLike, records: Iterable[Mapping[str, Any]]) -> None:
    """Write ``results.csv`` atomically from the latest record of each run.

    Raises
    ------
    InputError
        If the file cannot be written.
    """
    atomic_write_text(path, records_to_csv(latest_records(records)))
