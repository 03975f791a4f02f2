"""The safety layer's rule for bodies followed while they drive (``releases_on_start``), under an adversarial network.

Live ``turning`` bodies drive straight from cell to cell, all at one speed, so
drives end in the order they began. A robot releases its Present as its body
starts driving out of it; a robot following it in may be granted the cell and
start behind it. The adversary of ``test_safety`` holds every message in a bag
and delivers any of them, in any order, any number of times, or never; robots
crash between drives (a crash mid-drive is outside the rule's assumption, see
``docs/protocol.md``, "Following while driving").

Checked after every event: a cell is covered (stood on, or driven into or out
of) by at most two robots, and when by two, one drives out of it and the other
drives in, the one driving in began after the one driving out, and not from the
cell the other drives to (no swap). Broken variants, caught: a robot that
releases its cell when its claim wins its majority (before its body starts), and
a replica that grants its own Present to a waiting claim as soon as it claims
another cell.
"""

import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_safety import adversarial_run, caught, neighbours

from mrmp.protocol.safety import SafetyLayer


class Node:
    """A robot reduced to its safety layer, with a body that drives when allowed."""

    def __init__(self, index, starts):
        self.layer = SafetyLayer(
            index, starts, claim_timeout=400, retry_interval=60, waits_for_release=True, releases_on_start=True
        )
        self.index = index
        self.seq = 0
        self.crashed = False
        self.began = None
        """When its drive in progress began (an event number), None when it stands."""

    def stamp(self, message):
        self.seq += 1
        return message.with_seq(self.seq)


def act(node, nodes, adversary, rng, now):
    """One random action: crash (standing only), claim, start the drive, end the first drive begun, run the timers,
    or give the claim up. Returns whether a drive ended."""
    layer = node.layer
    action = rng.random()
    if action < 0.0005 and node.began is None:
        node.crashed = True
    elif action < 0.15 and layer.target is None and layer.pending is None:
        cell = rng.choice(neighbours(layer.present))
        claim = layer.start_claim(cell, now)
        if claim is not None:
            adversary.send(node, claim, layer.claim_recipients(cell))
    elif action < 0.3 and layer.pending is not None and layer.target is None:
        if layer.may_enter(layer.pending.cell):
            layer.begin_move(layer.pending.cell)
            node.began = now
            adversary.send_all(node, layer.expire(now))  # a driver runs the timers right after starting a drive
    elif action < 0.4 and node.began is not None:
        first = min(other.began for other in nodes if other.began is not None)
        if node.began == first:  # one speed: drives end in the order they began
            layer.end_move(layer.target)
            node.began = None
            return True
    elif action < 0.44:
        adversary.send_all(node, layer.expire(now))
    elif action < 0.45 and layer.pending is not None and layer.target is None:
        layer.cancel_claim()
    return False


def assert_followed_only(nodes, now):
    """At most a leader driving out and a follower driving in, begun after it and not from its next cell, per cell."""
    covering = {}
    for node in nodes:
        layer = node.layer
        covering.setdefault(layer.present, []).append(node)
        if layer.target is not None:
            covering.setdefault(layer.target, []).append(node)
    for cell, robots in covering.items():
        if len(robots) < 2:
            continue
        assert len(robots) == 2, f"event {now}: {len(robots)} robots on {cell}"
        leader, follower = sorted(robots, key=lambda node: node.layer.target == cell)
        assert leader.layer.present == cell and leader.layer.target not in (None, cell), f"event {now}: two on {cell}"
        assert follower.layer.target == cell, f"event {now}: two on {cell}"
        assert follower.began > leader.began, f"event {now}: {follower.index} drove into {cell} before {leader.index} left"
        assert leader.layer.target != follower.layer.present, f"event {now}: swap of {leader.index}, {follower.index}"


def run(seed, robots, steps, check=assert_followed_only):
    return adversarial_run(seed, robots, steps, Node, act, check)


def followings(seed, robots, steps):
    """How many drives began while the cell's last occupant still drove out of it."""
    count = 0

    def check_and_count(nodes, now):
        nonlocal count
        assert_followed_only(nodes, now)
        for node in nodes:
            target = node.layer.target
            if target is not None and node.began == now:
                count += any(other.layer.present == target and other is not node for other in nodes)

    run(seed, robots, steps, check_and_count)
    return count


@settings(max_examples=300, derandomize=True, deadline=None)
@given(seed=st.integers(0, 10**9), robots=st.integers(2, 7))
def test_a_robot_drives_into_a_cell_only_behind_the_robot_driving_out_of_it(seed, robots):
    run(seed, robots, steps=1500)


def test_robots_do_follow_one_another_in():
    """The invariant is not bought by standing still: robots drive, and drive into cells still being left."""
    assert sum(run(seed, 6, 1500) for seed in range(10)) >= 20
    assert sum(followings(seed, 6, 1500) for seed in range(20)) >= 5


class ReleasesOnItsMajority(SafetyLayer):
    """Releases its Present as soon as its claim has a majority, before its body starts driving."""

    def handle_reply(self, message, now):
        sends = super().handle_reply(message, now)
        pending = self.pending
        if pending is not None and self.may_enter(pending.cell) and not self.present_released:
            self.present_released = True
            self._release(self.present, self.present_claim)
        return sends


class GivesItsCellAwayWhenItClaims(SafetyLayer):
    """As a replica of its own Present, grants a waiting claim for it as soon as it claims another cell."""

    def start_claim(self, cell, now):
        claim = super().start_claim(cell, now)
        if claim is not None and self.index in self.replicas_of(self.present):
            self.present_released = True
            self._grants_on_start.extend(self._grant_deferred(self.present))
        return claim


@pytest.mark.parametrize("variant", [ReleasesOnItsMajority, GivesItsCellAwayWhenItClaims])
def test_the_adversary_catches_cells_given_away_before_the_drive(variant, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "SafetyLayer", variant)
    assert caught(lambda seed: run(seed, 5, 1500), range(40)) > 0
