"""The one table of decision rules, by name.

Examples
--------
>>> sorted(POLICIES)
['astar', 'thesis']
>>> make_policy(PolicyOptions(name="thesis", resolve="wait")).resolve
'wait'
"""

from __future__ import annotations

from collections.abc import Callable

from mrmp.core.errors import InputError, Problem
from mrmp.core.scenario import PolicyOptions, Timing
from mrmp.policies.astar import AstarPolicy
from mrmp.policies.base import Policy
from mrmp.policies.thesis import ThesisPolicy

PolicyFactory = Callable[[PolicyOptions, Timing], Policy]

POLICIES: dict[str, PolicyFactory] = {
    "thesis": lambda options, timing: ThesisPolicy(resolve=options.resolve),
    "astar": lambda options, timing: AstarPolicy(
        resolve=options.resolve, heading_aware=options.heading_aware, timing=timing
    ),
}
"""Every policy name a scenario or ``--policy`` may use, with its factory."""

ROUND_POLICIES: tuple[str, ...] = ("pibt",)
"""Policies whose robots decide together by messages in synchronous rounds
(:mod:`mrmp.sim.rounds`), rather than each alone by a :class:`Policy`."""

ASYNC_POLICIES: tuple[str, ...] = ("causal",)
"""Policies whose robots run asynchronously, each at its own speed, and interact through locks
(:mod:`mrmp.robot.causal_pibt`, simulated by :mod:`mrmp.sim.asynchronous`)."""

POLICY_NAMES: tuple[str, ...] = (*POLICIES, *ROUND_POLICIES, *ASYNC_POLICIES)


def make_policy(options: PolicyOptions, timing: Timing | None = None) -> Policy:
    """A fresh policy object for one robot.

    Raises
    ------
    InputError
        If ``options.name`` is not a known policy.
    """
    if options.name in ROUND_POLICIES:
        raise InputError(
            Problem("policy.name", f"{options.name!r} runs in synchronous rounds (mrmp.sim.rounds), not as a per-robot policy")
        )
    if options.name in ASYNC_POLICIES:
        raise InputError(
            Problem("policy.name", f"{options.name!r} runs asynchronously (mrmp.sim.asynchronous), not as a per-robot policy")
        )
    try:
        factory = POLICIES[options.name]
    except KeyError:
        raise InputError(
            Problem("policy.name", f"unknown policy {options.name!r}; known: {', '.join(POLICY_NAMES)}")
        ) from None
    return factory(options, timing or Timing())
