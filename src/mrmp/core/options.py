"""Policy settings declared once: each is a dataclass field whose metadata says how it is read, written and checked.

A setting's :class:`Setting` metadata gives its help text, its key under
``policy`` in a scenario file and its ``mrmp run`` flag, and checks its value.
The YAML reader and writer (:mod:`mrmp.io.scenario_file`) and the command line
(:mod:`mrmp.cli`) walk :func:`settings` of
:class:`~mrmp.core.scenario.PolicyOptions` instead of listing the settings;
every policy's own options dataclass (:mod:`mrmp.policies.options`) declares
the settings it reads with the same field functions and checks them when built
(:func:`check_settings`).

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class Example:
...     resolve: str = resolve_setting()
...     def __post_init__(self) -> None:
...         check_settings(self)
>>> [(field.name, setting.flag) for field, setting in settings(Example)]
[('resolve', '--resolve')]
>>> Example(resolve="wiat")
Traceback (most recent call last):
...
mrmp.core.errors.InputError: policy.resolve: must be one of divert, wait, got 'wiat'
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from mrmp.core.body import BODY_NAMES, DEFAULT_BODY
from mrmp.core.errors import InputError, Problem
from mrmp.core.limits import MAX_RADIUS

RESOLUTIONS = ("divert", "wait")
"""How a lower-priority robot resolves a conflict: divert (prioritized technique,
"change of route") or wait (velocity tuning), thesis section 2.1."""

SEARCH_NAMES = ("update-coordinate", "dijkstra", "best-first", "astar")
"""The single-robot searches a per-robot policy may plan with (the table of them:
:data:`mrmp.search.choices.SEARCH_TABLE`): the thesis's update coordinate method
(sections 3.1-3.2) and the three searches of its chapter 1 and future work 1."""

SEQUENCINGS = ("driver", "local")
"""Who orders ``pibt``'s calls: the simulator, in priority order (:mod:`mrmp.sim.rounds`), or the robots
themselves, by messages among neighbours (:mod:`mrmp.sim.local_rounds`)."""

GUIDANCES = ("none", "crisscross")
"""The lanes a ``pibt`` robot's tables may be guided by (:data:`mrmp.search.guidance.GUIDANCE_TABLE`): none, or the
crisscross pattern (moves against a row's or column's lane cost one step more)."""

SYNCHRONIZERS = ("clock", "local")
"""When a ``pibt`` robot (local sequencing) ends its step: at a time common to all (:mod:`mrmp.sim.local_rounds`),
or once every robot within 2 cells has decided, by its own word (:mod:`mrmp.sim.synchronized_rounds`)."""

POLICY_DEFAULT_SEARCH = "default"
"""The ``search`` value that leaves each policy its own search (``thesis``: update-coordinate, ``astar``: A*)."""

SETTING = "mrmp.setting"
"""The key of a field's :class:`Setting` in its dataclass metadata."""

Check = Callable[[Any], "str | None"]
"""Why a setting's value is wrong, or None when it is right."""


def _always_right(value: object) -> str | None:
    return None


@dataclass(frozen=True)
class Setting:
    """How one policy setting is named, explained and checked.

    Attributes
    ----------
    help:
        One line for ``mrmp run --help``.
    yaml_key:
        Its key under ``policy`` in a scenario file; problems are named ``policy.<yaml_key>``.
    flag:
        Its ``mrmp run`` option: ``--name``, or ``--name/--no-name`` for a switch.
    check:
        Why a value is wrong (None when it is right), beyond ``choices``.
    choices:
        The values it may take, when they are a list of names (listed by ``mrmp run --help``; any other
        value is wrong: :meth:`problem`).
    """

    help: str
    yaml_key: str
    flag: str
    check: Check = _always_right
    choices: tuple[str, ...] = ()

    @property
    def path(self) -> str:
        """The setting's field path in a scenario, as problems name it.

        >>> Setting("", "radius", "--radius").path
        'policy.radius'
        """
        return f"policy.{self.yaml_key}"

    def problem(self, value: object) -> str | None:
        """Why ``value`` is wrong for this setting (not one of its ``choices``, or its ``check``'s reason), or None.

        >>> Setting("", "sequencing", "--sequencing", choices=("local", "driver")).problem("central")
        "must be one of local, driver, got 'central'"
        """
        if self.choices and value not in self.choices:
            return f"must be one of {', '.join(self.choices)}, got {value!r}"
        return self.check(value)


def setting(
    default: Any, *, help: str, yaml_key: str, flag: str, check: Check = _always_right, choices: tuple[str, ...] = ()
) -> Any:
    """A dataclass field holding a policy setting (its default, and its :class:`Setting` as metadata)."""
    return dataclasses.field(default=default, metadata={SETTING: Setting(help, yaml_key, flag, check, choices)})


def settings(options_type: type) -> tuple[tuple[dataclasses.Field[Any], Setting], ...]:
    """The setting fields of an options dataclass, in declaration order, each with its :class:`Setting`."""
    return tuple((field, field.metadata[SETTING]) for field in dataclasses.fields(options_type) if SETTING in field.metadata)


def setting_types(options_type: type) -> dict[str, type]:
    """The Python type of each setting field of ``options_type``, by field name (annotations resolved).

    >>> from mrmp.core.scenario import PolicyOptions
    >>> {name: kind.__name__ for name, kind in setting_types(PolicyOptions).items()}  # doctest: +NORMALIZE_WHITESPACE
    {'resolve': 'str', 'heading_aware': 'bool', 'radius': 'int', 'swap': 'bool', 'search': 'str', 'sequencing': 'str',
     'synchronizer': 'str', 'body': 'str', 'guidance': 'str'}
    """
    hints = typing.get_type_hints(options_type)
    return {field.name: hints[field.name] for field, _ in settings(options_type)}


def setting_problems(options: object) -> list[Problem]:
    """Every wrong setting of an options dataclass instance, each named by its field path."""
    problems = []
    for field, info in settings(type(options)):
        reason = info.problem(getattr(options, field.name))
        if reason is not None:
            problems.append(Problem(info.path, reason))
    return problems


def check_settings(options: object) -> None:
    """Raise :class:`~mrmp.core.errors.InputError` naming every wrong setting of ``options`` (for ``__post_init__``)."""
    problems = setting_problems(options)
    if problems:
        raise InputError(problems)


def _radius_in_bounds(value: int) -> str | None:
    if value < 2:
        return f"must be at least 2 (cells), got {value}"
    return None if value <= MAX_RADIUS else f"must be at most {MAX_RADIUS} (cells), got {value}"


def resolve_setting() -> Any:
    """``resolve``: the thesis's two collision-avoidance techniques (section 2.1), ``divert`` or ``wait``."""
    return setting(
        "divert", help="Conflict resolution: divert (change of route) or wait (velocity tuning).", yaml_key="resolve",
        flag="--resolve", choices=RESOLUTIONS,
    )


def heading_aware_setting() -> Any:
    """``heading_aware``: planners charge turns (``pibt``: prefer fewer turns among equally near cells)."""
    return setting(
        False, help="Charge turns when planning.", yaml_key="heading_aware", flag="--heading-aware/--no-heading-aware"
    )


def radius_setting() -> Any:
    """``radius``: how far a ``pibt`` robot's beacon reaches (cells, Manhattan, 2 to :data:`~mrmp.core.limits.MAX_RADIUS`)."""
    return setting(
        2, help=f"pibt: how far a robot's beacon reaches, in cells (2 to {MAX_RADIUS}).", yaml_key="radius",
        flag="--radius", check=_radius_in_bounds,
    )


def search_setting() -> Any:
    """``search``: the single-robot search a per-robot policy plans with (``default``: the policy's own).

    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True)
    ... class Example:
    ...     search: str = search_setting()
    ...     def __post_init__(self) -> None:
    ...         check_settings(self)
    >>> Example(search="bfs")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: policy.search: must be one of default, update-coordinate, dijkstra, best-first, astar, got 'bfs'
    """
    return setting(
        POLICY_DEFAULT_SEARCH,
        help=f"thesis, astar: the single-robot search; {POLICY_DEFAULT_SEARCH} is the policy's own "
        "(thesis: update-coordinate, astar: astar).",
        yaml_key="search", flag="--search", choices=(POLICY_DEFAULT_SEARCH, *SEARCH_NAMES),
    )


def sequencing_setting() -> Any:
    """``sequencing``: who orders ``pibt``'s calls, ``driver`` (the simulator) or ``local`` (the robots themselves)."""
    return setting(
        "local", help="pibt: who orders the robots' calls: local (the robots themselves) or driver (the simulator).",
        yaml_key="sequencing", flag="--sequencing", choices=SEQUENCINGS,
    )  # fmt: skip


def synchronizer_setting() -> Any:
    """``synchronizer``: when a ``pibt`` robot ends its step, ``clock`` (a time common to all) or ``local`` (its own word)."""
    return setting(
        "clock",
        help="pibt (local sequencing, simulated or live): when a robot ends its step: clock (a time common to all) or "
        "local (once every robot within 2 cells has decided; a local synchronizer).",
        yaml_key="synchronizer", flag="--synchronizer", choices=SYNCHRONIZERS,
    )  # fmt: skip


def guidance_setting() -> Any:
    """``guidance``: the lanes that shape a ``pibt`` robot's distance tables (:data:`GUIDANCES`)."""
    return setting(
        "none",
        help="pibt with turning bodies (others ignore it): the lanes that shape the robots' distance tables: none, "
        "or crisscross (rows and columns alternate direction; a move against its lane counts one step more).",
        yaml_key="guidance", flag="--guidance", choices=GUIDANCES,
    )  # fmt: skip


def body_setting() -> Any:
    """``body``: the body model robots plan for and drive (:data:`~mrmp.core.body.BODY_TABLE`).

    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True)
    ... class Example:
    ...     body: str = body_setting()
    ...     def __post_init__(self) -> None:
    ...         check_settings(self)
    >>> Example(body="legs")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: policy.body: must be one of omni, thesis, turning, got 'legs'
    """
    return setting(
        DEFAULT_BODY,
        help="The body model robots plan for and drive: omni (any direction, turns free: the classic MAPF model) or "
        "turning (LoRR's MAPF_T: forward, a quarter turn either way, or wait; pibt with sequencing: driver, simulated). "
        "thesis is known to the referee and the execution bound only.",
        yaml_key="body", flag="--body", choices=BODY_NAMES,
    )  # fmt: skip


def swap_setting() -> Any:
    """``swap``: ``pibt``'s swap technique for corridors."""
    return setting(True, help="pibt: the swap technique for corridors.", yaml_key="swap", flag="--swap/--no-swap")
