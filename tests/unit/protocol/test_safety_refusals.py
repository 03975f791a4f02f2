"""A claim refused by one replica of three: given up under the lockstep rule, kept live while the other two may grant.

Live (no lockstep rule), a replica that still records the cell's last owner (its
release is on its way) refuses; the claimant enters on the other two replicas'
grants, a majority, which is all the safety argument uses (``docs/protocol.md``,
"States"). Two refusals leave no majority: the claim is given up.
"""

from __future__ import annotations

import pytest

from mrmp.protocol.messages import ReplyMessage
from mrmp.protocol.safety import SafetyLayer

STARTS = [(0, 0), (0, 1), (0, 2), (0, 3), (0, 4)]
CELL = (7, 7)


def claimed(following: bool) -> tuple[SafetyLayer, tuple[int, ...]]:
    layer = SafetyLayer(0, STARTS, following=following)
    assert layer.start_claim(CELL, now=0.0) is not None
    replicas = layer.claim_recipients(CELL)
    assert len(replicas) == 3  # robot 0 is not a replica of the cell: three others vote
    return layer, replicas


def answer(layer: SafetyLayer, replica: int, granted: bool) -> None:
    assert layer.pending is not None
    layer.handle_reply(ReplyMessage(replica, 1, 0, layer.pending.number, CELL, granted), now=0.0)


def test_live_one_refusal_of_three_costs_nothing_when_the_other_two_grant() -> None:
    layer, (first, second, third) = claimed(following=False)
    answer(layer, first, False)
    layer.expire(0.01)
    assert layer.pending is not None and not layer.may_enter(CELL)  # still hoping for a majority
    answer(layer, second, True)
    answer(layer, third, True)
    assert layer.may_enter(CELL) and layer.stats.refused == 0


def test_live_two_refusals_of_three_give_the_claim_up() -> None:
    layer, (first, second, _) = claimed(following=False)
    answer(layer, first, False)
    answer(layer, second, False)
    layer.expire(0.01)
    assert layer.pending is None and layer.stats.refused == 1


def test_a_grant_after_a_refusal_from_the_same_replica_replaces_it() -> None:
    """The release of the cell's last owner reached the replica before the claim came again."""
    layer, (first, second, third) = claimed(following=False)
    answer(layer, first, False)
    answer(layer, second, False)
    answer(layer, first, True)  # the resent claim, granted: only the second still refuses
    layer.expire(0.01)
    assert layer.pending is not None
    answer(layer, third, True)
    assert layer.may_enter(CELL)


@pytest.mark.parametrize("granted_by_others", [True, False])
def test_under_the_lockstep_rule_a_refusal_loses_the_claim_unless_a_majority_committed_it(granted_by_others: bool) -> None:
    layer, (first, second, third) = claimed(following=True)
    answer(layer, first, False)
    if granted_by_others:
        answer(layer, second, True)
        answer(layer, third, True)  # committed on its majority: the lockstep rule hands the Present off
        assert layer.may_enter(CELL)
        return
    assert not layer.may_enter(CELL)
    layer.expire(0.01)
    assert layer.pending is None and layer.stats.refused == 1
