"""The safety layer's lockstep rule (following through handoffs) under an adversarial network.

The lockstep model: time runs in ticks; in each tick robots claim cells, the
network delivers messages, and at the tick's end every robot whose claim has a
majority moves at once (a committed robot always does). Robots on a small grid
claim random neighbouring cells, occupied or not, so that they often claim the
cell of a robot that leaves it. An adversary holds every message in a bag and
delivers any of them, in any order, any number of times, in this tick or a
later one, or never. Robots crash between ticks. With standing claims
(``keep_refused``), a refused claim is kept over ticks until its robot gives it
up, and its replicas grant it on a handoff or on the release of the cell.

Checked after every delivery: the cells robots *cover* in the lockstep
argument of ``docs/protocol.md`` (Present until handed off, and the cell of a
claim that won its majority) are pairwise disjoint. Checked at every tick's
end: no two robots on one cell, no swap, no rotation. Broken variants of the
rule (a handoff before the robot's own majority, a replica that gives its own
cell away while it only claims another, a committed robot that stays, a
replica that takes a stale handoff, a replica that grants a standing claim on
a release that did not free the cell) must be caught.
"""

import random
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_safety import GrantsOnAnyRelease, caught

from mrmp.centralized.dependencies import rotations_at
from mrmp.protocol.messages import ClaimMessage, HandoffMessage, ReleaseAckMessage, ReleaseMessage, ReplyMessage
from mrmp.protocol.safety import SafetyLayer

SIZE = 3


def neighbours(cell):
    x, y = cell
    return [(x + dx, y + dy) for dx, dy in ((1, 0), (0, 1), (-1, 0), (0, -1)) if 0 <= x + dx < SIZE and 0 <= y + dy < SIZE]


class Node:
    """A robot reduced to its safety layer under the lockstep rule."""

    def __init__(self, index, starts, keep_refused=False):
        self.layer = SafetyLayer(
            index, starts, claim_timeout=6, retry_interval=2, following=True, keep_refused=keep_refused
        )
        self.index = index
        self.seq = 0
        self.crashed = False

    def stamp(self, message):
        self.seq += 1
        return message.with_seq(self.seq)

    def covered(self):
        """Present until handed off, and the cell of a claim with a majority."""
        layer = self.layer
        cells = set() if layer.present_handed_off else {layer.present}
        pending = layer.pending
        if pending is not None and len(pending.votes) >= layer.quorum:
            cells.add(pending.cell)
        return cells


class Adversary:
    def __init__(self, nodes, rng):
        self.nodes, self.rng = nodes, rng
        self.bag = []

    def send(self, node, message, recipients):
        stamped = node.stamp(message)
        self.bag.extend((recipient, stamped) for recipient in recipients if recipient != node.index)

    def send_all(self, node, sends):
        for message, recipients in sends:
            self.send(node, message, recipients)

    def deliver_one(self):
        rng, bag = self.rng, self.bag
        position = rng.randrange(len(bag))
        recipient, message = bag[position]
        fate = rng.random()
        if fate < 0.95:
            bag.pop(position)
        if 0.85 <= fate < 0.95:
            return  # lost
        target = self.nodes[recipient]
        if target.crashed:
            return
        layer = target.layer
        if isinstance(message, ClaimMessage):
            reply = layer.handle_claim(message, claimant_outranks=message.sender < recipient)
            if reply is not None:
                self.send(target, reply, (message.sender,))
        elif isinstance(message, ReplyMessage):
            self.send_all(target, layer.handle_reply(message, 0))
        elif isinstance(message, HandoffMessage):
            self.send_all(target, layer.handle_handoff(message))
        elif isinstance(message, ReleaseMessage):
            self.send(target, layer.handle_release(message), (message.sender,))
            self.send_all(target, layer.take_granted_on_release())
        elif isinstance(message, ReleaseAckMessage):
            layer.handle_release_ack(message)


def assert_disjoint(nodes, where):
    covered = [node.covered() for node in nodes]
    for i in range(len(nodes)):
        for j in range(i + 1, len(nodes)):
            assert not covered[i] & covered[j], f"{where}: robots {i} and {j} both cover {covered[i] & covered[j]}"


def check_tick(tick, before, after):
    """The lockstep referee's rules, and no rotation."""
    assert len(set(after)) == len(after), f"tick {tick}: two robots on one cell: {after}"
    assert rotations_at(tick, before, after) == [], f"tick {tick}: a swap or rotation: {before} -> {after}"


def run(seed, robots, ticks, crashes=True, keep_refused=False):
    """One adversarial lockstep run; returns (moves, following moves).

    With ``keep_refused``, a robot gives its standing claim up (for another claim, or none) half the time.
    """
    rng = random.Random(seed)
    cells = [(x, y) for x in range(SIZE) for y in range(SIZE)]
    starts = rng.sample(cells, robots)
    nodes = [Node(i, starts, keep_refused) for i in range(robots)]
    adversary = Adversary(nodes, rng)
    moves = follows = 0
    for tick in range(1, ticks + 1):
        before_claims = {node.layer.present for node in nodes}
        for node in nodes:
            layer = node.layer
            if not node.crashed and layer.standing and rng.random() < 0.5:
                given_up = layer.give_up_claim()
                adversary.send_all(node, layer.releases_due(tick) + given_up)
            if not node.crashed and layer.pending is None and rng.random() < 0.5:
                occupied = [cell for cell in neighbours(layer.present) if cell in before_claims]
                cell = rng.choice(occupied if occupied and rng.random() < 0.5 else neighbours(layer.present))
                claim = layer.start_claim(cell, tick)
                if claim is not None:
                    adversary.send(node, claim, layer.claim_recipients(cell))
        for event in range(rng.randrange(40)):
            if not adversary.bag:
                break
            adversary.deliver_one()
            assert_disjoint(nodes, f"tick {tick}, event {event}")
        before = [node.layer.present for node in nodes]
        for node in nodes:
            layer = node.layer
            pending = layer.pending
            if not node.crashed and pending is not None and layer.may_enter(pending.cell):
                layer.begin_move(pending.cell)
                layer.end_move(pending.cell)
        after = [node.layer.present for node in nodes]
        check_tick(tick, before, after)
        moved = {before[i] for i in range(robots) if before[i] != after[i]}
        moves += len(moved)
        follows += sum(1 for i in range(robots) if before[i] != after[i] and after[i] in moved)
        for node in nodes:
            if node.crashed:
                continue
            if crashes and rng.random() < 0.0005:
                node.crashed = True
            elif rng.random() < 0.8:
                adversary.send_all(node, node.layer.expire(tick))
        assert_disjoint(nodes, f"end of tick {tick}")
    return moves, follows


@pytest.mark.slow
@settings(max_examples=300, derandomize=True, deadline=None)
@given(seed=st.integers(0, 10**9), robots=st.integers(2, 7))
def test_no_collision_swap_or_rotation_under_the_lockstep_rule(seed, robots):
    run(seed, robots, ticks=150)


@settings(max_examples=150, derandomize=True, deadline=None)
@given(seed=st.integers(0, 10**9), robots=st.integers(2, 7))
def test_no_collision_swap_or_rotation_with_standing_claims(seed, robots):
    run(seed, robots, ticks=150, keep_refused=True)


@pytest.mark.parametrize("keep_refused", [False, True], ids=["refused-given-up", "standing"])
def test_the_adversarial_runs_do_follow(keep_refused):
    """The invariant is not bought by standing still: robots move, and many moves follow a leaving robot."""
    moves, follows = map(sum, zip(*(run(seed, 4, 150, keep_refused=keep_refused) for seed in range(10))))
    assert moves >= 300 and follows >= 30


def test_standing_claims_are_granted_when_the_cell_is_given_up():
    """Pinned, in a fleet of two (both robots replicas of every cell, 2 of 2 needed).

    A and B claim (0, 2) at once; each owns it through its own claim and refuses the other's, so both claims
    stand and nothing is sent again. A decides otherwise and gives its claim up: the cell is free in A's
    registry, so A grants B's standing claim at once, and B has its majority.
    """
    starts = [(0, 0), (0, 1)]
    a, b = (SafetyLayer(i, starts, following=True, keep_refused=True, resend_refused=False) for i in (0, 1))
    claim_a, claim_b = a.start_claim((0, 2), 1), b.start_claim((0, 2), 1)
    a.handle_reply(b.handle_claim(claim_a, claimant_outranks=False), 1)
    b.handle_reply(a.handle_claim(claim_b, claimant_outranks=False), 1)
    assert a.expire(1) == [] and b.expire(1) == []  # both claims stand: nothing is sent again
    assert a.standing and b.standing and b.resend_claim(1) == []
    [(grant, to_b)] = a.give_up_claim()
    assert to_b == (1,) and grant.granted and grant.claim == claim_b.claim
    [(handoff, _)] = b.handle_reply(grant, 2)
    assert b.may_enter((0, 2)) and isinstance(handoff, HandoffMessage)


def test_a_standing_claim_is_granted_when_the_claim_holding_the_cell_is_released():
    """Pinned, in a fleet of five: replica R registered the cell to A's claim, which then won no majority; R
    refused B's claim meanwhile. When A gives its claim up, its release frees the cell at R, and R grants B's
    standing claim with its acknowledgement; a release that frees nothing (a stale one) grants nothing."""
    starts = [(0, 0), (0, 2), (0, 4), (0, 6), (0, 8)]
    layers = [SafetyLayer(i, starts, following=True, keep_refused=True, resend_refused=False) for i in range(5)]
    cell = (3, 3)
    first, second, _ = replicas = layers[0].replicas_of(cell)
    a, b = (layers[i] for i in range(5) if i not in replicas)
    r = layers[first]
    claim_a = a.start_claim(cell, 1)
    a.handle_reply(r.handle_claim(claim_a, claimant_outranks=False), 1)  # A's claim reaches R alone: granted
    claim_b = b.start_claim(cell, 1)
    b.handle_reply(r.handle_claim(claim_b, claimant_outranks=False), 1)  # refused at R: A owns the cell there
    assert b.expire(1) == [] and b.standing
    stale = ReleaseMessage(a.index, 9, claim_a.claim - 1, cell)
    r.handle_release(stale)
    assert r.take_granted_on_release() == []  # it names an older claim: A's record stands, nothing is granted
    a.cancel_claim()
    release = next(message for message, _ in a.releases_due(2) if message.cell == cell)
    ack = r.handle_release(release)
    [(grant, to_b)] = r.take_granted_on_release()
    assert ack.claim == claim_a.claim and to_b == (b.index,) and grant.granted and grant.claim == claim_b.claim
    b.handle_reply(grant, 2)
    b.handle_reply(layers[second].handle_claim(claim_b, claimant_outranks=False), 2)  # its claim reaches a second replica
    assert b.may_enter(cell)



# -- broken variants the adversary must catch ---------------------------------------------------


class EagerHandoff(SafetyLayer):
    """Hands its Present off as soon as it claims, before its own claim has a majority (no commitment)."""

    def start_claim(self, cell, now):
        claim = super().start_claim(cell, now)
        if claim is not None and not self.present_handed_off:
            self.present_handed_off = True
            self._eager = [(HandoffMessage(self.index, 0, self.present_claim, self.present), self.claim_recipients(self.present))]
            if self.index in self.replicas_of(self.present):
                self._eager.extend(self._grant_deferred(self.present))
        return claim

    def cancel_claim(self):
        super().cancel_claim()
        self.present_handed_off = False  # it stays after all (the handoff is out)

    def expire(self, now):
        sends = getattr(self, "_eager", [])
        self._eager = []
        return sends + super().expire(now)


class GivesItsCellWhileClaiming(SafetyLayer):
    """As a replica of its own Present, grants it to a follower while its own claim is only pending (cycles)."""

    def handle_claim(self, message, claimant_outranks):
        if message.cell == self.present and self.pending is not None and not self.present_handed_off:
            self.present_handed_off = True
            try:
                return super().handle_claim(message, claimant_outranks)
            finally:
                self.present_handed_off = bool(self.pending is not None and self.pending.committed)
        return super().handle_claim(message, claimant_outranks)


class CommittedButStays(SafetyLayer):
    """Hands off on its majority, but then does not move if a late refusal comes (the commitment broken)."""

    def may_enter(self, cell):
        pending = self.pending
        return pending is not None and pending.cell == cell and not pending.refused and len(pending.votes) >= self.quorum


class StaleHandoff(SafetyLayer):
    """Takes a handoff for a cell from its registered owner whatever claim it names (a late one included)."""

    def handle_handoff(self, message):
        registration = self._registry.get(message.cell)
        if registration is not None and registration.owner == message.sender:
            message = HandoffMessage(message.sender, message.seq, registration.claim, message.cell)
        return super().handle_handoff(message)


def test_the_adversary_catches_a_replica_that_grants_standing_claims_on_any_release(monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "SafetyLayer", GrantsOnAnyRelease)
    assert caught(lambda seed: run(seed, 5, 150, keep_refused=True), range(30)) > 0


@pytest.mark.parametrize("variant", [EagerHandoff, GivesItsCellWhileClaiming, CommittedButStays])
def test_the_adversary_catches_broken_following(variant, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "SafetyLayer", variant)
    assert caught(lambda seed: run(seed, 5, 150), range(30)) > 0


@pytest.mark.slow
def test_the_adversary_catches_a_replica_that_takes_stale_handoffs(monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "SafetyLayer", StaleHandoff)
    assert caught(lambda seed: run(seed, 5, 300), range(60)) > 0


def test_a_swap_is_refused_a_chain_follows_in_one_tick():
    """Pinned schedules in a fleet of two (both robots replicas of every cell, 2 of 2 needed).

    Swap: each claims the other's cell; each refuses the other (its own Present, not handed off), so
    neither wins a majority, and nobody hands off. Follow: B claims (0, 2) first and hands (0, 1) off;
    A's claim for (0, 1), refused a moment earlier, is granted then: both move in one tick.
    """
    a, b = SafetyLayer(0, [(0, 0), (0, 1)], following=True), SafetyLayer(1, [(0, 0), (0, 1)], following=True)
    claim_a, claim_b = a.start_claim((0, 1), 1), b.start_claim((0, 0), 1)
    reply_to_a, reply_to_b = b.handle_claim(claim_a, False), a.handle_claim(claim_b, False)
    assert not reply_to_a.granted and not reply_to_b.granted
    assert a.handle_reply(reply_to_a, 1) == [] and b.handle_reply(reply_to_b, 1) == []
    assert not a.may_enter((0, 1)) and not b.may_enter((0, 0))

    a, b = SafetyLayer(0, [(0, 0), (0, 1)], following=True), SafetyLayer(1, [(0, 0), (0, 1)], following=True)
    claim_a = a.start_claim((0, 1), 1)
    assert not b.handle_claim(claim_a, False).granted  # B stands there: refused, and remembered
    claim_b = b.start_claim((0, 2), 1)
    handoff = b.handle_reply(a.handle_claim(claim_b, False), 1)  # A grants (0, 2): B has its majority
    assert b.may_enter((0, 2)) and b.pending.committed
    [(message, recipients), (grant, to_a)] = handoff
    assert isinstance(message, HandoffMessage) and message.cell == (0, 1) and recipients == (0,)
    assert grant.granted and grant.claimant == 0 and to_a == (0,)  # B, as replica of (0, 1), grants A's claim now
    assert a.handle_handoff(message) == []  # A's own vote for (0, 1): now its own
    a.handle_reply(grant, 1)
    assert a.may_enter((0, 1))


def test_a_claim_short_of_its_majority_is_resent_to_the_missing_replicas_only():
    """The lockstep tick's second round: a lost answer is asked for again at once (retry interval 0)."""
    starts = [(0, 0), (1, 1), (2, 2), (0, 2)]
    layer = SafetyLayer(3, starts, retry_interval=0, following=True)
    cell = next((x, y) for x in range(3, 20) for y in range(3, 20) if 3 not in layer.replicas_of((x, y)))
    claim = layer.start_claim(cell, 5)
    first, second, third = layer.replicas_of(cell)
    layer.handle_reply(ReplyMessage(first, 1, 3, claim.claim, cell, True), 5)
    [(again, recipients)] = layer.resend_claim(5)
    assert again.claim == claim.claim and recipients == (second, third)
    layer.handle_reply(ReplyMessage(second, 1, 3, claim.claim, cell, True), 5)
    assert layer.resend_claim(5) == [] and layer.may_enter(cell)  # committed: nothing to resend
    late = SafetyLayer(3, starts, retry_interval=2, following=True)
    late.start_claim(cell, 5)
    assert late.resend_claim(5) == [] and len(late.resend_claim(7)) == 1  # not before its answers are due
    for following, resent in ((True, (first, second, third)), (False, None)):
        refused = SafetyLayer(3, starts, retry_interval=0, following=following)
        number = refused.start_claim(cell, 5).claim
        refused.handle_reply(ReplyMessage(first, 1, 3, number, cell, False), 5)
        sends = refused.resend_claim(5)  # lockstep: the refusing replica may have granted it since, the grant lost
        assert (sends[0][1] if sends else None) == resent
