"""PIBT sequenced by the robots themselves: safe in crowds, close to central PIBT, and every rule needed."""

import dataclasses
import random
from collections import Counter
from pathlib import Path

import pytest

from mrmp.centralized.pibt_step import PIBT
from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.core.errors import InputError
from mrmp.core.grid import connected_regions
from mrmp.core.heading import Heading
from mrmp.io import load_movingai_scenario
from mrmp.protocol.messages import AnswerMessage, BeaconMessage
from mrmp.protocol.pibt_local import (
    NO_CLAIM,
    CallAbortMessage,
    CallAckMessage,
    CallInheritMessage,
    CallReserveMessage,
    CallWoundMessage,
)
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_local import LocalPibtRobot
from mrmp.robot.pibt_reliable import ReliablePibtRobot
from mrmp.robot.pibt_robot import RESERVE_RADIUS
from mrmp.search.flat_map import FlatMap
from mrmp.sim.local_rounds import LocalRoundsSimulator
from mrmp.sim.rounds import RoundsSimulator


def random_scenario(seed, swap, radius=2, faults=None):
    """The random scenarios of ``test_pibt_robot.py``: up to half the largest region's cells hold robots."""
    rng = random.Random(seed)
    x_size, y_size = rng.randint(3, 9), rng.randint(3, 9)
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    blocked = set(rng.sample(cells, k=rng.randint(0, len(cells) // 5)))
    grid = Grid(x_size, y_size, blocked)
    free = sorted(max(connected_regions(grid, grid.free_cells())[1], key=len))
    count = rng.randint(1, max(1, len(free) // 2))
    starts, goals = rng.sample(free, count), rng.sample(free, count)
    robots = tuple(RobotSpec(f"r{i}", s, g) for i, (s, g) in enumerate(zip(starts, goals)))
    policy = PolicyOptions(name="pibt", radius=radius, swap=swap)
    return Scenario(grid, robots, network=faults or NetworkFaults(), policy=policy, seed=seed)


def central_next(simulator, swap):
    """The cells central PIBT gives the simulator's robots next, for their present cells and priorities."""
    robots = simulator.robots
    flat = simulator.flat
    pibt = PIBT(flat.neighbours, [flat.distances(robot.goal) for robot in robots], [robot.goal for robot in robots], swap=swap)
    order = [robot.index for robot in sorted(robots, key=lambda robot: robot.priority, reverse=True)]
    return pibt.step([robot.present for robot in robots], order)


def crowd(seed, density=0.8, swap=None, max_ticks=40):
    """A random map with up to ``density`` of its largest region's cells holding robots."""
    rng = random.Random(seed)
    x_size, y_size = rng.randint(4, 10), rng.randint(4, 10)
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    grid = Grid(x_size, y_size, set(rng.sample(cells, k=rng.randint(0, len(cells) // 6))))
    free = sorted(max(connected_regions(grid, grid.free_cells())[1], key=len))
    count = rng.randint(1, max(1, int(len(free) * density)))
    starts, goals = rng.sample(free, count), rng.sample(free, count)
    robots = tuple(RobotSpec(f"r{i}", s, g) for i, (s, g) in enumerate(zip(starts, goals)))
    swap = bool(seed % 2) if swap is None else swap
    return Scenario(grid, robots, policy=PolicyOptions(name="pibt", swap=swap), seed=seed, max_ticks=max_ticks)


def collisions(robot_type, seeds):
    """Collisions the referee saw over crowded runs of ``robot_type``."""

    class Simulator(LocalRoundsSimulator):
        pass

    Simulator.robot_type = robot_type
    return sum(len(Simulator(crowd(seed)).run().collisions) for seed in seeds)


@pytest.mark.parametrize("seed", range(60))
def test_crowds_never_collide_and_nobody_abandons_a_step(seed):
    result = LocalRoundsSimulator(crowd(seed)).run()
    assert result.collisions == []
    assert result.network["abandoned"] == 0
    assert result.network["sent"] == result.network["delivered"] == result.network["messages"]


def test_decisions_stay_close_to_central_pibt():
    steps = differ = decisions = moved_otherwise = 0
    for seed in range(40):
        for swap in (False, True):
            simulator = LocalRoundsSimulator(random_scenario(seed, swap, radius=2), random_ties=False)
            for _ in range(30):
                expected = central_next(simulator, swap)
                simulator.step()
                got = [robot.present for robot in simulator.robots]
                steps += 1
                differ += got != expected
                decisions += len(got)
                moved_otherwise += sum(a != b for a, b in zip(got, expected))
            assert simulator.referee.collisions == []
    # measured: 55 of 2,400 steps, 168 of 19,020 decisions (docs/protocol.md, "Local sequencing")
    assert differ <= 0.05 * steps
    assert moved_otherwise <= 0.02 * decisions


@pytest.mark.parametrize("seed", range(20))
def test_robots_within_two_cells_of_each_other_decide_as_central_pibt(seed):
    # on a 1 x 3 corridor plus one bay every robot is within 2 cells of every other: the local order is the global one
    rng = random.Random(seed)
    grid = Grid.from_rows(["...", ".##"])
    free = sorted(grid.free_cells())
    count = rng.randint(1, 3)
    starts, goals = rng.sample(free, count), rng.sample(free, count)
    robots = tuple(RobotSpec(f"r{i}", s, g) for i, (s, g) in enumerate(zip(starts, goals)))
    scenario = Scenario(grid, robots, policy=PolicyOptions(name="pibt", swap=False), seed=seed)
    simulator = LocalRoundsSimulator(scenario, random_ties=False)
    for _ in range(10):
        expected = central_next(simulator, False)
        simulator.step()
        assert [robot.present for robot in simulator.robots] == expected


def test_robots_count_their_waits_and_the_network_carries_everything():
    result = LocalRoundsSimulator(crowd(3, density=0.6, max_ticks=20)).run()
    assert result.network["waits"] > 0
    assert result.network["rounds"] > result.network["steps"]
    assert all(key in result.network for key in ("withdrawn", "refused", "passed_busy", "abandoned", "lost"))


FAULTS = {
    "lossy": NetworkFaults(loss=0.3, duplicate=0.1),
    "slow": NetworkFaults(loss=0.1, delay_min=0, delay_max=2, duplicate=0.1, reorder=0.2),
}


@pytest.mark.parametrize("faults", FAULTS)
@pytest.mark.parametrize("seed", range(12))
def test_over_a_faulty_network_crowds_never_collide(seed, faults):
    scenario = crowd(seed, density=0.5, max_ticks=120).with_changes(network=FAULTS[faults])
    simulator = LocalRoundsSimulator(scenario)
    result = simulator.run()
    assert result.collisions == []
    assert simulator.step_ticks == 8 * (2 * FAULTS[faults].delay_max + 1)
    if len(scenario.robots) > 1:
        assert result.network["lost"] > 0 and result.network["acks"] > 0


def test_over_a_lossy_network_robots_arrive():
    scenario = crowd(4, density=0.3, max_ticks=4000).with_changes(network=FAULTS["lossy"])
    result = LocalRoundsSimulator(scenario).run()
    assert result.success and result.collisions == []
    assert result.network["abandoned"] < result.network["steps"] * len(scenario.robots) / 2
    assert result.network["lost"] > 0 and result.network["retransmissions"] > 0


def test_a_cut_network_abandons_every_step_and_only_robots_alone_move():
    scenario = crowd(5, density=0.5, max_ticks=12).with_changes(network=NetworkFaults(loss=1.0))
    result = LocalRoundsSimulator(scenario, step_ticks=3).run()
    starts = [spec.start for spec in scenario.robots]

    def alone(cell):  # nobody within 2 cells: nothing to ask, nobody to tell
        return all(other == cell or abs(other[0] - cell[0]) + abs(other[1] - cell[1]) > 2 for other in starts)

    crowded = [robot for robot in result.robots if not alone(robot.start)]
    assert crowded and all(set(robot.path) == {robot.start} for robot in crowded)
    assert result.network["abandoned"] >= 4 * len(crowded)
    assert result.collisions == []


def test_a_step_of_no_ticks_is_refused_in_one_line():
    with pytest.raises(InputError, match=r"^step_ticks: must be at least 1, got 0$"):
        LocalRoundsSimulator(crowd(1), step_ticks=0)


# -- every rule is needed: broken variants that the tests above would catch ----------------------------


class Hasty(LocalPibtRobot):
    """Broken: a reservation is final at once (no round for a call of higher priority to win the cell)."""

    def _reserve(self, cell, out, final=False):
        super()._reserve(cell, out, final)
        self._confirmed = True


class Stubborn(LocalPibtRobot):
    """Broken: a robot never withdraws a reservation that a call of higher priority made in the same round."""

    def act(self):
        self._lost = False
        return super().act()


class Trusting(LocalPibtRobot):
    """Broken: the cell of a neighbour busy in another call counts as free (that neighbour may yet stay)."""

    def _continue(self, out):
        self._calls = {robot: self._root for robot in self._calls}
        super()._continue(out)


@pytest.mark.slow
@pytest.mark.parametrize("variant", [Hasty, Stubborn, Trusting])
def test_each_broken_variant_collides(variant):
    seeds = range(60)
    assert collisions(LocalPibtRobot, seeds) == 0
    assert collisions(variant, seeds) > 0


class Eager(LocalPibtRobot):
    """Broken: a robot starts its call without waiting for the robots within 2 cells that outrank it."""

    def _may_start(self):
        return True


def test_without_waiting_for_higher_priorities_decisions_drift_from_central_pibt():
    def differing(robot_type):
        class Simulator(LocalRoundsSimulator):
            pass

        Simulator.robot_type = robot_type
        count = 0
        for seed in range(20):
            simulator = Simulator(random_scenario(seed, True, radius=2), random_ties=False)
            for _ in range(20):
                expected = central_next(simulator, True)
                simulator.step()
                count += sum(robot.present != cell for robot, cell in zip(simulator.robots, expected))
        return count

    assert differing(Eager) > 3 * differing(LocalPibtRobot)


@pytest.mark.slow
@pytest.mark.parametrize("swap", [False, True])
@pytest.mark.parametrize("seed", range(40))
def test_a_radius_that_covers_the_map_gives_central_pibt_exactly(seed, swap):
    # every robot waits for every robot of higher priority: the calls run one at a time, in priority order
    simulator = LocalRoundsSimulator(random_scenario(seed, swap, radius=32), random_ties=False)
    for _ in range(30):
        expected = central_next(simulator, swap)
        simulator.step()
        assert [robot.present for robot in simulator.robots] == expected
    assert simulator.referee.collisions == []


class Impatient(ReliablePibtRobot):
    """Broken: over a faulty network, a reservation is confirmed without waiting for the acknowledgements."""

    def _may_confirm(self):
        return True


class Secretive(ReliablePibtRobot):
    """Broken: an acknowledgement does not carry its sender's claim, so claims of one cell go unnoticed."""

    def receive(self, message):
        target, self.target = self.target, None
        try:
            return super().receive(message)
        finally:
            self.target = target


@pytest.mark.slow
@pytest.mark.parametrize("variant", [Impatient, Secretive])
def test_each_broken_variant_collides_over_a_faulty_network(variant):
    class Simulator(LocalRoundsSimulator):
        reliable_type = variant

    collided = 0
    for seed in range(30):  # radius 2: calls near each other run at once, so claims of one cell meet often
        scenario = crowd(seed, density=0.7, max_ticks=60).with_changes(
            network=FAULTS["lossy"], policy=PolicyOptions(name="pibt", radius=2)
        )
        assert LocalRoundsSimulator(scenario).run().collisions == []
        collided += len(Simulator(scenario).run().collisions)
    assert collided > 0


def _blind_to_neighbours(base):
    class BlindToNeighbours(base):
        """Broken: a claim is settled at once when the cell's own occupant has decided, whoever stands next to it."""

        def _uncontested(self, cell):
            other = self._occupants.get(cell)
            return other is None or other == self.index or other in self._final

    return BlindToNeighbours


@pytest.mark.parametrize("faults", [None, "lossy"])
def test_a_claim_is_settled_at_once_only_when_no_robot_next_to_the_cell_is_undecided(faults):
    """The uncontested shortcut (``LocalPibtRobot._uncontested``) is safe; looking at the cell alone is not."""

    class Simulator(LocalRoundsSimulator):
        robot_type = _blind_to_neighbours(LocalPibtRobot)
        reliable_type = _blind_to_neighbours(ReliablePibtRobot)

    collided = settled_at_once = 0
    for seed in range(20):
        scenario = crowd(seed, density=0.5, max_ticks=60).with_changes(policy=PolicyOptions(name="pibt", radius=2))
        if faults is not None:
            scenario = scenario.with_changes(network=FAULTS[faults])
        result = LocalRoundsSimulator(scenario).run()
        assert result.collisions == []
        settled_at_once += result.network["settled_at_once"]
        collided += len(Simulator(scenario).run().collisions)
    assert collided > 0 and settled_at_once > 0


def test_a_pushed_robot_never_takes_its_own_cell_back_when_another_claim_of_it_is_withdrawn():
    """Over a faulty network a request can overtake the asker's reservation; the cell stays the asker's.

    Robot R (1) on a corridor is pushed by A (0); B (2), in a call of higher
    priority, claims R's cell and then withdraws to another. R's own cell is
    still promised to A, so R, with no cell to go to, must answer "could not
    move" (a brain that forgot the promise stayed and answered "moved", and A
    entered R's cell: the collision this test was written from).
    """
    flat = FlatMap(Grid.from_rows(["....."]))
    cell = flat.index
    robot = ReliablePibtRobot(1, cell((0, 1)), cell((0, 4)), flat, tie=1)
    robot.waits_to_join = False  # joins A's call at once, although B outranks it (the rule this test predates)
    robot.begin_step(1, sensed=[cell((0, 0)), cell((0, 2)), cell((0, 3))], now=0)
    robot.receive(BeaconMessage(0, 1, 1, (0, 0), (0, 4), 1, 0))  # A
    robot.receive(BeaconMessage(2, 1, 1, (0, 2), (0, 0), 2, 5))  # B
    robot.receive(CallInheritMessage(0, 3, 1, (0, 1), 0, 1, 0))  # A's request, ahead of its reservation
    robot.act()  # R takes the request, and waits to know every robot near before deciding
    robot.receive(CallReserveMessage(2, 2, 1, (0, 1), 2, 2, 5, False))  # B claims R's cell ...
    robot.receive(CallReserveMessage(2, 3, 1, (0, 3), 2, 2, 5, False))  # ... and withdraws from it
    robot.receive(CallReserveMessage(0, 2, 1, (0, 1), 0, 1, 0, False))  # A's reservation, overtaken: dropped
    robot.receive(BeaconMessage(3, 1, 1, (0, 3), (0, 3), 0, 0))  # the last robot near
    (claim,) = [item.message for item in robot.act() if isinstance(item.message, CallReserveMessage)]
    assert claim.cell == (0, 1) and not claim.final  # R can only stay
    for sender, (held, root, elapsed, tie) in {0: ((0, 1), 0, 1, 0), 2: ((0, 3), 2, 2, 5), 3: (NO_CLAIM, 0, 0, 0)}.items():
        robot.receive(CallAckMessage(sender, 9, 1, claim.seq, held, root, elapsed, tie))
    answers = [item for item in robot.act() if isinstance(item.message, AnswerMessage)]
    assert [(item.message.moved, item.recipients) for item in answers] == [(False, (0,))]
    assert robot.dropped["overtaken"] == 1


def test_a_robot_asked_to_join_a_call_waits_for_the_robots_near_it_that_outrank_the_call():
    """Over a faulty network a call may reach a robot before a robot next to it that outranks the call decides.

    Robot R (1) is asked by A (0), whose call ranks below B (2), next to R and
    undecided. R takes no part in A's call until B has decided for good (as
    in central PIBT, where B goes first); then it does.
    """
    flat = FlatMap(Grid.from_rows(["....."]))
    cell = flat.index
    robot = ReliablePibtRobot(1, cell((0, 1)), cell((0, 4)), flat, tie=1)
    robot.begin_step(1, sensed=[cell((0, 0)), cell((0, 2))], now=0)
    robot.receive(BeaconMessage(0, 1, 1, (0, 0), (0, 4), 1, 0))  # A
    robot.receive(BeaconMessage(2, 1, 1, (0, 2), (0, 0), 2, 5))  # B, which outranks A
    robot.receive(CallReserveMessage(0, 2, 1, (0, 1), 0, 1, 0, False))  # A reserves R's cell ...
    robot.receive(CallInheritMessage(0, 3, 1, (0, 1), 0, 1, 0))  # ... and asks R
    waited = robot.act()
    assert not [item for item in waited if isinstance(item.message, CallReserveMessage)]
    assert robot._parent is None and robot.stats["join_waits"] == 1
    robot.receive(CallReserveMessage(2, 2, 1, (0, 2), 2, 2, 5, True))  # B decides for good: it stays
    joined = robot.act()
    assert robot._parent == 0
    assert [item.message.cell for item in joined if isinstance(item.message, CallReserveMessage)] == [(0, 1)]


def test_the_stay_of_the_robot_asked_to_leave_is_no_rival_claim_of_its_cell():
    """A turning robot asks the occupant of the cell ahead to leave; the occupant stays this step, turning to
    leave the next. Its final reservation of its cell may come before its answer: the robot still stays facing
    that cell, to follow it, as when the answer comes first (not withdrawing, and turning elsewhere)."""
    flat = FlatMap(Grid.from_rows(["...", "..."]))
    cell = flat.index
    ahead = Heading.between((0, 1), (0, 2))
    robot = ReliablePibtRobot(0, cell((0, 1)), cell((0, 2)), flat, tie=1, heading=ahead, turning=True, swap=False)
    robot.begin_step(1, sensed=[cell((0, 2))], now=0)
    robot.receive(BeaconMessage(1, 1, 1, (0, 2), (1, 2), 0, 0, ahead))  # the occupant, outranked by the robot
    asked = [item.recipients for item in robot.act() if isinstance(item.message, CallInheritMessage)]
    assert asked == [(1,)]
    robot.receive(CallReserveMessage(1, 2, 1, (0, 2), 0, 0, 1, True))  # it stays for good, in the robot's call ...
    robot.receive(AnswerMessage(1, 3, 1, False, True))  # ... turning to leave next step
    robot.act()
    assert robot.stats["withdrawn"] == 0
    assert flat.cells[robot._stay_toward] == (0, 2)


# -- progress on maps with dead ends: a stalled robot's reach grows ------------------------------------


def dead_ends(seed, density, blocked, max_ticks=120):
    """A random map with a third of its cells blocked (corridors, dead ends), ``density`` of its region holding robots.

    Radius 2, where a fixed reach leaves these maps deadlocked (a radius of 3 gets some of them through by itself).
    """
    rng = random.Random(seed)
    x_size, y_size = rng.randint(6, 12), rng.randint(6, 12)
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    grid = Grid(x_size, y_size, set(rng.sample(cells, k=int(len(cells) * blocked))))
    free = sorted(max(connected_regions(grid, grid.free_cells())[1], key=len))
    count = max(2, int(len(free) * density))
    starts, goals = rng.sample(free, count), rng.sample(free, count)
    robots = tuple(RobotSpec(f"r{i}", s, g) for i, (s, g) in enumerate(zip(starts, goals)))
    return Scenario(grid, robots, policy=PolicyOptions(name="pibt", radius=2), seed=seed, max_ticks=max_ticks)


DEAD_ENDS = [(21, 0.3, 0.35), (57, 0.3, 0.35), (40, 0.3, 0.35), (55, 0.4, 0.3)]
GROWTH_CASES = [(27, 0.5, 0.35), (55, 0.5, 0.3), (60, 0.3, 0.35), (91, 0.4, 0.35)]
"""Maps with dead ends where a fixed reach deadlocks even with calls taking robots over (:attr:`LocalPibtRobot.preempts`)."""


class Confined(LocalPibtRobot):
    """Broken: a stalled robot's reach never grows (robots beyond 2 cells start before its call reaches them)."""

    reach_cap = 0


@pytest.mark.parametrize("case", GROWTH_CASES)
def test_a_growing_reach_gets_robots_out_of_dead_ends_where_a_fixed_one_deadlocks(case):
    class Fixed(LocalRoundsSimulator):
        robot_type = Confined

    scenario = dead_ends(*case)
    assert RoundsSimulator(scenario).run().success  # the sequenced order arrives
    grown = LocalRoundsSimulator(scenario).run()
    assert grown.success and grown.collisions == [] and grown.network["abandoned"] == 0
    fixed = Fixed(scenario).run()
    assert not fixed.success and fixed.collisions == []


def test_the_reach_grows_one_cell_per_stalled_step_after_the_slack_up_to_the_cap():
    simulator = LocalRoundsSimulator(dead_ends(*DEAD_ENDS[0]))
    seen = set()
    for _ in range(40):
        stalled = [robot.stalled for robot in simulator.robots]
        simulator.step()
        for robot, before in zip(simulator.robots, stalled):
            assert robot.reach == min(robot.radius + max(0, before - robot.stall_slack), robot.reach_cap)
            seen.add(robot.reach)
    assert {2, 3, LocalPibtRobot.reach_cap} <= seen


class RecordKeeping(LocalPibtRobot):
    """Counts a stall unless a step ends nearer the goal than the robot has ever been."""

    stall_from_best = True


@pytest.mark.parametrize("brain", [LocalPibtRobot, RecordKeeping])
def test_a_stall_is_a_step_without_progress_from_its_start_or_from_the_record(brain):
    class Simulator(LocalRoundsSimulator):
        robot_type = brain

    simulator = Simulator(dead_ends(*DEAD_ENDS[0]))
    robots = simulator.robots
    nearest = [robot.flat.distances(robot.goal)[robot.present] for robot in robots]
    expected = [0] * len(robots)
    back_and_forth = 0  # steps nearer than they began, but no nearer than ever before
    for _ in range(40):
        began = [robot.flat.distances(robot.goal)[robot.present] for robot in robots]
        simulator.step()
        for index, robot in enumerate(robots):
            distance = robot.flat.distances(robot.goal)[robot.present]
            by_record = distance < nearest[index] or robot.at_goal
            by_step = distance < began[index] or robot.at_goal
            back_and_forth += by_step and not by_record
            progressed = by_record if brain.stall_from_best else by_step
            expected[index] = 0 if progressed else expected[index] + 1
            nearest[index] = min(nearest[index], distance)
        assert [robot.stalled for robot in robots] == expected
    assert back_and_forth > 0  # the two counts part on this map


# -- a call of higher priority takes over the robots of a call of lower priority (wound-wait) --------------


class FinalHolderOnly(LocalPibtRobot):
    """Broken: a claim given up hands its cell back only to a claim decided for good, not to a provisional one.

    The provisional claim that lost to an occupant staying on its cell is
    forgotten when the occupant gives its call up, and a robot of the same call
    then rotates into the cell: two robots decide for it.
    """

    def _restore_holder(self, cell):
        for robot in self._final:
            if self._targets.get(robot) == cell:
                self._reserved[cell] = robot
                return


class KeepsTheRequestOfAQuitter(LocalPibtRobot):
    """Broken: a robot keeps the request of a call whose asker has since given that call up, and never answers it."""

    def _take_wounds(self, out):
        kept = self._wound
        if kept is not None:
            self._control = [m for m in self._control if not (isinstance(m, CallWoundMessage) and m.sender == kept.sender)]
        super()._take_wounds(out)


class AnyAbortEndsTheCall(LocalPibtRobot):
    """Broken: an abort of the robot a robot asked ends the asker's call whichever call it gave up (the robot's old one)."""

    informing = LocalPibtRobot.informing.copy()

    @informing.on(CallAbortMessage)
    def _take_any_abort(self, message):
        return self._take_abort(dataclasses.replace(message, root=self._root))


def crowd_at(seed, radius):
    scenario = crowd(seed)
    return scenario.with_changes(policy=PolicyOptions(name="pibt", radius=radius, swap=scenario.policy.swap))


@pytest.mark.parametrize("seed", range(40))
@pytest.mark.parametrize("radius", [2, 3])
def test_calls_taking_robots_over_stay_safe_and_finish_their_steps(seed, radius):
    result = LocalRoundsSimulator(crowd_at(seed, radius)).run()
    assert result.collisions == [] and result.network["abandoned"] == 0


def test_crowds_see_calls_taken_over_and_robots_waiting_for_a_call_of_higher_priority():
    counts = Counter()
    for seed in range(20):
        counts.update(LocalRoundsSimulator(crowd_at(seed, 2)).run().network)
    assert counts["aborted"] > 0 and counts["blocked"] > 0


def test_a_given_up_claim_hands_its_cell_to_the_claim_still_standing():
    class Simulator(LocalRoundsSimulator):
        robot_type = FinalHolderOnly

    assert LocalRoundsSimulator(crowd_at(1, 3)).run().collisions == []
    assert Simulator(crowd_at(1, 3)).run().collisions != []


def test_an_abort_ends_the_askers_call_only_when_it_gives_that_call_up():
    class Simulator(LocalRoundsSimulator):
        robot_type = AnyAbortEndsTheCall

    cases = [(6, 2), (22, 2), (53, 2)]
    assert all(LocalRoundsSimulator(crowd_at(*case)).run().collisions == [] for case in cases)
    assert all(Simulator(crowd_at(*case)).run().collisions != [] for case in cases)


def test_a_request_whose_asker_gave_its_call_up_is_refused():
    class Simulator(LocalRoundsSimulator):
        robot_type = KeepsTheRequestOfAQuitter

    cases = [(5, 2), (6, 2), (48, 2)]
    assert all(LocalRoundsSimulator(crowd_at(*case)).run().network["abandoned"] == 0 for case in cases)
    assert all(Simulator(crowd_at(*case)).run().network["abandoned"] > 0 for case in cases)


class NoTakeOver(LocalPibtRobot):
    """Broken: a call passes by the cell of a robot busy in another call, whatever that call's priority."""

    preempts = False


class PulledAtItsOwnPriority(LocalPibtRobot):
    """Broken: a pulled robot claims the cell it is pulled into with its own priority, not the puller's call's."""

    def _take_pull_local(self, message, out):
        cell = self.flat.index(message.cell)
        if self._idle() and cell not in self._reserved:
            self._root, self._rank = self.index, self.priority
            self._candidates, self._next, self._pulled = [cell], 0, None
            self._continue(out)


def warehouse_400(seed):
    maps = Path(__file__).resolve().parents[3] / "maps"
    name = "warehouse-10-20-10-2-1"
    scenario = load_movingai_scenario(maps / f"{name}.map", maps / f"{name}-random-1.scen", 400)
    return scenario.with_changes(seed=seed, max_ticks=500)


@pytest.mark.slow
def test_warehouse_with_400_robots_arrives_on_every_seed_of_the_bench():
    """``bench/pibt_scale.py --only warehouse-10-20-10-2-1 --seeds 15``: every seed arrives, within 500 ticks."""
    for seed in range(15):
        result = LocalRoundsSimulator(warehouse_400(seed)).run()
        assert result.success and result.collisions == [] and result.network["abandoned"] == 0, seed


@pytest.mark.slow
@pytest.mark.parametrize(("seed", "broken"), [(1, NoTakeOver), (0, PulledAtItsOwnPriority)])
def test_warehouse_jams_that_local_sequencing_gets_through(seed, broken):
    """warehouse-10-20-10-2-1 with 400 robots: the default arrives within 500 ticks; each broken rule jams a corridor."""
    scenario = warehouse_400(seed)

    class Simulator(LocalRoundsSimulator):
        robot_type = broken

    through = LocalRoundsSimulator(scenario).run()
    jammed = Simulator(scenario).run()
    assert through.success and through.collisions == []
    assert not jammed.success and jammed.collisions == []


@pytest.mark.parametrize("seed", range(8))
def test_handing_messages_over_equals_sending_them_encoded_through_the_network(seed):
    class Encoded(LocalRoundsSimulator):
        encode_perfect = True

    for scenario in (crowd(seed), dead_ends(*DEAD_ENDS[seed % len(DEAD_ENDS)], max_ticks=40)):
        handed, encoded = LocalRoundsSimulator(scenario).run(), Encoded(scenario).run()
        assert [robot.path for robot in handed.robots] == [robot.path for robot in encoded.robots]
        assert [robot.bytes_sent for robot in handed.robots] == [robot.bytes_sent for robot in encoded.robots]
        assert handed.network == encoded.network


class Broadcasting(LocalPibtRobot):
    """Every reservation by radio to every robot within its radius, and a look at the start rule after every decision."""

    reconsiders_at_every_decision = True

    def _reservation(self, message, final):
        return Outgoing(message, None, self.reach if final else RESERVE_RADIUS)


@pytest.mark.parametrize("radius", [2, 3])
@pytest.mark.parametrize("seed", range(6))
def test_reservations_by_name_and_fewer_looks_change_no_decision_and_send_fewer_messages(seed, radius):
    class Radio(LocalRoundsSimulator):
        robot_type = Broadcasting

    for scenario in (crowd(seed), dead_ends(*DEAD_ENDS[seed % len(DEAD_ENDS)], max_ticks=40)):
        scenario = scenario.with_changes(policy=PolicyOptions(name="pibt", radius=radius))
        named, radio = LocalRoundsSimulator(scenario).run(), Radio(scenario).run()
        assert [robot.path for robot in named.robots] == [robot.path for robot in radio.robots]
        assert named.network["messages"] <= radio.network["messages"]
        if len(scenario.robots) > 3:
            assert named.network["waits"] < radio.network["waits"] or radio.network["waits"] == 0
