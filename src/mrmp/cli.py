"""The ``mrmp`` command: run scenarios, validate files.

Exit codes: 0 when every robot arrived with no collision; 1 when a run ended
otherwise (deadlock, livelock, tick limit, collision; the result is still
printed and written); 2 for bad input (each problem on one line, no traceback).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.console import Console
from rich.table import Table

from mrmp.core.errors import InputError, MrmpError, Problem
from mrmp.core.result import RunResult
from mrmp.core.scenario import NetworkFaults, PolicyOptions, RESOLUTIONS, Scenario, scenario_problems
from mrmp.io import load_movingai_scenario, load_scenario, validate_file, write_result_json
from mrmp.policies.registry import POLICY_NAMES
from mrmp.sim.simulator import simulate

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Multi-robot motion planning with communication: decentralized robots on a grid.",
)

TABLE_ROWS = 40
"""Robots listed in the terminal table; the JSON result always has every robot."""


def _fail(problems: list[Problem] | tuple[Problem, ...]) -> typer.Exit:
    err = Console(stderr=True, highlight=False, soft_wrap=True)
    for problem in problems:
        err.print(f"error: {problem}", markup=False)
    return typer.Exit(2)


def parse_delay(text: str) -> tuple[int, int]:
    """Read ``--delay``: ``N`` or ``A..B`` ticks.

    >>> parse_delay("0..3"), parse_delay("2")
    ((0, 3), (2, 2))
    """
    low, separator, high = text.partition("..")
    try:
        bounds = (int(low), int(high)) if separator else (int(low), int(low))
    except ValueError:
        raise InputError(Problem("--delay", f"expected N or A..B ticks, got {text!r}")) from None
    return bounds


def _load(
    scenario_path: Optional[Path], map_path: Optional[Path], scen_path: Optional[Path], agents: Optional[int]
) -> Scenario:
    if scenario_path is not None:
        if map_path or scen_path:
            raise InputError(Problem("--map/--scen", "give either a scenario file or --map and --scen, not both"))
        return load_scenario(scenario_path, known_policies=POLICY_NAMES)
    if map_path is None or scen_path is None:
        raise InputError(Problem("SCENARIO", "give a scenario file, or --map and --scen (with --agents)"))
    if agents is not None and agents <= 0:
        raise InputError(Problem("--agents", f"must be positive, got {agents}"))
    return load_movingai_scenario(map_path, scen_path, agents)


def _apply_options(scenario: Scenario, **options: object) -> Scenario:
    policy = scenario.policy
    policy_changes = {key: options[key] for key in ("name", "resolve", "heading_aware") if options.get(key) is not None}
    if policy_changes:
        policy = PolicyOptions(**{**policy.__dict__, **policy_changes})
    network = scenario.network
    network_changes: dict[str, object] = {
        key: options[key] for key in ("loss", "duplicate", "reorder") if options.get(key) is not None
    }
    if options.get("delay") is not None:
        network_changes["delay_min"], network_changes["delay_max"] = parse_delay(str(options["delay"]))
    if network_changes:
        network = NetworkFaults(**{**network.__dict__, **network_changes})
    changes: dict[str, object] = {"policy": policy, "network": network}
    for key in ("seed", "max_ticks", "safety"):
        if options.get(key) is not None:
            changes[key] = options[key]
    updated = scenario.with_changes(**changes)
    problems = scenario_problems(updated)
    if policy.name not in POLICY_NAMES:
        problems.append(Problem("--policy", f"unknown policy {policy.name!r}; known: {', '.join(POLICY_NAMES)}"))
    if problems:
        raise InputError(problems)
    return updated


def _cell(cell: tuple[int, int]) -> str:
    return f"({cell[0]},{cell[1]})"


def print_result(result: RunResult, console: Console) -> None:
    """Print the per-robot table and the summary line."""
    table = Table(title=f"{result.scenario or 'run'}: policy {result.policy}, seed {result.seed}")
    for column in ("robot", "start", "goal", "arrived", "steps", "turns", "waits", "messages"):
        table.add_column(column, justify="left" if column in ("robot", "start", "goal") else "right")
    for robot in result.robots[:TABLE_ROWS]:
        arrived = f"yes @{robot.arrival_tick}" if robot.arrived else "[red]no[/red]"
        table.add_row(
            robot.id,
            _cell(robot.start),
            _cell(robot.goal),
            arrived,
            str(robot.steps),
            str(robot.turns),
            str(robot.waits),
            str(robot.messages_sent),
        )
    if len(result.robots) > TABLE_ROWS:
        table.caption = f"{len(result.robots) - TABLE_ROWS} more robots in the --json result"
    console.print(table)
    verdict = "[green]success[/green]" if result.success else "[red]failure[/red]"
    console.print(
        f"{verdict} ({result.stop_reason} at tick {result.ticks}): makespan {result.makespan} ticks "
        f"({result.time_makespan_s:.1f} s), sum of costs {result.sum_of_costs}, lower bound {result.lower_bound}, "
        f"collisions: {len(result.collisions)}, messages {result.messages}, wall time {result.wall_time_s:.3f} s"
    )
    for collision in result.collisions[:10]:
        console.print(f"  [red]{collision.describe()}[/red]")
    if len(result.collisions) > 10:
        console.print(f"  ... and {len(result.collisions) - 10} more collisions")
    if result.not_arrived:
        names = ", ".join(result.not_arrived[:20]) + (" ..." if len(result.not_arrived) > 20 else "")
        console.print(f"  did not arrive: {names}")


@app.command()
def run(
    scenario_path: Annotated[Optional[Path], typer.Argument(metavar="SCENARIO", help="A YAML scenario.")] = None,
    map_path: Annotated[Optional[Path], typer.Option("--map", help="A MovingAI .map file.")] = None,
    scen_path: Annotated[Optional[Path], typer.Option("--scen", help="A MovingAI .scen file.")] = None,
    agents: Annotated[Optional[int], typer.Option(help="Robots taken from the .scen (default: all).")] = None,
    policy: Annotated[Optional[str], typer.Option(help=f"Decision rule: {', '.join(POLICY_NAMES)}.")] = None,
    resolve: Annotated[Optional[str], typer.Option(help=f"Conflict resolution: {', '.join(RESOLUTIONS)}.")] = None,
    heading_aware: Annotated[Optional[bool], typer.Option("--heading-aware/--no-heading-aware", help="Charge turns when planning.")] = None,
    unsafe: Annotated[bool, typer.Option("--unsafe", help="Turn the safety layer off: the policy as written.")] = False,
    max_ticks: Annotated[Optional[int], typer.Option(help="Stop after this many ticks.")] = None,
    seed: Annotated[Optional[int], typer.Option(help="Seed of the simulated network.")] = None,
    loss: Annotated[Optional[float], typer.Option(help="Probability that a message is lost.")] = None,
    delay: Annotated[Optional[str], typer.Option(help="Message delay in ticks: N or A..B.")] = None,
    duplicate: Annotated[Optional[float], typer.Option(help="Probability that a message is duplicated.")] = None,
    reorder: Annotated[Optional[float], typer.Option(help="Probability that a message overtakes earlier ones.")] = None,
    json_path: Annotated[Optional[str], typer.Option("--json", help="Write the whole result as JSON (- for stdout).")] = None,
    animate: Annotated[Optional[Path], typer.Option(help="Write an animation: .gif or .svg.")] = None,
) -> None:
    """Run a scenario in the lockstep simulator and report what happened."""
    console = Console(stderr=json_path == "-", highlight=False)
    try:
        scenario = _load(scenario_path, map_path, scen_path, agents)
        scenario = _apply_options(
            scenario,
            name=policy,
            resolve=resolve,
            heading_aware=heading_aware,
            loss=loss,
            delay=delay,
            duplicate=duplicate,
            reorder=reorder,
            seed=seed,
            max_ticks=max_ticks,
            safety=False if unsafe else None,
        )
        if animate is not None and animate.suffix.lower() not in (".gif", ".svg"):
            raise InputError(Problem("--animate", f"unsupported suffix {animate.suffix!r}; use .gif or .svg"))
    except InputError as error:
        raise _fail(error.problems) from None
    result = simulate(scenario)
    print_result(result, console)
    try:
        if json_path is not None:
            write_result_json(result, json_path)
        if animate is not None:
            from mrmp.viz import write_animation

            write_animation(scenario.grid, result, animate)
            console.print(f"animation written to {animate}")
    except (MrmpError, OSError) as error:
        Console(stderr=True).print(f"error: {error}", markup=False)
        raise typer.Exit(2) from None
    raise typer.Exit(0 if result.success else 1)


@app.command()
def validate(
    files: Annotated[list[Path], typer.Argument(metavar="FILE...", help="Scenarios (.yaml), maps (.map) or .scen files.")],
) -> None:
    """Check scenario and map files and report every problem, one per line."""
    problems: list[Problem] = []
    console = Console(highlight=False)
    for path in files:
        found = validate_file(path, known_policies=POLICY_NAMES)
        if found:
            problems.extend(found)
        else:
            console.print(f"{path}: ok", markup=False)
    if problems:
        raise _fail(problems)


def main() -> None:
    """Entry point of the ``mrmp`` command."""
    try:
        app()
    except KeyboardInterrupt:
        sys.exit(130)
