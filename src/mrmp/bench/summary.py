"""The summary of a benchmark: one row per map, method and number of robots.

Examples
--------
>>> records = [
...     {"map": "m", "policy": "pibt", "agents": 5, "status": "done", "success": True, "soc_over_lb": 1.2},
...     {"map": "m", "policy": "pibt", "agents": 5, "status": "timeout", "success": None, "soc_over_lb": None},
... ]
>>> row = summary_rows(records)[0]
>>> row.runs, row.success_rate, row.mean_soc_over_lb, row.timeouts
(2, 0.5, 1.2, 1)
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from statistics import mean
from typing import Any


@dataclass(frozen=True)
class SummaryRow:
    """The runs of one map, method and N.

    ``success_rate`` counts every run (a timeout or an error is a failure);
    ``mean_soc_over_lb`` averages the sum of costs over the lower bound of the
    successful runs (None when none succeeded); ``mean_wall_time_s`` averages
    the finished runs' wall time; ``mean_tasks_finished`` the tasks finished by
    runs of League of Robot Runners problems (None for other runs).
    """

    map: str
    policy: str
    agents: int
    runs: int
    success_rate: float
    mean_soc_over_lb: float | None
    mean_wall_time_s: float | None
    timeouts: int
    errors: int
    mean_tasks_finished: float | None = None


def summary_rows(records: Iterable[Mapping[str, Any]]) -> list[SummaryRow]:
    """One :class:`SummaryRow` per (map, policy, agents), in order of first appearance."""
    groups: dict[tuple[str, str, int], list[Mapping[str, Any]]] = {}
    for record in records:
        groups.setdefault((record["map"], record["policy"], record["agents"]), []).append(record)
    rows = []
    for (map_name, policy, agents), group in groups.items():
        ratios = [r["soc_over_lb"] for r in group if r.get("success") and r.get("soc_over_lb") is not None]
        walls = [r["wall_time_s"] for r in group if r.get("wall_time_s") is not None]
        tasks = [r["tasks_finished"] for r in group if r.get("tasks_finished") is not None]
        rows.append(
            SummaryRow(
                map=map_name,
                policy=policy,
                agents=agents,
                runs=len(group),
                success_rate=sum(1 for r in group if r.get("success")) / len(group),
                mean_soc_over_lb=mean(ratios) if ratios else None,
                mean_wall_time_s=mean(walls) if walls else None,
                timeouts=sum(1 for r in group if r.get("status") == "timeout"),
                errors=sum(1 for r in group if r.get("status") == "error"),
                mean_tasks_finished=mean(tasks) if tasks else None,
            )
        )
    return rows
