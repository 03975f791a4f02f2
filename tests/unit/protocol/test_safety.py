"""The safety layer under an adversarial network: no two robots ever cover one cell.

Robots on a small grid repeatedly claim neighbouring cells from the cells'
replicas, start moving when allowed, and finish moves at arbitrary times, while
an adversary holds every message in a bag and delivers any of them, in any
order, any number of times (duplication, reordering, delay), or never (loss).
Robots may also crash (stop for ever). After every event, the cells covered by
robots (Present, and the cell being entered) must be pairwise disjoint. Fleets
of up to seven robots make the replica sets (three robots) proper subsets of the
fleet.
"""

import random
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.protocol import safety
from mrmp.protocol.messages import ClaimMessage, ReleaseAckMessage, ReleaseMessage, ReplyMessage
from mrmp.protocol.replicas import replica_set
from mrmp.protocol.safety import SafetyLayer

SIZE = 3  # a 3x3 grid: crowded enough for contention


def neighbours(cell):
    x, y = cell
    return [(x + dx, y + dy) for dx, dy in ((1, 0), (0, 1), (-1, 0), (0, -1)) if 0 <= x + dx < SIZE and 0 <= y + dy < SIZE]


class Node:
    """A robot reduced to its safety layer, with a body that moves when allowed."""

    def __init__(self, index, starts, waits=False):
        """``waits``: refused claims wait for releases (``waits_for_release``), as live ``pibt`` robots' do."""
        self.layer = SafetyLayer(index, starts, claim_timeout=400, retry_interval=60, waits_for_release=waits)
        self.index = index
        self.seq = 0
        self.crashed = False

    def stamp(self, message):
        self.seq += 1
        return message.with_seq(self.seq)

    def covered(self):
        layer = self.layer
        return {layer.present} | ({layer.target} if layer.target is not None else set())


class Adversary:
    """The bag of messages in flight, and the robots' reactions to what it delivers."""

    def __init__(self, nodes, rng, oldest_first=False):
        self.nodes, self.rng, self.oldest_first = nodes, rng, oldest_first
        self.bag = []  # (recipient, message)

    def send(self, node, message, recipients):
        stamped = node.stamp(message)
        self.bag.extend((recipient, stamped) for recipient in recipients if recipient != node.index)

    def send_all(self, node, sends):
        for message, recipients in sends:
            self.send(node, message, recipients)

    def deliver_one(self, fair=False):
        """Deliver a message of the bag (fair: the oldest, once, never lost)."""
        rng, bag = self.rng, self.bag
        if fair:
            recipient, message = bag.pop(0)
        else:
            position = rng.randrange(min(len(bag), 3)) if self.oldest_first else rng.randrange(len(bag))
            recipient, message = bag[position]
            fate = rng.random()
            if fate < 0.95:
                bag.pop(position)  # delivered once, or lost
            if 0.8 <= fate < 0.95:
                return  # lost
            # else (fate >= 0.95): delivered and kept in the bag: a duplicate may come later
        target = self.nodes[recipient]
        if target.crashed:
            return
        layer = target.layer
        if isinstance(message, ClaimMessage):
            reply = layer.handle_claim(message, claimant_outranks=message.sender < recipient)
            if reply is not None:
                self.send(target, reply, (message.sender,))
        elif isinstance(message, ReplyMessage):
            layer.handle_reply(message, 0)
        elif isinstance(message, ReleaseMessage):
            self.send(target, layer.handle_release(message), (message.sender,))
            self.send_all(target, layer.take_granted_on_release())
        elif isinstance(message, ReleaseAckMessage):
            layer.handle_release_ack(message)


def act(node, adversary, rng, now, crashes=True):
    """One random action of a live robot: crash, claim, move, arrive, run its timers, or give up its claim."""
    layer = node.layer
    action = rng.random()
    if action < 0.0005 and crashes:
        node.crashed = True
    elif action < 0.15 and layer.target is None and layer.pending is None:
        cell = rng.choice(neighbours(layer.present))
        claim = layer.start_claim(cell, now)
        if claim is not None:
            adversary.send(node, claim, layer.claim_recipients(cell))
    elif action < 0.3 and layer.pending is not None and layer.target is None:
        if layer.may_enter(layer.pending.cell):
            layer.begin_move(layer.pending.cell)
            adversary.send_all(node, layer.expire(now))  # a driver runs the timers right after starting a move
    elif action < 0.4 and layer.target is not None:
        layer.end_move(layer.target)
        return True
    elif action < 0.44:
        adversary.send_all(node, layer.expire(now))
    elif action < 0.45 and layer.pending is not None and layer.target is None:
        layer.cancel_claim()
    return False


def assert_disjoint(nodes, now):
    covered = [node.covered() for node in nodes]
    for i in range(len(nodes)):
        for j in range(i + 1, len(nodes)):
            assert not covered[i] & covered[j], f"step {now}: robots {i} and {j} both cover {covered[i] & covered[j]}"


def adversarial_run(seed, robots, steps, make_node, act_once, check, oldest_first=False):
    """``robots`` nodes (``make_node(index, starts)``) on the grid, each event either a random node's action
    (``act_once(node, nodes, adversary, rng, now)``, True when a move ended) or a delivery of the adversary's;
    ``check(nodes, now)`` after every event. Returns how many moves ended."""
    rng = random.Random(seed)
    cells = [(x, y) for x in range(SIZE) for y in range(SIZE)]
    starts = rng.sample(cells, robots)
    nodes = [make_node(index, starts) for index in range(robots)]
    adversary = Adversary(nodes, rng, oldest_first)
    moves = 0
    for now in range(steps):
        node = rng.choice(nodes)
        if rng.random() < 0.55 and not node.crashed:
            moves += act_once(node, nodes, adversary, rng, now)
        elif adversary.bag:
            adversary.deliver_one()
        check(nodes, now)
    return moves


def run(seed, robots, steps, oldest_first=False, waits=False):
    def make_node(index, starts):
        return Node(index, starts, waits)

    def act_once(node, nodes, adversary, rng, now):
        return act(node, adversary, rng, now)

    return adversarial_run(seed, robots, steps, make_node, act_once, assert_disjoint, oldest_first)


@pytest.mark.slow
@settings(max_examples=400, derandomize=True, deadline=None)
@given(seed=st.integers(0, 10**9), robots=st.integers(2, 7))
def test_no_two_robots_ever_cover_one_cell(seed, robots):
    run(seed, robots, steps=1500)


@pytest.mark.slow
def test_the_adversarial_runs_do_move():
    """The invariant is not bought by standing still: robots do complete moves, in small and larger fleets."""
    assert sum(run(seed, 4, 1500) for seed in range(10)) >= 20
    assert sum(run(seed, 6, 1500) for seed in range(10)) >= 20


@pytest.mark.slow
@settings(max_examples=300, derandomize=True, deadline=None)
@given(seed=st.integers(0, 10**9), robots=st.integers(2, 7))
def test_no_overlap_when_old_messages_come_first(seed, robots):
    """An adversary that prefers the oldest messages in flight (late deliveries everywhere)."""
    run(seed, robots, steps=1500, oldest_first=True)


# -- liveness of the registries: on a fair network every release lands ---------------------------


def settle(nodes, adversary, now):
    """Deliver everything, fairly, and run every robot's timers until nothing is in flight."""
    for round_number in range(200):
        for node in nodes:
            if not node.crashed:
                adversary.send_all(node, node.layer.expire(now + 100 * round_number))
        if not adversary.bag:
            return
        while adversary.bag:
            adversary.deliver_one(fair=True)
    raise AssertionError("messages kept flowing")


def stale_registrations(nodes):
    """Registrations that name a robot which neither covers the cell nor claims it."""
    stale = []
    for node in nodes:
        for cell, registration in node.layer._registry.items():
            owner = nodes[registration.owner]
            pending = owner.layer.pending
            if cell not in owner.covered() and not (pending is not None and pending.cell == cell):
                stale.append((node.index, cell, registration.owner))
    return stale


def run_then_settle(seed, robots, steps=800, waits=False):
    """A lossy, duplicating adversary for ``steps`` events (no crash), then a fair network: the stale registrations."""
    rng = random.Random(seed)
    cells = [(x, y) for x in range(SIZE) for y in range(SIZE)]
    starts = rng.sample(cells, robots)
    nodes = [Node(i, starts, waits) for i in range(robots)]
    adversary = Adversary(nodes, rng)
    for now in range(steps):
        node = rng.choice(nodes)
        if rng.random() < 0.55:
            act(node, adversary, rng, now, crashes=False)  # every robot must be able to release
        elif adversary.bag:
            adversary.deliver_one()
    for node in nodes:
        if node.layer.target is not None:
            node.layer.end_move(node.layer.target)
        node.layer.cancel_claim()
    settle(nodes, adversary, steps)
    return stale_registrations(nodes)


@pytest.mark.parametrize("seed", range(30))
def test_every_cell_left_is_free_again_once_the_network_is_fair(seed):
    """Releases are retried until acknowledged: after a lossy spell, no replica keeps a cell for a robot that left it."""
    assert run_then_settle(seed, robots=5) == []


# -- pinned schedules ---------------------------------------------------------------------------


def test_a_late_old_claim_cannot_roll_a_registration_back():
    """U's old claim and its old release arrive late at V, after U's newer claim for the same cell.

    1. U claims c (claim 1); the claim is late at V. 2. U gives it up: Release(c, 1), late at V.
    3. U claims c again (claim 2); V grants it: U has U + V, a majority of three, and enters c.
    4. The late claim 1 reaches V. 5. The late release 1 reaches V. 6. W claims c from V.
    V must still hold c for U, and refuse W.
    """
    c = (0, 1)
    starts = [(0, 0), (1, 1), (2, 2)]
    v = SafetyLayer(1, starts)
    reply = v.handle_claim(ClaimMessage(0, 3, 2, c), claimant_outranks=False)
    assert reply.granted and v.owner_of(c) == 0
    assert v.handle_claim(ClaimMessage(0, 1, 1, c), claimant_outranks=False) is None  # older than claim 2: over
    v.handle_release(ReleaseMessage(0, 2, 1, c))  # releases claim 1, not claim 2
    assert v.owner_of(c) == 0
    assert not v.handle_claim(ClaimMessage(2, 1, 1, c), claimant_outranks=True).granted


def test_a_claim_arriving_after_its_release_is_ignored():
    """A retransmitted claim that comes after its release must not leave a registration nobody will release."""
    v = SafetyLayer(1, [(0, 0), (1, 1)])
    c = (0, 1)
    assert v.handle_claim(ClaimMessage(0, 5, 1, c), claimant_outranks=False).granted
    v.handle_release(ReleaseMessage(0, 6, 1, c))
    assert v.owner_of(c) is None
    assert v.handle_claim(ClaimMessage(0, 3, 1, c), claimant_outranks=False) is None  # an older copy of claim 1
    assert v.owner_of(c) is None


def test_claims_go_to_the_cells_replicas_and_need_a_majority_of_them():
    starts = [(x, 0) for x in range(10)] + [(x, 1) for x in range(10)]
    layer = SafetyLayer(0, starts)
    cell = (5, 5)
    replicas = replica_set(cell, 20)
    claim = layer.start_claim(cell, now=0)
    assert layer.claim_recipients(cell) == tuple(r for r in replicas if r != 0) and len(replicas) == 3
    outsider = next(index for index in range(20) if index not in replicas)
    layer.handle_reply(ReplyMessage(outsider, 1, 0, claim.claim, cell, True), now=0)  # not a replica: not counted
    assert not layer.may_enter(cell)
    for replica in replicas:
        layer.handle_reply(ReplyMessage(replica, 1, 0, claim.claim, cell, True), now=0)
    assert layer.may_enter(cell)
    other = SafetyLayer(outsider, starts)
    assert other.handle_claim(ClaimMessage(0, 1, claim.claim, cell), claimant_outranks=False) is None  # it keeps no registry


def test_a_release_unacknowledged_is_retried_then_given_up():
    layer = SafetyLayer(0, [(0, 0), (1, 1), (2, 2)], retry_interval=1.0)
    assert layer.start_claim((0, 1), now=0) is not None
    layer.handle_reply(ReplyMessage(1, 1, 0, 1, (0, 1), True), now=0)
    layer.begin_move((0, 1))
    layer.end_move((0, 1))
    sent = [layer.expire(now) for now in range(safety.RELEASE_TRIES + 5)]
    releases = [recipients for sends in sent for message, recipients in sends if isinstance(message, ReleaseMessage)]
    assert releases == [(1, 2)] * safety.RELEASE_TRIES
    assert layer.unacknowledged_releases == 0 and layer.stats.releases_given_up == 1
    acked = SafetyLayer(0, [(0, 0), (1, 1), (2, 2)], retry_interval=1.0)
    acked.end_move((1, 0))  # leaves its start (unguarded-style move: claim 0)
    assert [recipients for _, recipients in acked.expire(0)] == [(1, 2)]
    acked.handle_release_ack(ReleaseAckMessage(1, 1, 0, 0, (0, 0)))
    assert [recipients for _, recipients in acked.expire(1)] == [(2,)]  # only the replica that has not answered
    acked.handle_release_ack(ReleaseAckMessage(2, 1, 0, 0, (0, 0)))
    assert acked.expire(2) == [] and acked.unacknowledged_releases == 0


# -- broken variants the adversary must catch -----------------------------------------------------


class BrokenQuorum(SafetyLayer):
    """Moves without any grant."""

    def may_enter(self, cell):
        return self.pending is not None and self.pending.cell == cell


class ForgetfulReplica(SafetyLayer):
    """Drops a registration on any release of its owner, whatever cell and claim it names."""

    def handle_release(self, message):
        self._registry = {cell: r for cell, r in self._registry.items() if r.owner != message.sender}
        return super().handle_release(message)


class EarlyRelease(SafetyLayer):
    """Releases the cell it leaves as soon as its body starts moving, not once it has left it."""

    def begin_move(self, cell):
        self._release(self.present, self.present_claim)
        super().begin_move(cell)


class OwnReplicaSet(SafetyLayer):
    """Computes replica sets of its own (shifted by its index), unlike everyone else."""

    def replicas_of(self, cell):
        return tuple(sorted((replica + self.index) % self.fleet_size for replica in super().replicas_of(cell)))


class ReleaseToWrongReplicas(SafetyLayer):
    """Sends its releases to the replicas of another cell: registrations it leaves behind never go."""

    def claim_recipients(self, cell):
        if self.pending is None or self.pending.cell != cell:
            cell = (cell[0] + 7, cell[1] + 3)
        return super().claim_recipients(cell)


def caught(run_once, seeds):
    """In how many of ``seeds`` the adversarial run ``run_once(seed)`` found two robots covering one cell."""
    count = 0
    for seed in seeds:
        try:
            run_once(seed)
        except AssertionError:
            count += 1
    return count


@pytest.mark.parametrize("variant", [BrokenQuorum, ForgetfulReplica, EarlyRelease, OwnReplicaSet])
def test_the_adversary_catches_unsafe_variants(variant, monkeypatch):
    """The harness is strong enough to find the collisions that broken rules allow."""
    monkeypatch.setattr(sys.modules[__name__], "SafetyLayer", variant)
    assert caught(lambda seed: run(seed, 5, 1500), range(40)) > 0


def test_the_liveness_check_catches_releases_sent_to_the_wrong_replicas(monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "SafetyLayer", ReleaseToWrongReplicas)
    assert any(run_then_settle(seed, robots=5) for seed in range(30))


# -- claims that wait for a release ------------------------------------------------------------


class GrantsOnAnyRelease(SafetyLayer):
    """Grants a claim it refused (standing or waiting) on any release of the cell, also one that did not free it
    (a stale or foreign one, its owner's newer registration still there)."""

    def handle_release(self, message):
        acknowledgement = super().handle_release(message)
        if not self.granted_on_release and message.cell in self._deferred:
            self._registry.pop(message.cell, None)
            self.granted_on_release = self._grant_deferred(message.cell)
        return acknowledgement


@pytest.mark.slow
@settings(max_examples=300, derandomize=True, deadline=None)
@given(seed=st.integers(0, 10**9), robots=st.integers(2, 7))
def test_no_overlap_when_refused_claims_wait_for_releases(seed, robots):
    run(seed, robots, steps=1500, waits=True)
    run(seed, robots, steps=1500, oldest_first=True, waits=True)


def test_waiting_claims_still_move_and_leave_no_stale_registration():
    assert sum(run(seed, 6, 1500, waits=True) for seed in range(10)) >= 20
    assert all(run_then_settle(seed, robots=5, waits=True) == [] for seed in range(20))


def test_the_adversary_catches_a_grant_on_a_release_that_dropped_nothing(monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "SafetyLayer", GrantsOnAnyRelease)
    assert caught(lambda seed: run(seed, 5, 1500, waits=True), range(40)) > 0


def test_a_refused_claim_waits_and_is_granted_with_the_release_of_the_cell():
    """Robot 0 claims robot 1's cell: refused; robot 1 leaves and releases it: the replicas grant at once."""
    cell = next((0, y) for y in range(1, 9) if 0 not in replica_set((0, y), 5))  # robot 0 is none of its replicas
    starts = [(0, 0), cell, (3, 3), (4, 4), (5, 5)]
    layers = [SafetyLayer(index, starts, retry_interval=1.0, waits_for_release=True) for index in range(5)]
    first, leader = layers[0], layers[1]
    claim = first.start_claim(cell, now=0.0)
    replies = [layers[replica].handle_claim(claim, claimant_outranks=False) for replica in first.claim_recipients(cell)]
    for reply in replies:
        first.handle_reply(reply, now=0.0)
    assert not first.may_enter(cell)
    assert first.expire(now=0.5) == [] and first.pending is not None  # refused: it waits, neither given up nor resent yet
    assert [type(message).__name__ for message, _ in first.expire(now=1.5)] == ["ClaimMessage"]  # sent again, grants lost
    leader.begin_move((1, cell[1]))  # unguarded here: the test is about the cell it leaves
    leader.end_move((1, cell[1]))
    grants = []
    for message, recipients in leader.expire(now=2.0):
        for replica in recipients:
            layers[replica].handle_release(message)
            grants.extend(message for message, _ in layers[replica].take_granted_on_release())
    assert len(grants) == 2  # the replicas the release reached grant on it, with no claim sent again: a majority
    for grant in grants:
        first.handle_reply(grant, now=2.0)
    assert first.may_enter(cell)
