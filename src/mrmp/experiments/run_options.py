"""A scenario with a run's options applied: policy and its settings, network faults, seed, tick limit, safety, lifelong.

``mrmp run``'s options and :func:`mrmp.with_options`'s keyword arguments are
the same settings; :func:`apply_run_options` applies them for both, and
gathers every problem found before raising. The two differ only in how they
name the fields in their errors (``--policy`` on the command line, ``policy``
in Python): :class:`OptionNames` says which.

>>> from mrmp.io import load_scenario
>>> scenario = apply_run_options(load_scenario("examples/thesis-swap.yaml"), "astar", delay="0..2", seed=3)
>>> scenario.policy.name, (scenario.network.delay_min, scenario.network.delay_max), scenario.seed
('astar', (0, 2), 3)
>>> apply_run_options(scenario, "teleport", names=FLAG_NAMES)
Traceback (most recent call last):
...
mrmp.core.errors.InputError: --policy: unknown policy 'teleport'; known: thesis, astar, pibt, causal
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any

from mrmp.core.errors import InputError, Problem
from mrmp.core.scenario import PolicyOptions, Scenario, scenario_problems
from mrmp.sim.policy_table import policy_names

NETWORK_OPTIONS = ("loss", "duplicate", "reorder")
"""Options that replace a network fault of the same name."""
SCENARIO_OPTIONS = ("seed", "max_ticks", "safety", "lifelong")
"""Options that replace a scenario field of the same name."""
POLICY_SETTINGS = tuple(field.name for field in fields(PolicyOptions) if field.name != "name")
"""The policy's settings (``resolve``, ``heading_aware``, ...): the fields of :class:`PolicyOptions` but its name."""


@dataclass(frozen=True)
class OptionNames:
    """How the fields that :func:`apply_run_options` checks itself are named in its errors."""

    policy: str = "policy"
    delay: str = "delay"


FIELD_NAMES = OptionNames()
"""Python's names (:func:`mrmp.with_options`)."""
FLAG_NAMES = OptionNames(policy="--policy", delay="--delay")
"""The command line's names (``mrmp run``)."""


def parse_range(text: str, option: str, unit: str = "ticks", whole: bool = True) -> tuple[float, float]:
    """Read ``N`` or ``A..B`` (whole numbers when ``whole``), with ``0 <= A <= B``.

    >>> parse_range("0..3", "--delay"), parse_range("2", "--delay")
    ((0, 3), (2, 2))
    >>> parse_range("20..80", "--delay-ms", "milliseconds", whole=False)
    (20.0, 80.0)
    """
    low, separator, high = text.partition("..")
    number = int if whole else float
    try:
        bounds = (number(low), number(high)) if separator else (number(low), number(low))
    except ValueError:
        raise InputError(Problem(option, f"expected N or A..B {unit}, got {text!r}")) from None
    if not 0 <= bounds[0] <= bounds[1]:
        raise InputError(Problem(option, f"expected 0 <= A <= B {unit}, got {text!r}"))
    return bounds


def delay_range(delay: object, option: str = "delay") -> tuple[int, int]:
    """A delay in ticks as a ``(low, high)`` pair: from ``N``, a pair ``(A, B)``, or the text ``"N"`` or ``"A..B"``.

    >>> delay_range(2), delay_range((0, 3)), delay_range("1..4", "--delay")
    ((2, 2), (0, 3), (1, 4))
    >>> delay_range((3, 1))
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: delay: expected ticks N or (A, B) with 0 <= A <= B, got (3, 1)
    """
    if isinstance(delay, str):
        low, high = parse_range(delay, option)
        return int(low), int(high)
    pair = tuple(delay) if isinstance(delay, tuple | list) and len(delay) == 2 else (delay, delay)
    bounds = [value for value in pair if isinstance(value, int) and not isinstance(value, bool)]
    if not (len(bounds) == 2 and 0 <= bounds[0] <= bounds[1]):
        raise InputError(Problem(option, f"expected ticks N or (A, B) with 0 <= A <= B, got {delay!r}"))
    return bounds[0], bounds[1]


def apply_run_options(
    scenario: Scenario,
    policy: str | None = None,
    policy_settings: dict[str, Any] | None = None,
    names: OptionNames = FIELD_NAMES,
    **options: Any,
) -> Scenario:
    """``scenario`` with ``policy``, its ``policy_settings`` and the run ``options`` given (not None) applied.

    ``options`` are the network faults ``loss``, ``duplicate``, ``reorder``
    and ``delay`` (see :func:`delay_range`), and ``seed``, ``max_ticks``,
    ``safety`` and ``lifelong``; ``policy_settings`` maps fields of
    :class:`PolicyOptions` to values. Every problem found (an unknown policy,
    a bad setting, and :func:`scenario_problems` of the result) is raised in
    one :class:`InputError`, the fields checked here named as ``names`` says.

    >>> from mrmp.io import load_scenario
    >>> apply_run_options(load_scenario("examples/thesis-swap.yaml"), policy_settings={"radius": 1}, loss=2.0)
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: network.loss: must be a probability in [0, 1], got 2.0
    policy.radius: must be at least 2 (cells), got 1
    """
    given = {key: value for key, value in options.items() if value is not None}
    unknown = sorted(set(given) - {*NETWORK_OPTIONS, "delay", *SCENARIO_OPTIONS})
    if unknown:
        raise TypeError(f"apply_run_options() got unknown options: {', '.join(unknown)}")
    problems: list[Problem] = []
    policy_changes = {key: value for key, value in (policy_settings or {}).items() if value is not None}
    if policy is not None:
        if policy in policy_names():
            policy_changes["name"] = policy
        else:
            problems.append(Problem(names.policy, f"unknown policy {policy!r}; known: {', '.join(policy_names())}"))
    policy_options = scenario.policy
    try:
        policy_options = replace(scenario.policy, **policy_changes)
    except InputError as error:
        problems = list(error.problems) + problems
    network_changes = {key: given[key] for key in NETWORK_OPTIONS if key in given}
    if "delay" in given:
        network_changes["delay_min"], network_changes["delay_max"] = delay_range(given["delay"], names.delay)
    network = replace(scenario.network, **network_changes) if network_changes else scenario.network
    changes = {key: given[key] for key in SCENARIO_OPTIONS if key in given}
    updated = scenario.with_changes(policy=policy_options, network=network, **changes)
    problems = scenario_problems(updated) + problems
    if problems:
        raise InputError(problems)
    return updated
