"""A toy message-based policy, added through the policy table alone, checked by the same conformance suite.

Robots take turns: at tick ``t`` only robot ``(t - 1) mod N`` may move, one
cell along a shortest path around the cells its peers announced. Every robot
announces its cell in a :class:`~mrmp.protocol.messages.StateMessage` after
each tick; the toy's simulator delivers every message at once (it ignores the
scenario's network faults), so beliefs are exact and one mover at a time never
collides.
"""

from __future__ import annotations

import time
from collections import deque

from test_policies import check_policy

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.result import RobotResult, RunResult
from mrmp.core.scenario import Scenario
from mrmp.policies.options import CausalOptions
from mrmp.protocol.messages import StateMessage
from mrmp.sim.metrics import default_max_ticks, shortest_steps
from mrmp.sim.policy_table import PolicyEntry, policy_names, registered
from mrmp.sim.referee import Referee
from mrmp.sim.simulator import simulate
from mrmp.sim.ticking import TickObserver, run_result, run_ticks


def next_cell(grid: Grid, start: Cell, goal: Cell, taken: set[Cell]) -> Cell:
    """The first cell of a shortest path from ``start`` to ``goal`` avoiding ``taken`` (``start`` when there is none)."""
    parents: dict[Cell, Cell] = {start: start}
    frontier = deque([start])
    while frontier:
        cell = frontier.popleft()
        if cell == goal:
            while parents[cell] != start:
                cell = parents[cell]
            return cell
        for neighbour in grid.neighbours(cell):
            if neighbour not in parents and neighbour not in taken:
                parents[neighbour] = cell
                frontier.append(neighbour)
    return start


class TurnTakingRobot:
    """The toy's sans-IO brain: its cell, its goal, and the cells its peers announced."""

    def __init__(self, index: int, grid: Grid, start: Cell, goal: Cell) -> None:
        self.index, self.grid, self.present, self.goal = index, grid, start, goal
        self.peers: dict[int, Cell] = {}
        self.seq = 0

    def receive(self, message: StateMessage) -> None:
        self.peers[message.sender] = message.present

    def move(self, my_turn: bool) -> None:
        if my_turn and self.present != self.goal:
            self.present = next_cell(self.grid, self.present, self.goal, set(self.peers.values()))

    def announce(self) -> StateMessage:
        self.seq += 1
        return StateMessage(self.index, self.seq, self.present, self.present, arrived=self.present == self.goal)


class TurnTakingSimulator:
    """Runs the toy's robots tick by tick, with the referee watching."""

    def __init__(self, scenario: Scenario, on_tick: TickObserver | None = None) -> None:
        self.scenario, self.on_tick = scenario, on_tick
        self.robots = [TurnTakingRobot(i, scenario.grid, spec.start, spec.goal) for i, spec in enumerate(scenario.robots)]
        self.referee = Referee(scenario.grid, [spec.id for spec in scenario.robots])
        self.lengths = shortest_steps(scenario)
        self.max_ticks = scenario.max_ticks or default_max_ticks(scenario, self.lengths)
        self.tick = 0
        self.results = [RobotResult(spec.id, spec.start, spec.goal, path=[spec.start]) for spec in scenario.robots]
        self._broadcast()

    def _broadcast(self) -> None:
        for robot, result in zip(self.robots, self.results):
            message = robot.announce()
            for peer in self.robots:
                if peer is not robot:
                    peer.receive(message)
                    result.messages_sent += 1

    def step(self) -> None:
        self.tick += 1
        before = [robot.present for robot in self.robots]
        for robot in self.robots:
            robot.move(robot.index == (self.tick - 1) % len(self.robots))
        self._broadcast()
        after = [robot.present for robot in self.robots]
        self.referee.check_tick(self.tick, before, after)
        for result, cell in zip(self.results, after):
            result.path.append(cell)
        if self.on_tick is not None:
            self.on_tick(self.tick, after)

    def run(self) -> RunResult:
        started = time.perf_counter()
        self.referee.check_start([robot.present for robot in self.robots])
        stop = run_ticks(self, lambda: all(robot.present == robot.goal for robot in self.robots))
        messages = sum(result.messages_sent for result in self.results)
        return run_result(self, self.results, "turns", stop, time.perf_counter() - started, {"messages": messages})


TOY = PolicyEntry(
    "turns", CausalOptions, TurnTakingRobot, simulator=TurnTakingSimulator, runs="runs in turns (its own simulator)",
    not_live="is a toy: simulated only",
)
"""The toy's one entry: options with no settings, its brain, its simulator, no live driver."""


def test_the_toy_is_in_the_table_only_while_registered() -> None:
    with registered(TOY):
        assert policy_names()[-1] == "turns"
    assert "turns" not in policy_names()


def test_simulate_runs_the_toy_through_the_table() -> None:
    from mrmp.core import Grid, PolicyOptions, RobotSpec

    robots = (RobotSpec("A", (0, 0), (2, 0)), RobotSpec("B", (1, 2), (1, 0)))
    crossing = Scenario(Grid(3, 3), robots, policy=PolicyOptions("turns"))
    with registered(TOY):
        result = simulate(crossing)
    assert result.policy == "turns" and result.success and not result.collisions


def test_the_toy_passes_the_policy_conformance_suite() -> None:
    with registered(TOY):
        check_policy("turns", max_examples=40)
