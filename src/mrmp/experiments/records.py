"""One benchmark run executed exactly as ``mrmp run`` would, and its results record.

A decentralized policy runs with :func:`mrmp.sim.simulator.simulate` (which
hands ``pibt`` to the synchronous-rounds simulator); a central planner plans
with :func:`mrmp.centralized.registry.plan_with` under the run's time limit
and its plan is executed by :func:`mrmp.experiments.execution.execute_in_simulator`.
Either way the referee's findings are in the result, and the record carries
their count (``collisions``) next to ``success``.

The record is the shared contract of ``results.jsonl`` (format
``mrmp-bench-1``): the run's parameters, ``status`` (``done``, ``timeout`` or
``error``) with a one-line ``error``, the result's summary metrics from
:func:`mrmp.io.results.result_to_dict` without the robots and with the
collisions counted, and derived figures (``soc_over_lb``, ``robots_arrived``,
``goals_reached``, ``steps``, ``wall_time_per_step_s``,
``messages_per_robot_move``). For a timeout or an error every result field is
null. A central planner that gives up within its limit is a ``timeout``; one
that proves or declares the instance unsolvable is ``done`` with ``success``
false and ``stop_reason`` ``"no plan: <status>"``.

Examples
--------
>>> run = BenchRun("gen:room-9x9-r3-d1-s0", 3, "pibt", generator=(("doors", 1), ("height", 9), ("kind", "room"),
...                ("room_size", 3), ("seed", 0), ("width", 9)), instance=0)
>>> record = execute_run(run)
>>> record["status"], record["success"], record["collisions"], record["run_id"] == run.run_id
('done', True, 0, True)
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable
from typing import Any

from mrmp.core.errors import MrmpError
from mrmp.core.map_generators import generate, random_instance
from mrmp.core.result import RunResult
from mrmp.core.scenario import PolicyOptions, Scenario
from mrmp.experiments.matrix import BenchRun, faults_to_dict
from mrmp.io.bench_results import RECORD_FORMAT, RESULT_FIELDS


def build_scenario(run: BenchRun) -> Scenario:
    """The scenario of ``run``: its map and robots, with its policy, faults, seed and limits applied.

    Raises
    ------
    InputError
        If a MovingAI file is missing or malformed.
    ValueError
        If a generator spec is wrong or the robots do not fit.
    """
    if run.lorr is not None:
        return _lorr_scenario(run)
    if run.generator is not None:
        grid = generate(run.generator_spec or {})
        base = random_instance(grid, run.agents, seed=run.instance or 0, name=f"{grid.name}-i{run.instance or 0}")
    elif run.scen is not None and run.map_path is not None:
        from mrmp.io import load_movingai_scenario

        base = load_movingai_scenario(run.map_path, run.scen, run.agents)
    elif run.map_path is not None:
        from mrmp.io.movingai import read_map

        grid = read_map(run.map_path)
        base = random_instance(grid, run.agents, seed=run.instance or 0, name=f"{run.map_name}-i{run.instance or 0}")
    else:
        raise ValueError(f"run {run.run_id} names neither a map file nor a generator")
    policy = PolicyOptions(name=run.policy) if run.kind == "decentralized" else base.policy
    return base.with_changes(
        policy=policy, network=run.faults, seed=run.seed, max_ticks=run.max_ticks, lifelong=run.lifelong
    )


def _lorr_scenario(run: BenchRun) -> Scenario:
    """The scenario of a run on a LoRR problem: its first ``agents`` robots and its task stream, for ``max_ticks``
    steps (the Start-Kit's 5,000 when unset), with the run's policy, faults and seed; the problem's bodies."""
    from mrmp.experiments.run_options import apply_run_options
    from mrmp.io.lorr import LORR_STEPS, lorr_scenario, read_lorr_problem

    assert run.lorr is not None
    problem = read_lorr_problem(run.lorr).with_team(run.agents)
    scenario = lorr_scenario(problem, run.max_ticks or LORR_STEPS)
    return apply_run_options(scenario.with_changes(network=run.faults), run.policy, seed=run.seed)


def base_record(run: BenchRun, status: str, error: str | None = None) -> dict[str, Any]:
    """A record of ``run`` with its parameters and every result field null."""
    record: dict[str, Any] = {
        "format": RECORD_FORMAT,
        "run_id": run.run_id,
        "status": status,
        "error": error,
        "bench": run.bench,
        "map": run.map_name,
        "map_path": run.map_path,
        "scen": run.scen,
        "generator": run.generator_spec,
        "instance": run.instance,
        "lorr": run.lorr,
        "agents": run.agents,
        "policy": run.policy,
        "kind": run.kind,
        "seed": run.seed,
        "faults": faults_to_dict(run.faults),
        "lifelong": run.lifelong,
        "max_ticks": run.max_ticks,
        "time_limit_s": float(run.time_limit_s),
    }
    record.update(dict.fromkeys(RESULT_FIELDS))
    return record


def result_fields(result: RunResult) -> dict[str, Any]:
    """The record's result fields from a finished run (see the module docstring).

    >>> from mrmp.core.result import RobotResult
    >>> robot = RobotResult("A", (0, 0), (0, 2), path=[(0, 0), (0, 1), (0, 2)], messages_sent=4)
    >>> fields = result_fields(RunResult("s", "thesis", 0, [robot], [], "all arrived", 2, 2, 0.5, {"messages": 4}))
    >>> fields["soc_over_lb"], fields["messages_per_robot_move"], fields["collisions"], fields["wall_time_per_step_s"]
    (1.0, 2.0, 0, 0.25)
    """
    from mrmp.io.results import result_to_dict

    data = result_to_dict(result)
    fields = {key: data[key] for key in RESULT_FIELDS if key in data and key != "collisions"}
    moves = sum(robot.steps for robot in result.robots)
    steps = result.ticks
    fields.update(
        collisions=len(result.collisions),
        soc_over_lb=(
            result.sum_of_costs / result.lower_bound
            if result.success and not result.lifelong and result.lower_bound > 0
            else None
        ),
        robots_arrived=sum(1 for robot in result.robots if robot.arrived),
        tasks_finished=result.tasks.finished if result.tasks is not None else None,
        goals_reached=sum(robot.goals_reached for robot in result.robots),
        steps=steps,
        wall_time_per_step_s=result.wall_time_s / steps if steps else None,
        messages_per_robot_move=result.messages / moves if moves else None,
    )
    return fields


def execute_run(run: BenchRun, on_ready: Callable[[], None] = lambda: None) -> dict[str, Any]:
    """Run ``run`` in this process and return its record (never raises for a failing run).

    A central planner that stops at its limit gives status ``timeout``; any
    exception gives status ``error`` with a one-line message. Wall-clock
    limits beyond the planner's own are enforced by the caller
    (:func:`mrmp.bench.runner.run_isolated`), counted from ``on_ready``: it is
    called once the run's scenario is built (or has failed to build), when
    the planner's or the simulator's own clock is about to start.
    """
    try:
        try:
            scenario = build_scenario(run)
        finally:
            on_ready()
        if run.kind == "centralized":
            from mrmp.centralized.registry import plan_with
            from mrmp.experiments.execution import execute_in_simulator

            plan = plan_with(run.policy, scenario, time_limit_s=run.time_limit_s)
            if plan.status == "limit":
                reason = plan.message or f"stopped at its limit after {plan.planning_time_s:.1f} s"
                return base_record(run, "timeout", _one_line(f"{run.policy}: {reason}"))
            if not plan.solved:
                record = base_record(run, "done")
                record.update(success=False, stop_reason=f"no plan: {plan.status}", planning_time_s=plan.planning_time_s)
                return record
            result = execute_in_simulator(scenario, plan)
        else:
            from mrmp.sim.simulator import simulate

            started = time.perf_counter()
            result = simulate(scenario)
            if result.wall_time_s <= 0:
                result.wall_time_s = time.perf_counter() - started
    except (MrmpError, ValueError) as error:
        return base_record(run, "error", _one_line(str(error)))
    except Exception as error:  # a crash of the method itself: recorded, never lost
        origin = traceback.extract_tb(error.__traceback__)[-1]
        where = f" ({origin.filename.rsplit('/', 1)[-1]}:{origin.lineno})"
        return base_record(run, "error", _one_line(f"{type(error).__name__}: {error}{where}"))
    record = base_record(run, "done")
    record.update(result_fields(result))
    return record


def _one_line(text: str, limit: int = 300) -> str:
    """The first line of ``text``, at most ``limit`` characters.

    >>> _one_line("first\\nsecond")
    'first'
    """
    line = text.strip().splitlines()[0] if text.strip() else "unknown error"
    return line if len(line) <= limit else line[: limit - 3] + "..."
