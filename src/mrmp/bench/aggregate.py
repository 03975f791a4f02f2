"""The numbers a benchmark report shows, computed from its run records (pure: no files, no plotting).

Runs are grouped by configuration -- map, policy, fault setting, number of
robots, and whether the run was lifelong -- over their seeds and instances.
For each group (:class:`GroupSummary`):

* ``success_rate``: successful runs over all runs; a timeout or an error
  counts as a failure;
* ``mean_soc_over_lb``: sum of costs over the lower bound (the sum of the
  robots' shortest path lengths; Stern et al., SoCS 2019), mean over the
  successful runs; ``mean_makespan`` likewise;
* ``mean_wall_time_per_step_s`` and ``mean_messages_per_robot_move``: means
  over the finished runs (status ``done``);
* ``mean_throughput``: goals reached per tick, mean over finished lifelong runs;
* ``mean_tasks_finished``: tasks finished (the League of Robot Runners' score), mean over the finished runs
  of LoRR problems;
* ``timeouts``, ``errors`` and ``runs_with_collisions`` (referee findings).

A mean over no run is None. :func:`headline_table` formats the groups as
text cells, shared by the terminal, Markdown and HTML tables.

Examples
--------
>>> from mrmp.io.report_input import BenchRecord, FaultSetting
>>> def run(seed, success, soc, status="done"):
...     done = status == "done"
...     return BenchRecord(f"r{seed}", status, "empty-8-8", 4, "pibt", seed, FaultSetting(), False,
...                        success=success if done else None, soc_over_lb=soc, makespan=10 + seed if done else None,
...                        wall_time_per_step_s=0.002 if done else None, messages_per_robot_move=3.0 if done else None)
>>> [group] = summarize([run(0, True, 1.5), run(1, True, 1.25), run(2, False, None), run(3, None, None, "timeout")])
>>> group.runs, group.successes, group.success_rate, group.mean_soc_over_lb, group.mean_makespan, group.timeouts
(4, 2, 0.5, 1.375, 10.5, 1)
>>> print(headline_markdown([group]))
| map | policy | faults | N | runs | success | SoC/LB | makespan | ms/step | msgs/move |
|---|---|---|---:|---:|---:|---:|---:|---:|---:|
| empty-8-8 | pibt | none | 4 | 4 | 50% (2/4) | 1.375 | 10.5 | 2.00 | 3.00 |
"""

from __future__ import annotations

from collections import Counter, defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from mrmp.io.report_input import STATUSES, BenchRecord, FaultSetting


@dataclass(frozen=True, order=True)
class GroupKey:
    """A configuration of the benchmark matrix; its runs differ only by seed or instance."""

    map: str
    policy: str
    faults: FaultSetting
    agents: int
    lifelong: bool = False


@dataclass(frozen=True)
class GroupSummary:
    """What the runs of one configuration achieved (see the module docstring for each figure)."""

    key: GroupKey
    runs: int
    done: int
    successes: int
    timeouts: int
    errors: int
    runs_with_collisions: int
    seeds: tuple[int, ...]
    mean_soc_over_lb: float | None
    mean_makespan: float | None
    mean_wall_time_per_step_s: float | None
    mean_messages_per_robot_move: float | None
    mean_throughput: float | None
    mean_tasks_finished: float | None = None

    @property
    def success_rate(self) -> float:
        """Successful runs over all runs of the configuration."""
        return self.successes / self.runs if self.runs else 0.0


@dataclass(frozen=True)
class FaultSuccess:
    """Success of one policy on one map under one fault setting, over every N and seed."""

    map: str
    policy: str
    faults: FaultSetting
    runs: int
    successes: int

    @property
    def success_rate(self) -> float:
        """Successful runs over all runs."""
        return self.successes / self.runs if self.runs else 0.0


@dataclass(frozen=True)
class BenchOverview:
    """What was run: the values of each dimension of the matrix, and how the runs ended.

    ``central_policies`` are the policies that are central planners (kind
    ``centralized``); ``instances`` the instance numbers of generated maps
    (empty when none); ``benches`` the benchmark names the records carry.
    """

    runs: int
    maps: tuple[str, ...]
    policies: tuple[str, ...]
    central_policies: tuple[str, ...]
    agents: tuple[int, ...]
    seeds: tuple[int, ...]
    instances: tuple[int, ...]
    faults: tuple[FaultSetting, ...]
    lifelong: tuple[bool, ...]
    benches: tuple[str, ...]
    statuses: tuple[tuple[str, int], ...]
    successes: int
    runs_with_collisions: int


@dataclass(frozen=True)
class TextTable:
    """A table as text: column names, right-aligned columns, and rows of cells."""

    columns: tuple[str, ...]
    numeric: tuple[bool, ...]
    rows: tuple[tuple[str, ...], ...]


def mean(values: Iterable[float | None]) -> float | None:
    """The mean of the values that are not None, or None when there is none.

    >>> mean([1, None, 2]), mean([None])
    (1.5, None)
    """
    present = [value for value in values if value is not None]
    return sum(present) / len(present) if present else None


def group_key(record: BenchRecord) -> GroupKey:
    """The configuration a run belongs to."""
    return GroupKey(record.map, record.policy, record.faults, record.agents, record.lifelong)


def summarize(records: Iterable[BenchRecord]) -> list[GroupSummary]:
    """One :class:`GroupSummary` per configuration, sorted by map, policy, fault setting, N.

    Parameters
    ----------
    records:
        Run records, any order.

    Returns
    -------
    list of GroupSummary
    """
    groups: dict[GroupKey, list[BenchRecord]] = defaultdict(list)
    for record in records:
        groups[group_key(record)].append(record)
    return [_summary(key, runs) for key, runs in sorted(groups.items())]


def _summary(key: GroupKey, runs: Sequence[BenchRecord]) -> GroupSummary:
    done = [run for run in runs if run.finished]
    solved = [run for run in done if run.success]
    return GroupSummary(
        key=key,
        runs=len(runs),
        done=len(done),
        successes=len(solved),
        timeouts=sum(1 for run in runs if run.status == "timeout"),
        errors=sum(1 for run in runs if run.status == "error"),
        runs_with_collisions=sum(1 for run in done if run.collisions),
        seeds=tuple(sorted({run.seed for run in runs})),
        mean_soc_over_lb=mean(run.soc_over_lb for run in solved),
        mean_makespan=mean(run.makespan for run in solved),
        mean_wall_time_per_step_s=mean(run.wall_time_per_step_s for run in done),
        mean_messages_per_robot_move=mean(run.messages_per_robot_move for run in done),
        mean_throughput=mean(run.throughput for run in done if run.lifelong),
        mean_tasks_finished=mean(run.tasks_finished for run in done if run.tasks_finished is not None),
    )


def success_by_faults(summaries: Iterable[GroupSummary]) -> list[FaultSuccess]:
    """Pool the configurations over N: success per (map, policy, fault setting), one-shot runs only.

    >>> from mrmp.io.report_input import FaultSetting
    >>> lossy = FaultSetting(loss=0.2)
    >>> def group(agents, faults, runs, successes):
    ...     return GroupSummary(GroupKey("m", "pibt", faults, agents), runs, runs, successes, 0, 0, 0, (0,),
    ...                         None, None, None, None, None)
    >>> pooled = success_by_faults([group(4, lossy, 2, 1), group(8, lossy, 2, 2), group(4, FaultSetting(), 2, 2)])
    >>> [(row.faults.label, row.runs, row.successes) for row in pooled]
    [('none', 2, 2), ('loss 0.2', 4, 3)]
    """
    runs: Counter[tuple[str, str, FaultSetting]] = Counter()
    successes: Counter[tuple[str, str, FaultSetting]] = Counter()
    for summary in summaries:
        if summary.key.lifelong:
            continue
        where = (summary.key.map, summary.key.policy, summary.key.faults)
        runs[where] += summary.runs
        successes[where] += summary.successes
    return [FaultSuccess(*where, runs[where], successes[where]) for where in sorted(runs)]


def overview(records: Sequence[BenchRecord]) -> BenchOverview:
    """The dimensions of the benchmark and the statuses of its runs.

    >>> from mrmp.io.report_input import BenchRecord, FaultSetting
    >>> records = [BenchRecord("a", "done", "m", 8, "pibt", 1, FaultSetting(), False, success=True),
    ...            BenchRecord("b", "timeout", "m", 4, "astar", 0, FaultSetting(), False)]
    >>> summary = overview(records)
    >>> summary.policies, summary.agents, summary.seeds, summary.statuses
    (('astar', 'pibt'), (4, 8), (0, 1), (('done', 1), ('timeout', 1)))
    """
    statuses = Counter(record.status for record in records)
    return BenchOverview(
        runs=len(records),
        maps=tuple(sorted({record.map for record in records})),
        policies=tuple(sorted({record.policy for record in records})),
        central_policies=tuple(sorted({record.policy for record in records if record.kind == "centralized"})),
        agents=tuple(sorted({record.agents for record in records})),
        seeds=tuple(sorted({record.seed for record in records})),
        instances=tuple(sorted({record.instance for record in records if record.instance is not None})),
        faults=tuple(sorted({record.faults for record in records})),
        lifelong=tuple(sorted({record.lifelong for record in records})),
        benches=tuple(sorted({record.bench for record in records if record.bench})),
        statuses=tuple((status, statuses[status]) for status in STATUSES if statuses[status]),
        successes=sum(1 for record in records if record.succeeded),
        runs_with_collisions=sum(1 for record in records if record.collisions),
    )


def notable_runs(records: Iterable[BenchRecord]) -> list[BenchRecord]:
    """The runs a reader must hear about: timeouts, errors, and runs where the referee found collisions.

    >>> from mrmp.io.report_input import BenchRecord, FaultSetting
    >>> ok = BenchRecord("a", "done", "m", 2, "pibt", 0, FaultSetting(), False, success=True, collisions=0)
    >>> bad = BenchRecord("b", "error", "m", 2, "pibt", 1, FaultSetting(), False, error="boom")
    >>> [record.run_id for record in notable_runs([ok, bad])]
    ['b']
    """
    return [record for record in records if not record.finished or record.collisions]


def _number(value: float | None, digits: int) -> str:
    """``value`` with ``digits`` decimals, or ``-`` for None.

    >>> _number(1.23456, 3), _number(None, 1)
    ('1.235', '-')
    """
    return "-" if value is None else f"{value:.{digits}f}"


def format_success(summary: GroupSummary | FaultSuccess) -> str:
    """Success as a percentage with its count, e.g. ``67% (2/3)``."""
    return f"{100 * summary.success_rate:.0f}% ({summary.successes}/{summary.runs})"


def format_milliseconds(seconds: float | None) -> str:
    """A wall time per step in milliseconds, about three significant digits (``-`` for None).

    >>> format_milliseconds(0.0123456), format_milliseconds(0.000045), format_milliseconds(2.5)
    ('12.3', '0.045', '2500')
    """
    if seconds is None:
        return "-"
    milliseconds = 1000 * seconds
    decimals = 0 if milliseconds >= 100 else 1 if milliseconds >= 10 else 2 if milliseconds >= 1 else 3
    return f"{milliseconds:.{decimals}f}"


_HEADLINE: tuple[tuple[str, bool, Callable[[GroupSummary], str]], ...] = (
    ("map", False, lambda summary: summary.key.map),
    ("policy", False, lambda summary: summary.key.policy),
    ("faults", False, lambda summary: summary.key.faults.label),
    ("N", True, lambda summary: str(summary.key.agents)),
    ("runs", True, lambda summary: str(summary.runs)),
    ("success", True, format_success),
    ("SoC/LB", True, lambda summary: _number(summary.mean_soc_over_lb, 3)),
    ("makespan", True, lambda summary: _number(summary.mean_makespan, 1)),
    ("ms/step", True, lambda summary: format_milliseconds(summary.mean_wall_time_per_step_s)),
    ("msgs/move", True, lambda summary: _number(summary.mean_messages_per_robot_move, 2)),
)
_THROUGHPUT = ("throughput", True, lambda summary: _number(summary.mean_throughput, 3))
_TASKS = ("tasks", True, lambda summary: _number(summary.mean_tasks_finished, 1))


def headline_table(summaries: Sequence[GroupSummary]) -> TextTable:
    """The headline table: one row per configuration, a ``lifelong`` and ``throughput`` column when lifelong runs exist,
    and a ``tasks`` column (tasks finished) when runs of LoRR problems do.

    Success counts every run; SoC/LB and makespan are means over the
    successful runs; ms/step (wall time per step) and msgs/move (messages per
    robot move) over the finished runs.
    """
    columns = list(_HEADLINE)
    if any(summary.key.lifelong for summary in summaries):
        columns.insert(3, ("lifelong", False, lambda summary: "yes" if summary.key.lifelong else "no"))
        columns.append(_THROUGHPUT)
    if any(summary.mean_tasks_finished is not None for summary in summaries):
        columns.append(_TASKS)
    return TextTable(
        columns=tuple(name for name, _, _ in columns),
        numeric=tuple(numeric for _, numeric, _ in columns),
        rows=tuple(tuple(cell(summary) for _, _, cell in columns) for summary in summaries),
    )


def _markdown_cell(text: str) -> str:
    """A table cell for Markdown: pipes escaped, no line breaks."""
    return text.replace("\\", "\\\\").replace("|", "\\|").replace("\n", " ")


def headline_markdown(summaries: Sequence[GroupSummary]) -> str:
    """The headline table as GitHub-flavoured Markdown (numbers right-aligned), ending without a newline."""
    return table_markdown(headline_table(summaries))


def compact_table(records: Sequence[BenchRecord]) -> TextTable:
    """One row per (map, N), one column per method: success over every seed and fault setting, then mean SoC/LB.

    A cell reads ``100%, 1.08`` (success rate, mean SoC/LB of the successful
    runs), ``0%`` when no run succeeded, ``t/o`` when every run hit its time
    limit, and is empty when the method did not run there. Maps, N and
    methods keep the order in which the records first name them (N ascending
    within a map). Lifelong runs are left out (their figure is throughput).

    >>> from mrmp.io.report_input import BenchRecord, FaultSetting
    >>> def run(policy, agents, success, soc, status="done"):
    ...     return BenchRecord("r", status, "empty-8-8", agents, policy, 0, FaultSetting(), False,
    ...                        success=success, soc_over_lb=soc)
    >>> table = compact_table([run("pibt", 4, True, 1.5), run("pibt", 4, False, None), run("cbs", 4, None, None, "timeout"),
    ...                        run("pibt", 8, True, 1.25)])
    >>> table.columns, table.rows
    (('map', 'N', 'pibt', 'cbs'), (('empty-8-8', '4', '50%, 1.50', 't/o'), ('empty-8-8', '8', '100%, 1.25', '')))
    """
    one_shot = [record for record in records if not record.lifelong]
    maps = list(dict.fromkeys(record.map for record in one_shot))
    methods = list(dict.fromkeys(record.policy for record in one_shot))
    cells: dict[tuple[str, int, str], list[BenchRecord]] = defaultdict(list)
    for record in one_shot:
        cells[(record.map, record.agents, record.policy)].append(record)
    rows = []
    for map_name in maps:
        for agents in sorted({record.agents for record in one_shot if record.map == map_name}):
            row = [map_name, str(agents)]
            row.extend(_compact_cell(cells.get((map_name, agents, method), [])) for method in methods)
            rows.append(tuple(row))
    return TextTable(
        columns=("map", "N", *methods), numeric=(False, True, *(False for _ in methods)), rows=tuple(rows)
    )


def _compact_cell(runs: Sequence[BenchRecord]) -> str:
    """A method's runs at one (map, N) as ``success%, SoC/LB``, ``0%``, ``t/o`` or empty."""
    if not runs:
        return ""
    if all(run.status == "timeout" for run in runs):
        return "t/o"
    successes = [run for run in runs if run.success]
    rate = f"{round(100 * len(successes) / len(runs))}%"
    quality = mean(run.soc_over_lb for run in successes)
    return rate if quality is None else f"{rate}, {quality:.2f}"


def table_markdown(table: TextTable) -> str:
    """``table`` as GitHub-flavoured Markdown (numeric columns right-aligned), ending without a newline."""
    lines = [
        "| " + " | ".join(_markdown_cell(column) for column in table.columns) + " |",
        "|" + "|".join("---:" if numeric else "---" for numeric in table.numeric) + "|",
    ]
    lines.extend("| " + " | ".join(_markdown_cell(cell) for cell in row) + " |" for row in table.rows)
    return "\n".join(lines)
