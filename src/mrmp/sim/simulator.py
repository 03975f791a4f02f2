"""The lockstep simulator: every robot's brain, a simulated network, ideal bodies and the referee.

Per tick, as in the thesis (section 3.5-3.6):

1. every robot computes its intended Next and sends Present and Next to its peers;
2. the network delivers what is due (at once with zero delay; later with delay,
   so decisions rest on stale knowledge);
3. every robot checks for obstacles and decides;
4. the bodies carry out the moves (turning right first when the heading
   changes) and each robot observes its new cell;
5. the referee checks the new configuration.

The run ends when every robot stands on its goal, at the tick limit, or when
the same configuration of every robot's cell and heading has recurred
:data:`RECURRENCE_LIMIT` times ("deadlock" if nobody moved meanwhile, else
"livelock"), or on Ctrl-C ("interrupted"), always returning what was computed.
It is deterministic for a seed.

Examples
--------
>>> from mrmp.core import Grid, RobotSpec, Scenario
>>> swap = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))))
>>> result = simulate(swap)
>>> result.success, result.makespan, result.sum_of_costs, result.lower_bound
(True, 6, 10, 8)
"""

from __future__ import annotations

import time
from collections import Counter

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading, right_turns
from mrmp.core.result import RobotResult, RunResult
from mrmp.core.scenario import Scenario
from mrmp.policies.base import Decision
from mrmp.policies.registry import make_policy
from mrmp.protocol.codec import DecodeError, decode, encode
from mrmp.protocol.messages import Message
from mrmp.robot.robot import Robot
from mrmp.sim.metrics import default_max_ticks, shortest_steps
from mrmp.sim.network import SimulatedNetwork
from mrmp.sim.referee import Referee

RECURRENCE_LIMIT = 10
"""How often one configuration may recur before the run is declared stuck."""


class LockstepSimulator:
    """Runs a scenario tick by tick (see the module docstring).

    Parameters
    ----------
    scenario:
        What to run; its policy, network faults, seed and tick limit apply.
    record_decisions:
        Keep every robot's :class:`~mrmp.policies.base.Decision` of every tick
        in :attr:`decisions` (for tests and traces).
    """

    def __init__(self, scenario: Scenario, record_decisions: bool = False) -> None:
        self.scenario = scenario
        grid = scenario.grid
        self.robots = [
            Robot(spec, index, grid, make_policy(scenario.policy, scenario.timing))
            for index, spec in enumerate(scenario.robots)
        ]
        index_of = {spec.id: index for index, spec in enumerate(scenario.robots)}
        links = {(index_of[link.sender], index_of[link.recipient]): link.faults for link in scenario.links}
        self.network = SimulatedNetwork(scenario.network, seed=scenario.seed, links=links)
        self.referee = Referee(grid, [spec.id for spec in scenario.robots])
        self.lengths = shortest_steps(scenario)
        self.max_ticks = scenario.max_ticks or default_max_ticks(scenario, self.lengths)
        self.record_decisions = record_decisions
        self.decisions: list[list[Decision]] = []
        self.tick = 0
        self._results = [
            RobotResult(spec.id, spec.start, spec.goal, path=[spec.start], headings=[spec.heading])
            for spec in scenario.robots
        ]
        self._durations: list[list[float]] = [[] for _ in scenario.robots]
        self._recurrences: Counter[tuple[tuple[Cell, ...], tuple[Heading, ...]]] = Counter()
        self._still_since = 0

    def run(self) -> RunResult:
        """Run to the end and return the result (partial on Ctrl-C)."""
        started = time.perf_counter()
        self.referee.check_start([robot.present for robot in self.robots])
        stop_reason = "tick limit"
        try:
            while self.tick < self.max_ticks:
                if all(robot.arrived for robot in self.robots):
                    stop_reason = "all arrived"
                    break
                self.step()
                stuck = self._stuck()
                if stuck:
                    stop_reason = stuck
                    break
            else:
                if all(robot.arrived for robot in self.robots):
                    stop_reason = "all arrived"
        except KeyboardInterrupt:
            stop_reason = "interrupted"
        return self._result(stop_reason, time.perf_counter() - started)

    def step(self) -> None:
        """Advance one tick."""
        self.tick += 1
        tick = self.tick
        robots = self.robots
        network = self.network
        everyone = range(len(robots))
        for robot in robots:
            outgoing = robot.intend(tick)
            result = self._results[robot.index]
            for item in outgoing:
                payload = encode(item.message)
                recipients = item.recipients if item.recipients is not None else everyone
                for recipient in recipients:
                    if recipient != robot.index:
                        network.send(robot.index, recipient, payload, tick)
                        result.messages_sent += 1
                        result.bytes_sent += len(payload)
        decoded: dict[bytes, Message | None] = {}
        for _, recipient, payload in network.deliver(tick):
            message = decoded.get(payload, False)
            if message is False:
                try:
                    message = decode(payload)
                except DecodeError:
                    message = None
                decoded[payload] = message
            if message is None:
                robots[recipient].receive_datagram(payload, tick)
            else:
                robots[recipient].receive(message, tick)
        decisions = [robot.decide(tick) for robot in robots]
        if self.record_decisions:
            self.decisions.append(decisions)
        before = [robot.present for robot in robots]
        timing = self.scenario.timing
        grid = self.scenario.grid
        moved = False
        for robot, decision in zip(robots, decisions):
            result = self._results[robot.index]
            target = decision.next
            heading = robot.heading
            duration = timing.cell_time
            if target != robot.present:
                moved = True
                try:
                    new_heading = Heading.between(robot.present, target)
                except ValueError:
                    new_heading = heading
                turns = right_turns(heading, new_heading)
                result.turns += turns
                duration = turns * timing.turn_time + timing.cell_time * (grid.cost(target) if grid.in_bounds(target) else 1.0)
                heading = new_heading
            robot.observe(target, heading)
            result.path.append(target)
            result.headings.append(heading)
            self._durations[robot.index].append(duration)
        self.referee.check_tick(tick, before, [robot.present for robot in robots])
        self._still_since = self._still_since + 1 if not moved else 0

    def _stuck(self) -> str | None:
        configuration = (tuple(robot.present for robot in self.robots), tuple(robot.heading for robot in self.robots))
        self._recurrences[configuration] += 1
        if self._recurrences[configuration] < RECURRENCE_LIMIT or all(robot.arrived for robot in self.robots):
            return None
        return "deadlock" if self._still_since >= RECURRENCE_LIMIT - 1 else "livelock"

    def _result(self, stop_reason: str, wall_time: float) -> RunResult:
        for index, result in enumerate(self._results):
            result.time_s = sum(self._durations[index][: result.cost])
        network = self.network.stats.as_dict()
        network["dropped_by_robots"] = sum(sum(robot.dropped.values()) for robot in self.robots)
        network["stale"] = sum(robot.belief.stale_messages for robot in self.robots)
        return RunResult(
            scenario=self.scenario.name,
            policy=self.scenario.policy.name,
            seed=self.scenario.seed,
            robots=self._results,
            collisions=list(self.referee.collisions),
            stop_reason=stop_reason,
            ticks=self.tick,
            lower_bound=sum(self.lengths),
            wall_time_s=wall_time,
            network=network,
        )


def simulate(scenario: Scenario, record_decisions: bool = False) -> RunResult:
    """Run ``scenario`` in the lockstep simulator and return its result."""
    return LockstepSimulator(scenario, record_decisions=record_decisions).run()
