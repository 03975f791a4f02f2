"""mrmp from Python: load a scenario, run it, look at the result, draw it.

The three functions here are what ``mrmp run`` does, without the command
line: :func:`load` reads a YAML scenario or a MovingAI map and ``.scen``,
:func:`run` simulates it (with a decentralized policy, or executing a central
planner's plan) and returns a :class:`Result`, and :func:`animate` draws that
result. A :class:`Result` shows its summary and an animation of the run in a
Jupyter notebook. ``docs/python.md`` walks through a session.

>>> import mrmp
>>> result = mrmp.run("examples/thesis-swap.yaml")
>>> result.success, result.makespan, result.collisions
(True, 6, 0)
>>> mrmp.run("examples/thesis-swap.yaml", policy="astar", loss=0.2, seed=4).success
True
"""

from __future__ import annotations

import html
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mrmp.centralized.plan import PlanningResult
from mrmp.centralized.registry import PLANNER_NAMES, plan_with
from mrmp.core.errors import InputError, Problem
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.experiments.execution import execute_in_simulator
from mrmp.experiments.run_options import FIELD_NAMES, NETWORK_OPTIONS, POLICY_SETTINGS, SCENARIO_OPTIONS, apply_run_options
from mrmp.io import load_movingai_scenario, load_scenario, write_result_json
from mrmp.io.lorr import is_lorr_problem, load_lorr_scenario
from mrmp.io.results import result_to_dict
from mrmp.sim.policy_table import policy_names
from mrmp.sim.simulator import simulate
from mrmp.viz import write_animation
from mrmp.viz.svg import svg_text

ScenarioSource = Scenario | str | os.PathLike[str]
"""A scenario, or the path of a YAML scenario file."""



def load(path: str | os.PathLike[str], scen: str | os.PathLike[str] | None = None, agents: int | None = None) -> Scenario:
    """The scenario in a YAML file, a League of Robot Runners problem (``.json``: a lifelong run of its task
    stream, :func:`mrmp.io.lorr.lorr_scenario`), or a MovingAI map with the first ``agents`` robots of ``scen``.

    Raises :class:`~mrmp.core.errors.InputError` naming the file, line and
    field of every problem found.

    >>> import mrmp
    >>> scenario = mrmp.load("examples/thesis-swap.yaml")
    >>> scenario.grid.x_size, [robot.id for robot in scenario.robots]
    (5, ['A', 'B'])
    >>> len(mrmp.load("maps/random-32-32-20.map", scen="maps/random-32-32-20-random-1.scen", agents=20).robots)
    20
    >>> lorr = mrmp.load("examples/lorr/maze-example_40.json")
    >>> len(lorr.robots), lorr.policy.body, lorr.max_ticks
    (40, 'turning', 5000)
    """
    if scen is None:
        if agents is not None:
            raise InputError(Problem("agents", "robots are chosen from a .scen file: give scen too"))
        if is_lorr_problem(path):
            return load_lorr_scenario(path)
        return load_scenario(Path(path), known_policies=policy_names())
    if agents is not None and agents <= 0:
        raise InputError(Problem("agents", f"must be positive, got {agents}"))
    return load_movingai_scenario(Path(path), Path(scen), agents)


def with_options(scenario: Scenario, policy: str | None = None, **options: Any) -> Scenario:
    """``scenario`` with a policy, its settings, network faults and run options replaced.

    ``options`` are the policy settings (``resolve``, ``heading_aware``, ...:
    the fields of :class:`~mrmp.core.scenario.PolicyOptions`), the network
    faults ``loss``, ``duplicate``, ``reorder`` and ``delay`` (ticks: a number
    or a ``(low, high)`` pair), and ``seed``, ``max_ticks``, ``safety`` and
    ``lifelong``. ``None`` leaves a value as the scenario has it.

    >>> scenario = with_options(load("examples/thesis-swap.yaml"), policy="astar", delay=(0, 2), seed=3)
    >>> scenario.policy.name, scenario.network.delay_max, scenario.seed
    ('astar', 2, 3)
    >>> with_options(scenario, speed=2)
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: speed: unknown option; known: resolve, heading_aware, ...
    """
    given = {key: value for key, value in options.items() if value is not None}
    unknown = sorted(set(given) - set(POLICY_SETTINGS) - set(NETWORK_OPTIONS) - set(SCENARIO_OPTIONS) - {"delay"})
    if unknown:
        known = ", ".join((*POLICY_SETTINGS, *NETWORK_OPTIONS, "delay", *SCENARIO_OPTIONS))
        raise InputError([Problem(key, f"unknown option; known: {known}") for key in unknown])
    settings = {key: given.pop(key) for key in POLICY_SETTINGS if key in given}
    return apply_run_options(scenario, policy, settings, names=FIELD_NAMES, **given)


def run(
    scenario: ScenarioSource,
    policy: str | None = None,
    planner: str | None = None,
    time_limit: float = 30.0,
    record_messages: bool = False,
    **options: Any,
) -> Result:
    """Simulate ``scenario`` in the lockstep simulator (``mrmp run`` without ``--live``).

    Parameters
    ----------
    scenario:
        A :class:`~mrmp.core.scenario.Scenario` or the path of a YAML scenario.
    policy:
        The decentralized policy every robot runs (default: the scenario's).
    planner:
        A central planner (``cbs``, ``pp``, ``lacam``): plan first, then the
        robots execute the plan through its action dependencies.
    time_limit:
        Seconds the planner may spend.
    record_messages:
        Keep each tick's messages (drawn by ``animate(..., show_messages=True)``).
    **options:
        Policy settings, network faults and run options, as
        :func:`with_options` takes them.

    Raises :class:`~mrmp.core.errors.InputError` for a bad scenario or option,
    and :class:`ValueError` when the planner finds no plan.

    >>> result = run("examples/thesis-swap.yaml", planner="cbs")
    >>> result.success, result.plan is not None
    (True, True)
    """
    if planner is not None and planner not in PLANNER_NAMES:
        raise InputError(Problem("planner", f"unknown planner {planner!r}; known: {', '.join(PLANNER_NAMES)}"))
    if not time_limit > 0:
        raise InputError(Problem("time_limit", f"must be positive, got {time_limit}"))
    loaded = scenario if isinstance(scenario, Scenario) else load(scenario)
    configured = with_options(loaded, policy, **options)
    if planner is None:
        return Result(simulate(configured, record_messages=record_messages), configured)
    plan = plan_with(planner, configured, time_limit_s=time_limit)
    if not plan.solved:
        raise ValueError(f"{planner}: no plan ({plan.status}: {plan.message}) after {plan.planning_time_s:.2f} s")
    return Result(execute_in_simulator(configured, plan, record_messages=record_messages), configured, plan)


def animate(
    result: Result,
    path: str | os.PathLike[str],
    show_messages: bool = False,
    goal_lines: bool = False,
    colour_by: str | None = None,
    speed: float = 1.0,
) -> Path:
    """Write ``result`` as an animation, GIF, SVG or MP4 by ``path``'s suffix; returns the path written.

    The options are those of ``mrmp run --animate``: ``show_messages``
    draws each tick's messages (a run made with ``record_messages=True``),
    ``goal_lines`` a line from each robot to its goal, ``colour_by`` colours
    the robots by ``"robot"``, ``"progress"`` or ``"heading"`` (by default
    ``"robot"`` for a few robots, ``"progress"`` for a crowd), and ``speed``
    plays a live run that many times faster than real time.

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> animate(run("examples/thesis-swap.yaml"), folder / "swap.svg").suffix
    '.svg'
    >>> drawn = animate(run("examples/thesis-swap.yaml"), folder / "lines.svg", goal_lines=True, colour_by="heading")
    >>> text = drawn.read_text()
    >>> 'id="goal-lines"' in text, 'facing north' in text
    (True, True)
    >>> animate(run("examples/thesis-swap.yaml"), folder / "x.svg", colour_by="rainbow")
    Traceback (most recent call last):
    ...
    ValueError: colour_by must be one of robot, progress, heading, got 'rainbow'
    """
    return write_animation(
        result.scenario.grid, result.run, path,
        show_messages=show_messages, goal_lines=goal_lines, colour_by=colour_by, speed=speed,
    )  # fmt: skip


@dataclass(frozen=True)
class Result:
    """A simulated run, with the scenario it ran and the plan it executed (if any).

    ``run`` has everything the run produced (robots' paths, collisions,
    network counts); the properties below are its headline figures.

    >>> result = run("examples/thesis-swap.yaml")
    >>> result
    Result(thesis-swap: success, makespan 6, sum of costs 10, lower bound 8, collisions 0, messages 57)
    >>> "<svg" in result._repr_html_() and "sum of costs" in result._repr_html_()
    True
    """

    run: RunResult
    scenario: Scenario
    plan: PlanningResult | None = None

    @property
    def success(self) -> bool:
        """Every robot arrived and the referee found no collision."""
        return self.run.success

    @property
    def makespan(self) -> int:
        """Ticks until the last robot settled at its goal."""
        return self.run.makespan

    @property
    def sum_of_costs(self) -> int:
        """Ticks until each robot settled, summed over the robots."""
        return self.run.sum_of_costs

    @property
    def lower_bound(self) -> int:
        """The sum of the robots' shortest path lengths."""
        return self.run.lower_bound

    @property
    def collisions(self) -> int:
        """Vertex and swap collisions the referee found."""
        return len(self.run.collisions)

    @property
    def messages(self) -> int:
        """Messages the robots sent."""
        return self.run.messages

    def summary(self) -> dict[str, object]:
        """The headline figures as a dictionary (planner runs add the plan's own cost).

        >>> run("examples/thesis-swap.yaml").summary()["stop reason"]
        'all arrived'
        """
        figures: dict[str, object] = {
            "scenario": self.run.scenario,
            "policy": self.run.policy,
            "success": self.success,
            "stop reason": self.run.stop_reason,
            "makespan": self.makespan,
            "sum of costs": self.sum_of_costs,
            "lower bound": self.lower_bound,
            "collisions": self.collisions,
            "messages": self.messages,
            "wall time (s)": round(self.run.wall_time_s, 3),
        }
        if self.plan is not None:
            figures["plan sum of costs"] = self.plan.sum_of_costs()
            figures["plan makespan"] = self.plan.makespan()
        return figures

    def to_dict(self) -> dict[str, Any]:
        """The result's JSON form, as ``mrmp run --json`` writes it."""
        return result_to_dict(self.run, grid=self.scenario.grid)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the result's JSON form to ``path`` (``mrmp report`` and ``mrmp animate`` read it)."""
        write_result_json(self.run, os.fspath(path), grid=self.scenario.grid)

    def __repr__(self) -> str:
        outcome = "success" if self.success else f"failure ({self.run.stop_reason})"
        return (
            f"Result({self.run.scenario}: {outcome}, makespan {self.makespan}, sum of costs {self.sum_of_costs}, "
            f"lower bound {self.lower_bound}, collisions {self.collisions}, messages {self.messages})"
        )

    def _repr_html_(self) -> str:
        """The summary as a table and the run as an inline animated SVG (Jupyter)."""
        rows = "".join(
            f"<tr><th style='text-align:left'>{html.escape(key)}</th><td>{html.escape(str(value))}</td></tr>"
            for key, value in self.summary().items()
        )
        picture = svg_text(self.scenario.grid, self.run)
        return f"<div><table>{rows}</table>{picture}</div>"
