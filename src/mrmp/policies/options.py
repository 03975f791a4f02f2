"""Each policy's own options: one frozen dataclass per policy, holding the settings it reads.

The settings are declared by the field functions of :mod:`mrmp.core.options`
(help text, YAML key, ``mrmp run`` flag, check) and checked when the options
are built. A scenario's :class:`~mrmp.core.scenario.PolicyOptions` holds every
setting; :func:`options_from` takes the ones a policy reads.

Examples
--------
>>> from mrmp.core.scenario import PolicyOptions
>>> options_from(AstarOptions, PolicyOptions(name="astar", resolve="wait", radius=3))
AstarOptions(resolve='wait', heading_aware=False, search='default')
>>> ThesisOptions(resolve="wiat")
Traceback (most recent call last):
...
mrmp.core.errors.InputError: policy.resolve: must be one of divert, wait, got 'wiat'
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TypeVar

from mrmp.core.options import (
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
from mrmp.core.scenario import PolicyOptions

Options = TypeVar("Options")


@dataclass(frozen=True)
class ThesisOptions:
    """The thesis's rule (:class:`~mrmp.policies.thesis.ThesisPolicy`): how a conflict is resolved, and the search of Next."""

    resolve: str = resolve_setting()
    search: str = search_setting()

    def __post_init__(self) -> None:
        check_settings(self)


@dataclass(frozen=True)
class AstarOptions:
    """Reactive A* (:class:`~mrmp.policies.astar.AstarPolicy`): conflict resolution, the search, whether turns cost time."""

    resolve: str = resolve_setting()
    heading_aware: bool = heading_aware_setting()
    search: str = search_setting()

    def __post_init__(self) -> None:
        check_settings(self)


@dataclass(frozen=True)
class PibtOptions:
    """PIBT by messages (:class:`~mrmp.robot.pibt_robot.PibtRobot`): turn-aware order, beacon radius, swap, who sequences."""

    heading_aware: bool = heading_aware_setting()
    radius: int = radius_setting()
    swap: bool = swap_setting()
    sequencing: str = sequencing_setting()
    synchronizer: str = synchronizer_setting()
    guidance: str = guidance_setting()

    def __post_init__(self) -> None:
        check_settings(self)


@dataclass(frozen=True)
class CausalOptions:
    """Causal-PIBT (:class:`~mrmp.robot.causal_pibt.CausalRobot`): no settings."""


def options_from(options_type: type[Options], policy: PolicyOptions) -> Options:
    """An ``options_type`` holding the settings of ``policy`` that it declares (checked as it is built)."""
    names = [field.name for field in dataclasses.fields(options_type)]  # type: ignore[arg-type]
    return options_type(**{name: getattr(policy, name) for name in names})
