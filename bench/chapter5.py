"""The thesis's chapter 5 measured: decentralized against centralized, on complexity, speed and synchronization.

The thesis (chapter 5, "Comparing Approaches") argues that a decentralized
fleet beats a central planner in *complexity* (each robot plans only its own
path), *speed* (few values exchanged) and *synchronization*, without measuring
it. This script measures, on one MovingAI map (the first N agents of its
``-random-1.scen``), for fleets of 2 to a few hundred robots, in the lockstep
simulator on a perfect network, guarded by the safety layer:

* decentralized ``astar`` (each robot plans its own A* path and yields by the
  thesis's priority rule; every robot's decision rule is timed alone) and
  ``pibt`` (PIBT computed by the robots through messages with their neighbours,
  in synchronous rounds; only the whole simulated step is timed);
* centralized ``lacam`` and ``pp`` (prioritized planning): one planner computes
  every path, then the fleet executes the plan through its action dependencies.

Columns: *ok* (every robot arrived, no collision); *compute/robot/step*
(decentralized): the mean wall time of one robot's decision in one step
(``pibt``: the simulated step, its messages included, per robot); *busiest
robot*: the computation of the robot that computes most over the whole run
(decentralized ``astar``: the largest sum of one robot's decisions; ``pibt``:
the run's wall time over N; centralized: the planner's wall time, all of it on
one computer); *first move*: the wall time before the first robot can move
(decentralized: the slowest robot's first decision, robots deciding in
parallel; centralized: the planning time; neither counts the network's latency);
*msgs/move* and *bytes/move*: datagrams and bytes sent per robot-move
(a message to k robots counts k), of which *states/move* are states
(Present and Next; for a plan, with the robot's progress), the others the safety
layer's claims, replies and releases (``pibt``: its beacons, requests and
answers, not told apart); *plan bytes*: the shares of
the plan handed to the robots; *waiting*: the share of robot-ticks before
arrival spent standing still (waiting for a claim, a higher-priority robot, or a
dependency of the plan; the plan's own waits are included). Counts are
deterministic; times are this machine's, the least of ``--repeats`` runs.
``astar`` runs up to ``--astar-up-to`` robots (its crowds livelock, and a
livelocked run lasts until the tick limit).

With ``--plots DIR`` it also draws one figure per claim, against N: the busiest
robot's computation (complexity), datagrams per robot-move (speed) and the share
of robot-ticks spent waiting (synchronization), as ``DIR/complexity.png``,
``DIR/speed.png`` and ``DIR/synchronization.png`` (``docs/chapter5/`` holds the
published ones).

Usage: python bench/chapter5.py [--map empty-32-32] [--sizes 2,10,50,100,200] [--max-ticks 300] [--repeats 3] [--plots DIR]
"""

from __future__ import annotations

import argparse
import functools
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from mrmp.centralized.registry import plan_with
from mrmp.core import PolicyOptions, Scenario
from mrmp.core.cell import Cell
from mrmp.core.result import RunResult
from mrmp.experiments.execution import execute_in_simulator
from mrmp.io import load_movingai_scenario
from mrmp.policies.base import Decision, Policy, Situation, interaction_radius
from mrmp.sim.policy_table import make_policy
from mrmp.sim.simulator import simulate
from mrmp.viz.series_plot import write_series_plot

MAPS = Path(__file__).resolve().parents[1] / "maps"


@dataclass
class TimedPolicy:
    """A robot's decision rule, with the wall time of each of its steps (intend plus decide)."""

    inner: Policy
    step_times: list[float] = field(default_factory=list)
    _intended_in: float = 0.0

    @property
    def name(self) -> str:
        return self.inner.name

    @property
    def interaction_radius(self) -> int | None:
        """The timed rule's own radius, so that its robots' states go where they would without the timing."""
        return interaction_radius(self.inner)

    def intend(self, situation: Situation) -> Cell:
        started = time.perf_counter()
        cell = self.inner.intend(situation)
        self._intended_in = time.perf_counter() - started
        return cell

    def decide(self, situation: Situation, intended: Cell) -> Decision:
        started = time.perf_counter()
        decision = self.inner.decide(situation, intended)
        self.step_times.append(self._intended_in + time.perf_counter() - started)
        return decision


@dataclass
class Row:
    """One method on one fleet: the run, and its wall times (the least of the repetitions)."""

    method: str
    kind: str
    robots: int
    result: RunResult | None
    step_s: float | None
    busiest_s: float
    first_move_s: float
    plan_bytes: int | None = None
    status: str = ""
    state_messages: int | None = None

    def fastest(self, other: Row) -> Row:
        """This row with the smaller of its and ``other``'s wall times (the counts are the same)."""
        return replace(
            self,
            step_s=None if self.step_s is None or other.step_s is None else min(self.step_s, other.step_s),
            busiest_s=min(self.busiest_s, other.busiest_s),
            first_move_s=min(self.first_move_s, other.first_move_s),
        )

    def waiting_share(self) -> float | None:
        """The share of robot-ticks before arrival spent standing still (None for a run that did not happen)."""
        result = self.result
        if result is None:
            return None
        return sum(robot.waits for robot in result.robots) / max(1, sum(robot.cost for robot in result.robots))

    def messages_per_move(self) -> float | None:
        """Datagrams sent per robot-move (None for a run that did not happen)."""
        result = self.result
        if result is None:
            return None
        return result.messages / max(1, sum(robot.steps for robot in result.robots))

    def cells(self) -> list[str]:
        result = self.result
        step = "-" if self.step_s is None else _seconds(self.step_s)
        if result is None:
            return [self.method, self.kind, str(self.robots), f"no ({self.status})", step, _seconds(self.busiest_s),
                    _seconds(self.first_move_s), "-", "-", "-", "-", "-", "-"]  # fmt: skip
        moves = max(1, sum(robot.steps for robot in result.robots))
        sent_bytes = sum(robot.bytes_sent for robot in result.robots)
        ok = "yes" if result.success else f"no ({result.stop_reason})"
        states = "-" if self.state_messages is None else f"{self.state_messages / moves:.1f}"
        return [
            self.method, self.kind, str(self.robots), ok, step, _seconds(self.busiest_s), _seconds(self.first_move_s),
            f"{self.messages_per_move():.1f}", states, f"{sent_bytes / moves:.0f}",
            "-" if self.plan_bytes is None else str(self.plan_bytes), f"{self.waiting_share():.0%}", str(result.ticks),
        ]  # fmt: skip


HEADER = ["method", "kind", "N", "ok", "compute/robot/step", "busiest robot", "first move", "msgs/move", "states/move",
          "bytes/move", "plan bytes", "waiting", "ticks"]  # fmt: skip


def _seconds(value: float) -> str:
    """A wall time in ms or s, three significant digits."""
    return f"{value * 1000:.3g} ms" if value < 1.0 else f"{value:.3g} s"


def decentralized_astar(scenario: Scenario) -> Row:
    """Each robot's own A* decision, timed per robot and step."""
    policies = [TimedPolicy(make_policy(PolicyOptions(name="astar"), scenario.timing)) for _ in scenario.robots]
    result = simulate(scenario, policies=policies, record_messages=True)  # type: ignore[arg-type]
    steps = [duration for policy in policies for duration in policy.step_times]
    busiest = max(sum(policy.step_times) for policy in policies)
    first = max((policy.step_times[0] for policy in policies if policy.step_times), default=0.0)
    row = Row("astar", "decentralized", len(scenario.robots), result, sum(steps) / max(1, len(steps)), busiest, first)
    return replace(row, state_messages=state_messages(result))


def state_messages(result: RunResult) -> int:
    """How many of the run's messages were states (Present and Next; the rest belong to the safety layer)."""
    return sum(1 for tick in result.message_log or [] for _, _, kind in tick if kind == "state")


def decentralized_pibt(scenario: Scenario) -> Row:
    """PIBT by messages: the simulated step (every robot's decision and its messages) per robot."""
    ticks_done: list[float] = []
    started = time.perf_counter()
    result = simulate(
        scenario.with_changes(policy=PolicyOptions(name="pibt")),
        on_tick=lambda tick, cells: ticks_done.append(time.perf_counter()),
    )
    total = (ticks_done[-1] if ticks_done else time.perf_counter()) - started
    robots = len(scenario.robots)
    first = (ticks_done[0] - started) / robots if ticks_done else 0.0
    return Row("pibt", "decentralized", robots, result, total / max(1, robots * result.ticks), total / robots, first)


def centralized(scenario: Scenario, planner: str, time_limit_s: float) -> Row:
    """One planner for the fleet, then the fleet executes the plan through its dependencies."""
    plan = plan_with(planner, scenario, time_limit_s=time_limit_s)
    robots, planning = len(scenario.robots), plan.planning_time_s
    if not plan.solved:
        return Row(planner, "centralized", robots, None, None, planning, planning, status=plan.status)
    result = execute_in_simulator(scenario, plan, record_messages=True)
    row = Row(planner, "centralized", robots, result, None, planning, planning, result.plan_bytes)
    return replace(row, state_messages=state_messages(result))


def measured(method: Callable[[Scenario], Row], scenario: Scenario, repeats: int) -> Row:
    """``method`` run ``repeats`` times on ``scenario``: its counts, and its least wall times."""
    row = method(scenario)
    for _ in range(repeats - 1):
        row = row.fastest(method(scenario))
    return row


def write_claim_plots(rows: list[Row], folder: Path) -> None:
    """One PNG per claim of chapter 5, each method a line against N (runs that did not happen left out)."""

    def series(value: Callable[[Row], float | None]) -> dict[str, list[tuple[int, float]]]:
        by_method: dict[str, list[tuple[int, float]]] = {}
        for row in rows:
            measured_value = value(row)
            if measured_value is not None:
                by_method.setdefault(f"{row.method} ({row.kind})", []).append((row.robots, measured_value))
        return by_method

    folder.mkdir(parents=True, exist_ok=True)
    write_series_plot(folder / "complexity.png", "Complexity: the busiest robot's computation", "ms over the run (log)",
                      series(lambda row: 1000 * row.busiest_s or None), log_y=True)  # fmt: skip
    write_series_plot(folder / "speed.png", "Speed: datagrams per robot-move", "datagrams / move (log)",
                      series(lambda row: row.messages_per_move() or None), log_y=True)  # fmt: skip
    waiting = series(lambda row: None if row.waiting_share() is None else 100 * (row.waiting_share() or 0.0))
    write_series_plot(folder / "synchronization.png", "Synchronization: time spent waiting",
                      "robot-ticks standing still (%)", waiting, percent=True)  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="empty-32-32")
    parser.add_argument("--sizes", default="2,10,50,100,200")
    parser.add_argument("--max-ticks", type=int, default=300)
    parser.add_argument("--time-limit", type=float, default=30.0, help="central planners' limit, seconds")
    parser.add_argument("--repeats", type=int, default=3, help="runs of each method; wall times are the least")
    parser.add_argument("--astar-up-to", type=int, default=200,
                        help="largest fleet for astar (its crowds livelock until the tick limit)")  # fmt: skip
    parser.add_argument("--plots", type=Path, default=None, help="write one PNG per claim into this folder")
    arguments = parser.parse_args()
    warm_up = load_movingai_scenario(MAPS / f"{arguments.map}.map", MAPS / f"{arguments.map}-random-1.scen", 2)
    for warm in (decentralized_astar, decentralized_pibt):  # one-time set-ups (imports, grid tables) not counted
        warm(warm_up)
    centralized(warm_up, "lacam", arguments.time_limit)
    centralized(warm_up, "pp", arguments.time_limit)
    print("| " + " | ".join(HEADER) + " |")
    print("|" + "---|" * len(HEADER))
    rows: list[Row] = []
    for size in [int(text) for text in arguments.sizes.split(",")]:
        scenario = load_movingai_scenario(
            MAPS / f"{arguments.map}.map", MAPS / f"{arguments.map}-random-1.scen", size
        ).with_changes(max_ticks=arguments.max_ticks)
        methods: list[Callable[[Scenario], Row]] = [
            decentralized_pibt,
            functools.partial(centralized, planner="lacam", time_limit_s=arguments.time_limit),
            functools.partial(centralized, planner="pp", time_limit_s=arguments.time_limit),
        ]
        if size <= arguments.astar_up_to:
            methods.insert(0, decentralized_astar)
        for method in methods:
            rows.append(measured(method, scenario, arguments.repeats))
            print("| " + " | ".join(rows[-1].cells()) + " |", flush=True)
    if arguments.plots is not None:
        write_claim_plots(rows, arguments.plots)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
