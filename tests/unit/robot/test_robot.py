"""The sans-IO robot: its step protocol, its belief, what it sends, and what it drops."""

from mrmp.core import Grid, Heading, RobotSpec
from mrmp.policies.thesis import ThesisPolicy
from mrmp.protocol.codec import encode
from mrmp.protocol.messages import ClaimMessage, ReleaseMessage, ReplyMessage, StateMessage
from mrmp.robot.robot import Robot

STARTS = [(0, 2), (4, 2)]


def robot(index=0, guarded=True):
    spec = RobotSpec("AB"[index], STARTS[index], STARTS[1 - index])
    return Robot(spec, index, Grid(5, 5), ThesisPolicy(), STARTS, guarded=guarded)


def test_guarded_move_needs_the_peers_grant():
    a = robot()
    [state] = a.announce(now=1)
    assert state.message.present == (0, 2) and state.message.next == (1, 2) and state.recipients is None
    [claim] = a.decide(now=1)
    assert isinstance(claim.message, ClaimMessage) and claim.message.cell == (1, 2)
    assert a.motion(now=1) is None  # a fleet of two needs both
    a.receive(ReplyMessage(1, 1, 0, claim.message.claim, (1, 2), True), now=1)
    assert a.motion(now=1) == (1, 2) and a.moving
    assert a.announce(now=1)[0].message.target == (1, 2)  # while moving it covers both cells
    a.arrived_at((1, 2), Heading.NORTH)
    assert a.present == (1, 2) and a.progress == 1 and not a.moving


def test_unguarded_moves_at_once():
    a = robot(guarded=False)
    a.announce(now=1)
    assert a.decide(now=1) == [] and a.motion(now=1) == (1, 2)


def test_refusal_abandons_the_claim_and_the_robot_decides_again():
    a = robot()
    a.announce(now=1)
    [claim] = a.decide(now=1)
    a.receive(ReplyMessage(1, 1, 0, claim.message.claim, (1, 2), False), now=1)
    assert a.motion(now=1) is None
    [release] = a.expire(now=1)  # the replicas that granted it are told the claim is over
    assert isinstance(release.message, ReleaseMessage) and release.message.cell == (1, 2) and release.recipients == (1,)
    assert a.safety.pending is None and a.wanted is None
    assert a.decide(now=2) != []  # a new claim


def test_answers_claims_addressed_back_to_the_claimant():
    b = robot(index=1)
    [reply] = b.receive(ClaimMessage(0, 1, 1, (1, 2)), now=0)
    assert reply.recipients == (0,) and reply.message.granted
    [refusal] = b.receive(ClaimMessage(0, 2, 2, (4, 2)), now=0)  # the cell b stands on
    assert not refusal.message.granted


def test_belief_keeps_the_newest_state_and_the_robot_drops_garbage_and_its_own_messages():
    a = robot()
    a.receive(StateMessage(1, 5, (3, 2), (2, 2)), now=1)
    a.receive(StateMessage(1, 4, (4, 2), (3, 2)), now=2)
    assert a.belief.peers[1].present == (3, 2) and a.belief.stale_messages == 1
    a.receive_datagram(b"\x00garbage", now=3)
    a.receive_datagram(b"\x09" + encode(StateMessage(1, 9, (3, 2), (3, 2)))[1:], now=3)
    a.receive_datagram(encode(StateMessage(0, 9, (0, 2), (0, 2))), now=3)
    assert dict(a.dropped) == {"truncated": 1, "version": 1, "own": 1}
    assert a.belief.peers[1].seq == 5  # none of it changed what the robot knows


def test_heartbeat_while_claiming_repeats_the_claimed_next():
    a = robot()
    a.announce(now=1)
    [claim] = a.decide(now=1)
    assert a.announce(now=2)[0].message.next == claim.message.cell
