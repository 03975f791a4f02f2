"""Turning a live run's files into the common :class:`~mrmp.core.result.RunResult`.

A live robot's path is its ground truth (the referee's intervals) sampled every
``tick_seconds``: at each sample, the cell it most recently started to enter
among those it covers. Metrics in ticks then follow the simulator's
definitions; wall-clock figures (arrival times, makespan) come from the agents'
clocks.
"""

from __future__ import annotations

import itertools
import math
from collections import Counter
from collections.abc import Mapping, Sequence
from typing import Any

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.errors import NoPathError
from mrmp.core.heading import Heading
from mrmp.core.result import Collision, RobotResult, RunResult
from mrmp.core.scenario import Scenario
from mrmp.search.planners import astar
from mrmp.sim.metrics import shortest_steps


def ideal_makespan(scenario: Scenario, time_scale: float) -> float:
    """The longest single-robot path time (turns included) at the run's speed, in seconds.

    For bodies that turn in place (``turning``), the most ticks any robot needs
    alone (:func:`~mrmp.sim.metrics.shortest_steps`: moves and quarter turns),
    a cell time each; otherwise the thesis's body (right turns, then a cell).

    >>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Timing
    >>> alone = Scenario(Grid(3, 3), (RobotSpec("A", (0, 0), (0, 2), heading=Heading.NORTH),), timing=Timing(1.0, 0.5))
    >>> ideal_makespan(alone, 1.0), ideal_makespan(alone.with_changes(policy=PolicyOptions(body="turning")), 2.0)
    (2.5, 1.5)
    """
    if body_model(scenario.policy.body).turns_in_place:
        return max(shortest_steps(scenario), default=0) * scenario.timing.cell_time / time_scale
    longest = 0.0
    for robot in scenario.robots:
        try:
            cost = astar(scenario.grid, robot.start, robot.goal, heading=robot.heading, timing=scenario.timing).cost
        except NoPathError:
            continue
        longest = max(longest, cost)
    return longest / time_scale


def _sample(intervals: Sequence[Mapping[str, Any]], start: Cell, times: Sequence[float]) -> list[Cell]:
    spans = sorted(
        (
            (float(i["start"]), math.inf if i["end"] is None else float(i["end"]), (int(i["cell"][0]), int(i["cell"][1])))
            for i in intervals
        ),
        key=lambda span: span[0],
    )
    path, last = [], start
    for t in times:
        covering = [span for span in spans if span[0] <= t < span[1]]
        if covering:
            last = covering[-1][2]
        path.append(last)
    return path


def live_result(
    scenario: Scenario,
    reports: Sequence[Mapping[str, Any] | None],
    referee: Mapping[str, Any] | None,
    *,
    stop_reason: str,
    wall_time_s: float,
    tick_seconds: float,
    time_scale: float,
) -> RunResult:
    """Build the result of a live run from the agents' reports and the referee's verdict.

    Wall-clock arrival times count from the fleet's start (the first robot to
    begin its first step). Arrival is judged on ground truth (where the body really ended), not on
    the robot's own belief, which a missed grid line can make wrong. A robot
    without a report (its process died before writing one) still has its path
    from the referee.
    """
    starts = [float(report["started_at"]) for report in reports if report]
    fleet_start = min(starts, default=0.0)
    t0 = min(float(referee["start_time"]), fleet_start) if referee else fleet_start
    end = max([float(report["ended_at"]) for report in reports if report] or [t0])
    ticks = max(1, math.ceil((end - t0) / tick_seconds))
    times = [t0 + k * tick_seconds for k in range(ticks + 1)]
    intervals = list(referee["intervals"]) if referee else []
    robots: list[RobotResult] = []
    network: Counter[str] = Counter()
    for index, spec in enumerate(scenario.robots):
        report = reports[index] if index < len(reports) else None
        own = [interval for interval in intervals if int(interval["robot"]) == index]
        path = _sample(own, spec.start, times)
        headings = [spec.heading]
        for before, after in itertools.pairwise(path):
            adjacent = abs(before[0] - after[0]) + abs(before[1] - after[1]) == 1
            headings.append(Heading.between(before, after) if adjacent else headings[-1])
        result = RobotResult(spec.id, spec.start, spec.goal, path=path, headings=headings)
        if report:
            result.turns = int(report.get("turns", 0))
            result.messages_sent = int(report.get("messages_sent", 0))
            result.bytes_sent = int(report.get("bytes_sent", 0))
            arrival = report.get("arrival_time")
            if arrival is not None and result.arrived:
                result.time_s = float(report["started_at"]) + float(arrival) - fleet_start
            else:  # not settled at its goal (by ground truth): it counts the whole run, as in the simulator
                result.time_s = float(report["ended_at"]) - fleet_start
            network["messages_sent"] += int(report.get("messages_sent", 0))
            network["datagrams_sent"] += int(report.get("datagrams_sent", 0))
            network["messages_received"] += int(report.get("messages_received", 0))
            network["bytes_sent"] += int(report.get("bytes_sent", 0))
            network["moves"] += int(report.get("steps", 0))
            network["missed_lines"] += int(report.get("missed_lines", 0))
            for reason, count in dict(report.get("rejected", {})).items():
                network[f"rejected_{reason}"] += int(count)
            for kind, count in dict(report.get("sent_by_kind", {})).items():
                network[f"sent_{kind}"] += int(count)
            for name, count in dict(report.get("faults", {})).items():
                network[f"injected_{name}"] += int(count)
            for name, count in dict(report.get("safety", {})).items():
                network[f"safety_{name}"] += int(count)
        robots.append(result)
    collisions = []
    for item in referee["collisions"] if referee else []:
        tick = round(int(item["tick"]) / 1000.0 / tick_seconds)
        collisions.append(
            Collision(
                str(item["kind"]),
                tick,
                tuple(str(robot) for robot in item["robots"]),
                tuple((int(cell[0]), int(cell[1])) for cell in item["cells"]),
            )
        )
    return RunResult(
        scenario=scenario.name,
        policy=scenario.policy.name,
        seed=scenario.seed,
        robots=robots,
        collisions=collisions,
        stop_reason=stop_reason,
        ticks=ticks,
        lower_bound=sum(shortest_steps(scenario)),
        wall_time_s=wall_time_s,
        network=dict(network),
        mode="live",
        tick_seconds=tick_seconds,
        ideal_makespan_s=ideal_makespan(scenario, time_scale),
        body=scenario.policy.body,
    )
