"""``pibt`` with a local synchronizer: robots end their own steps; no cell decided twice; every rule needed."""

import dataclasses
from pathlib import Path

import pytest
from test_pibt_live import Boastful, BrainFleet, Forgetful, corridor
from test_pibt_local import FAULTS, crowd

from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario, Timing
from mrmp.core.errors import InputError
from mrmp.core.heading import Heading
from mrmp.io import load_movingai_scenario, load_scenario
from mrmp.live.pibt_agent import PibtBrain, PibtTiming
from mrmp.protocol.messages import BeaconMessage
from mrmp.protocol.pibt_local import NO_CLAIM, CallAckMessage, CallReserveMessage
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_local import LocalPibtRobot
from mrmp.robot.pibt_synchronized import SynchronizedPibtRobot
from mrmp.search.flat_map import FlatMap
from mrmp.sim.live_rounds import LiveRoundsSimulator
from mrmp.sim.policy_table import pibt_simulator
from mrmp.sim.synchronized_rounds import SynchronizedRoundsSimulator

MAPS = Path(__file__).resolve().parents[3] / "maps"
EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def synchronized(scenario):
    return scenario.with_changes(policy=PolicyOptions(name="pibt", swap=scenario.policy.swap, synchronizer="local"))


@pytest.mark.slow
@pytest.mark.parametrize("faults", ["perfect", *FAULTS])
@pytest.mark.parametrize("seed", range(10))
def test_crowds_arrive_and_no_cell_is_decided_twice(seed, faults):
    """The bodies' rule alone keeps bodies apart; the audits check the decisions, step by step."""
    network = FAULTS.get(faults, NetworkFaults())
    scenario = synchronized(crowd(seed, density=0.5, max_ticks=2000)).with_changes(network=network)
    result = SynchronizedRoundsSimulator(scenario).run()
    assert result.success and result.collisions == []
    assert result.network["conflicting_decisions"] == result.network["conflicting_steps"] == 0


class Idle(SynchronizedPibtRobot):
    """Broken: never acts."""

    def act(self):
        return []


def test_a_fleet_whose_brains_do_nothing_arrives_nowhere():
    scenario = synchronized(crowd(1, density=0.5, max_ticks=100))
    assert not run_with(Idle, scenario)[0].success


@pytest.mark.parametrize("seed", range(8))
def test_on_a_perfect_network_each_step_takes_one_tick_and_the_moves_are_the_live_brains_in_lockstep(seed):
    scenario = synchronized(crowd(seed, density=0.3, max_ticks=400))
    ended = SynchronizedRoundsSimulator(scenario).run()
    lockstep = LiveRoundsSimulator(scenario, step_ticks=1).run()
    assert ended.success and lockstep.success
    assert [robot.path for robot in ended.robots] == [robot.path for robot in lockstep.robots]
    assert ended.network["steps"] == ended.makespan


def random_32(agents, network, seed=0, max_ticks=3000):
    scenario = load_movingai_scenario(MAPS / "random-32-32-20.map", MAPS / "random-32-32-20-random-1.scen", agents)
    return synchronized(scenario).with_changes(network=network, seed=seed, max_ticks=max_ticks)


LOSSY = NetworkFaults(loss=0.2, delay_max=2)


def test_over_twenty_percent_loss_every_robot_arrives_and_the_robots_count_their_synchronizer():
    result = SynchronizedRoundsSimulator(random_32(30, LOSSY)).run()
    network = result.network
    assert result.success and result.collisions == []
    assert network["lost"] > 0 and network["retransmissions"] > 0
    assert network["late_acks"] > 0 and network["ahead"] > 0
    assert network["conflicting_decisions"] == network["conflicting_steps"] == 0


# -- broken variants: each rule is needed ---------------------------------------------


class EndsAlone(SynchronizedPibtRobot):
    """Broken: ends its step once it decided, whether its neighbours did or not."""

    @property
    def step_done(self):
        return self._done


class IgnoresLaterSteps(SynchronizedPibtRobot):
    """Broken: a message of a later step does not tell it that its sender decided (rule 4)."""

    def _ahead(self, peer):
        pass


class AcknowledgesInThePast(SynchronizedPibtRobot):
    """Broken: acknowledges a message of an ended step with an acknowledgement of that step (rule 3)."""

    def _acknowledge_late(self, message):
        self.seq += 1
        elapsed, tie, _ = self._own_rank
        ack = CallAckMessage(self.index, self.seq, message.step, message.seq, NO_CLAIM, self.index, elapsed, tie)
        self._replies.append(Outgoing(ack, (message.sender,)))


class StopsListeningOnceDecided(SynchronizedPibtRobot):
    """Broken: once decided, it no longer notes who else decided (rule 2)."""

    def receive(self, message):
        if self._done and isinstance(message, CallReserveMessage) and message.step == self.step:
            return super(SynchronizedPibtRobot, self).receive(message)
        return super().receive(message)


class ForgetfulSynchronized(Forgetful, SynchronizedPibtRobot):
    """Broken (as ``Forgetful``): a peer is taken to be where it was last heard of, as if it had not moved since."""


class BoastfulSynchronized(Boastful, SynchronizedPibtRobot):
    """Broken (as ``Boastful``): the news its beacon tells is stamped with the current step."""


def run_with(brain, scenario):
    class Simulator(SynchronizedRoundsSimulator):
        robot_type = reliable_type = brain

    simulator = Simulator(scenario)
    return simulator.run(), min(robot.step for robot in simulator.robots)


@pytest.mark.slow
@pytest.mark.parametrize("brain", [EndsAlone, IgnoresLaterSteps, AcknowledgesInThePast, StopsListeningOnceDecided])
def test_without_any_one_rule_the_fleet_stops_advancing_over_a_lossy_network(brain):
    scenario = random_32(30, LOSSY, max_ticks=2000)
    result, _ = run_with(SynchronizedPibtRobot, scenario)
    assert result.success and result.makespan < 1500
    broken, slowest_step = run_with(brain, scenario)
    assert not broken.success and slowest_step <= 5  # some robot never got past its first steps in 2,000 ticks


class JoinsAtOnce(SynchronizedPibtRobot):
    """Broken: joins a call at once, though a robot near it that outranks the call has not decided."""

    waits_to_join = False


class WithdrawsForTheRobotItAsked(SynchronizedPibtRobot):
    """Broken: takes the stay of the robot it asked to leave for a rival claim of that cell, and withdraws."""

    informing = SynchronizedPibtRobot.informing.copy()

    @informing.on(CallReserveMessage)
    def _take_call_reservation_blind(self, message):
        return self._blind_to_asked(lambda: LocalPibtRobot._take_call_reservation(self, message))

    def _take_ack(self, message):
        return self._blind_to_asked(lambda: SynchronizedPibtRobot._take_ack(self, message))

    def _blind_to_asked(self, take):
        asked, self._waiting = self._waiting, None
        try:
            return take()
        finally:
            self._waiting = asked


def causal_32_turning(seed):
    scenario = load_scenario(EXAMPLES / "causal-32.yaml")
    policy = PolicyOptions(name="pibt", synchronizer="local", body="turning", swap=False)
    return scenario.with_changes(robots=scenario.robots[:24], policy=policy, network=LOSSY, seed=seed)


@pytest.mark.slow
@pytest.mark.parametrize("brain", [JoinsAtOnce, WithdrawsForTheRobotItAsked])
def test_over_a_lossy_network_turning_robots_decide_nearly_as_over_a_perfect_one(brain):
    """24 turning robots of causal-32 take 29 steps over a perfect network; at 20% loss, about as many
    (``bench/pibt_loss.py``). A call joined before a robot near that outranks it decided, or a withdrawal for
    the stay of the robot asked to leave, makes robots turn away and stay, at the cost of steps."""
    perfect, _ = run_with(SynchronizedPibtRobot, causal_32_turning(0).with_changes(network=NetworkFaults()))
    assert perfect.success and perfect.network["steps"] == 29
    steps, broken_steps = 0, 0
    for seed in range(6):
        result, _ = run_with(SynchronizedPibtRobot, causal_32_turning(seed))
        broken, _ = run_with(brain, causal_32_turning(seed))
        assert result.success and broken.success and result.collisions == broken.collisions == []
        steps += result.network["steps"]
        broken_steps += broken.network["steps"]
    assert steps <= 6 * 30.5
    assert broken_steps >= steps + 9


class DeafToNews(SynchronizedPibtRobot):
    """A brain that takes in no news: it learns where a peer stands from that peer only."""

    def _take_news(self, news):
        pass


@pytest.mark.slow
def test_news_spares_robots_messages_to_and_waits_for_peers_that_cannot_be_near():
    scenario = random_32(100, NetworkFaults())
    told, _ = run_with(SynchronizedPibtRobot, scenario)
    deaf, _ = run_with(DeafToNews, scenario)
    assert told.success and deaf.success
    assert told.network["messages"] < 0.8 * deaf.network["messages"]


@pytest.mark.slow
@pytest.mark.parametrize("brain", [ForgetfulSynchronized, BoastfulSynchronized])
def test_a_robot_that_forgets_that_peers_move_or_tells_old_news_as_new_decides_cells_that_others_decided(brain):
    conflicts = 0
    for seed in range(2):
        scenario = random_32(100, LOSSY, seed=seed, max_ticks=300)
        assert run_with(SynchronizedPibtRobot, scenario)[0].network["conflicting_decisions"] == 0
        broken, _ = run_with(brain, scenario)
        assert broken.collisions == []  # two bodies never enter one cell: both wait
        conflicts += broken.network["conflicting_decisions"]
    assert conflicts > 0


# -- the brain's rules, one message at a time --------------------------------------------


def pair():
    flat = FlatMap(Grid(4, 1))
    starts = [flat.index((0, 0)), flat.index((1, 0))]
    a = SynchronizedPibtRobot(0, starts[0], flat.index((0, 0)), flat, tie=2, starts=starts)
    b = SynchronizedPibtRobot(1, starts[1], flat.index((3, 0)), flat, tie=1, starts=starts)
    return flat, a, b


def exchange(robots, sent):
    """Deliver ``sent`` (sender, item) pairs to the other robot until nothing more is sent."""
    while sent:
        for sender, item in sent:
            robots[1 - sender].receive(item.message)
        sent = [(robot.index, item) for robot in robots for item in robot.act()]


def test_a_robot_ends_its_step_only_once_every_neighbour_decided():
    _, a, b = pair()
    robots = (a, b)
    sent = [(robot.index, item) for robot in robots for item in robot.begin_step(1)]
    decided_before_its_neighbour = 0
    while sent:
        for sender, item in sent:
            robots[1 - sender].receive(item.message)
        sent = [(robot.index, item) for robot in robots for item in robot.act()]
        for robot, neighbour in ((a, b), (b, a)):
            if robot.final and not neighbour.final:
                decided_before_its_neighbour += 1
                assert not robot.step_done
    assert decided_before_its_neighbour > 0
    assert a.step_done and b.step_done


def test_a_message_of_an_ended_step_is_acknowledged_from_the_present_step():
    flat, a, b = pair()
    exchange((a, b), [(0, item) for item in a.begin_step(1)] + [(1, item) for item in b.begin_step(1)])
    a.finish_step()
    a.begin_step(2)
    late = CallReserveMessage(1, 99, 1, flat.cells[b.present], 1, 0, 1, True)
    assert a.receive(late)
    acks = [item for item in a.act() if isinstance(item.message, CallAckMessage) and item.message.acked == 99]
    assert [(item.message.step, item.recipients) for item in acks] == [(2, (1,))]
    assert a.stats["late_acks"] == 1


def test_a_message_of_a_later_step_marks_its_sender_done_and_stops_retransmissions_to_it():
    flat, a, b = pair()
    b_out = b.begin_step(1)
    a.begin_step(1)
    a.receive(b_out[0].message)
    a.act()
    assert any(1 in entry.pending for entry in a._unacknowledged.values())
    beacon = BeaconMessage(1, 50, 2, flat.cells[b.present], flat.cells[b.goal], 0, 1)
    assert a.receive(beacon)
    assert 1 in a._final and a.stats["ahead"] == 1
    assert all(1 not in entry.pending for entry in a._unacknowledged.values())
    a.finish_step()
    a.begin_step(2)  # the beacon kept for step 2 is taken in now
    assert a.known[1] == (b.present, 2)


def test_local_step_ends_need_local_sequencing():
    scenario = crowd(0).with_changes(policy=PolicyOptions(name="pibt", sequencing="driver", synchronizer="local"))
    with pytest.raises(InputError, match=r"policy\.synchronizer"):
        pibt_simulator(scenario)
    assert isinstance(pibt_simulator(synchronized(crowd(0))), SynchronizedRoundsSimulator)


# -- live: PibtBrain with the synchronizer, simulated bodies on an in-memory network ------------------------


@pytest.mark.slow
@pytest.mark.parametrize("paced", [True, False])
def test_live_brains_that_end_their_own_steps_arrive_over_a_lossy_network_and_their_bodies_never_collide(paced):
    """Steps at least an action long (``PibtTiming.pace``, the default) keep this fleet's steps together; without
    the pace its robots run apart, in different steps (rule 4), and arrive without a collision all the same."""
    for seed in range(3):
        scenario = synchronized(crowd(seed, density=0.3, max_ticks=200))
        timing = PibtTiming.for_body(scenario.timing.cell_time, scenario.timing.turn_time)
        timing = timing if paced else dataclasses.replace(timing, pace=0.0)
        fleet = BrainFleet(scenario, timing=timing, loss=0.2, seed=seed, tick=0.01)
        fleet.run(until=120)
        assert fleet.collisions() == [] and all(brain.settled for brain in fleet.brains)
        assert fleet.most_pending <= 1  # a held robot decides no second move before its first is granted
        assert all(brain.synchronized for brain in fleet.brains)
        if not paced:
            assert sum(brain.robot.stats["ahead"] for brain in fleet.brains) > 0  # robots were in different steps


def test_a_robot_off_its_goal_begins_its_next_step_as_its_body_runs_out_of_work():
    """``PibtTiming.lead``: a thesis body's straight move (1 s) is shorter than the pace (a move and a right
    turn, 1.5 s). A lone robot off its goal begins its next step once its body has half an action of work left,
    so its body drives on without a stop; with no lead (a broken variant) each step waits for the pace, and the
    body stands still for half a second after every move. On its goal it does not hurry
    (``test_robots_ending_their_own_steps_take_no_step_shorter_than_an_action_of_their_bodies``)."""
    scenario = Scenario(
        Grid(6, 1), [RobotSpec("a", (0, 0), (5, 0))], timing=Timing(1.0, 0.5),
        policy=PolicyOptions(name="pibt", synchronizer="local"),
    )  # fmt: skip
    timing = PibtTiming.for_body(1.0, 0.5)
    assert (timing.pace, timing.lead) == (1.5, 0.75)
    arrivals = []
    for lead in (timing.lead, 0.0):
        fleet = BrainFleet(scenario, timing=dataclasses.replace(timing, lead=lead))
        arrivals.append(fleet.run(until=30))
        assert fleet.brains[0].settled
    leading, paced = arrivals
    assert leading < 5.2  # five moves of 1 s, one after the other
    assert paced > 7.0  # four waits of half a second between them


CROSS = (
    RobotSpec("a", (0, 2), (4, 2)),
    RobotSpec("b", (4, 2), (0, 2)),
    RobotSpec("c", (2, 0), (2, 4)),
    RobotSpec("d", (2, 4), (2, 0)),
)


@pytest.mark.parametrize("radius", [2, 8])
def test_on_a_perfect_network_live_brains_that_end_their_own_steps_make_the_simulators_moves(radius):
    """Two head-on pairs crossing around a pillar: the cells each robot enters, in order, are the simulator's
    (held robots that gave up stayed a step longer, without changing what the fleet decided next)."""
    policy = PolicyOptions(name="pibt", radius=radius, synchronizer="local")
    scenario = Scenario(Grid(5, 5, [(2, 2)]), CROSS, timing=Timing(1.0, 0.5), policy=policy)
    simulated = SynchronizedRoundsSimulator(scenario).run()
    fleet = BrainFleet(scenario, time_scale=10)
    fleet.run()
    assert fleet.collisions() == [] and all(brain.settled for brain in fleet.brains)
    assert sum(brain.robot.stats["gave_up"] for brain in fleet.brains) > 0
    assert [distinct(path) for path in fleet.decided_paths()] == [distinct(robot.path) for robot in simulated.robots]


def distinct(cells):
    """``cells`` without repeats of the cell before."""
    out = []
    for cell in map(tuple, cells):
        if not out or out[-1] != cell:
            out.append(cell)
    return out


class NeverGivesUp(PibtBrain):
    """A held robot that waits for its grant however long it takes (its brain never gives up)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.robot.give_up = lambda: None


def test_a_held_robot_that_never_gives_up_makes_a_convoy_move_one_body_at_a_time():
    convoy = synchronized(corridor())
    giving_up = BrainFleet(convoy)
    waiting = BrainFleet(convoy, brain_type=NeverGivesUp)
    assert giving_up.run() < waiting.run()
    assert giving_up.collisions() == waiting.collisions() == []


def strip():
    """Robot ``a`` on its goal in a strip two cells wide; ``b``, far to the west, goes to the strip's east end
    through ``a``'s cell (``a`` steps aside and back)."""
    robots = (RobotSpec("a", (8, 0), (8, 0), Heading.EAST), RobotSpec("b", (0, 0), (12, 0), Heading.EAST))
    return Scenario(Grid(13, 2), robots, timing=Timing(0.5, 0.25), policy=PolicyOptions(name="pibt", synchronizer="local"))


class Sleepy(PibtBrain):
    """Broken: rests on its goal whatever its peers send (a message of a later step does not end the rest)."""

    @property
    def resting(self):
        return self.settled


class Dawdling(PibtBrain):
    """Broken: a settled robot behind its peers catches up a step per pace, as a robot on its goal otherwise steps."""

    def _behind(self):
        return False


@pytest.mark.parametrize("loss", [0.0, 0.2])
def test_a_robot_resting_on_its_goal_wakes_for_a_peer_that_comes_and_gives_way(loss):
    """``PibtBrain.resting``: ``a`` begins no step while ``b`` is far; ``b``'s beacons end the rest, ``a`` catches
    up at once, steps aside and back, and both arrive; a robot that sleeps through them stalls ``b`` for good,
    and one that catches up a step per pace holds ``b`` up."""
    fleet = BrainFleet(strip(), loss=loss, seed=3, tick=0.005)
    fleet.run(until=60)
    a, b = fleet.brains
    assert fleet.collisions() == [] and a.settled and b.settled
    assert a.robot.stats["rested"] >= 1 and [cell for _, cell in a.moves] == [(8, 1), (8, 0)]
    dawdling = BrainFleet(strip(), brain_type=Dawdling, loss=loss, seed=3, tick=0.005)
    dawdling.run(until=60)
    assert dawdling.brains[1].settled and dawdling.arrivals[1] > fleet.arrivals[1] + 1.0  # measured, no loss: 9.2 s and 7.5 s
    sleepy = BrainFleet(strip(), brain_type=Sleepy, loss=loss, seed=3, tick=0.005)
    sleepy.run(until=60)
    assert not sleepy.brains[1].settled
