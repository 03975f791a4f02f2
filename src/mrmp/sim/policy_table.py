"""The one table of policies: everything the rest of mrmp asks about a policy, by name.

Each :class:`PolicyEntry` says what its options are, how its robots' brains are
built and which simulator drives them, which live driver runs it in ``mrmp
agent`` (if any), whether its bodies always enter cells through the safety
layer, and whether its simulator records the messages sent. :func:`simulate
<mrmp.sim.simulator.simulate>`, the command line, ``mrmp agent``
(:mod:`mrmp.live.process`), the benchmarks, ``mrmp compare`` and the
conformance suite ask this table; nothing else tests a policy's name.

The table lives in the simulator layer because its entries name simulators
(which live here) and brains and decision rules (the layers below). A live
driver lives above, in :mod:`mrmp.live`, so an entry names it by a kind that
:mod:`mrmp.live.process` resolves.

Two shapes of policy:

* *per-robot*: a :class:`~mrmp.policies.base.Policy` decides for each robot
  alone; ``decision_rule`` builds it, the lockstep simulator
  (:class:`~mrmp.sim.simulator.LockstepSimulator`, ``simulator`` None) and the
  live :class:`~mrmp.live.agent.Agent` run it inside a
  :class:`~mrmp.robot.robot.Robot`;
* *message-based*: the robots decide together with messages of their own;
  ``simulator`` builds the brains (of type ``brain``) and runs them.

Examples
--------
>>> policy_names()
('thesis', 'astar', 'pibt', 'causal')
>>> policy_entry("pibt").simulator.__name__, policy_entry("pibt").live_driver
('pibt_simulator', 'pibt')
>>> make_policy(PolicyOptions(name="thesis", resolve="wait")).resolve
'wait'
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Protocol

from mrmp.core.body import DEFAULT_BODY, BodyModel, body_model
from mrmp.core.errors import InputError, Problem
from mrmp.core.result import RunResult
from mrmp.core.scenario import PolicyOptions, Scenario, Timing
from mrmp.policies.astar import AstarPolicy
from mrmp.policies.base import Policy
from mrmp.policies.options import AstarOptions, CausalOptions, PibtOptions, ThesisOptions, options_from
from mrmp.policies.thesis import ThesisPolicy
from mrmp.robot.causal_pibt import CausalRobot
from mrmp.robot.pibt_robot import PibtRobot
from mrmp.robot.robot import Robot
from mrmp.search.choices import chosen_search
from mrmp.sim.asynchronous import AsynchronousSimulator
from mrmp.sim.local_rounds import LocalRoundsSimulator
from mrmp.sim.rounds import RoundsSimulator
from mrmp.sim.synchronized_rounds import SynchronizedRoundsSimulator
from mrmp.sim.ticking import TickObserver


class Simulation(Protocol):
    """What a message-based policy's simulator gives: its brains, and a run to the end."""

    robots: Any

    def run(self) -> RunResult:
        """Run to the end and return the result."""
        ...


SimulatorFactory = Callable[..., Simulation]
"""A simulator class (or function) called as ``simulator(scenario, on_tick=on_tick)``."""

DecisionRule = Callable[[Any, Timing, BodyModel], Policy]
"""Builds one robot's per-robot :class:`~mrmp.policies.base.Policy` from the policy's options, the robots' timing
and their body model."""


@dataclass(frozen=True)
class PolicyEntry:
    """One policy: the answers to everything the rest of mrmp asks about it.

    Attributes
    ----------
    name:
        What a scenario's ``policy.name`` and ``--policy`` say.
    options:
        Its options dataclass (:mod:`mrmp.policies.options`), built from the
        scenario's :class:`~mrmp.core.scenario.PolicyOptions` by :meth:`options_of`.
    brain:
        The type of its robots' brains.
    decision_rule:
        Per-robot policies: builds one robot's decision rule. None for a
        message-based policy (its simulator builds its brains).
    simulator:
        Message-based policies: the simulator that builds and runs its brains.
        None for a per-robot policy (the lockstep simulator runs it).
    live_driver:
        The kind of live driver that runs it in ``mrmp agent`` (``"agent"``:
        the per-robot :class:`~mrmp.live.agent.Agent`; ``"causal"``:
        :class:`~mrmp.live.causal_agent.CausalAgent`; ``"pibt"``:
        :class:`~mrmp.live.pibt_agent.PibtAgent`), or None when it is simulated only.
    live_note:
        What a live run of it says first about how it runs live (empty: nothing).
    runs:
        Message-based policies: how they run, for the error of asking them for a per-robot rule.
    not_live:
        With no live driver: why, for the ``--live`` error message.
    always_guarded:
        Its bodies always enter cells through the safety layer (it has no ``--unsafe`` form).
    records_messages:
        Its simulator can keep a message log (``--show-messages``).
    live_tasks:
        Its live driver takes a lifelong run's tasks from the task desk
        (:mod:`mrmp.live.task_desk`): it can run a task stream live.
    tick_is_a_step:
        Whether every tick of its simulator's run of a scenario is one step of every robot (one
        action each, as LoRR's output has): by default, yes.
    bodies:
        The body models (:mod:`mrmp.core.body`) its robots plan for and its
        simulator drives.
    live_bodies:
        The body models its live driver drives.
    """

    name: str
    options: type
    brain: type
    decision_rule: DecisionRule | None = None
    simulator: SimulatorFactory | None = None
    live_driver: str | None = None
    runs: str = ""
    not_live: str = ""
    live_note: str = ""
    always_guarded: bool = False
    records_messages: bool = False
    live_tasks: bool = False
    tick_is_a_step: Callable[[Scenario], bool] = lambda scenario: True
    bodies: tuple[str, ...] = (DEFAULT_BODY,)
    live_bodies: tuple[str, ...] = (DEFAULT_BODY,)

    @property
    def per_robot(self) -> bool:
        """Whether each robot decides alone with a :class:`~mrmp.policies.base.Policy`."""
        return self.decision_rule is not None

    def options_of(self, policy: PolicyOptions) -> Any:
        """This policy's options, from the settings of a scenario's ``policy`` section."""
        return options_from(self.options, policy)

    def make_policy(self, policy: PolicyOptions, timing: Timing) -> Policy:
        """A fresh per-robot decision rule for one robot.

        Raises
        ------
        InputError
            If this is a message-based policy (it has no per-robot form).
        """
        if self.decision_rule is None:
            raise InputError(Problem("policy.name", f"{self.name!r} {self.runs}, not as a per-robot policy"))
        return self.decision_rule(self.options_of(policy), timing, body_model(policy.body))

    def simulation(self, scenario: Scenario, on_tick: TickObserver | None = None) -> Simulation:
        """This message-based policy's simulator, set up for ``scenario``."""
        if self.simulator is None:
            raise ValueError(f"{self.name} is a per-robot policy: the lockstep simulator runs it")
        return self.simulator(scenario, on_tick=on_tick)


STEP_ENDS: dict[str, Callable[..., RoundsSimulator]] = {
    "clock": LocalRoundsSimulator,
    "local": SynchronizedRoundsSimulator,
}
"""``pibt``'s simulator with local sequencing, by ``synchronizer``: steps on a common clock, or ended by each robot."""


def pibt_simulator(scenario: Scenario, on_tick: TickObserver | None = None) -> RoundsSimulator:
    """Policy ``pibt``'s simulator: the robots' calls ordered by the driver, or by the robots (``sequencing``).

    >>> from mrmp.core import Grid, RobotSpec
    >>> robots = (RobotSpec("A", (0, 0), (2, 0)),)
    >>> type(pibt_simulator(Scenario(Grid(3, 1), robots, policy=PolicyOptions(name="pibt", sequencing="local")))).__name__
    'LocalRoundsSimulator'
    >>> type(pibt_simulator(Scenario(Grid(3, 1), robots, policy=PolicyOptions(name="pibt", synchronizer="local")))).__name__
    'SynchronizedRoundsSimulator'
    """
    options = options_from(PibtOptions, scenario.policy)
    if options.sequencing == "local":
        return STEP_ENDS[options.synchronizer](scenario, on_tick=on_tick)
    if options.synchronizer != "clock":
        raise InputError(
            Problem("policy.synchronizer", "local needs sequencing: local (the driver's order ends steps on global quiet)")
        )
    return RoundsSimulator(scenario, on_tick=on_tick)


def pibt_tick_is_a_step(scenario: Scenario) -> bool:
    """Whether policy ``pibt``'s simulator makes a step of every tick: not with local sequencing over a faulty
    network, whose steps span several ticks (:class:`~mrmp.sim.local_rounds.LocalRoundsSimulator`).

    >>> from mrmp.core import Grid, RobotSpec
    >>> from mrmp.core.scenario import NetworkFaults
    >>> swap = Scenario(Grid(1, 2), (RobotSpec("A", (0, 0), (0, 1)),), policy=PolicyOptions(name="pibt"))
    >>> pibt_tick_is_a_step(swap), pibt_tick_is_a_step(swap.with_changes(network=NetworkFaults(loss=0.1)))
    (True, False)
    """
    return scenario.perfect_network or options_from(PibtOptions, scenario.policy).sequencing != "local"


POLICY_TABLE: dict[str, PolicyEntry] = {
    "thesis": PolicyEntry(
        "thesis",
        ThesisOptions,
        Robot,
        decision_rule=lambda options, timing, body: ThesisPolicy(
            resolve=options.resolve, search=chosen_search(options.search, ThesisPolicy.own_search).planner, body=body
        ),
        live_driver="agent",
        records_messages=True,
        bodies=(DEFAULT_BODY, "turning"),
        live_bodies=(DEFAULT_BODY, "turning"),
    ),
    "astar": PolicyEntry(
        "astar",
        AstarOptions,
        Robot,
        decision_rule=lambda options, timing, body: AstarPolicy(
            resolve=options.resolve,
            heading_aware=options.heading_aware,
            timing=timing,
            body=body,
            search=chosen_search(options.search, AstarPolicy.own_search).planner,
        ),
        live_driver="agent",
        records_messages=True,
        bodies=(DEFAULT_BODY, "turning"),
        live_bodies=(DEFAULT_BODY, "turning"),
    ),
    "pibt": PolicyEntry(
        "pibt",
        PibtOptions,
        PibtRobot,
        simulator=pibt_simulator,
        runs="runs in synchronous rounds (mrmp.sim.rounds)",
        live_driver="pibt",
        live_tasks=True,
        tick_is_a_step=pibt_tick_is_a_step,
        live_note=(
            "pibt runs live with local sequencing, whatever policy.sequencing says"
            " (no driver can order live processes; sequencing: driver is the simulator's)"
        ),
        bodies=(DEFAULT_BODY, "turning"),
        live_bodies=(DEFAULT_BODY, "turning"),
    ),
    "causal": PolicyEntry(
        "causal",
        CausalOptions,
        CausalRobot,
        simulator=AsynchronousSimulator,
        runs="runs asynchronously (mrmp.sim.asynchronous)",
        live_driver="causal",
        always_guarded=True,
        bodies=(DEFAULT_BODY, "turning"),
        live_bodies=(DEFAULT_BODY, "turning"),
    ),
}
"""Every policy a scenario or ``--policy`` may name, in the order they are listed and compared."""


def policy_names() -> tuple[str, ...]:
    """Every policy's name, in table order."""
    return tuple(POLICY_TABLE)


def policy_entry(name: str) -> PolicyEntry:
    """The table's entry for ``name``.

    Raises
    ------
    InputError
        If no policy has that name.

    >>> policy_entry("greedy")
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: policy.name: unknown policy 'greedy'; known: thesis, astar, pibt, causal
    """
    try:
        return POLICY_TABLE[name]
    except KeyError:
        raise InputError(
            Problem("policy.name", f"unknown policy {name!r}; known: {', '.join(policy_names())}")
        ) from None


EXECUTING_BODIES: tuple[str, ...] = (DEFAULT_BODY, "turning")
"""The bodies that execute a central plan (the per-robot :class:`~mrmp.robot.robot.Robot` drives them: a body that
turns in place turns toward its next cell while it waits), in the simulator and live."""


def body_problem(scenario: Scenario, *, live: bool = False, planned: bool = False) -> Problem | None:
    """Why ``scenario``'s robots cannot run in its body model this way, or None when they can.

    A policy runs the bodies of its entry's :attr:`~PolicyEntry.bodies`, in
    the simulator, and those of its :attr:`~PolicyEntry.live_bodies` live; a
    central plan is executed by every body of :data:`EXECUTING_BODIES`, in
    the simulator and live.

    >>> from mrmp.core import Grid, RobotSpec
    >>> robots = (RobotSpec("A", (0, 0), (0, 1)),)
    >>> turning = Scenario(Grid(1, 2), robots, policy=PolicyOptions(name="pibt", body="turning", sequencing="driver"))
    >>> body_problem(turning) is None
    True
    >>> body_problem(turning, live=True) is None
    True
    >>> print(body_problem(turning.with_changes(policy=PolicyOptions(name="causal", body="thesis")), live=True))
    policy.body: causal drives omni, turning bodies live so far, not thesis
    >>> body_problem(turning, live=True, planned=True) is None
    True
    >>> body_problem(turning.with_changes(policy=PolicyOptions(name="astar", body="turning")), live=True) is None
    True
    >>> print(body_problem(turning.with_changes(policy=PolicyOptions(name="astar", body="thesis"))))
    policy.body: astar plans for omni, turning bodies, not thesis
    """
    body = scenario.policy.body
    if body == DEFAULT_BODY:
        return None
    if planned:
        if body in EXECUTING_BODIES:
            return None
        return Problem("policy.body", f"central plans are executed by {', '.join(EXECUTING_BODIES)} bodies, not {body}")
    entry = policy_entry(scenario.policy.name)
    if live and body not in entry.live_bodies:
        return Problem("policy.body", f"{entry.name} drives {', '.join(entry.live_bodies)} bodies live so far, not {body}")
    if body not in entry.bodies:
        return Problem("policy.body", f"{entry.name} plans for {', '.join(entry.bodies)} bodies, not {body}")
    return None


def make_policy(options: PolicyOptions, timing: Timing | None = None) -> Policy:
    """A fresh per-robot decision rule for one robot, for the policy ``options.name``.

    Raises
    ------
    InputError
        If ``options.name`` is not a known per-robot policy.
    """
    return policy_entry(options.name).make_policy(options, timing or Timing())


@contextmanager
def registered(entry: PolicyEntry) -> Iterator[PolicyEntry]:
    """Add ``entry`` to the table for the duration of a ``with`` block (for a policy defined outside mrmp, or a test).

    >>> toy = PolicyEntry("toy", ThesisOptions, Robot, decision_rule=POLICY_TABLE["thesis"].decision_rule)
    >>> with registered(toy):
    ...     policy_names()[-1]
    'toy'
    >>> "toy" in policy_names()
    False
    """
    if entry.name in POLICY_TABLE:
        raise ValueError(f"a policy named {entry.name!r} is already in the table")
    POLICY_TABLE[entry.name] = entry
    try:
        yield entry
    finally:
        del POLICY_TABLE[entry.name]
