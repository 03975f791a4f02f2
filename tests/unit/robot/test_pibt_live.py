"""``pibt``'s live brain: it knows, instead of sensing, which robots can be near; safe in crowds; what it answers."""

import heapq
import itertools
import math
import random

import pytest
from test_pibt_local import FAULTS, crowd

from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario, Timing
from mrmp.core.heading import Heading
from mrmp.live.body import OccupancyRecorder, SimulatedBody
from mrmp.live.pibt_agent import PibtBrain, PibtTiming
from mrmp.protocol.messages import BeaconMessage, FarewellMessage, StateMessage
from mrmp.protocol.pibt_local import CallAckMessage, CallInheritMessage, CallReserveMessage, NewsBeaconMessage
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_live import LivePibtRobot
from mrmp.robot.pibt_synchronized import SynchronizedPibtRobot
from mrmp.search.flat_map import FlatMap
from mrmp.sim.live_rounds import LiveRoundsSimulator


@pytest.mark.slow
@pytest.mark.parametrize("faults", ["perfect", *FAULTS])
@pytest.mark.parametrize("seed", range(8))
def test_crowds_never_collide(seed, faults):
    network = FAULTS.get(faults, NetworkFaults())
    scenario = crowd(seed, density=0.5, max_ticks=200).with_changes(network=network)
    result = LiveRoundsSimulator(scenario, step_ticks=8 * (2 * network.delay_max + 1)).run()
    assert result.collisions == []


def test_on_a_perfect_network_every_robot_arrives_and_no_step_is_abandoned():
    for seed in range(6):
        result = LiveRoundsSimulator(crowd(seed, density=0.3, max_ticks=2000), step_ticks=2).run()
        assert result.success and result.network["abandoned"] == 0


class Forgetful(LivePibtRobot):
    """Broken: a peer is taken to be where it was last heard of, as if it had not moved since."""

    def possibly_within(self, radius):
        cells = self.flat.cells
        x, y = cells[self.present]
        return sorted(
            peer for peer, (cell, _) in self.known.items() if abs(cells[cell][0] - x) + abs(cells[cell][1] - y) <= radius
        )


class Boastful(LivePibtRobot):
    """Broken: the news its beacon tells is stamped with the current step, as if heard at its start."""

    def _fresh_news(self):
        return tuple((peer, cell, self.step) for peer, cell, _ in super()._fresh_news())


@pytest.mark.slow
@pytest.mark.parametrize("brain", [Forgetful, Boastful])
def test_a_robot_that_forgets_that_peers_move_or_tells_old_news_as_new_collides(brain):
    class Simulator(LiveRoundsSimulator):
        robot_type = reliable_type = brain

    collided = 0
    for seed in range(20):
        scenario = crowd(seed, density=0.5, max_ticks=60)
        assert LiveRoundsSimulator(scenario, step_ticks=2).run().collisions == []
        collided += len(Simulator(scenario, step_ticks=2).run().collisions)
    assert collided > 0


def line(length):
    flat = FlatMap(Grid(length, 1))
    return flat, [flat.index((x, 0)) for x in range(length)]


def test_a_peer_not_heard_of_for_steps_is_waited_for_and_its_beacon_pulled():
    flat, cells = line(8)
    a = LivePibtRobot(0, cells[0], cells[1], flat, starts=[cells[0], cells[6]])
    b = LivePibtRobot(1, cells[6], cells[7], flat, starts=[cells[0], cells[6]])
    a.step = b.step = 4  # three steps without news: b can be anywhere within 4 + 2 of a's cell
    sent = a.begin_step(5)
    assert [item.recipients for item in sent] == [(1,)] and not a.complete
    b.learn(0, cells[0], 5)  # b knows a freshly: it did not address a, and answers a's beacon with its own
    assert b.begin_step(5)[0].recipients == ()
    b.receive(sent[0].message)
    answers = [item for item in b.act() if isinstance(item.message, BeaconMessage)]
    assert [item.recipients for item in answers] == [(0,)] and b.stats["pulled"] == 1
    a.receive(answers[0].message)
    assert a.complete and a.known[1] == (cells[6], 5)


@pytest.mark.parametrize("brain", [LivePibtRobot, SynchronizedPibtRobot])
def test_a_peer_that_fresher_news_puts_out_of_reach_is_no_longer_waited_for(brain):
    flat, cells = line(12)
    a = brain(0, cells[0], cells[1], flat, starts=[cells[0], cells[4]])
    sent = a.begin_step(3)  # no news for two steps: robot 1, 4 cells away at step 1, can be within 2 now
    assert [item.recipients for item in sent] == [(1,)] and not a.complete
    a.learn(1, cells[11], 3)  # a fleet heartbeat: at the start of this step it stood 11 cells away
    assert a.complete and a.wake
    resent = a.on_tick(10 * a.retry)
    assert all(1 not in (item.recipients or ()) for item in resent)  # nor asked again for a beacon that will not come


def test_a_neighbours_news_spares_a_wait_for_a_peer_it_puts_out_of_reach():
    flat, cells = line(12)
    starts = [cells[0], cells[2], cells[5]]
    a = LivePibtRobot(0, cells[0], cells[1], flat, starts=starts)
    b = LivePibtRobot(1, cells[2], cells[3], flat, starts=starts)
    b.learn(2, cells[7], 3)  # b heard robot 2 at the start of step 3; a last knew it 5 cells away at step 1
    a.begin_step(4)
    assert not a.complete  # robot 2 can be within 2 + 3 of where a last knew it: a waits for its beacon
    beacon = b.begin_step(4)[0].message
    assert beacon.news == ((2, (7, 0), 3),)  # only what is fresh: b's news of a is from step 1
    a.receive(beacon)
    assert a.known[2] == (cells[7], 3) and a.complete  # 7 cells away a step ago: out of reach, not waited for


def test_news_of_a_later_step_of_no_robot_or_of_no_cell_is_not_taken():
    flat, cells = line(12)
    starts = [cells[0], cells[2], cells[5]]
    a = LivePibtRobot(0, cells[0], cells[1], flat, starts=starts)
    a.begin_step(4)
    news = ((2, (9, 0), 5), (7, (3, 0), 3), (2, (40, 0), 3), (0, (11, 0), 4))
    a.receive(NewsBeaconMessage(1, 1, 4, (2, 0), (3, 0), 0, 0, news=news))
    assert a.known[2] == (cells[5], 1) and not a.complete  # where it stands at step 5 does not bound step 4
    assert a.dropped["bad_news"] == 2  # robot 7 is not in the fleet; (40, 0) is off the map; news of a itself ignored


def test_a_message_of_the_next_step_waits_for_that_step():
    flat, cells = line(4)
    starts = [cells[0], cells[1]]
    a, b = LivePibtRobot(0, cells[0], cells[3], flat, starts=starts), LivePibtRobot(1, cells[1], cells[2], flat, starts=starts)
    a.begin_step(1)
    beacon = b.begin_step(1)[0].message
    b.finish_step()
    early = b.begin_step(2)[0].message
    assert a.receive(early) is False and not a.complete
    a.receive(beacon)
    a.finish_step()
    a.begin_step(2)
    assert a.complete and a.known[1] == (cells[1], 2)


def test_a_held_robot_answers_a_request_once_its_move_is_allowed_or_refuses_it_when_it_gives_up():
    flat, cells = line(5)
    starts = [cells[0], cells[1]]
    for allowed in (True, False):
        b = LivePibtRobot(1, cells[1], cells[4], flat, starts=starts)
        b.begin_step(3, held=True)
        b.receive(BeaconMessage(0, 1, 3, (0, 0), (4, 0), 9, 9))
        b.receive(CallInheritMessage(0, 2, 3, (1, 0), 0, 9, 9))
        assert not [item for item in b.act() if type(item.message).__name__ == "AnswerMessage"]  # it waits
        b.release() if allowed else b.give_up()
        sent = b.act()
        answers = [item.message for item in sent if type(item.message).__name__ == "AnswerMessage"]
        if allowed:
            # it took the request up: nobody else can claim (2, 0), so it leaves for it for good at once
            assert [answer.moved for answer in answers] == [True] and flat.cell(b.target) == (2, 0) and b.final
        else:
            assert [answer.moved for answer in answers] == [False] and b.stats["gave_up"] == 1


def test_a_held_robot_that_gives_up_stays_for_good_at_once_only_when_nobody_next_to_its_cell_is_undecided():
    flat, cells = line(5)
    for neighbour in (False, True):
        starts = [cells[1], cells[2]] if neighbour else [cells[1]]
        b = LivePibtRobot(0, cells[1], cells[4], flat, starts=starts, tie=5)
        b.begin_step(3, held=True)
        if neighbour:  # robot 1 next to b's cell, of lower priority: it has not decided when b's turn comes
            b.receive(BeaconMessage(1, 1, 3, (2, 0), (0, 0), 0, 0))
        b.act()
        assert b.target is None  # held: it does not start
        b.give_up()
        reservations = [item.message for item in b.act() if isinstance(item.message, CallReserveMessage)]
        assert b.target == cells[1]  # it stays
        assert [message.final for message in reservations] == [not neighbour]
        assert b.final is (not neighbour) and b.stats["settled_at_once"] == (0 if neighbour else 1)


# -- the live brain (PibtBrain) in steps on a clock, its bodies in simulated real time -------------------------


class BrainFleet:
    """``PibtBrain`` robots and simulated bodies on an in-memory network, driven as ``PibtAgent`` drives them.

    Sans-IO: time is a number advanced by ``tick`` seconds; a message arrives
    ``delay`` seconds after it is sent (lost with probability ``loss``); every
    second each robot sends its state to every peer (the fleet heartbeat). Each
    robot's loop is the driver's: messages in, the body (``PibtAgent._step``),
    then the brain's timers.
    """

    def __init__(self, scenario, timing=None, brain_type=PibtBrain, tick=0.005, delay=0.002, loss=0.0, seed=0, time_scale=1.0):
        self.timing = timing or PibtTiming.for_body(
            scenario.timing.cell_time / time_scale, scenario.timing.turn_time / time_scale
        )
        self.scenario, self.tick, self.delay, self.loss = scenario, tick, delay, loss
        self.rng = random.Random(seed)
        self.brains = [brain_type(scenario, index, self.timing) for index in range(len(scenario.robots))]
        self.recorders = [OccupancyRecorder() for _ in scenario.robots]
        self.bodies = [
            SimulatedBody(spec.start, spec.heading, scenario.grid, scenario.timing, time_scale, recorder=recorder)
            for spec, recorder in zip(scenario.robots, self.recorders, strict=True)
        ]
        self.inbox: list[tuple[float, int, int, object]] = []
        self.sent = 0
        self.most_pending = 0
        """The most moves one robot had decided and not yet been granted at once (the deadlock argument needs 1)."""
        self.decided_while_moving = 0
        """Moves decided while the robot's body was still performing the one before."""
        self.arrivals: list[float | None] = [None] * len(self.brains)
        self.now = 0.0

    def send(self, sender, outgoing):
        for item in outgoing:
            recipients = item.recipients
            if item.radius is not None:
                recipients = (*self.brains[sender].robot.possibly_within(item.radius), *(recipients or ()))
            if recipients is None:
                recipients = [peer for peer in range(len(self.brains)) if peer != sender]
            for peer in dict.fromkeys(recipients):
                self.sent += 1
                if self.rng.random() >= self.loss:
                    heapq.heappush(self.inbox, (self.now + self.delay, self.sent, peer, item.message))

    def run(self, until=120.0):
        """Run until every robot is settled (or ``until`` seconds); return the time the last body arrived."""
        for brain in self.brains:
            brain.start(0.0)
        heartbeat = 0.0
        while self.now < until and not all(brain.settled for brain in self.brains):
            while self.inbox and self.inbox[0][0] <= self.now:
                _, _, peer, message = heapq.heappop(self.inbox)
                self.send(peer, self.brains[peer].receive(message, self.now))
            for index, (brain, body) in enumerate(zip(self.brains, self.bodies, strict=True)):
                if body.moving and body.poll(self.now):
                    brain.arrived_at(body.cell)
                    self.arrivals[index] = self.now
                if not body.moving:  # in the turn the body arrives too, as the driver does
                    target, out = brain.motion(self.now)
                    self.send(index, out)
                    if target is not None:
                        body.start_move(target, self.now)
                decided = len(brain.moves)
                self.send(index, brain.expire(self.now))
                self.most_pending = max(self.most_pending, len(brain.queue))
                self.decided_while_moving += len(brain.moves) > decided and body.moving
            if self.now >= heartbeat:
                heartbeat += 1.0
                for index, brain in enumerate(self.brains):
                    self.send(index, [Outgoing(brain.state(), None)])
            self.now = round(self.now + self.tick, 6)
        return max((t for t in self.arrivals if t is not None), default=0.0)

    def collisions(self):
        """Pairs of robots whose bodies covered one cell at once (ground truth, as the referee sees it)."""
        covering: dict = {}
        for index, (spec, recorder) in enumerate(zip(self.scenario.robots, self.recorders, strict=True)):
            since = {spec.start: -1.0}
            for event, cell, t in recorder.events:
                if event == "enter":
                    since[cell] = t
                else:
                    covering.setdefault(cell, []).append((since.pop(cell), t, index))
            for cell, t in since.items():
                covering.setdefault(cell, []).append((t, math.inf, index))
        clashes = set()
        for intervals in covering.values():
            for a, b in itertools.combinations(intervals, 2):
                if a[2] != b[2] and a[0] < b[1] and b[0] < a[1]:
                    clashes.add((min(a[2], b[2]), max(a[2], b[2])))
        return sorted(clashes)

    def decided_paths(self):
        """Every robot's decided cells, from its start, in order."""
        return [
            [spec.start, *(cell for _, cell in brain.moves)]
            for spec, brain in zip(self.scenario.robots, self.brains, strict=True)
        ]


def test_a_beacon_is_not_acknowledged_and_goes_again_only_to_ask_the_peers_whose_beacon_is_missing():
    flat, cells = line(8)
    starts = [cells[2], cells[0], cells[4]]  # b and c both within the radio radius of a
    a, b, c = (LivePibtRobot(index, starts[index], cells[7], flat, starts=starts) for index in range(3))
    sent = a.begin_step(1)
    assert [item.recipients for item in sent] == [(1, 2)]
    b.begin_step(1)  # b's beacon to a is lost
    b.receive(sent[0].message)  # c's copy of a's beacon is lost
    assert b.act() == []  # a beacon is not acknowledged
    resent = [item for item in a.on_tick(a.beacon_retry) if isinstance(item.message, BeaconMessage)]
    assert [(item.recipients, item.message.asks) for item in resent] == [((1, 2), True)]
    b.receive(resent[0].message)  # a second copy, but it asks: b answers with its beacon
    answer = b.act()
    assert [(item.recipients, type(item.message)) for item in answer] == [((0,), NewsBeaconMessage)]
    a.receive(answer[0].message)
    resent = [item for item in a.on_tick(2 * a.beacon_retry) if isinstance(item.message, BeaconMessage)]
    assert [item.recipients for item in resent] == [(2,)] and c.index == 2  # only c's beacon is still missing


@pytest.mark.parametrize("longest", [1, 2, 4])
def test_asks_for_a_missing_beacon_come_at_gaps_doubling_up_to_the_longest(longest):
    """A robot asks one ``beacon_retry`` after its step's beacon, then at gaps doubling up to ``longest_beacon_gap``
    retries (a live robot over multicast asks every two: ``LONGEST_ASK_GAP_TOGETHER``)."""
    flat, cells = line(8)
    starts = [cells[2], cells[0]]
    a = LivePibtRobot(0, starts[0], cells[7], flat, starts=starts, beacon_retry=10)
    a.longest_beacon_gap = longest
    a.begin_step(1)  # the peer's beacon never comes
    asked = [now for now in range(0, 200) if any(isinstance(item.message, BeaconMessage) for item in a.on_tick(now))]
    gaps = [later - earlier for earlier, later in itertools.pairwise(asked)]
    assert asked[0] == 10
    assert gaps[:4] == {1: [10, 10, 10, 10], 2: [20, 20, 20, 20], 4: [20, 40, 40, 40]}[longest]
    a.begin_step(2, now=200)  # a new step asks one beacon_retry after its beacon again
    assert not any(isinstance(item.message, BeaconMessage) for item in a.on_tick(209))
    assert any(isinstance(item.message, BeaconMessage) for item in a.on_tick(210))


class DeafToAsking(LivePibtRobot):
    """Broken: answers a beacon only when it did not send its own to that peer, never because the beacon asks."""

    def _take_step_beacon(self, sender, cell, asks):
        super()._take_step_beacon(sender, cell, asks=False)


@pytest.mark.parametrize("brain", [LivePibtRobot, DeafToAsking])
def test_a_robot_whose_peers_beacon_was_lost_asks_for_it_and_is_answered(brain):
    """The robot that waits for a beacon asks for it until it comes (``docs/protocol.md``, "A beacon is not
    acknowledged"): ``b`` has ``a``'s beacon and nothing tells it that ``a`` lacks its own but ``a``'s asking.
    A robot deaf to the asking leaves its peer waiting for good."""
    flat, cells = line(8)
    starts = [cells[2], cells[3]]
    a, b = (brain(index, starts[index], cells[7 - 7 * index], flat, starts=starts, retry=15, beacon_retry=30)
            for index in range(2))  # fmt: skip
    b.begin_step(1, now=0)  # lost
    b.receive(a.begin_step(1, now=0)[0].message)
    robots = (a, b)
    for now in range(30, 30 * 20, 30):
        out = [item for robot in robots for item in robot.on_tick(now)]
        while out:
            for item in out:
                for recipient in item.recipients:
                    robots[recipient].receive(item.message)
            out = [item for robot in robots for item in robot.act()]
        if a.complete:
            break
    assert b.complete and a.complete == (brain is LivePibtRobot)
    assert now == 30 or brain is DeafToAsking  # answered at the first asking


def test_a_calls_message_goes_again_after_retry_and_the_beacon_only_after_beacon_retry():
    """The live brain's two intervals (``PibtTiming.for_body``: 15 ms and 30 ms): a message of a call not
    acknowledged goes again every ``retry``; a beacon that asks for a missing one every ``beacon_retry``. The
    broken variant (the beacon on ``retry`` too) sends the beacon again at the first interval."""
    flat, cells = line(8)
    starts = [cells[2], cells[3]]
    a, b = (LivePibtRobot(index, starts[index], cells[7 - 7 * index], flat, starts=starts, retry=15, beacon_retry=30)
            for index in range(2))  # fmt: skip
    a.begin_step(1, now=0)  # its beacon to b is lost
    a.receive(b.begin_step(1, now=0)[0].message)  # a has b's beacon; b never acknowledges anything of a's
    call = [item for item in a.act() if not isinstance(item.message, BeaconMessage | CallAckMessage)]
    assert call and all(item.recipients == (1,) for item in call)  # a's call asks b to leave its cell
    assert a.on_tick(14) == []
    again = a.on_tick(15)
    assert [item.message for item in again] == [item.message for item in call]  # the call's messages, not the beacon
    assert [item.message for item in a.on_tick(30)] == [item.message for item in call]  # b asks for a's beacon itself
    assert b.on_tick(15) == []
    asking = b.on_tick(30)
    assert [(type(item.message), item.recipients, item.message.asks) for item in asking] == [(NewsBeaconMessage, (0,), True)]


def test_a_peer_that_says_farewell_is_an_obstacle_for_good_and_done():
    scenario = corridor(robots=2, length=6)
    brain = PibtBrain(scenario, 0, PibtTiming.for_body(0.5, 0.25))
    brain.start(0.0)
    sent = brain.expire(0.0)
    assert any(1 in (item.recipients or ()) for item in sent)
    brain.receive(FarewellMessage(1, 7, (1, 0)), 0.01)
    assert brain.heard[1] == (math.inf, True) and brain.robot.crashed == {1: brain.flat.index((1, 0))}
    late = StateMessage(1, 6, (1, 0), (1, 0), progress=1)  # a copy sent before the farewell, arriving after it
    assert brain.receive(late, 0.02) == [] and brain.dropped["departed"] == 1 and 1 in brain.robot.crashed
    later = [item for now in (0.05, 0.1, 0.2, 0.8, 1.6) for item in brain.expire(now)]
    assert later and all(1 not in (item.recipients or ()) for item in later)
    assert brain.receive(FarewellMessage(1, 8, (40, 0)), 0.3) == []  # off the map: dropped, counted
    off_map = PibtBrain(scenario, 0, PibtTiming.for_body(0.5, 0.25))
    off_map.receive(FarewellMessage(1, 8, (40, 0)), 0.0)
    assert off_map.dropped["off_map"] == 1 and not off_map.robot.departed


def corridor(robots=3, length=9):
    """``robots`` robots nose to tail at the west end of a one-row corridor, each going ``length - robots`` cells east."""
    specs = tuple(RobotSpec(f"r{i}", (i, 0), (length - robots + i, 0), Heading.EAST) for i in range(robots))
    return Scenario(Grid(length, 1), specs, timing=Timing(0.5, 0.25), policy=PolicyOptions(name="pibt"))


def test_a_move_decided_for_good_is_queued_and_started_before_the_decision_phase_ends():
    scenario = corridor(robots=1)
    brain = PibtBrain(scenario, 0, PibtTiming.for_body(0.5, 0.25))
    brain.start(0.0)
    for now in (0.01, 0.02, 0.03):
        brain.expire(now)
    assert brain.robot.final and brain.queue == [(1, 0)] and brain.step == 1  # its decision phase lasts 0.7 s
    brain.motion(0.04)  # the claim: its only replica is itself, which registers the cell at once
    assert brain.motion(0.05) == ((1, 0), [])  # the body goes, 0.65 s before the decision phase ends


def test_a_convoy_decides_its_next_steps_while_its_bodies_move_and_arrives_sooner_than_with_steps_in_series():
    overlapped = BrainFleet(corridor())
    series = BrainFleet(corridor(), PibtTiming(decide=0.3, step=0.85, retry=0.03, hold=0.15), brain_type=LateBrain)
    assert overlapped.run() < series.run()
    assert overlapped.collisions() == [] and all(brain.settled for brain in overlapped.brains)
    assert overlapped.decided_while_moving > series.decided_while_moving
    assert overlapped.most_pending == 1  # a held robot decides no second move before its first is granted


class LateBrain(PibtBrain):
    """The step in series: a move is queued only when the decision phase ends."""

    def _queue_decided(self):
        self._decided = None


class EagerBrain(PibtBrain):
    """Broken: the body starts into the next decided cell without waiting for its grant."""

    def motion(self, now):
        if self.moving or not self.queue:
            return None, []
        self.moving = True
        cell = self.queue.pop(0)
        if not self.queue:
            self.robot.release()
        return cell, []

    def arrived_at(self, cell):
        self.moving = False


class UnheldBrain(PibtBrain):
    """Broken: a robot whose move has not been granted takes part in the next step as if it had been."""

    def expire(self, now):
        queue, self.queue = self.queue, []  # what begin_step is told: nothing pending
        try:
            return super().expire(now)
        finally:
            self.queue = queue + self.queue


def test_bodies_that_start_before_their_grant_collide():
    guarded = BrainFleet(corridor())
    guarded.run()
    assert guarded.collisions() == [] and all(brain.settled for brain in guarded.brains)
    eager = BrainFleet(corridor(), brain_type=EagerBrain)
    eager.run(until=20)
    assert eager.collisions() != []


def test_a_robot_not_held_decides_a_second_move_before_its_first_is_granted():
    unheld = BrainFleet(corridor(), brain_type=UnheldBrain)
    unheld.run(until=20)
    assert unheld.most_pending > 1


@pytest.mark.parametrize("seed", range(4))
def test_live_brains_in_crowds_over_a_lossy_network_arrive_and_their_bodies_never_collide(seed):
    scenario = crowd(seed, density=0.3, max_ticks=200)
    fleet = BrainFleet(scenario, loss=0.2, seed=seed, tick=0.01)
    fleet.run(until=120)
    assert fleet.collisions() == [] and all(brain.settled for brain in fleet.brains)
    assert fleet.most_pending <= 1


def test_on_a_perfect_network_live_brains_make_the_simulators_decisions():
    """Radius covering the map (the calls run in priority order), moves short beside the decisions: no robot gives
    up a step, and every robot's decided cells are the simulator's."""
    robots = (
        RobotSpec("a", (0, 2), (4, 2)),
        RobotSpec("b", (4, 2), (0, 2)),
        RobotSpec("c", (2, 0), (2, 4)),
        RobotSpec("d", (2, 4), (2, 0)),
    )
    scenario = Scenario(Grid(5, 5, [(2, 2)]), robots, timing=Timing(1.0, 0.5), policy=PolicyOptions(name="pibt", radius=8))
    simulated = LiveRoundsSimulator(scenario, step_ticks=4).run()
    fleet = BrainFleet(scenario, time_scale=10)
    fleet.run()
    assert sum(brain.robot.stats["gave_up"] + brain.robot.stats["abandoned"] for brain in fleet.brains) == 0
    assert [[cell for i, cell in enumerate(path) if i == 0 or path[i - 1] != cell] for path in fleet.decided_paths()] == [
        [tuple(cell) for i, cell in enumerate(robot.path) if i == 0 or robot.path[i - 1] != cell] for robot in simulated.robots
    ]


def test_robots_ending_their_own_steps_take_no_step_shorter_than_an_action_of_their_bodies():
    """``PibtTiming.pace``: robots settled on their goals, side by side, end their steps as soon as they have heard
    each other; they begin one an action apart (a step of the simulator is one action), not as fast as their
    messages go, each step costing beacons. Without the pace (a broken variant) they run many more steps. (They
    do not rest here, as robots all settled would: ``PibtBrain.resting``.)"""
    import dataclasses

    class Restless(PibtBrain):
        resting = False

    robots = (RobotSpec("a", (0, 0), (0, 0)), RobotSpec("b", (0, 1), (0, 1)), RobotSpec("c", (1, 0), (1, 0)))
    scenario = Scenario(Grid(5, 5), robots, timing=Timing(1.0, 0.5), policy=PolicyOptions(name="pibt", synchronizer="local"))
    paced = PibtTiming.for_body(0.5, 0.25)
    assert paced.pace == 0.75

    def steps_in_three_seconds(timing):
        fleet = BrainFleet(scenario, timing, brain_type=Restless)
        for brain in fleet.brains:
            brain.start(0.0)
        while fleet.now < 3.0:
            while fleet.inbox and fleet.inbox[0][0] <= fleet.now:
                _, _, peer, message = heapq.heappop(fleet.inbox)
                fleet.send(peer, fleet.brains[peer].receive(message, fleet.now))
            for index, brain in enumerate(fleet.brains):
                fleet.send(index, brain.expire(fleet.now))
            fleet.now = round(fleet.now + fleet.tick, 6)
        return [brain.step for brain in fleet.brains]

    assert steps_in_three_seconds(paced) == [4, 4, 4]  # steps begin at 0, 0.75, 1.5 and 2.25 s
    assert min(steps_in_three_seconds(dataclasses.replace(paced, pace=0.0))) > 20
