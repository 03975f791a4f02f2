"""Reading a benchmark's ``results.jsonl`` (format ``mrmp-bench-1``) into typed records for a report.

``mrmp bench`` appends one JSON object per finished run to
``DIR/results.jsonl`` and flushes it to disk as the run ends, so an
interrupted benchmark may leave its last line cut short. This reader accepts
exactly that: a last line without its final newline that is not valid JSON is
set aside and counted (:attr:`BenchResults.truncated_lines`). Every other
defect -- a line that is not JSON, not an object, of another format, or with a
missing or mistyped field -- raises :class:`~mrmp.core.errors.InputError`
whose problems read ``FILE:LINE: reason``.

When a run appears more than once (a benchmark resumed after a crash may run
it again), the last record wins and :attr:`BenchResults.replaced_records`
counts the earlier ones.

Examples
--------
>>> import json, tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> record = {"format": "mrmp-bench-1", "run_id": "0123456789abcdef", "status": "timeout", "error": None,
...           "map": "empty-8-8", "map_path": None, "scen": None, "generator": None, "agents": 4,
...           "policy": "pibt", "kind": "decentralized", "seed": 0,
...           "faults": {"loss": 0.0, "delay": [0, 0], "duplicate": 0.0, "reorder": 0.0},
...           "lifelong": False, "max_ticks": None, "time_limit_s": 1.0}
>>> _ = (folder / "results.jsonl").write_text(json.dumps(record) + "\\n" + '{"format": "mrmp-be')
>>> results = read_bench_results(folder)
>>> len(results.records), results.records[0].status, results.truncated_lines
(1, 'timeout', 1)
>>> _ = (folder / "results.jsonl").write_text(json.dumps(dict(record, agents="four")) + "\\n")
>>> read_bench_results(folder)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
mrmp.core.errors.InputError: ...results.jsonl:1: agents: expected a whole number, got 'four'
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mrmp.core.errors import InputError, Problem
from mrmp.core.limits import MAX_RECORD_FILE_BYTES
from mrmp.io._files import PathLike, read_text
from mrmp.io.bench_results import RECORD_FORMAT, RESULTS_JSONL

STATUSES = ("done", "timeout", "error")
"""A record's ``status``: the run finished (successfully or not), ran out of time, or failed."""

MAX_PROBLEMS = 20
"""Problems listed before the rest are summed up in one line."""

_INT = "a whole number"
_NUMBER = "a number"
_TEXT = "a string"
_BOOL = "true or false"
_OBJECT = "an object"

# Every field of the record: what it must be and whether null is allowed.
# The result fields are null (or absent) for timeouts and errors; those marked
# required must not be null for a finished (``done``) run.
_FIELDS: dict[str, tuple[str, bool]] = {  # name -> (kind, nullable)
    "run_id": (_TEXT, False),
    "status": (_TEXT, False),
    "error": (_TEXT, True),
    "map": (_TEXT, False),
    "map_path": (_TEXT, True),
    "scen": (_TEXT, True),
    "generator": (_OBJECT, True),
    "agents": (_INT, False),
    "policy": (_TEXT, False),
    "kind": (_TEXT, False),
    "seed": (_INT, False),
    "faults": (_OBJECT, False),
    "lifelong": (_BOOL, False),
    "max_ticks": (_INT, True),
    "time_limit_s": (_NUMBER, True),
}
_RESULT_FIELDS: dict[str, tuple[str, bool]] = {  # name -> (kind, required when done)
    "success": (_BOOL, True),
    "stop_reason": (_TEXT, True),
    "ticks": (_INT, True),
    "makespan": (_INT, True),
    "sum_of_costs": (_INT, True),
    "lower_bound": (_INT, True),
    "time_makespan_s": (_NUMBER, False),
    "messages": (_INT, True),
    "network": (_OBJECT, False),
    "wall_time_s": (_NUMBER, True),
    "planning_time_s": (_NUMBER, False),
    "plan_bytes": (_INT, False),
    "throughput": (_NUMBER, False),
    "collisions": (_INT, True),
    "soc_over_lb": (_NUMBER, False),
    "robots_arrived": (_INT, True),
    "goals_reached": (_INT, True),
    "steps": (_INT, True),
    "wall_time_per_step_s": (_NUMBER, True),
    "messages_per_robot_move": (_NUMBER, False),
}
_OPTIONAL_FIELDS: dict[str, str] = {
    "bench": _TEXT, "instance": _INT, "time_sum_of_costs_s": _NUMBER, "lorr": _TEXT, "tasks_finished": _INT,
}  # fmt: skip
"""Fields a record may lack: the benchmark's name, a generated map's instance number, the sum of costs in seconds
(recorded since bodies were named), a LoRR problem file and the tasks finished (recorded since benchmarks took
LoRR problems)."""
_KINDS = ("decentralized", "centralized")


@dataclass(frozen=True, order=True)
class FaultSetting:
    """The network faults a run was given: loss, delay range (ticks), duplication, reordering.

    Examples
    --------
    >>> FaultSetting().label, FaultSetting(loss=0.2, delay=(0, 3)).label
    ('none', 'loss 0.2, delay 0..3')
    """

    loss: float = 0.0
    delay: tuple[float, float] = (0, 0)
    duplicate: float = 0.0
    reorder: float = 0.0

    @property
    def is_perfect(self) -> bool:
        """Whether no fault was injected."""
        return self.loss == 0 and self.delay[1] == 0 and self.duplicate == 0 and self.reorder == 0

    @property
    def label(self) -> str:
        """A short name for a person: ``none`` or the faults that are on.

        >>> FaultSetting(duplicate=0.1, reorder=0.05, delay=(2, 2)).label
        'delay 2, duplicate 0.1, reorder 0.05'
        """
        if self.is_perfect:
            return "none"
        parts = []
        if self.loss:
            parts.append(f"loss {self.loss:g}")
        if self.delay[1]:
            low, high = self.delay
            parts.append(f"delay {low:g}" if low == high else f"delay {low:g}..{high:g}")
        if self.duplicate:
            parts.append(f"duplicate {self.duplicate:g}")
        if self.reorder:
            parts.append(f"reorder {self.reorder:g}")
        return ", ".join(parts)


@dataclass(frozen=True)
class BenchRecord:
    """One run of a benchmark, as ``mrmp bench`` recorded it (see the module docstring).

    Result fields (``success`` to ``messages_per_robot_move``) are None when
    the run did not finish (``status`` ``timeout`` or ``error``). ``bench``
    (the benchmark's name) and ``instance`` (a generated map's instance
    number) are None when the record lacks them. ``line`` is where the record
    stands in its file, for messages.
    """

    run_id: str
    status: str
    map: str
    agents: int
    policy: str
    seed: int
    faults: FaultSetting
    lifelong: bool
    kind: str = "decentralized"
    error: str | None = None
    map_path: str | None = None
    scen: str | None = None
    generator: Mapping[str, Any] | None = None
    max_ticks: int | None = None
    time_limit_s: float | None = None
    success: bool | None = None
    stop_reason: str | None = None
    ticks: int | None = None
    makespan: int | None = None
    sum_of_costs: int | None = None
    lower_bound: int | None = None
    time_makespan_s: float | None = None
    time_sum_of_costs_s: float | None = None
    messages: int | None = None
    network: Mapping[str, Any] | None = None
    wall_time_s: float | None = None
    planning_time_s: float | None = None
    plan_bytes: int | None = None
    throughput: float | None = None
    collisions: int | None = None
    soc_over_lb: float | None = None
    robots_arrived: int | None = None
    goals_reached: int | None = None
    steps: int | None = None
    wall_time_per_step_s: float | None = None
    messages_per_robot_move: float | None = None
    bench: str | None = None
    instance: int | None = None
    lorr: str | None = None
    tasks_finished: int | None = None
    line: int = field(default=0, compare=False)

    @property
    def finished(self) -> bool:
        """Whether the run ended by itself (``status`` ``done``), successfully or not."""
        return self.status == "done"

    @property
    def succeeded(self) -> bool:
        """Whether the run finished and succeeded."""
        return self.status == "done" and bool(self.success)


@dataclass(frozen=True)
class BenchResults:
    """The records of one ``results.jsonl``, in file order (one per run).

    ``truncated_lines`` is 1 when the last line was cut short (an interrupted
    benchmark) and set aside, else 0; ``replaced_records`` counts records of a
    run that a later record of the same run replaced.
    """

    path: Path
    records: tuple[BenchRecord, ...]
    truncated_lines: int = 0
    replaced_records: int = 0


def results_file(path: PathLike) -> Path:
    """The ``results.jsonl`` that ``path`` names: the file itself, or the one inside a folder.

    >>> results_file("runs/results.jsonl"), results_file("/")
    (PosixPath('runs/results.jsonl'), PosixPath('/results.jsonl'))
    """
    candidate = Path(path)
    return candidate / RESULTS_JSONL if candidate.is_dir() else candidate


def read_bench_results(path: PathLike) -> BenchResults:
    """Read every run record of a benchmark.

    Parameters
    ----------
    path:
        A ``results.jsonl`` file, or a folder that holds one.

    Returns
    -------
    BenchResults
        The records (the last one of each ``run_id``), and how many lines were
        set aside as truncated.

    Raises
    ------
    InputError
        If the file is missing or unreadable, or any line but a truncated last
        one is not a valid record; each problem reads ``FILE:LINE: reason``.
    """
    target = results_file(path)
    if Path(path).is_dir() and not target.exists():
        raise InputError(Problem(str(path), f"no {RESULTS_JSONL} in this folder (is it the --out of mrmp bench?)"))
    text = read_text(target, MAX_RECORD_FILE_BYTES)
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    ends_cleanly = text.endswith("\n") or not text
    records: list[BenchRecord] = []
    problems: list[Problem] = []
    truncated = 0
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        where = f"{target}:{number}"
        try:
            data = json.loads(line)
        except json.JSONDecodeError as error:
            if number == len(lines) and not ends_cleanly:
                truncated = 1
                continue
            problems.append(Problem(where, f"not valid JSON ({error.msg} at column {error.colno})"))
            continue
        except RecursionError:
            problems.append(Problem(where, "not valid JSON (nested too deeply)"))
            continue
        try:
            records.append(record_from_dict(data, line=number))
        except ValueError as error:
            problems.append(Problem(where, str(error)))
    if problems:
        if len(problems) > MAX_PROBLEMS:
            hidden = len(problems) - MAX_PROBLEMS
            problems = [*problems[:MAX_PROBLEMS], Problem(str(target), f"... and {hidden} more bad lines")]
        raise InputError(problems)
    latest = {record.run_id: record for record in records}  # the last record of each run
    kept = tuple(sorted(latest.values(), key=lambda record: record.line))
    return BenchResults(target, kept, truncated_lines=truncated, replaced_records=len(records) - len(kept))


def _kind_problem(value: Any, kind: str) -> str | None:
    """Why ``value`` is not of ``kind`` (one of the ``_INT``... names), or None when it is."""
    if kind == _TEXT:
        good = isinstance(value, str)
    elif kind == _BOOL:
        good = isinstance(value, bool)
    elif kind == _INT:
        good = isinstance(value, int) and not isinstance(value, bool)
    elif kind == _NUMBER:
        good = isinstance(value, (int, float)) and not isinstance(value, bool)
        if good and not math.isfinite(value):
            return f"expected a finite number, got {value!r}"
    else:
        good = isinstance(value, dict)
    return None if good else f"expected {kind}, got {value!r}"


def _typed(name: str, value: Any, kind: str) -> Any:
    """``value`` of field ``name`` if it is of ``kind`` (a number as a float), else ``ValueError`` naming the field."""
    problem = _kind_problem(value, kind)
    if problem:
        raise ValueError(f"{name}: {problem}")
    return float(value) if kind == _NUMBER else value


def _faults_from_dict(data: Mapping[str, Any]) -> FaultSetting:
    """The :class:`FaultSetting` of a record's ``faults`` object (``ValueError`` naming the bad field)."""
    values: dict[str, Any] = {}
    for name in ("loss", "duplicate", "reorder"):
        if name not in data:
            raise ValueError(f"faults.{name}: missing")
        problem = _kind_problem(data[name], _NUMBER)
        if problem is None and not 0 <= data[name] <= 1:
            problem = f"expected a probability in 0..1, got {data[name]!r}"
        if problem:
            raise ValueError(f"faults.{name}: {problem}")
        values[name] = float(data[name])
    delay = data.get("delay")
    if (
        not isinstance(delay, list)
        or len(delay) != 2
        or any(_kind_problem(bound, _NUMBER) for bound in delay)
        or not 0 <= delay[0] <= delay[1]
    ):
        raise ValueError(f"faults.delay: expected [low, high] with 0 <= low <= high, got {delay!r}")
    return FaultSetting(delay=(delay[0], delay[1]), **values)


def record_from_dict(data: Any, line: int = 0) -> BenchRecord:
    """Check one decoded JSON line against the record format and type it.

    Parameters
    ----------
    data:
        The decoded JSON value.
    line:
        Its line number, kept in the record for later messages.

    Returns
    -------
    BenchRecord

    Raises
    ------
    ValueError
        Naming the first field that is missing or wrong, and why.

    Examples
    --------
    >>> record_from_dict([1, 2])
    Traceback (most recent call last):
    ...
    ValueError: expected a JSON object (one run record), got a list
    >>> record_from_dict({"format": "mrmp-bench-0"})
    Traceback (most recent call last):
    ...
    ValueError: format: expected 'mrmp-bench-1', got 'mrmp-bench-0'
    """
    if not isinstance(data, dict):
        raise ValueError(f"expected a JSON object (one run record), got {_json_kind(data)}")
    if data.get("format") != RECORD_FORMAT:
        raise ValueError(f"format: expected {RECORD_FORMAT!r}, got {data.get('format')!r}")
    values: dict[str, Any] = {}
    for name, (kind, nullable) in _FIELDS.items():
        if name not in data:
            raise ValueError(f"{name}: missing")
        value = data[name]
        values[name] = None if value is None and nullable else _typed(name, value, kind)
    status = values["status"]
    if status not in STATUSES:
        raise ValueError(f"status: expected one of {', '.join(STATUSES)}, got {status!r}")
    if values["kind"] not in _KINDS:
        raise ValueError(f"kind: expected one of {', '.join(_KINDS)}, got {values['kind']!r}")
    if values["agents"] < 1:
        raise ValueError(f"agents: expected at least 1, got {values['agents']}")
    if status == "error" and values["error"] is None:
        raise ValueError("error: a run with status 'error' needs its one-line error message")
    values["faults"] = _faults_from_dict(values["faults"])
    # A central planner that found no plan finishes ("done") without an execution to measure.
    planless = status == "done" and str(data.get("stop_reason") or "").startswith("no plan")
    measured = status == "done" and not planless
    for name, (kind, required) in _RESULT_FIELDS.items():
        if name not in data and measured:
            raise ValueError(f"{name}: missing (a finished run records every result field)")
        value = data.get(name)
        if value is None:
            if required and (measured or (planless and name in ("success", "stop_reason"))):
                raise ValueError(f"{name}: null, but the run finished (status 'done')")
            values[name] = None
            continue
        values[name] = _typed(name, value, kind)
    for name, kind in _OPTIONAL_FIELDS.items():
        value = data.get(name)
        values[name] = None if value is None else _typed(name, value, kind)
    return BenchRecord(line=line, **values)


def _json_kind(value: Any) -> str:
    """The JSON name of a decoded value's type, with its article.

    >>> _json_kind([]), _json_kind("x"), _json_kind(None)
    ('a list', 'a string', 'null')
    """
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "a string"
    return "a list"
