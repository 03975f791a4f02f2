"""The ``mrmp`` command: run scenarios, validate files.

Exit codes: 0 when every robot arrived with no collision; 1 when a run ended
otherwise (deadlock, livelock, tick limit, collision; the result is still
printed and written); 2 for bad input (each problem on one line, no traceback).
"""

from __future__ import annotations

import functools
import inspect
import sys
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
import typer.core
from rich.console import Console
from rich.table import Table

from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.errors import InputError, MrmpError, Problem
from mrmp.core.limits import (
    MAX_LIVE_DELAY_SECONDS,
    MAX_LIVE_ROBOTS,
    MAX_RUN_SECONDS,
    MAX_STEP_SECONDS,
    MAX_TICKS,
    MAX_TIME_SCALE,
    MAX_VIRTUAL_ROBOTS,
    MIN_TIME_SCALE,
    shown,
)
from mrmp.core.options import Setting, setting_types, settings
from mrmp.core.result import RunResult
from mrmp.core.scenario import PolicyOptions, Scenario
from mrmp.experiments.run_options import FLAG_NAMES, apply_run_options, parse_range
from mrmp.io import load_movingai_scenario, load_scenario, validate_file, write_result_json
from mrmp.io.lorr import LORR_STEPS, is_lorr_problem, load_lorr_scenario
from mrmp.live.transport_table import TRANSPORTS
from mrmp.sim.policy_table import body_problem, policy_entry, policy_names
from mrmp.sim.simulator import TickObserver, simulate

if TYPE_CHECKING:
    from mrmp.centralized.plan import PlanningResult
    from mrmp.live.transport import LiveFaults

FLAG = ""
"""The metavar of an option that takes no value (an on/off flag): none is shown."""


def _flags_without_value_type(params: list[Any]) -> list[Any]:
    """``params`` with their on/off flags (``--help`` too) given an empty metavar, so that help shows no ``<bool>``.

    Options whose choices come from a table of a heavy module (the colourings
    of :mod:`mrmp.viz`) get their metavar and default here, on first use, so
    that commands without them (``mrmp agent``, ``mrmp referee``) start
    without importing it.
    """
    for param in params:
        if getattr(param, "is_flag", False) and param.metavar is None:
            param.metavar = FLAG
        elif param.name in _LATE_DETAILS and param.metavar is None:
            param.metavar, param.show_default = _LATE_DETAILS[param.name]()
    return params


class _Command(typer.core.TyperCommand):
    """A command whose help shows no value type for its flags (they take none)."""

    def get_params(self, ctx: Any) -> list[Any]:
        """The command's parameters, flags without value types."""
        return _flags_without_value_type(super().get_params(ctx))


class _Group(typer.core.TyperGroup):
    """The ``mrmp`` group: its own flags (``--version``, completion, help) show no value type either."""

    def get_params(self, ctx: Any) -> list[Any]:
        """The group's parameters, flags without value types."""
        return _flags_without_value_type(super().get_params(ctx))


app = typer.Typer(
    cls=_Group,
    no_args_is_help=True,
    context_settings={"help_option_names": ["-h", "--help"], "show_default": True},
    help="Multi-robot motion planning with communication: decentralized robots on a grid.",
)
command = functools.partial(app.command, cls=_Command)
"""``app.command`` for mrmp's commands (help without value types for flags)."""

SCENARIOS = "Scenario"
POLICIES = "Policy"
FAULTS = "Network faults (simulated; live runs inject them too)"
OUTPUT = "Output"
PLANNING = "Central planner"
LIVE = "Live run (--live)"
"""The panels ``mrmp run --help`` groups its options in."""
SCENARIO_DEFAULT = "the scenario's"
"""The default shown for an option that replaces a value of the scenario file."""


def choices(names: Iterable[str]) -> str:
    """An option's metavar listing the values it takes, e.g. ``[udp|multicast|zenoh]``.

    >>> choices(["divert", "wait"])
    '[divert|wait]'
    """
    return "[" + "|".join(names) + "]"


def _colourings() -> tuple[str, ...]:
    from mrmp.viz.colouring import COLOURINGS

    return COLOURINGS


def _colour_by_option(panel: str | None = None) -> Any:
    """The ``--colour-by`` option of ``mrmp run --animate`` and ``mrmp animate``, its choices from the viz's table."""
    return typer.Option(
        help="Colour the robots by their id, the share of their path done, or their heading.",
        autocompletion=_colourings,
        rich_help_panel=panel,
    )


def _colour_by_details() -> tuple[str, str]:
    """``--colour-by``'s metavar and default, from :mod:`mrmp.viz.colouring`."""
    from mrmp.viz.colouring import COLOURINGS, CROWD

    return choices(COLOURINGS), f"robot up to {CROWD} robots, else progress"


_LATE_DETAILS: dict[str, Callable[[], tuple[str, str]]] = {"colour_by": _colour_by_details}
"""Options whose metavar and shown default are looked up when the command's parameters are first listed."""


def _check_drawing(colour_by: str | None, speed: float) -> None:
    """Refuse, before the run, a colouring or speed the animation cannot use."""
    if colour_by is not None and colour_by not in _colourings():
        raise InputError(Problem("--colour-by", f"unknown colouring {colour_by!r}; known: {', '.join(_colourings())}"))
    _positive(speed, "--speed")


def _planner_names() -> tuple[str, ...]:
    from mrmp.centralized.registry import PLANNER_NAMES

    return tuple(PLANNER_NAMES)


def _version(value: bool) -> None:
    if value:
        print(f"mrmp {_installed_version()}")
        raise typer.Exit(0)


def _installed_version() -> str:
    """The installed distribution's version."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("mrmp")
    except PackageNotFoundError:
        return "(not installed: pip install -e . in the checkout)"


@app.callback()
def _main(
    version: Annotated[
        bool, typer.Option("--version", "-V", is_eager=True, callback=_version, help="Print mrmp's version and exit.")
    ] = False,
) -> None:
    """Multi-robot motion planning with communication: decentralized robots on a grid."""


TABLE_ROWS = 40
"""Robots listed in the terminal table; the JSON result always has every robot."""


def _fail(problems: list[Problem] | tuple[Problem, ...]) -> typer.Exit:
    err = Console(stderr=True, highlight=False, soft_wrap=True)
    for problem in problems:
        err.print(f"error: {problem}", markup=False)
    return typer.Exit(2)


def _load(
    scenario_path: Path | None, map_path: Path | None, scen_path: Path | None, agents: int | None, steps: int | None = None
) -> Scenario:
    if scenario_path is not None:
        if map_path or scen_path:
            raise InputError(Problem("--map/--scen", "give either a scenario file or --map and --scen, not both"))
        if agents is not None:
            raise InputError(
                Problem("--agents", "goes with --map and --scen; a YAML scenario lists its robots (or sets agents: next to scen:)")
            )
        if is_lorr_problem(scenario_path):
            return load_lorr_scenario(scenario_path, _steps(steps))
        if steps is not None:
            raise InputError(Problem("--steps", "is the length of a LoRR problem's run (a .json file); use --max-ticks"))
        return load_scenario(scenario_path, known_policies=policy_names())
    if map_path is None or scen_path is None:
        raise InputError(Problem("SCENARIO", "give a scenario file, or --map and --scen (with --agents)"))
    if agents is not None and agents <= 0:
        raise InputError(Problem("--agents", f"must be positive, got {agents}"))
    return load_movingai_scenario(map_path, scen_path, agents)


def _steps(steps: int | None) -> int:
    """``--steps``, checked: a LoRR run's length in steps (the Start-Kit's default when not given)."""
    if steps is None:
        return LORR_STEPS
    if not 1 <= steps <= MAX_TICKS:
        raise InputError(Problem("--steps", f"must be between 1 and {MAX_TICKS}, got {steps}"))
    return steps


def with_policy_flags(command: Callable[..., None]) -> Callable[..., None]:
    """``command`` with one ``mrmp run`` option per policy setting, in place of its ``policy_settings`` parameter.

    The options are derived from the fields of
    :class:`~mrmp.core.scenario.PolicyOptions` (flag, help text and type, from
    :mod:`mrmp.core.options`); each is None when not given, and ``command``
    receives them as one ``policy_settings`` dict by field name.

    >>> def show(policy_settings: dict[str, Any]) -> None:
    ...     print(policy_settings)
    >>> list(inspect.signature(with_policy_flags(show)).parameters)
    ['resolve', 'heading_aware', 'radius', 'swap', 'search', 'sequencing', 'synchronizer', 'body', 'guidance']
    >>> with_policy_flags(show)(radius=3)
    {'resolve': None, 'heading_aware': None, 'radius': 3, 'swap': None, 'search': None, 'sequencing': None, 'synchronizer': None, 'body': None, 'guidance': None}
    """
    types = setting_types(PolicyOptions)
    flags = [
        inspect.Parameter(
            field.name,
            inspect.Parameter.POSITIONAL_OR_KEYWORD,
            default=None,
            annotation=Annotated[types[field.name] | None, _setting_option(setting, types[field.name], field.default)],
        )
        for field, setting in settings(PolicyOptions)
    ]
    signature = inspect.signature(command, eval_str=True)
    parameters: list[inspect.Parameter] = []
    for parameter in signature.parameters.values():
        parameters.extend(flags if parameter.name == "policy_settings" else [parameter])

    @functools.wraps(command)
    def with_flags(**arguments: Any) -> None:
        given = {name: arguments.pop(name, None) for name in types}
        return command(**arguments, policy_settings=given)

    with_flags.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
    with_flags.__annotations__ = {parameter.name: parameter.annotation for parameter in parameters} | {"return": None}
    return with_flags


def _setting_option(setting: Setting, kind: type, default: object) -> Any:
    """The ``mrmp run`` option of a policy setting: its choices, or no metavar for a switch; the scenario's value by default."""
    metavar = choices(setting.choices) if setting.choices else None
    return typer.Option(
        setting.flag,
        help=setting.help,
        metavar=metavar,
        show_default=f"the scenario's, else {_shown_default(setting, default)}",
        rich_help_panel=POLICIES,
        autocompletion=(lambda: list(setting.choices)) if setting.choices else None,
    )


def _shown_default(setting: Setting, default: object) -> str:
    """A setting's default as its option spells it: ``divert``, ``2``, ``--swap``.

    >>> _shown_default(Setting("", "swap", "--swap/--no-swap"), True), _shown_default(Setting("", "radius", "--radius"), 2)
    ('--swap', '2')
    """
    if isinstance(default, bool):
        on, _, off = setting.flag.partition("/")
        return on if default else off
    return str(default)


def _positive(value: float, option: str, largest: float | None = None, unit: str = "") -> float:
    """``value`` if it is positive (and at most ``largest`` when given).

    >>> _positive(2.5, "--time-limit", MAX_RUN_SECONDS)
    2.5
    >>> _positive(float("inf"), "--time-limit", MAX_RUN_SECONDS, "seconds")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: --time-limit: must be at most 86400 seconds, got inf
    """
    if not value > 0:
        raise InputError(Problem(option, f"must be positive, got {value}"))
    if largest is not None and not value <= largest:
        raise InputError(Problem(option, f"must be at most {shown(largest)}{' ' + unit if unit else ''}, got {value}"))
    return value


def time_scale_checked(value: float, option: str = "--time-scale") -> float:
    """A ``--time-scale`` between :data:`~mrmp.core.limits.MIN_TIME_SCALE` and :data:`~mrmp.core.limits.MAX_TIME_SCALE`.

    >>> time_scale_checked(10.0)
    10.0
    >>> time_scale_checked(float("inf"))
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: --time-scale: must be between 0.001 and 1000 (times the robots' real speed), got inf
    """
    if not MIN_TIME_SCALE <= value <= MAX_TIME_SCALE:
        bounds = f"between {shown(MIN_TIME_SCALE)} and {shown(MAX_TIME_SCALE)}"
        raise InputError(Problem(option, f"must be {bounds} (times the robots' real speed), got {value}"))
    return value


def _not_negative(value: float, option: str, largest: float) -> float:
    """``value`` if it is between 0 and ``largest``.

    >>> _not_negative(float("nan"), "--listen-time", MAX_STEP_SECONDS)
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: --listen-time: must be between 0 and 3600, got nan
    """
    if not 0.0 <= value <= largest:
        raise InputError(Problem(option, f"must be between 0 and {shown(largest)}, got {value}"))
    return value


def _fraction(value: float, option: str) -> float:
    if not 0.0 <= value <= 1.0:
        raise InputError(Problem(option, f"must be in [0, 1], got {value}"))
    return value


def parse_range_ms(text: str, option: str) -> tuple[float, float]:
    """Read ``N`` or ``A..B`` milliseconds, as seconds.

    >>> parse_range_ms("20..80", "--delay-ms")
    (0.02, 0.08)
    """
    low, high = parse_range(text, option, "milliseconds", whole=False)
    if not high <= MAX_LIVE_DELAY_SECONDS * 1000:
        raise InputError(Problem(option, f"must be at most {shown(MAX_LIVE_DELAY_SECONDS * 1000)} milliseconds, got {text!r}"))
    return low / 1000.0, high / 1000.0


def parse_kills(items: list[str]) -> dict[str, float]:
    """Read ``--kill ID@SECONDS`` options.

    >>> parse_kills(["B@2.5"])
    {'B': 2.5}
    """
    kills = {}
    for item in items:
        robot, separator, seconds = item.rpartition("@")
        try:
            kills[robot] = float(seconds)
        except ValueError:
            robot = ""
        if not separator or not robot:
            raise InputError(Problem("--kill", f"expected ROBOT@SECONDS, got {item!r}"))
        if not 0.0 <= kills[robot] <= MAX_RUN_SECONDS:
            raise InputError(Problem("--kill", f"the seconds of {item!r} must be between 0 and {shown(MAX_RUN_SECONDS)}"))
    return kills


def live_faults(scenario: Scenario, time_scale: float, delay_ms: str | None) -> LiveFaults:
    """The scenario's network faults for a live run: probabilities as given, delays in seconds.

    A delay of one tick in the simulator is one cell time at the run's speed;
    ``--delay-ms`` overrides it.
    """
    from mrmp.live.transport import LiveFaults

    network = scenario.network
    tick = scenario.timing.cell_time / time_scale
    low, high = network.delay_min * tick, network.delay_max * tick
    if delay_ms is not None:
        low, high = parse_range_ms(delay_ms, "--delay-ms")
    elif high > MAX_LIVE_DELAY_SECONDS:
        reason = (
            f"a delay of {network.delay_max} ticks is {high:g} s at this speed, more than the bound of "
            f"{shown(MAX_LIVE_DELAY_SECONDS)} s; give --delay-ms"
        )
        raise InputError(Problem("network.delay", reason))
    return LiveFaults(network.loss, low, high, network.duplicate, network.reorder)


def _plan(name: str, scenario: Scenario, time_limit: float, console: Console) -> PlanningResult:
    """Run a central planner; an unsolved plan ends the command with status 1 and its reason."""
    from mrmp.centralized.registry import PLANNER_NAMES, plan_with

    if name not in PLANNER_NAMES:
        raise InputError(Problem("--planner", f"unknown planner {name!r}; known: {', '.join(PLANNER_NAMES)}"))
    plan = plan_with(name, scenario, time_limit_s=_positive(time_limit, "--time-limit", MAX_RUN_SECONDS, "seconds"))
    if not plan.solved:
        console.print(f"[red]{name}: no plan[/red] ({plan.status}: {plan.message}) after {plan.planning_time_s:.2f} s")
        raise typer.Exit(1)
    console.print(f"{name}: planned in {plan.planning_time_s:.3f} s, sum of costs {plan.sum_of_costs()}, makespan {plan.makespan()}")
    return plan


def _cell(cell: tuple[int, int]) -> str:
    return f"({cell[0]},{cell[1]})"


def _body_note(body: str) -> str:
    """`` (turning bodies)`` after a figure of a run whose bodies are not the default ones, else nothing."""
    return "" if body == "omni" else f" ({body} bodies)"


def print_result(result: RunResult, console: Console) -> None:
    """Print the per-robot table and the summary line."""
    table = Table(title=f"{result.scenario or 'run'}: policy {result.policy}, seed {result.seed}")
    for column in ("robot", "start", "goal", "arrived", "steps", "turns", "waits", "messages"):
        table.add_column(column, justify="left" if column in ("robot", "start", "goal") else "right")
    live = result.mode == "live"
    for robot in result.robots[:TABLE_ROWS]:
        arrived = f"yes @{robot.time_s:.2f}s" if live else f"yes @{robot.arrival_tick}"
        if not robot.arrived:
            arrived = "[red]no[/red]"
        table.add_row(
            robot.id,
            _cell(robot.start),
            _cell(robot.goal),
            arrived,
            str(robot.steps),
            str(robot.turns),
            "-" if live else str(robot.waits),
            str(robot.messages_sent),
        )
    if len(result.robots) > TABLE_ROWS:
        table.caption = f"{len(result.robots) - TABLE_ROWS} more robots not shown (--json writes every robot)"
    console.print(table)
    verdict = "[green]success[/green]" if result.success else "[red]failure[/red]"
    if result.mode == "live":
        network = result.network
        rejected = _counts(network, "rejected_")
        injected = _counts(network, "injected_")
        moves = sum(robot.steps for robot in result.robots)
        if body_model(result.body).turns_in_place:  # its lower bound counts the quarter turns too
            moves_said = f"moves {moves} and quarter turns {sum(robot.turns for robot in result.robots)}"
        else:
            moves_said = f"moves {moves}"
        arrivals = sum(robot.time_s for robot in result.robots if robot.arrived)
        virtual = "virtual_turns" in network  # a fleet on a virtual clock: its times are virtual, its wall time CPU
        clock, spent = ("virtual", "CPU time") if virtual else ("wall-clock", "wall time")
        datagrams = int(network.get("datagrams_sent", result.messages))
        on_the_wire = f" in {datagrams} datagrams" if datagrams != result.messages else ""  # multicast: fewer
        console.print(
            f"{verdict} ({result.stop_reason}): {clock} makespan {result.time_makespan_s:.2f} s "
            f"(ideal {result.ideal_makespan_s or 0:.2f} s: the longest single-robot path at this speed), "
            f"sum of arrival times {arrivals:.2f} s, "
            f"{moves_said} (lower bound {result.lower_bound}), collisions: {len(result.collisions)}, "
            f"messages {result.messages}{on_the_wire}, {spent} {result.wall_time_s:.1f} s"
        )
        console.print(f"  dropped by robots: {rejected}; injected faults: {injected}", markup=False)
        if result.tasks is not None:
            errands = sum(robot.goals_reached for robot in result.robots)
            console.print(f"  tasks finished within the run's steps: {result.tasks.finished} ({errands} errands), by the task desk's book")
            not_visited = result.network.get("tasks_errands_not_visited", 0)
            if not_visited:
                console.print(f"  [red]{not_visited} of those errands were never entered by their robot's body (referee)[/red]")
        if network.get("missed_lines"):
            console.print(f"  grid lines missed by bodies: {network['missed_lines']} (positions believed wrong from then on)")
    elif result.tasks is not None:
        console.print(
            f"{verdict} ({result.stop_reason} at step {result.ticks}): {result.tasks.finished} tasks finished "
            f"({sum(robot.goals_reached for robot in result.robots)} errands), collisions: {len(result.collisions)}, "
            f"messages {result.messages}, wall time {result.wall_time_s:.3f} s"
        )
    elif result.lifelong:
        goals = sum(robot.goals_reached for robot in result.robots)
        console.print(
            f"{verdict} ({result.stop_reason} at tick {result.ticks}): throughput {result.throughput:.3f} goals per tick "
            f"({goals} goals reached), collisions: {len(result.collisions)}, messages {result.messages}, "
            f"wall time {result.wall_time_s:.3f} s"
        )
    else:
        console.print(
            f"{verdict} ({result.stop_reason} at tick {result.ticks}): makespan {result.makespan} ticks "
            f"({result.time_makespan_s:.1f} s), sum of costs {result.sum_of_costs} ({result.time_sum_of_costs_s:.1f} s), "
            f"lower bound {result.lower_bound}{_body_note(result.body)}, "
            f"collisions: {len(result.collisions)}, messages {result.messages}, wall time {result.wall_time_s:.3f} s"
        )
    if result.plan_sum_of_costs is not None:
        console.print(f"  the plan executed: sum of costs {result.plan_sum_of_costs}, makespan {result.plan_makespan}")
    for collision in result.collisions[:10]:
        console.print(f"  [red]{collision.describe()}[/red]")
    if len(result.collisions) > 10:
        console.print(f"  ... and {len(result.collisions) - 10} more collisions")
    if result.not_arrived and not result.lifelong:
        names = ", ".join(result.not_arrived[:20]) + (" ..." if len(result.not_arrived) > 20 else "")
        console.print(f"  did not arrive: {names}")


def _counts(network: dict[str, int], prefix: str) -> str:
    """The nonzero counts of ``network`` whose key starts with ``prefix``, as ``"lost 24, duplicated 3"``.

    >>> _counts({"injected_sent": 82, "injected_lost": 24, "injected_delayed": 0, "messages": 9}, "injected_")
    'sent 82, lost 24'
    >>> _counts({}, "rejected_")
    'none'
    """
    counts = [f"{key[len(prefix):].replace('_', ' ')} {value}" for key, value in network.items() if key.startswith(prefix) and value]
    return ", ".join(counts) or "none"


def _check_show_messages(scenario: Scenario, written: bool, live: bool, planned: bool) -> None:
    """Refuse ``--show-messages`` before the run when its messages would not be recorded or drawn."""
    from mrmp.sim.simulator import records_messages

    if not written:
        raise InputError(Problem("--show-messages", "messages are drawn in an animation: give --animate (or --json to keep them)"))
    if live:
        raise InputError(Problem("--show-messages", "live runs do not record their messages; simulate instead (without --live)"))
    if not planned and not records_messages(scenario):
        raise InputError(
            Problem(
                "--show-messages",
                f"{scenario.policy.name} {policy_entry(scenario.policy.name).runs}, which records no messages; "
                "use a per-robot policy or --planner",
            )
        )


def _watched(
    scenario: Scenario, fps: float | None, console: Console, start: Callable[[TickObserver | None], RunResult]
) -> RunResult:
    """``start(on_tick)``, drawing every tick in the terminal when ``fps`` is given (``--watch``).

    Without ``--watch``, a terminal shows one progress line while the run goes.
    """
    if fps is None:
        from mrmp.viz.progress import ProgressLine

        with ProgressLine(scenario, console) as progress:
            return start(progress.on_tick if console.is_terminal else None)
    from mrmp.viz.terminal import TerminalView

    with TerminalView(scenario, console, fps) as view:
        return start(view.on_tick)


@command()
@with_policy_flags
def run(
    scenario_path: Annotated[Path | None, typer.Argument(metavar="SCENARIO", help="A YAML scenario (or --map and --scen).", show_default=False)] = None,
    map_path: Annotated[Path | None, typer.Option("--map", help="A MovingAI .map file (with --scen).", rich_help_panel=SCENARIOS)] = None,
    scen_path: Annotated[Path | None, typer.Option("--scen", help="A MovingAI .scen file (with --map).", rich_help_panel=SCENARIOS)] = None,
    agents: Annotated[int | None, typer.Option(help="Robots taken from the .scen.", show_default="all", rich_help_panel=SCENARIOS)] = None,
    max_ticks: Annotated[int | None, typer.Option(help="Stop after this many ticks.", show_default=SCENARIO_DEFAULT, rich_help_panel=SCENARIOS)] = None,
    steps: Annotated[int | None, typer.Option(help="A LoRR problem (.json): steps the run lasts.", show_default=str(LORR_STEPS), rich_help_panel=SCENARIOS)] = None,
    lifelong: Annotated[bool, typer.Option("--lifelong", help="A robot that reaches its goal gets a new one (seeded); report throughput.", rich_help_panel=SCENARIOS)] = False,
    seed: Annotated[int | None, typer.Option(help="Seed of the run's random draws (network faults, tie-breaks, new goals, paces).", show_default=SCENARIO_DEFAULT, rich_help_panel=SCENARIOS)] = None,
    policy: Annotated[str | None, typer.Option(help="The decision rule every robot runs.", metavar=choices(policy_names()), show_default=SCENARIO_DEFAULT, autocompletion=policy_names, rich_help_panel=POLICIES)] = None,
    policy_settings: dict[str, Any] | None = None,
    unsafe: Annotated[bool, typer.Option("--unsafe", help="Turn the safety layer off: the policy as written.", rich_help_panel=POLICIES)] = False,
    loss: Annotated[float | None, typer.Option(help="Probability that a message is lost.", show_default=SCENARIO_DEFAULT, rich_help_panel=FAULTS)] = None,
    delay: Annotated[str | None, typer.Option(help="Message delay in ticks.", metavar="N|A..B", show_default=SCENARIO_DEFAULT, rich_help_panel=FAULTS)] = None,
    duplicate: Annotated[float | None, typer.Option(help="Probability that a message is duplicated.", show_default=SCENARIO_DEFAULT, rich_help_panel=FAULTS)] = None,
    reorder: Annotated[float | None, typer.Option(help="Probability that a message overtakes earlier ones.", show_default=SCENARIO_DEFAULT, rich_help_panel=FAULTS)] = None,
    json_path: Annotated[Path | None, typer.Option("--json", help="Write the whole result as JSON (- for stdout).", metavar="PATH|-", rich_help_panel=OUTPUT)] = None,
    record: Annotated[Path | None, typer.Option("--record", help="Write the run for ROS 2 tools: OUT.mcap, or OUT.bag (a rosbag2 folder); needs the ros2 extra (docs/ros2.md).", metavar="OUT", rich_help_panel=OUTPUT)] = None,
    lorr_output: Annotated[Path | None, typer.Option("--lorr-output", help="A LoRR problem's run: write the League of Robot Runners' output JSON (for its tools, such as PlanViz).", metavar="FILE", rich_help_panel=OUTPUT)] = None,
    animate: Annotated[Path | None, typer.Option(help="Write an animation: .gif, .svg or .mp4 (needs ffmpeg).", rich_help_panel=OUTPUT)] = None,
    show_messages: Annotated[bool, typer.Option("--show-messages", help="Record each tick's messages and draw them in the --animate animation (and the --json result).", rich_help_panel=OUTPUT)] = False,
    goal_lines: Annotated[bool, typer.Option("--goal-lines", help="Draw a line from each robot to its goal in the --animate animation.", rich_help_panel=OUTPUT)] = False,
    colour_by: Annotated[str | None, _colour_by_option(OUTPUT)] = None,
    speed: Annotated[float, typer.Option(help="--animate: play a live run this many times faster than real time.", rich_help_panel=OUTPUT)] = 1.0,
    watch: Annotated[bool, typer.Option("--watch", help="Draw the grid in the terminal as the robots move.", rich_help_panel=OUTPUT)] = False,
    watch_fps: Annotated[float, typer.Option(help="--watch: ticks drawn per second.", rich_help_panel=OUTPUT)] = 10.0,
    planner: Annotated[str | None, typer.Option(help="Plan centrally first, then the robots execute the plan.", metavar=choices(_planner_names()), show_default="none: the policy decides", autocompletion=_planner_names, rich_help_panel=PLANNING)] = None,
    time_limit: Annotated[float, typer.Option(help="Seconds a central planner may spend.", rich_help_panel=PLANNING)] = 30.0,
    live: Annotated[bool, typer.Option("--live", help="One OS process per robot, in real time, over a loopback network.", rich_help_panel=LIVE)] = False,
    transport: Annotated[str, typer.Option(help="How the robots' processes talk.", metavar=choices(TRANSPORTS.names), autocompletion=lambda: list(TRANSPORTS.names), rich_help_panel=LIVE)] = "udp",
    time_scale: Annotated[float, typer.Option(help="Run this many times faster than the robots' real speed.", rich_help_panel=LIVE)] = 1.0,
    delay_ms: Annotated[str | None, typer.Option(help="Message delay in milliseconds.", metavar="N|A..B", show_default="the scenario's delay in ticks, at this speed", rich_help_panel=LIVE)] = None,
    jitter: Annotated[float, typer.Option(help="Each move takes its time times 1 +- jitter.", rich_help_panel=LIVE)] = 0.0,
    miss_line: Annotated[float, typer.Option(help="Probability that a body misses a grid line.", rich_help_panel=LIVE)] = 0.0,
    results: Annotated[Path | None, typer.Option(help="Folder for the robots' traces and reports (mrmp agent's --results, for the whole fleet).", show_default="a new temporary folder", rich_help_panel=LIVE)] = None,
    kill: Annotated[list[str] | None, typer.Option(help="Kill robot ID's process S wall-clock seconds after the fleet's start (repeatable).", metavar="ID@S", show_default=False, rich_help_panel=LIVE)] = None,
    ros2: Annotated[bool, typer.Option("--ros2", help="Every robot process publishes its pose and state on ROS 2 topics (DDS, domain ROS_DOMAIN_ID; the ros2 extra; docs/ros2.md).", rich_help_panel=LIVE)] = False,
    virtual_clock: Annotated[bool, typer.Option("--virtual-clock", help="With --live: run every robot's live driver, brain and body in this process on a virtual clock, over a simulated network with a processor per robot (fleets larger than the machine; times in virtual seconds); with --transport multicast one datagram reaches several robots, as over multicast.", rich_help_panel=LIVE)] = False,
    robots_per_process: Annotated[int, typer.Option(help="With --live: robots each mrmp agent process hosts, each with its own socket, brain and body (udp, multicast, zenoh).", rich_help_panel=LIVE)] = 1,
) -> None:
    """Run a scenario (lockstep simulator, or --live processes) and report what happened."""
    # --resolve, --heading-aware, --radius, --swap and --search come from PolicyOptions' fields (with_policy_flags)
    request = RunRequest(
        None if json_path is None else str(json_path), animate, show_messages, watch, watch_fps, planner, time_limit, live, transport, time_scale,
        delay_ms, jitter, miss_line, results, kill or [], unsafe, goal_lines=goal_lines, colour_by=colour_by, speed=speed,
        record=record, ros2=ros2, lorr_output=lorr_output, virtual_clock=virtual_clock, robots_per_process=robots_per_process,
    )
    console = Console(stderr=request.json_path == "-", highlight=False)
    try:
        scenario = apply_run_options(
            _load(scenario_path, map_path, scen_path, agents, steps),
            policy,
            policy_settings,
            names=FLAG_NAMES,
            loss=loss,
            delay=delay,
            duplicate=duplicate,
            reorder=reorder,
            seed=seed,
            max_ticks=max_ticks,
            safety=False if unsafe else None,
            lifelong=True if lifelong else None,
        )
        _validate_run(scenario, request)
        plan = _plan(planner, scenario, time_limit, console) if planner is not None else None
        step_seconds: list[float] = []
        result = _live_run(scenario, request, plan, console) if live else _simulated_run(scenario, request, plan, console, step_seconds)
    except InputError as error:
        raise _fail(error.problems) from None
    except MrmpError as error:  # e.g. a plan that cannot be executed (PlanDeadlockError)
        Console(stderr=True).print(f"error: {error}", markup=False)
        raise typer.Exit(2) from None
    _output_run(result, scenario, request, console, step_seconds)


@dataclass(frozen=True)
class RunRequest:
    """What ``mrmp run`` was asked to do with its scenario (its options other than the scenario's own)."""

    json_path: str | None
    animate: Path | None
    show_messages: bool
    watch: bool
    watch_fps: float
    planner: str | None
    time_limit: float
    live: bool
    transport: str
    time_scale: float
    delay_ms: str | None
    jitter: float
    miss_line: float
    results: Path | None
    kill: list[str]
    unsafe: bool
    goal_lines: bool = False
    colour_by: str | None = None
    speed: float = 1.0
    record: Path | None = None
    ros2: bool = False
    lorr_output: Path | None = None
    virtual_clock: bool = False
    robots_per_process: int = 1


def _validate_run(scenario: Scenario, request: RunRequest) -> None:
    """Refuse, before anything runs, the combinations of options that cannot be honoured."""
    entry = policy_entry(scenario.policy.name)
    planned = request.planner is not None  # the plan replaces the policy: its limits do not apply
    if scenario.lifelong and planned:
        raise InputError(Problem("--lifelong", "lifelong runs are decentralized: no --planner"))
    if request.unsafe and entry.always_guarded and not planned:
        raise InputError(Problem("--unsafe", f"{entry.name} always enters cells through the safety layer; it has no unsafe form"))
    if request.live and entry.live_driver is None and not planned:
        raise InputError(Problem("--policy", f"{entry.name} {entry.not_live}"))
    body_issue = body_problem(scenario, live=request.live, planned=planned)
    if body_issue is not None:
        raise InputError(body_issue)
    if planned:
        _positive(request.time_limit, "--time-limit", MAX_RUN_SECONDS, "seconds")
    time_scale_checked(request.time_scale)
    if request.live:
        _validate_live(scenario, request)
    if request.animate is not None:
        from mrmp.viz.animate import animation_problem

        animation_issue = animation_problem(request.animate)
        if animation_issue is not None:
            raise InputError(Problem("--animate", animation_issue))
        _check_drawing(request.colour_by, request.speed)
    if request.show_messages:
        written = request.animate is not None or request.json_path is not None
        _check_show_messages(scenario, written, request.live, request.planner is not None)
    if request.record is not None:
        from mrmp.io.ros_export import export_problem

        record_issue = export_problem(request.record)
        if record_issue is not None:
            raise InputError(Problem(str(request.record), record_issue))
    if request.watch and request.live:
        raise InputError(Problem("--watch", "live runs are not drawn in the terminal (--watch is for simulated runs)"))
    if request.lorr_output is not None and scenario.tasks is None:
        raise InputError(Problem("--lorr-output", "writes the run of a LoRR problem (a .json problem file)"))
    if request.lorr_output is not None and not body_model(scenario.policy.body).turns_in_place:
        raise InputError(Problem("--lorr-output", f"LoRR's actions are those of turning bodies, not {scenario.policy.body}"))
    if request.lorr_output is not None and not entry.tick_is_a_step(scenario):
        raise InputError(Problem("--lorr-output", "LoRR's output has one action a step; over a faulty network a step of "
                                 "local sequencing spans several ticks: add --sequencing driver or drop the faults"))  # fmt: skip
    if request.virtual_clock and not request.live:
        raise InputError(Problem("--virtual-clock", "runs a live fleet on a virtual clock: add --live"))
    if request.robots_per_process != 1 and (not request.live or request.virtual_clock):
        raise InputError(Problem("--robots-per-process", "hosts the robots of a live run in processes: add --live (not --virtual-clock)"))
    if request.ros2 and not request.live:
        raise InputError(Problem("--ros2", "publishes the robots of a live run: add --live"))
    if request.ros2:
        _ros2_domain()
    if request.watch:
        _positive(request.watch_fps, "--watch-fps")


def _validate_live(scenario: Scenario, request: RunRequest) -> None:
    """Refuse, before any process starts, what a live run cannot do: too many robots, a results folder that is a file."""
    from mrmp.io.live_files import prepare_folder

    if request.virtual_clock:
        _validate_virtual_clock(scenario, request)
    elif len(scenario.robots) > MAX_LIVE_ROBOTS:
        reason = f"a live run runs at most {MAX_LIVE_ROBOTS} robots on this machine; this scenario has {len(scenario.robots)}"
        raise InputError(Problem("--live", reason))
    live_faults(scenario, request.time_scale, request.delay_ms)
    parse_kills(request.kill)
    if not 1 <= request.robots_per_process <= MAX_LIVE_ROBOTS:
        reason = f"must be 1 to {MAX_LIVE_ROBOTS}, got {request.robots_per_process}"
        raise InputError(Problem("--robots-per-process", reason))
    from mrmp.live.launcher import check_hosting, check_tasks

    planned = request.planner is not None
    check_hosting(request.robots_per_process, request.transport, bool(request.kill), request.ros2)  # before any plan
    check_tasks(scenario, request.transport, planned)
    if request.lorr_output is not None:
        raise InputError(Problem("--lorr-output", "writes a simulated run (LoRR's output has one action a step of every robot)"))
    _fraction(request.jitter, "--jitter")
    _fraction(request.miss_line, "--miss-line")
    if request.results is not None:
        try:
            prepare_folder(request.results)
        except InputError as error:
            raise InputError(Problem("--results", str(error))) from None


def _validate_virtual_clock(scenario: Scenario, request: RunRequest) -> None:
    """Refuse what a live fleet on a virtual clock cannot do: processes to kill, ROS 2, a plan."""
    if len(scenario.robots) > MAX_VIRTUAL_ROBOTS:
        reason = f"runs at most {MAX_VIRTUAL_ROBOTS} robots in one process; this scenario has {len(scenario.robots)}"
        raise InputError(Problem("--virtual-clock", reason))
    for given, flag in ((request.kill, "--kill"), (request.ros2, "--ros2"), (request.planner, "--planner")):
        if given:
            raise InputError(Problem("--virtual-clock", f"runs the fleet's own policy with no processes: not with {flag}"))


def _simulated_run(
    scenario: Scenario, request: RunRequest, plan: PlanningResult | None, console: Console, step_seconds: list[float]
) -> RunResult:
    """Simulate ``scenario`` (following ``plan`` when given), drawn in the terminal with ``--watch``; each tick's
    wall-clock seconds are appended to ``step_seconds``."""
    from mrmp.sim.simulator import records_messages

    recorded = request.record is not None and (plan is not None or records_messages(scenario))  # --record: /mrmp/messages
    record = request.show_messages or recorded
    if plan is not None:
        from mrmp.experiments.execution import execute_in_simulator

        executed_plan = plan

        def start(on_tick: TickObserver | None) -> RunResult:
            return execute_in_simulator(scenario, executed_plan, record_messages=record, on_tick=on_tick)
    else:

        def start(on_tick: TickObserver | None) -> RunResult:
            return simulate(scenario, record_messages=record, on_tick=on_tick)

    def timed_start(on_tick: TickObserver | None) -> RunResult:
        return start(StepTimer(step_seconds, on_tick))

    return _watched(scenario, request.watch_fps if request.watch else None, console, timed_start)


class StepTimer:
    """A tick observer that appends each tick's wall-clock seconds (since the tick before, or since it was made) to a list."""

    def __init__(self, seconds: list[float], then: TickObserver | None) -> None:
        self.seconds = seconds
        self.then = then
        self._last = time.perf_counter()

    def __call__(self, tick: int, cells: list[Cell]) -> None:
        now = time.perf_counter()
        self.seconds.append(now - self._last)
        self._last = now
        if self.then is not None:
            self.then(tick, cells)


def _live_run(scenario: Scenario, request: RunRequest, plan: PlanningResult | None, console: Console) -> RunResult:
    """Run ``scenario`` live: one OS process per robot over a loopback network, its progress shown on a terminal."""
    if request.virtual_clock:
        return _virtual_run(scenario, request, console)
    from mrmp.live.launcher import LiveOptions, run_live

    options = LiveOptions(
        transport=request.transport,
        time_scale=time_scale_checked(request.time_scale),
        faults=live_faults(scenario, request.time_scale, request.delay_ms),
        jitter=_fraction(request.jitter, "--jitter"),
        miss_line=_fraction(request.miss_line, "--miss-line"),
        guarded=scenario.safety,
        results=request.results,
        kill=parse_kills(request.kill),
        seed=scenario.seed,
        plan=plan,
        ros2=request.ros2,
        robots_per_process=request.robots_per_process,
    )
    from mrmp.viz.progress import LiveProgressLine

    with LiveProgressLine(console) as progress:
        return run_live(
            scenario, options, say=lambda text: console.print(text, markup=False),
            on_progress=progress.on_progress if console.is_terminal else None,
        )  # fmt: skip


def _virtual_run(scenario: Scenario, request: RunRequest, console: Console) -> RunResult:
    """Run ``scenario``'s live fleet in this process on a virtual clock (:mod:`mrmp.live.virtual_time`)."""
    import tempfile

    from mrmp.live.virtual_time import VirtualOptions, run_virtual

    results = request.results if request.results is not None else Path(tempfile.mkdtemp(prefix="mrmp-virtual-"))
    options = VirtualOptions(
        results=results,
        time_scale=time_scale_checked(request.time_scale),
        faults=live_faults(scenario, request.time_scale, request.delay_ms),
        jitter=_fraction(request.jitter, "--jitter"),
        seed=scenario.seed,
        multicast=TRANSPORTS.entry(request.transport).delivery.reaches_several,  # the simulated network delivers as it does
    )
    console.print(f"live: {len(scenario.robots)} robots on a virtual clock in this process; results in {results}", markup=False)
    return run_virtual(scenario, options)


def _output_run(
    result: RunResult, scenario: Scenario, request: RunRequest, console: Console, step_seconds: list[float]
) -> None:
    """Print the result, write its JSON, animation and LoRR output as asked, and exit with the run's status."""
    print_result(result, console)
    try:
        if request.json_path is not None:
            write_result_json(result, request.json_path, grid=scenario.grid)
        if request.lorr_output is not None:
            from mrmp.io.lorr_output import write_lorr_output

            write_lorr_output(result, scenario.grid, request.lorr_output, step_seconds)
            console.print(f"LoRR output written to {request.lorr_output}", markup=False)
        if request.animate is not None:
            from mrmp.viz import write_animation

            write_animation(
                scenario.grid, result, request.animate, show_messages=request.show_messages, goal_lines=request.goal_lines,
                colour_by=request.colour_by, speed=request.speed,
            )
            console.print(f"animation written to {request.animate}")
        if request.record is not None:
            from mrmp.io.ros_export import write_ros_export

            kind = write_ros_export(result, scenario.grid, request.record, tick_seconds=result.tick_seconds or scenario.timing.cell_time)
            console.print(f"{kind} written to {request.record}", markup=False)
    except (MrmpError, OSError) as error:
        Console(stderr=True).print(f"error: {error}", markup=False)
        raise typer.Exit(2) from None
    raise typer.Exit(0 if result.success else 1)


@command()
def compare(
    scenario_path: Annotated[Path | None, typer.Argument(metavar="SCENARIO", help="A YAML scenario (or --map and --scen).", show_default=False)] = None,
    map_path: Annotated[Path | None, typer.Option("--map", help="A MovingAI .map file (with --scen).")] = None,
    scen_path: Annotated[Path | None, typer.Option("--scen", help="A MovingAI .scen file (with --map).")] = None,
    agents: Annotated[int | None, typer.Option(help="Robots taken from the .scen.", show_default="all")] = None,
    time_limit: Annotated[float, typer.Option(help="Seconds each central planner may spend.")] = 30.0,
    json_path: Annotated[Path | None, typer.Option("--json", help="Write the rows as JSON (- for stdout).", metavar="PATH|-")] = None,
) -> None:
    """Solve one scenario every way: each decentralized policy, and each central planner plus execution."""
    from mrmp.experiments.compare import compare_methods

    console = Console(stderr=str(json_path) == "-", highlight=False)
    try:
        scenario = _load(scenario_path, map_path, scen_path, agents)
        rows = compare_methods(scenario, time_limit_s=_positive(time_limit, "--time-limit", MAX_RUN_SECONDS, "seconds"))
    except InputError as error:
        raise _fail(error.problems) from None
    table = Table(title=f"{scenario.name}: {len(scenario.robots)} robots, lower bound {rows[0].lower_bound if rows else 0}")
    table.caption = "robots: decentralized policy; central: planner + execution. plan s: planning wall time; plan B: plan to distribute"
    for column in ("method", "kind", "ok", "makespan", "SoC/LB", "plan s", "run s", "msgs", "plan B"):
        table.add_column(column, justify="left" if column in ("method", "kind") else "right")
    for row in rows:
        table.add_row(
            row.method,
            "central" if row.kind == "centralized" else "robots",
            "yes" if row.success else f"[red]no[/red] ({row.status})",
            str(row.makespan) if row.makespan is not None else "-",
            f"{row.cost_ratio:.3f}" if row.cost_ratio is not None else "-",
            f"{row.planning_time_s:.3f}" if row.planning_time_s is not None else "-",
            f"{row.run_time_s:.3f}",
            str(row.messages),
            str(row.plan_bytes) if row.plan_bytes is not None else "-",
        )
    console.print(table)
    if json_path is not None:
        from mrmp.io.live_files import write_json

        rows_data = [row.__dict__ for row in rows]
        if str(json_path) == "-":
            import json

            print(json.dumps(rows_data, indent=1))
        else:
            write_json(json_path, rows_data)


@command()
def report(
    source: Annotated[Path, typer.Argument(metavar="DIR_OR_JSONL", help="A benchmark's --out folder, or its results.jsonl.")],
    out: Annotated[Path, typer.Option(help="The HTML page to write; its plots go to <stem>_plots/ next to it.")] = Path("report.html"),
    title: Annotated[str | None, typer.Option(help="The page's title.", metavar="TEXT", show_default="named after the benchmark")] = None,
    markdown: Annotated[Path | None, typer.Option(help="Also write the headline table as Markdown to this file.")] = None,
) -> None:
    """Write an HTML report of a benchmark: what was run, the headline table, plots, timeouts and errors."""
    from mrmp.bench.aggregate import headline_table, summarize
    from mrmp.io.report_input import read_bench_results
    from mrmp.viz.report_html import write_report

    console = Console(highlight=False)
    try:
        results = read_bench_results(source)
        if not results.records:
            cut = f" ({results.truncated_lines} truncated line set aside)" if results.truncated_lines else ""
            raise InputError(Problem(str(results.path), f"no run record in the file{cut}"))
        files = write_report(results, out, title=title, markdown=markdown)
    except InputError as error:
        raise _fail(error.problems) from None
    summaries = summarize(results.records)
    console.print(f"{len(results.records)} runs from {results.path}", markup=False, soft_wrap=True)
    for map_name in sorted({summary.key.map for summary in summaries}):
        headline = headline_table([summary for summary in summaries if summary.key.map == map_name])
        table = Table(title=map_name, title_justify="left", box=None, pad_edge=False, padding=(0, 1), header_style="bold")
        for index, (column, numeric) in enumerate(zip(headline.columns[1:], headline.numeric[1:]), start=1):
            widest = max(len(row[index]) for row in headline.rows)
            table.add_column(column, justify="right" if numeric else "left", no_wrap=numeric, min_width=min(widest, 14))
        for row in headline.rows:
            table.add_row(*row[1:])
        console.print(table)
    if results.truncated_lines:
        console.print(f"note: the last line of {results.path} was cut short (an interrupted bench); it was set aside", markup=False, soft_wrap=True)
    unfinished = sum(1 for record in results.records if not record.finished)
    if unfinished:
        console.print(f"note: {unfinished} runs timed out or failed; see the report's notes", markup=False, soft_wrap=True)
    console.print(f"report written to {files.html}", markup=False, soft_wrap=True)
    console.print(f"{len(files.plots)} plots written to {files.plots_folder}", markup=False, soft_wrap=True)
    if markdown is not None:
        console.print(f"headline table (Markdown) written to {markdown}", markup=False, soft_wrap=True)


@command("animate")
def animate_command(
    result_path: Annotated[Path, typer.Argument(metavar="RESULT", help="A run saved with mrmp run --json (it holds the map).")],
    out: Annotated[Path, typer.Option("--out", help="The animation to write: .gif, .svg or .mp4 (needs ffmpeg).")],
    show_messages: Annotated[bool, typer.Option("--show-messages", help="Draw each tick's messages (runs saved with them).")] = False,
    goal_lines: Annotated[bool, typer.Option("--goal-lines", help="Draw a line from each robot to its goal.")] = False,
    colour_by: Annotated[str | None, _colour_by_option()] = None,
    speed: Annotated[float, typer.Option(help="Play a live run this many times faster than real time.")] = 1.0,
) -> None:
    """Draw a saved run as an animation."""
    from mrmp.io.results import read_result_json
    from mrmp.viz import animation_problem, write_animation

    console = Console(highlight=False)
    try:
        animation_issue = animation_problem(out)
        if animation_issue is not None:
            raise InputError(Problem("--out", animation_issue))
        _check_drawing(colour_by, speed)
        result, grid = read_result_json(result_path)
        if grid is None:
            raise InputError(Problem(str(result_path), "no map is stored with this run: save it with mrmp run --json"))
        if show_messages and not result.message_log:
            raise InputError(
                Problem(str(result_path), "no messages are recorded in this run: save it with mrmp run --show-messages --json")
            )
    except InputError as error:
        raise _fail(error.problems) from None
    try:
        write_animation(grid, result, out, show_messages=show_messages, goal_lines=goal_lines, colour_by=colour_by, speed=speed)
    except (MrmpError, OSError) as error:
        Console(stderr=True).print(f"error: {error}", markup=False)
        raise typer.Exit(2) from None
    console.print(f"animation written to {out}", markup=False)


@command("export")
def export_command(
    result_path: Annotated[Path, typer.Argument(metavar="RESULT", help="A run saved with mrmp run --json (it holds the map).")],
    out: Annotated[Path, typer.Argument(metavar="OUT", help="OUT.mcap: an MCAP file (Foxglove); OUT.bag or a path without suffix: a rosbag2 folder (ros2 bag play).")],
    tick_seconds: Annotated[float | None, typer.Option(help="Seconds per tick (a simulated run: its scenario's timing.cell_time).", show_default="the run's own (live), else 1")] = None,
    cell_size: Annotated[float, typer.Option(help="Metres per cell: the map's resolution.")] = 1.0,
) -> None:
    """Export a saved run for ROS 2 tools: the map, each robot's poses, path and goal, its messages (docs/ros2.md)."""
    from mrmp.io.results import read_result_json
    from mrmp.io.ros_export import export_problem, write_ros_export

    try:
        out_issue = export_problem(out)
        if out_issue is not None:
            raise InputError(Problem(str(out), out_issue))
        result, grid = read_result_json(result_path)
        if grid is None:
            raise InputError(Problem(str(result_path), "no map is stored with this run: save it with mrmp run --json"))
        kind = write_ros_export(result, grid, out, tick_seconds, cell_size)
    except InputError as error:
        raise _fail(error.problems) from None
    Console(highlight=False).print(f"{kind} written to {out}", markup=False)


@command()
def bench(
    config_path: Annotated[Path, typer.Argument(metavar="CONFIG.yaml", help="A benchmark configuration (see bench/tiny.yaml).")],
    out: Annotated[Path, typer.Option(help="Output folder: results.jsonl (one record per run) and results.csv.")],
    workers: Annotated[int | None, typer.Option(help="Worker processes.", show_default="the number of CPUs")] = None,
    dask: Annotated[str | None, typer.Option(help="Run on this dask.distributed scheduler instead.", metavar="HOST:PORT")] = None,
    time_limit: Annotated[float | None, typer.Option(help="Seconds per run.", show_default="the configuration's time_limit")] = None,
    only_missing: Annotated[
        bool,
        typer.Option(
            "--only-missing",
            help="Count a run whose last record is an error as missing, and run it again. "
            "A bench always resumes: runs with no record are run; without this, runs recorded as errors are kept.",
        ),
    ] = False,
) -> None:
    """Run a benchmark matrix (maps x robots x methods x seeds x faults); resumes where it stopped."""
    from mrmp.bench.runner import run_bench
    from mrmp.bench.summary import summary_rows
    from mrmp.experiments.bench_config import load_bench_config

    console = Console(highlight=False, width=None if sys.stdout.isatty() else 140)
    err = Console(stderr=True, highlight=False, soft_wrap=True)
    try:
        if workers is not None and workers < 1:
            raise InputError(Problem("--workers", f"must be at least 1, got {workers}"))
        if time_limit is not None:
            _positive(time_limit, "--time-limit", MAX_RUN_SECONDS, "seconds")
        config = load_bench_config(config_path, time_limit=time_limit)
        for note in config.notes:
            err.print(f"note: {note}", markup=False)
        if not config.runs:
            raise InputError(Problem(str(config_path), "the matrix has no runs (every combination was left out)"))
        console.print(f"{config.name}: {len(config.runs)} runs, results in {out}", markup=False)
        outcome = run_bench(
            config.runs, out, workers=workers, dask_address=dask, retry_errors=only_missing,
            say=lambda text: err.print(text, markup=False),
        )  # fmt: skip
    except InputError as error:
        raise _fail(error.problems) from None
    table = Table(title=f"{config.name}: {len(outcome.records)} of {outcome.total} runs recorded")
    rows = summary_rows(outcome.records)
    table.add_column("map", min_width=max((len(row.map) for row in rows), default=3))
    tasks = any(row.mean_tasks_finished is not None for row in rows)  # runs of LoRR problems: their score
    for column in ("policy", "N", "runs", "success", "SoC/LB", "wall s", "timeouts", "errors", *(("tasks",) if tasks else ())):
        table.add_column(column, justify="left" if column == "policy" else "right")
    for row in rows:
        table.add_row(
            row.map, row.policy, str(row.agents), str(row.runs), f"{100 * row.success_rate:.0f}%",
            f"{row.mean_soc_over_lb:.3f}" if row.mean_soc_over_lb is not None else "-",
            f"{row.mean_wall_time_s:.2f}" if row.mean_wall_time_s is not None else "-",
            str(row.timeouts), str(row.errors),
            *((f"{row.mean_tasks_finished:.1f}" if row.mean_tasks_finished is not None else "-",) if tasks else ()),
        )  # fmt: skip
    console.print(table)
    console.print(f"results: {out / 'results.jsonl'} and {out / 'results.csv'}", markup=False)
    if outcome.interrupted:
        raise typer.Exit(130)
    if outcome.failure is not None:
        raise typer.Exit(1)


@command()
def validate(
    files: Annotated[list[Path], typer.Argument(metavar="FILE...", help="Scenarios (.yaml), maps (.map) or .scen files.")],
) -> None:
    """Check scenario and map files and report every problem, one per line."""
    problems: list[Problem] = []
    console = Console(highlight=False)
    for path in files:
        found = validate_file(path, known_policies=policy_names())
        if found:
            problems.extend(found)
        else:
            console.print(f"{path}: ok", markup=False)
    if problems:
        raise _fail(problems)


@command()
def agent(
    scenario_path: Annotated[Path | None, typer.Argument(metavar="SCENARIO", help="The fleet's scenario (the same file on every robot).", show_default=False)] = None,
    robot: Annotated[list[str] | None, typer.Option(help="Which robot of the scenario this process is (required); repeat to host several, each with its own socket (udp, multicast).", metavar="ID", show_default=False)] = None,
    policy: Annotated[str | None, typer.Option(help="The decision rule (the same on every robot of the fleet).", metavar=choices(policy_names()), show_default=SCENARIO_DEFAULT, autocompletion=policy_names)] = None,
    transport: Annotated[str, typer.Option(help="How the robots talk.", metavar=choices(TRANSPORTS.names), autocompletion=lambda: list(TRANSPORTS.names))] = "udp",
    bind: Annotated[str, typer.Option(help="UDP: address to receive on.", metavar="HOST:PORT")] = "127.0.0.1:9001",
    peer: Annotated[list[str] | None, typer.Option(help="UDP: a peer (repeat for each).", metavar="ID=HOST:PORT", show_default=False)] = None,
    task_desk: Annotated[str, typer.Option(help="UDP, lifelong runs: the task desk's address (mrmp run --live starts it).", metavar="HOST:PORT", show_default="none")] = "",
    group: Annotated[str, typer.Option(help="Multicast: the group.", metavar="HOST:PORT")] = "239.255.77.1:47000",
    interface: Annotated[str, typer.Option(help="Multicast: IPv4 address of the interface to use.", metavar="IPV4")] = "127.0.0.1",
    listen: Annotated[str, typer.Option(help="Zenoh: this robot's endpoint, e.g. tcp/127.0.0.1:7447.", metavar="ENDPOINT", show_default="none")] = "",
    connect: Annotated[list[str] | None, typer.Option(help="Zenoh: a peer's endpoint (repeat for each; hosting several robots: every robot's, in the scenario's order, and no --listen).", metavar="ENDPOINT", show_default=False)] = None,
    fleet: Annotated[str, typer.Option(help="Zenoh: key-expression prefix of the fleet.", metavar="PREFIX")] = "mrmp",
    key_file: Annotated[Path | None, typer.Option(help="Fleet key file.", show_default="MRMP_FLEET_KEY")] = None,
    session: Annotated[int, typer.Option(help="Run number shared by the fleet; other runs' messages are dropped.")] = 1,
    results: Annotated[Path, typer.Option(help="Folder for this robot's report and trace (mrmp run --live gives each robot its run's folder).")] = Path("results"),
    time_scale: Annotated[float, typer.Option(help="Run this many times faster than the robot's real speed.")] = 1.0,
    jitter: Annotated[float, typer.Option(help="Each move takes its time times 1 +- jitter.")] = 0.0,
    miss_line: Annotated[float, typer.Option(help="Probability that the body misses a grid line.")] = 0.0,
    loss: Annotated[float, typer.Option(help="Inject: probability that a sent message is lost.")] = 0.0,
    delay_ms: Annotated[str, typer.Option(help="Inject: delay of sent messages, in milliseconds.", metavar="N|A..B")] = "0",
    duplicate: Annotated[float, typer.Option(help="Inject: probability that a sent message is duplicated.")] = 0.0,
    reorder: Annotated[float, typer.Option(help="Inject: probability that a sent message is held back.")] = 0.0,
    listen_time: Annotated[float, typer.Option(help="Seconds between announcing Next and deciding.")] = 0.05,
    unsafe: Annotated[bool, typer.Option("--unsafe", help="No safety layer: the policy as written.")] = False,
    no_follow: Annotated[bool, typer.Option("--no-follow", help="A body that turns in place keeps its cell until it has arrived in the next one, so that nobody follows it in (mrmp run --live sets it when it kills robots: a body stopped mid-drive could be driven into).")] = False,
    plan: Annotated[list[Path] | None, typer.Option(help="Follow this robot's share of a central plan (plan-<index>.json); hosting several robots, one per --robot, in the same order.", show_default="none: the policy decides")] = None,
    seed: Annotated[int, typer.Option(help="Seed of the body's and the fault injector's randomness.")] = 0,
    timeout: Annotated[float, typer.Option(help="Give up after this many seconds.")] = 600.0,
    ros2: Annotated[bool, typer.Option("--ros2", help="Publish this robot's pose and state on ROS 2 topics (DDS, domain ROS_DOMAIN_ID; the ros2 extra; docs/ros2.md).")] = False,
    drive: Annotated[str, typer.Option(help="The body: simulated, or ros2 (a robot's ROS 2 driver: Twist on /robot_<id>/cmd_vel, odometry from /robot_<id>/odom; docs/ros2.md).", metavar="simulated|ros2")] = "simulated",
    drive_wait: Annotated[float, typer.Option(help="With --drive ros2: seconds to wait for the driver's first odometry.")] = 30.0,
    scenario_option: Annotated[Path | None, typer.Option("--scenario", hidden=True, help="SCENARIO, as an option.")] = None,
) -> None:
    """Run one robot of a fleet as this process (one command per robot, on its own computer), or several."""
    import dataclasses
    import os

    from mrmp.io.lifetime import die_with_parent
    from mrmp.io.live_files import key_from_environment, read_key_file
    from mrmp.live.agent import AgentTiming
    from mrmp.live.process import AgentOptions, check_key_policy, run_agents, warn
    from mrmp.live.transport import LiveFaults

    die_with_parent()
    try:
        scenario_path = _scenario_argument(scenario_path, scenario_option)
        if not robot:
            raise InputError(Problem("--robot", "give the id of the robot this process is"))
        scenario = apply_run_options(load_scenario(scenario_path, known_policies=policy_names()), policy, names=FLAG_NAMES)
        entry = policy_entry(scenario.policy.name)
        if entry.live_driver is None:
            raise InputError(Problem("--policy", f"{entry.name} {entry.not_live}"))
        plans = plan or []
        body_issue = body_problem(scenario, live=True, planned=bool(plans))
        if body_issue is not None:
            raise InputError(body_issue)
        domain = _ros2_domain() if ros2 else None
        if drive not in ("simulated", "ros2"):
            raise InputError(Problem("--drive", f"must be simulated or ros2, got {drive!r}"))
        if drive == "ros2" and body_model(scenario.policy.body).turns_in_place:
            reason = f"drives the thesis's line-counting body, which does not turn in place ({scenario.policy.body} bodies)"
            raise InputError(Problem("--drive", reason))
        drive_domain = _ros2_domain("--drive") if drive == "ros2" else 0
        ids = [spec.id for spec in scenario.robots]
        for robot_id in robot:
            if robot_id not in ids:
                raise InputError(Problem("--robot", f"no robot has the id {robot_id!r} in {scenario_path}"))
        if len(set(robot)) < len(robot):
            raise InputError(Problem("--robot", "names a robot twice"))
        if len(robot) > 1 and (ros2 or drive != "simulated"):
            raise InputError(Problem("--robot", "one robot per process with --ros2 or --drive ros2"))
        if plans and len(plans) != len(robot):
            reason = f"give one share per --robot, in the same order ({len(robot)} --robot, {len(plans)} --plan)"
            raise InputError(Problem("--plan", reason))
        _check_task_desk(scenario, transport, task_desk, bool(plans))
        transport_values = {
            "bind": bind, "peer": peer, "group": group, "interface": interface, "listen": listen, "connect": connect, "fleet": fleet,
            "task_desk": task_desk,
        }
        specs = TRANSPORTS.hosted(transport, transport_values, ids, robot)
        missing = specs[0].entry.unavailable()
        if missing is not None:
            raise InputError(Problem("--transport", missing))
        key = read_key_file(key_file) if key_file is not None else key_from_environment(os.environ.get("MRMP_FLEET_KEY"))
        for spec in specs:
            key = check_key_policy(key, spec, warn)
        low, high = parse_range_ms(delay_ms, "--delay-ms")
        common = AgentOptions(
            index=0,
            transport=specs[0],
            key=key,
            session=session,
            results=results,
            time_scale=time_scale_checked(time_scale),
            faults=LiveFaults(_fraction(loss, "--loss"), low, high, _fraction(duplicate, "--duplicate"), _fraction(reorder, "--reorder")),
            jitter=_fraction(jitter, "--jitter"),
            miss_line=_fraction(miss_line, "--miss-line"),
            guarded=not unsafe and scenario.safety,
            follow=not no_follow,
            seed=seed,
            timing=AgentTiming(
                listen_time=_not_negative(listen_time, "--listen-time", MAX_STEP_SECONDS),
                timeout=_positive(timeout, "--timeout", MAX_RUN_SECONDS, "seconds"),
            ),
            ros2_domain=domain,
            drive=drive,
            drive_domain=drive_domain,
            drive_wait=_positive(drive_wait, "--drive-wait", MAX_RUN_SECONDS, "seconds"),
        )
        if plans:
            from mrmp.io.plans import read_share

            for robot_id, share in zip(robot, plans, strict=True):
                read_share(share, robot_id)  # a bad share is bad input: report it before any socket opens
        hosted = [
            dataclasses.replace(common, index=ids.index(robot_id), transport=spec, plan=plans[number] if plans else None)
            for number, (robot_id, spec) in enumerate(zip(robot, specs, strict=True))
        ]
        reports = run_agents(scenario, hosted)  # an address that cannot be used is bad input too
    except InputError as error:
        raise _fail(error.problems) from None
    raise typer.Exit(0 if all(report.arrived for report in reports) else 1)



def _check_task_desk(scenario: Scenario, transport: str, task_desk: str, planned: bool) -> None:
    """Refuse a lifelong robot without its task desk, or one whose policy or transport cannot reach a desk, and a
    desk for a robot that is not lifelong."""
    from mrmp.live.launcher import check_task_taker

    if not scenario.lifelong:
        if task_desk:
            raise InputError(Problem("--task-desk", "a task desk serves a lifelong run (lifelong: true)"))
        return
    check_task_taker(scenario, transport, planned)
    if not task_desk:
        raise InputError(Problem("--task-desk", "a lifelong robot takes its tasks from a task desk: give its HOST:PORT"))


def _ros2_domain(option: str = "--ros2") -> int:
    """The ROS 2 domain that ``option`` (``--ros2``, ``--drive ros2``) uses (``ROS_DOMAIN_ID``), once its package is there."""
    import os

    from mrmp.live.ros2_topics import DOMAIN_VARIABLE, ros2_domain, ros2_problem

    missing = ros2_problem()
    if missing is not None:
        raise InputError(Problem(option, missing))
    try:
        return ros2_domain(os.environ)
    except ValueError as error:
        raise InputError(Problem(DOMAIN_VARIABLE, str(error).removeprefix(f"{DOMAIN_VARIABLE}: "))) from None


@command()
def referee(
    scenario_path: Annotated[Path | None, typer.Argument(metavar="SCENARIO", help="The fleet's scenario.", show_default=False)] = None,
    results: Annotated[Path, typer.Option(help="The folder the robots wrote (or write) their traces to.")] = Path("results"),
    start_time: Annotated[
        float | None,
        typer.Option(help="The run's start on this machine's monotonic clock (collision ticks count milliseconds from it).", show_default="the traces' first event"),
    ] = None,
    done_file: Annotated[
        Path | None,
        typer.Option(help="Follow the traces as they grow, until this file appears.", show_default="none: judge the traces as they are and stop"),
    ] = None,
    scenario_option: Annotated[Path | None, typer.Option("--scenario", hidden=True, help="SCENARIO, as an option.")] = None,
) -> None:
    """Judge a run from the robots' ground-truth traces: as they are, or following them until told to stop."""
    from mrmp.io.lifetime import die_with_parent
    from mrmp.live.process import run_referee, stop_on_signals, warn

    stop = stop_on_signals()  # first: a stop (or its parent's end) from now on still writes the verdict
    die_with_parent()
    try:
        scenario = load_scenario(_scenario_argument(scenario_path, scenario_option), known_policies=policy_names())
        if not results.is_dir():
            raise InputError(Problem("--results", f"no such folder: {results}"))
    except InputError as error:
        raise _fail(error.problems) from None
    collisions = run_referee(scenario, results, start_time, done_file, warn, stop=stop)
    if done_file is None:  # by hand: say what was found (beside a live run, the launcher reports)
        found = f"{len(collisions)} collision{'' if len(collisions) == 1 else 's'}"
        Console(highlight=False).print(f"{found}; verdict written to {results / 'referee.json'}", markup=False)
    raise typer.Exit(1 if collisions else 0)


def _scenario_argument(argument: Path | None, option: Path | None) -> Path:
    """The scenario named by the ``SCENARIO`` argument, or by ``--scenario`` (the same, spelled as an option)."""
    if argument is not None and option is not None:
        raise InputError(Problem("--scenario", "give the scenario once: as SCENARIO or as --scenario"))
    if argument is None and option is None:
        raise InputError(Problem("SCENARIO", "give the fleet's scenario file"))
    return argument if argument is not None else option  # type: ignore[return-value]


def main() -> None:
    """Entry point of the ``mrmp`` command."""
    from mrmp.io.lifetime import interrupt_on_stop_signals

    interrupt_on_stop_signals()  # SIGTERM keeps what was computed, as Ctrl-C does
    try:
        app(prog_name="mrmp")  # also under python -m mrmp: its help, and its shell completion's variable, _MRMP_COMPLETE
    except KeyboardInterrupt:
        sys.exit(130)
