"""What the tick-driven simulators share: the scenario's network, the run loop, counted sending, the result.

The lockstep simulator (:mod:`mrmp.sim.simulator`), the asynchronous one
(:mod:`mrmp.sim.asynchronous`) and the synchronous rounds of policy ``pibt``
(:mod:`mrmp.sim.rounds`) differ in what a tick does; they run their ticks and
build their :class:`~mrmp.core.result.RunResult` alike, and read the
scenario's per-link faults alike, with these functions. The first two also
send their robots' messages over the simulated network alike.

Examples
--------
>>> from mrmp.core import Grid, RobotSpec, Scenario
>>> scenario = Scenario(Grid(1, 2), (RobotSpec("A", (0, 0), (0, 1)),))
>>> network = scenario_network(scenario)
>>> result = RobotResult("A", (0, 0), (0, 1))
>>> from mrmp.protocol.messages import ClaimMessage
>>> send_counted(network, 0, Outgoing(ClaimMessage(0, 1, 1, (0, 1)), (0, 1)), range(2), 0, result)
(0, 1)
>>> result.messages_sent, result.bytes_sent > 0
(1, True)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Protocol

from mrmp.core.cell import Cell
from mrmp.core.result import RobotResult, RunResult
from mrmp.core.scenario import NetworkFaults, Scenario
from mrmp.core.seeds import Stream, derive_seed
from mrmp.core.tasks import TaskLog
from mrmp.protocol.codec import encode
from mrmp.robot.robot import Outgoing
from mrmp.sim.network import SimulatedNetwork
from mrmp.sim.referee import Referee
from mrmp.sim.task_book import TaskBook

TickObserver = Callable[[int, list[Cell]], None]
"""Called after every tick with the tick number and every robot's cell, in scenario order."""


class TickedSimulation(Protocol):
    """What :func:`run_ticks` and :func:`run_result` read of a simulator."""

    scenario: Scenario
    referee: Referee
    tick: int
    max_ticks: int
    lengths: list[int]

    def step(self) -> None:
        """Advance one tick."""
        ...


def link_faults(scenario: Scenario) -> dict[tuple[int, int], NetworkFaults]:
    """The faults of ``scenario``'s links that have their own, by ``(sender, recipient)`` robot index."""
    index_of = {spec.id: index for index, spec in enumerate(scenario.robots)}
    return {(index_of[link.sender], index_of[link.recipient]): link.faults for link in scenario.links}


def scenario_network(scenario: Scenario) -> SimulatedNetwork:
    """The simulated network of ``scenario``: its faults, seed and per-link faults (by robot index)."""
    return SimulatedNetwork(
        scenario.network, seed=derive_seed(scenario.seed, Stream.NETWORK), links=link_faults(scenario)
    )


def run_ticks(
    simulation: TickedSimulation, all_arrived: Callable[[], bool], stuck: Callable[[], str | None] | None = None
) -> str:
    """Step ``simulation`` to the end and say why it ended.

    The run ends when every robot arrived (``"all arrived"``; never in a
    lifelong run), at the tick limit (``"tick limit"``, or ``"time up"`` in a
    lifelong run), when ``stuck`` (asked after every tick) gives a reason, or
    on Ctrl-C (``"interrupted"``).
    """
    lifelong = simulation.scenario.lifelong
    stop_reason = "time up" if lifelong else "tick limit"
    try:
        while simulation.tick < simulation.max_ticks:
            if not lifelong and all_arrived():
                stop_reason = "all arrived"
                break
            simulation.step()
            if stuck is not None:
                reason = stuck()
                if reason:
                    stop_reason = reason
                    break
        else:
            if not lifelong and all_arrived():
                stop_reason = "all arrived"
    except KeyboardInterrupt:
        stop_reason = "interrupted"
    return stop_reason


Near = Callable[[int, int], Sequence[int]]
"""The robots whose bodies stand within ``radius`` cells of robot ``sender``'s body: ``near(sender, radius)``."""


def send_counted(
    network: SimulatedNetwork,
    sender: int,
    item: Outgoing,
    everyone: range,
    tick: int,
    result: RobotResult,
    near: Near | None = None,
) -> Sequence[int] | range:
    """Send ``item`` over ``network`` to its recipients; count the messages and bytes sent in ``result``.

    The recipients are the robots ``item`` names plus, when it has a radius,
    every robot ``near`` gives within that radius of the sender (the simulated
    radio; without ``near``, the whole fleet); a message with neither goes to
    ``everyone``. The sender never sends to itself. Returns the recipients (the
    sender among them if it was listed or broadcast to).
    """
    payload = encode(item.message)
    named = item.recipients
    if item.radius is not None:
        around = near(sender, item.radius) if near is not None else everyone
        recipients: Sequence[int] | range = (
            around if not named else [*around, *(index for index in named if index not in around)]
        )
    else:
        recipients = named if named is not None else everyone
    size = len(payload)
    sent = 0
    for recipient in recipients:
        if recipient != sender:
            network.send(sender, recipient, payload, tick)
            sent += 1
    result.messages_sent += sent
    result.bytes_sent += sent * size
    return recipients


def _task_log(simulation: TickedSimulation) -> TaskLog | None:
    """The log of ``simulation``'s task book, if it has one (a simulator serving a task stream keeps it as ``task_book``)."""
    book: TaskBook | None = getattr(simulation, "task_book", None)
    return None if book is None else book.log


def run_result(
    simulation: TickedSimulation,
    results: list[RobotResult],
    policy: str,
    stop_reason: str,
    wall_time: float,
    network: dict[str, int],
    **extra: Any,
) -> RunResult:
    """The :class:`RunResult` of ``simulation`` so far: its robots' ``results``, the referee's collisions, ``extra`` fields."""
    scenario = simulation.scenario
    return RunResult(
        scenario=scenario.name,
        policy=policy,
        seed=scenario.seed,
        robots=results,
        collisions=list(simulation.referee.collisions),
        stop_reason=stop_reason,
        ticks=simulation.tick,
        lower_bound=sum(simulation.lengths),
        wall_time_s=wall_time,
        network=network,
        lifelong=scenario.lifelong,
        body=scenario.policy.body,
        tasks=_task_log(simulation),
        **extra,
    )
