"""The safety layer under an adversarial network: no two robots ever cover one cell.

Robots on a small grid repeatedly claim neighbouring cells, start moving when
allowed, and finish moves at arbitrary times, while an adversary holds every
message in a bag and delivers any of them, in any order, any number of times
(duplication, reordering, delay), or never (loss). Robots may also crash (stop
for ever). After every event, the cells covered by robots (Present, and the cell
being entered) must be pairwise disjoint.
"""

import random
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.protocol.messages import ClaimMessage, ReplyMessage, StateMessage
from mrmp.protocol.safety import SafetyLayer

SIZE = 3  # a 3x3 grid: crowded enough for contention


def neighbours(cell):
    x, y = cell
    return [(x + dx, y + dy) for dx, dy in ((1, 0), (0, 1), (-1, 0), (0, -1)) if 0 <= x + dx < SIZE and 0 <= y + dy < SIZE]


class Node:
    """A robot reduced to its safety layer, with a body that moves when allowed."""

    def __init__(self, index, starts):
        self.layer = SafetyLayer(index, starts, claim_timeout=400, retry_interval=60)
        self.index = index
        self.seq = 0
        self.crashed = False

    def stamp(self, message):
        self.seq += 1
        return type(message)(**{**{f: getattr(message, f) for f in message.__slots__}, "seq": self.seq})

    def state(self):
        self.seq += 1
        layer = self.layer
        return StateMessage(self.index, self.seq, layer.present, layer.present, **layer.state_fields())

    def covered(self):
        layer = self.layer
        return {layer.present} | ({layer.target} if layer.target is not None else set())


def run(seed, robots, steps, oldest_first=False):
    rng = random.Random(seed)
    cells = [(x, y) for x in range(SIZE) for y in range(SIZE)]
    starts = rng.sample(cells, robots)
    nodes = [Node(i, starts) for i in range(robots)]
    bag = []  # (recipient, message)

    def broadcast(node, message):
        bag.extend((other.index, message) for other in nodes if other.index != node.index)

    moves = 0
    for now in range(steps):
        node = rng.choice(nodes)
        action = rng.random()
        if node.crashed:
            pass
        elif action < 0.0005:
            node.crashed = True
        elif action < 0.15 and node.layer.target is None and node.layer.pending is None:
            claim = node.layer.start_claim(rng.choice(neighbours(node.layer.present)), now)
            if claim is not None:
                broadcast(node, node.stamp(claim))
        elif action < 0.3 and node.layer.pending is not None and node.layer.target is None:
            if node.layer.may_enter(node.layer.pending.cell):
                node.layer.begin_move(node.layer.pending.cell)
                broadcast(node, node.state())
        elif action < 0.4 and node.layer.target is not None:
            node.layer.end_move(node.layer.target)
            moves += 1
            broadcast(node, node.state())
        elif action < 0.44:
            resend = node.layer.expire(now)
            if resend is not None:
                broadcast(node, node.stamp(resend))
            broadcast(node, node.state())
        elif action < 0.45 and node.layer.pending is not None and node.layer.target is None:
            node.layer.cancel_claim()
            broadcast(node, node.state())
        elif bag:
            position = rng.randrange(min(len(bag), 3)) if oldest_first else rng.randrange(len(bag))
            recipient, message = bag[position]
            fate = rng.random()
            if fate < 0.8:
                bag.pop(position)  # delivered once (or lost, when the recipient is crashed)
            elif fate < 0.95:
                bag.pop(position)
                continue  # lost
            # else: delivered and kept in the bag: a duplicate may come later
            target = nodes[recipient]
            if target.crashed:
                continue
            if isinstance(message, StateMessage):
                target.layer.handle_state(message)
            elif isinstance(message, ClaimMessage):
                reply = target.layer.handle_claim(message, claimant_outranks=message.sender < recipient)
                if reply is not None:
                    bag.append((message.sender, target.stamp(reply)))
            elif isinstance(message, ReplyMessage):
                target.layer.handle_reply(message, now)
        covered = [node.covered() for node in nodes]
        for i in range(robots):
            for j in range(i + 1, robots):
                assert not covered[i] & covered[j], f"step {now}: robots {i} and {j} both cover {covered[i] & covered[j]}"
    return moves


@settings(max_examples=400, derandomize=True, deadline=None)
@given(seed=st.integers(0, 10**9), robots=st.integers(2, 5))
def test_no_two_robots_ever_cover_one_cell(seed, robots):
    run(seed, robots, steps=1500)


def test_the_adversarial_runs_do_move():
    """The invariant is not bought by standing still: robots do complete moves."""
    assert sum(run(seed, 4, 1500) for seed in range(10)) >= 20


def test_a_late_old_claim_cannot_roll_a_registration_back():
    """The schedule that once let two robots into one cell: U's old claim and old state arrive late at V.

    1. U claims c (claim 1); the claim is late at V. 2. U gives it up: a state (seq 2, no claim), late at V.
    3. U claims c again (claim 2); V grants it: U has U + V, a majority of three, and enters c.
    4. The late claim 1 reaches V. 5. The late state reaches V. 6. W claims c from V.
    V must still hold c for U, and refuse W.
    """
    c = (0, 1)
    starts = [(0, 0), (1, 1), (2, 2)]
    v = SafetyLayer(1, starts)
    late_claim = ClaimMessage(0, 1, 1, c)
    late_state = StateMessage(0, 2, (0, 0), (0, 0))
    reply = v.handle_claim(ClaimMessage(0, 3, 2, c), claimant_outranks=False)
    assert reply.granted and v.owner_of(c) == 0
    assert v.handle_claim(late_claim, claimant_outranks=False) is None  # older than claim 2: over
    v.handle_state(late_state)
    assert v.owner_of(c) == 0
    assert not v.handle_claim(ClaimMessage(2, 1, 1, c), claimant_outranks=True).granted


def test_retransmitted_claim_never_moves_the_release_point_back():
    v = SafetyLayer(1, [(0, 0), (1, 1)])
    c = (0, 1)
    assert v.handle_claim(ClaimMessage(0, 5, 1, c), claimant_outranks=False).granted
    assert v.handle_claim(ClaimMessage(0, 3, 1, c), claimant_outranks=False).granted  # an older copy of the same claim
    v.handle_state(StateMessage(0, 4, (0, 0), (0, 0)))  # older than the newest copy of the claim
    assert v.owner_of(c) == 0
    v.handle_state(StateMessage(0, 6, (0, 0), (0, 0)))  # newer, shows claim 1 given up and c not covered
    assert v.owner_of(c) is None


class BrokenQuorum(SafetyLayer):
    """A variant that moves without any grant."""

    def may_enter(self, cell):
        return self.pending is not None and self.pending.cell == cell


class EarlyRelease(SafetyLayer):
    """A variant that forgets a peer's cells on any newer state of that peer."""

    def handle_state(self, message):
        self._grants = {cell: grant for cell, grant in self._grants.items() if grant.owner != message.sender}


@pytest.mark.parametrize("variant", [BrokenQuorum, EarlyRelease])
def test_the_adversary_catches_broken_variants(variant, monkeypatch):
    """The harness is strong enough to find the collisions that broken rules allow."""
    monkeypatch.setattr(sys.modules[__name__], "SafetyLayer", variant)
    caught = 0
    for seed in range(40):
        try:
            run(seed, 4, 1500)
        except AssertionError:
            caught += 1
    assert caught > 0


@settings(max_examples=300, derandomize=True, deadline=None)
@given(seed=st.integers(0, 10**9), robots=st.integers(2, 5))
def test_no_overlap_when_old_messages_come_first(seed, robots):
    """An adversary that prefers the oldest messages in flight (late deliveries everywhere)."""
    run(seed, robots, steps=1500, oldest_first=True)
