"""The live referee for bodies that may be followed while they drive (``turning``): what it accepts and reports.

A follower may cover the cell its leader drives out of when it started strictly
after the leader, not from the leader's next cell, the leader was out by the time
the follower arrived, and the two centres, each moving straight over its recorded
times, stayed at least ``FOOTPRINT`` apart. The referee of bodies that do not
follow (``thesis``) reports every such overlap. Checked on hand-made traces and on
simulated turning bodies driven as the safety layer lets them.
"""

from __future__ import annotations

import math

import pytest

from mrmp.core.body import body_model
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Timing
from mrmp.live.body import OccupancyRecorder, SimulatedBody
from mrmp.live.referee import FOOTPRINT, Interval, IntervalReferee, _closest_approach


def judged(events, starts, follows=True, grid=None):
    """The collisions ``(kind, tick)`` of ``events`` ``(robot, event, cell, t)`` on a 5x5 grid (or ``grid``)."""
    referee = IntervalReferee(grid or Grid(5, 5), ["A", "B", "C"][: len(starts)], starts, 0.0, follows=follows)
    for event in events:
        referee.feed(*event)
    return [(collision.kind, collision.tick) for collision in referee.collisions()]


def follow(leader_start, leader_end, follower_start, follower_end, turn=False):
    """A (row 2) drives from (2, 2) north to (3, 2), or east to (2, 3) with ``turn``; B follows from (1, 2)."""
    ahead = (2, 3) if turn else (3, 2)
    return [
        (0, "enter", ahead, leader_start),
        (1, "enter", (2, 2), follower_start),
        (0, "leave", (2, 2), leader_end),
        (1, "leave", (1, 2), follower_end),
    ]


@pytest.mark.parametrize("turn", [False, True])
def test_a_follower_starting_after_its_leader_is_no_collision(turn):
    assert judged(follow(1.0, 2.0, 1.01, 2.01, turn), [(2, 2), (1, 2)]) == []


@pytest.mark.parametrize("turn", [False, True])
def test_the_same_traces_are_a_collision_for_bodies_that_do_not_follow(turn):
    assert judged(follow(1.0, 2.0, 1.01, 2.01, turn), [(2, 2), (1, 2)], follows=False) == [("vertex", 1010)]


def test_a_follower_starting_with_or_before_its_leader_is_a_collision():
    assert judged(follow(1.0, 2.0, 1.0, 2.0), [(2, 2), (1, 2)]) == [("vertex", 1000)]
    assert judged(follow(1.0, 2.0, 0.9, 1.9), [(2, 2), (1, 2)]) == [("vertex", 900)]


def test_a_follower_faster_than_its_leader_is_a_collision():
    """Started after it, but arrived before the leader was out: it drove into the leader's back."""
    assert judged(follow(1.0, 2.0, 1.1, 1.9), [(2, 2), (1, 2)]) == [("vertex", 1100)]


def test_a_slower_leader_turning_off_brings_the_follower_too_close():
    """The leader turns off at a right angle but takes longer than the follower: out before the follower arrives,
    yet their centres come closer than a footprint."""
    events = follow(1.0, 2.3, 1.01, 2.31, turn=True)
    assert judged(events, [(2, 2), (1, 2)]) == []  # out in time, and at the same speed: far enough
    slow = follow(1.0, 2.5, 1.01, 2.0, turn=True)
    assert judged(slow, [(2, 2), (1, 2)]) == [("vertex", 1010)]


def test_a_leader_that_never_left_is_a_collision_once_its_follower_arrived():
    events = [(0, "enter", (3, 2), 1.0), (1, "enter", (2, 2), 1.5)]  # A started out, and B in behind it
    assert judged(events, [(2, 2), (1, 2)]) == []  # both still drive: nothing to say yet
    stopped = [*events, (1, "leave", (1, 2), 2.5)]  # B arrived, and A is still there: it stopped mid-drive
    assert judged(stopped, [(2, 2), (1, 2)]) == [("vertex", 1500)]


def test_driving_into_each_others_cells_is_still_a_swap():
    events = [(0, "enter", (1, 2), 1.0), (1, "enter", (2, 2), 1.1), (0, "leave", (2, 2), 2.0), (1, "leave", (1, 2), 2.1)]
    assert [kind for kind, _ in judged(events, [(2, 2), (1, 2)])] == ["swap"]


def test_a_chain_of_followers_is_no_collision():
    """C follows B, which follows A, each a moment after the one ahead of it."""
    events = [
        (0, "enter", (4, 2), 1.0),
        (1, "enter", (3, 2), 1.01),
        (2, "enter", (2, 2), 1.02),
        (0, "leave", (3, 2), 2.0),
        (1, "leave", (2, 2), 2.01),
        (2, "leave", (1, 2), 2.02),
    ]
    assert judged(events, [(3, 2), (2, 2), (1, 2)]) == []


def bodies(grid, starts, headings):
    recorders = [OccupancyRecorder() for _ in starts]
    turning = body_model("turning")
    fleet = [
        SimulatedBody(start, heading, grid, Timing(1.0, 1.0), time_scale=1.0, recorder=recorder, model=turning)
        for start, heading, recorder in zip(starts, headings, recorders, strict=True)
    ]
    return fleet, recorders


def referee_of(grid, starts, recorders, follows=True):
    referee = IntervalReferee(grid, ["A", "B", "C"][: len(starts)], starts, 0.0, follows=follows)
    events = sorted((t, robot, event, cell) for robot, recorder in enumerate(recorders) for event, cell, t in recorder.events)
    for t, robot, event, cell in events:
        referee.feed(robot, event, cell, t)
    return referee


@pytest.mark.parametrize("lag", [0.001, 0.2, 0.9])
@pytest.mark.parametrize("leader_heading", [Heading.NORTH, Heading.EAST, Heading.WEST])
def test_simulated_turning_bodies_following_their_leader_are_judged_apart(lag, leader_heading):
    """Two simulated turning bodies: B drives into A's cell ``lag`` seconds after A drove out of it, whichever way
    A went; the footprints' argument holds, and the referee agrees."""
    grid = Grid(5, 5)
    (leader, follower), recorders = bodies(grid, [(2, 2), (1, 2)], [leader_heading, Heading.NORTH])
    assert leader.follows and follower.follows
    leader.start_move(leader_heading.ahead((2, 2)), now=1.0)
    follower.start_move((2, 2), now=1.0 + lag)
    for now in (1.5, 2.0 + lag, 3.0):
        leader.poll(now), follower.poll(now)
    assert referee_of(grid, [(2, 2), (1, 2)], recorders).collisions() == []
    assert [c.kind for c in referee_of(grid, [(2, 2), (1, 2)], recorders, follows=False).collisions()] == ["vertex"]


def test_the_closest_approach_of_a_right_angle_turn_off_is_the_footprint():
    """Started together, a follower and a leader turning off come closest, 1/sqrt(2) cell, half way."""
    assert pytest.approx(1 / math.sqrt(2)) == FOOTPRINT

    leader = Interval(0, (2, 2), 0.0, end=2.0, exit_at=1.0, exit_to=(2, 3))
    assert _closest_approach(leader, Interval(1, (2, 2), 1.0, source=(1, 2), arrived=2.0)) == pytest.approx(FOOTPRINT)
    assert _closest_approach(leader, Interval(1, (2, 2), 1.2, source=(1, 2), arrived=2.2)) > FOOTPRINT
