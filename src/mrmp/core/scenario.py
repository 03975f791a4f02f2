"""Scenarios: a grid, robots with starts and goals, timing, network faults, policy options.

A :class:`Scenario` is plain data; files become scenarios in :mod:`mrmp.io`.
:func:`scenario_problems` checks the meaning of a scenario (cells on the grid,
not on obstacles, no shared starts or goals, reachable goals) and names each
problem by its field path, which the I/O layer turns into a file and line.

Examples
--------
>>> from mrmp.core.grid import Grid, connected_regions
>>> swap = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))))
>>> [robot.heading.name for robot in swap.robots]
['NORTH', 'NORTH']
>>> scenario_problems(swap)
[]
>>> bad = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (9, 2)),))
>>> [str(problem) for problem in scenario_problems(bad)]
['robots[0].goal: cell (9, 2) is outside the 5x5 grid']
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from mrmp.core.cell import Cell
from mrmp.core.errors import Problem
from mrmp.core.grid import Grid, connected_regions
from mrmp.core.heading import Heading
from mrmp.core.limits import MAX_DELAY_TICKS, MAX_ROBOTS, MAX_STEP_SECONDS, MAX_TICKS, at_most
from mrmp.core.options import (
    RESOLUTIONS,
    body_setting,
    check_settings,
    guidance_setting,
    heading_aware_setting,
    radius_setting,
    resolve_setting,
    search_setting,
    sequencing_setting,
    swap_setting,
    synchronizer_setting,
)
from mrmp.core.tasks import TaskStream, task_problems

__all__ = [
    "RESOLUTIONS",
    "LinkFaults",
    "NetworkFaults",
    "PolicyOptions",
    "RobotSpec",
    "Scenario",
    "Timing",
    "scenario_problems",
]


@dataclass(frozen=True)
class RobotSpec:
    """One robot of a scenario: its name, start, goal and initial heading.

    The thesis's robots always start facing NORTH (section 3.2, assumption 1).
    """

    id: str
    start: Cell
    goal: Cell
    heading: Heading = Heading.NORTH


@dataclass(frozen=True)
class Timing:
    """How long the robot's body takes: one cell (``cell_time``), one right turn (``turn_time``), in seconds."""

    cell_time: float = 1.0
    turn_time: float = 0.5


@dataclass(frozen=True)
class NetworkFaults:
    """Faults of the simulated network, applied independently to every message on every link.

    ``loss``, ``duplicate`` and ``reorder`` are probabilities; a message's delay
    is drawn uniformly from ``delay_min .. delay_max`` ticks (0 means delivered
    within the tick it was sent).
    """

    loss: float = 0.0
    delay_min: int = 0
    delay_max: int = 0
    duplicate: float = 0.0
    reorder: float = 0.0

    @property
    def is_perfect(self) -> bool:
        """Whether the network delivers every message once, at once, in order."""
        return self == NetworkFaults()


@dataclass(frozen=True)
class LinkFaults:
    """Faults of one directed link, from robot ``sender`` to robot ``recipient`` (by id)."""

    sender: str
    recipient: str
    faults: NetworkFaults


@dataclass(frozen=True)
class PolicyOptions:
    """A scenario's ``policy`` section: which decision rule robots run, and every policy setting.

    ``resolve`` chooses the thesis's two collision-avoidance techniques
    (section 2.1); ``search`` the single-robot search of the per-robot
    policies (``default``: each policy's own); ``heading_aware`` makes planners charge turns (``pibt``:
    prefer fewer turns among equally near cells). ``radius`` (cells,
    Manhattan, at least 2) is how far a ``pibt`` robot's beacon reaches;
    ``swap`` turns on ``pibt``'s swap technique. Each setting is declared by
    its field function in :mod:`mrmp.core.options` (help, YAML key, flag,
    check); the settings are checked when the options are built. Each policy
    takes the settings it reads into its own options type (the policy table,
    :mod:`mrmp.sim.policy_table`).

    >>> PolicyOptions(name="pibt", radius=1)
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: policy.radius: must be at least 2 (cells), got 1
    """

    name: str = "thesis"
    resolve: str = resolve_setting()
    heading_aware: bool = heading_aware_setting()
    radius: int = radius_setting()
    swap: bool = swap_setting()
    search: str = search_setting()
    sequencing: str = sequencing_setting()
    synchronizer: str = synchronizer_setting()
    body: str = body_setting()
    guidance: str = guidance_setting()

    def __post_init__(self) -> None:
        check_settings(self)


@dataclass(frozen=True)
class Scenario:
    """Everything a run needs to start: world, robots and settings.

    ``safety`` turns on the safety layer that guards every move
    (:mod:`mrmp.protocol.safety`); ``False`` runs the policy as written.
    ``lifelong``: a robot that reaches its goal receives a new one (drawn with
    the seed, or, with ``tasks``, its next errand or a task from the stream's
    scheduler: :mod:`mrmp.core.tasks`), and the run lasts until its tick limit.
    """

    grid: Grid
    robots: tuple[RobotSpec, ...]
    timing: Timing = field(default_factory=Timing)
    network: NetworkFaults = field(default_factory=NetworkFaults)
    links: tuple[LinkFaults, ...] = ()
    policy: PolicyOptions = field(default_factory=PolicyOptions)
    safety: bool = True
    lifelong: bool = False
    tasks: TaskStream | None = None
    seed: int = 0
    max_ticks: int | None = None
    name: str = ""
    description: str = ""

    def with_changes(self, **changes: object) -> Scenario:
        """A copy with some fields replaced (a frozen dataclass ``replace``)."""
        return replace(self, **changes)  # type: ignore[arg-type]

    @property
    def perfect_network(self) -> bool:
        """Whether the simulators deliver every message at once and once: no fault on the network and no link
        with faults of its own (any link counts, as the simulators keep a faulty network's bookkeeping for it).

        >>> from mrmp.core.grid import Grid
        >>> Scenario(Grid(1, 1), ()).perfect_network, Scenario(Grid(1, 1), (), network=NetworkFaults(loss=0.1)).perfect_network
        (True, False)
        """
        return self.network.is_perfect and not self.links

    def worst_faults(self) -> NetworkFaults:
        """The worst loss, delay, duplication and reordering over the network and all its links.

        >>> from mrmp.core.grid import Grid, connected_regions
        >>> scenario = Scenario(Grid(2, 2), (), network=NetworkFaults(loss=0.1),
        ...                     links=(LinkFaults("A", "B", NetworkFaults(delay_max=3)),))
        >>> scenario.worst_faults()
        NetworkFaults(loss=0.1, delay_min=0, delay_max=3, duplicate=0.0, reorder=0.0)
        """
        every = [self.network, *(link.faults for link in self.links)]
        return NetworkFaults(
            loss=max(faults.loss for faults in every),
            delay_min=min(faults.delay_min for faults in every),
            delay_max=max(faults.delay_max for faults in every),
            duplicate=max(faults.duplicate for faults in every),
            reorder=max(faults.reorder for faults in every),
        )

    def robot(self, robot_id: str) -> RobotSpec:
        """The robot named ``robot_id``.

        Raises
        ------
        KeyError
            If no robot has that name.
        """
        for robot in self.robots:
            if robot.id == robot_id:
                return robot
        raise KeyError(robot_id)


def _fault_problems(faults: NetworkFaults, where: str) -> list[Problem]:
    problems = []
    for name in ("loss", "duplicate", "reorder"):
        value = getattr(faults, name)
        if not 0.0 <= value <= 1.0:
            problems.append(Problem(f"{where}.{name}", f"must be a probability in [0, 1], got {value}"))
    if faults.delay_min < 0 or faults.delay_max < faults.delay_min:
        problems.append(
            Problem(f"{where}.delay", f"must be a range 0 <= min <= max ticks, got {faults.delay_min}..{faults.delay_max}")
        )
    elif faults.delay_max > MAX_DELAY_TICKS:
        problems.append(Problem(f"{where}.delay", f"must be at most {MAX_DELAY_TICKS} ticks, got {faults.delay_max}"))
    return problems


def _timing_problems(timing: Timing) -> list[Problem]:
    """``cell_time`` positive, ``turn_time`` not negative, both finite and at most :data:`MAX_STEP_SECONDS`.

    >>> [str(problem) for problem in _timing_problems(Timing(cell_time=float("inf")))]
    ['timing.cell_time: must be at most 3600 seconds, got inf']
    """
    problems = []
    if not timing.cell_time > 0:
        problems.append(Problem("timing.cell_time", f"must be positive, got {timing.cell_time}"))
    if not timing.turn_time >= 0:
        problems.append(Problem("timing.turn_time", f"must not be negative, got {timing.turn_time}"))
    for name in ("cell_time", "turn_time"):
        value = getattr(timing, name)
        reason = at_most(value, MAX_STEP_SECONDS, "seconds") if value >= 0 else None
        if reason is not None:
            problems.append(Problem(f"timing.{name}", reason))
    return problems


def task_stream_problems(scenario: Scenario) -> list[Problem]:
    """Every problem with ``scenario``'s task stream (:func:`~mrmp.core.tasks.task_problems`), and one if the run
    that has it is not lifelong; none without a stream."""
    if scenario.tasks is None:
        return []
    problems = task_problems(scenario.tasks, scenario.grid)
    if not scenario.lifelong:
        problems.append(Problem("tasks", "a task stream needs a lifelong run"))
    return problems


def scenario_problems(scenario: Scenario) -> list[Problem]:
    """Every problem with the meaning of ``scenario``, each named by its field path.

    Checks: robots present (at most :data:`~mrmp.core.limits.MAX_ROBOTS`), unique
    ids, starts and goals on the grid and free, no two robots sharing a start or
    a goal, each goal reachable from its start, timing, fault values and tick
    limit in range (:mod:`mrmp.core.limits`), links between existing robots.
    """
    problems: list[Problem] = []
    grid = scenario.grid
    size = f"{grid.x_size}x{grid.y_size}"
    if not scenario.robots:
        problems.append(Problem("robots", "a scenario needs at least one robot"))
    if len(scenario.robots) > MAX_ROBOTS:
        problems.append(Problem("robots", f"a scenario has at most {MAX_ROBOTS} robots, this one has {len(scenario.robots)}"))
        return problems
    seen_ids: dict[str, int] = {}
    seen_starts: dict[Cell, int] = {}
    seen_goals: dict[Cell, int] = {}
    labels: dict[Cell, int] | None = None
    for index, robot in enumerate(scenario.robots):
        where = f"robots[{index}]"
        if robot.id in seen_ids:
            problems.append(Problem(f"{where}.id", f"id {robot.id!r} is already used by robots[{seen_ids[robot.id]}]"))
        else:
            seen_ids[robot.id] = index
        endpoints_ok = True
        for kind, cell, seen in (("start", robot.start, seen_starts), ("goal", robot.goal, seen_goals)):
            if not grid.in_bounds(cell):
                problems.append(Problem(f"{where}.{kind}", f"cell {cell} is outside the {size} grid"))
                endpoints_ok = False
            elif grid.is_blocked(cell):
                problems.append(Problem(f"{where}.{kind}", f"cell {cell} is an obstacle"))
                endpoints_ok = False
            elif cell in seen:
                problems.append(Problem(f"{where}.{kind}", f"cell {cell} is also the {kind} of robots[{seen[cell]}]"))
            else:
                seen[cell] = index
        if endpoints_ok:
            if labels is None:
                labels = connected_regions(grid, grid.free_cells())[0]
            if labels[robot.start] != labels[robot.goal]:
                problems.append(Problem(f"{where}.goal", f"cell {robot.goal} cannot be reached from start {robot.start}"))
    problems.extend(_timing_problems(scenario.timing))
    problems.extend(_fault_problems(scenario.network, "network"))
    for index, link in enumerate(scenario.links):
        where = f"network.links[{index}]"
        for end, robot_id in (("from", link.sender), ("to", link.recipient)):
            if robot_id not in seen_ids:
                problems.append(Problem(f"{where}.{end}", f"no robot has the id {robot_id!r}"))
        if link.sender == link.recipient:
            problems.append(Problem(f"{where}.to", "a link joins two different robots"))
        problems.extend(_fault_problems(link.faults, where))
    problems.extend(task_stream_problems(scenario))
    if scenario.max_ticks is not None and scenario.max_ticks <= 0:
        problems.append(Problem("max_ticks", f"must be positive, got {scenario.max_ticks}"))
    elif scenario.max_ticks is not None and scenario.max_ticks > MAX_TICKS:
        problems.append(Problem("max_ticks", f"must be at most {MAX_TICKS}, got {scenario.max_ticks}"))
    return problems
