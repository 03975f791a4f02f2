"""Benchmark records for the report tests: hand-made ones with known numbers, and ones from real simulated runs.

``record_of_run`` builds a record exactly as the bench record format says
(``mrmp-bench-1``) from a scenario and the :class:`RunResult` the simulator
returned, so the report is tested on what a benchmark really produces.
"""

from __future__ import annotations

import hashlib
import json
import random
from pathlib import Path
from typing import Any

from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
from mrmp.core.result import RunResult
from mrmp.core.scenario import NetworkFaults
from mrmp.io.results import result_to_dict
from mrmp.sim.simulator import simulate

NO_FAULTS = {"loss": 0.0, "delay": [0, 0], "duplicate": 0.0, "reorder": 0.0}


def make_record(**fields: Any) -> dict[str, Any]:
    """A valid finished-run record; ``fields`` replace the defaults."""
    record: dict[str, Any] = {
        "format": "mrmp-bench-1",
        "run_id": "0000000000000000",
        "status": "done",
        "error": None,
        "map": "empty-8-8",
        "map_path": "maps/empty-8-8.map",
        "scen": None,
        "generator": None,
        "agents": 4,
        "policy": "pibt",
        "kind": "decentralized",
        "seed": 0,
        "faults": dict(NO_FAULTS),
        "lifelong": False,
        "max_ticks": None,
        "time_limit_s": 60.0,
        "success": True,
        "stop_reason": "all arrived",
        "ticks": 10,
        "makespan": 10,
        "sum_of_costs": 30,
        "lower_bound": 25,
        "time_makespan_s": 10.0,
        "messages": 120,
        "network": {"messages": 120},
        "wall_time_s": 0.05,
        "planning_time_s": None,
        "plan_bytes": None,
        "throughput": 0.4,
        "collisions": 0,
        "soc_over_lb": 1.2,
        "robots_arrived": 4,
        "goals_reached": 4,
        "steps": 10,
        "wall_time_per_step_s": 0.005,
        "messages_per_robot_move": 4.0,
    }
    record.update(fields)
    return record


def unfinished(status: str, error: str | None = None, **fields: Any) -> dict[str, Any]:
    """A timeout or error record: every result field null."""
    record = make_record(status=status, error=error, **fields)
    for name in (
        "success", "stop_reason", "ticks", "makespan", "sum_of_costs", "lower_bound", "time_makespan_s", "messages",
        "network", "wall_time_s", "planning_time_s", "plan_bytes", "throughput", "collisions", "soc_over_lb",
        "robots_arrived", "goals_reached", "steps", "wall_time_per_step_s", "messages_per_robot_move",
    ):
        record[name] = None
    return record


def write_jsonl(path: Path, records: list[dict[str, Any]], tail: str = "") -> Path:
    """Write records one per line, then ``tail`` (e.g. a cut-short line)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(json.dumps(record) + "\n" for record in records) + tail)
    return path


def record_of_run(scenario: Scenario, result: RunResult, map_name: str) -> dict[str, Any]:
    """The bench record of one simulated run, by the record format."""
    faults = scenario.network
    parameters = {
        "map": map_name,
        "agents": len(scenario.robots),
        "policy": scenario.policy.name,
        "seed": scenario.seed,
        "faults": {
            "loss": faults.loss,
            "delay": [faults.delay_min, faults.delay_max],
            "duplicate": faults.duplicate,
            "reorder": faults.reorder,
        },
        "lifelong": scenario.lifelong,
        "max_ticks": scenario.max_ticks,
    }
    run_id = hashlib.sha256(json.dumps(parameters, sort_keys=True).encode()).hexdigest()[:16]
    data = result_to_dict(result)
    for name in ("robots", "format", "scenario", "policy", "seed", "mode", "tick_seconds", "ideal_makespan_s", "lifelong"):
        data.pop(name)
    data["collisions"] = len(result.collisions)
    moves = sum(robot.steps for robot in result.robots)
    steps = max(result.ticks, 1)
    return {
        "format": "mrmp-bench-1",
        "run_id": run_id,
        "status": "done",
        "error": None,
        "map_path": None,
        "scen": None,
        "generator": {"kind": "empty", "x_size": scenario.grid.x_size, "y_size": scenario.grid.y_size},
        "kind": "decentralized",
        "time_limit_s": 60.0,
        **parameters,
        **data,
        "soc_over_lb": result.sum_of_costs / result.lower_bound if result.success and result.lower_bound else None,
        "robots_arrived": sum(1 for robot in result.robots if robot.arrived),
        "goals_reached": sum(robot.goals_reached for robot in result.robots),
        "steps": result.ticks,
        "wall_time_per_step_s": result.wall_time_s / steps,
        "messages_per_robot_move": result.messages / moves if moves else None,
    }


def simulated_bench(
    agents: tuple[int, ...] = (2, 4),
    policies: tuple[str, ...] = ("pibt", "astar"),
    losses: tuple[float, ...] = (0.0, 0.3),
    seeds: tuple[int, ...] = (0, 1),
    size: int = 8,
) -> list[dict[str, Any]]:
    """Really simulate a small matrix on an empty grid and return its records."""
    grid = Grid(size, size, name=f"empty-{size}-{size}")
    records = []
    for count in agents:
        for seed in seeds:
            rng = random.Random(1000 * count + seed)
            cells = [(x, y) for x in range(size) for y in range(size)]
            starts, goals = rng.sample(cells, count), rng.sample(cells, count)
            robots = tuple(RobotSpec(f"r{i}", start, goal) for i, (start, goal) in enumerate(zip(starts, goals)))
            for policy in policies:
                for loss in losses:
                    scenario = Scenario(
                        grid,
                        robots,
                        policy=PolicyOptions(name=policy),
                        network=NetworkFaults(loss=loss),
                        seed=seed,
                        max_ticks=200,
                        name=grid.name,
                    )
                    records.append(record_of_run(scenario, simulate(scenario), grid.name))
    return records


def lifelong_records(seeds: tuple[int, ...] = (0, 1)) -> list[dict[str, Any]]:
    """Really simulate lifelong pibt runs of 3 robots on an empty 8x8 grid, 60 ticks each."""
    grid = Grid(8, 8, name="empty-8-8")
    robots = (RobotSpec("a", (0, 0), (7, 7)), RobotSpec("b", (7, 0), (0, 7)), RobotSpec("c", (3, 3), (5, 1)))
    records = []
    for seed in seeds:
        scenario = Scenario(grid, robots, policy=PolicyOptions(name="pibt"), lifelong=True, max_ticks=60, seed=seed)
        records.append(record_of_run(scenario, simulate(scenario), grid.name))
    return records
