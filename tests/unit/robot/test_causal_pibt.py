"""The Causal-PIBT brain: its transitions, and its locks under duplicates, late and malformed messages."""

from dataclasses import replace

from mrmp.core.grid import Grid
from mrmp.protocol.codec import encode
from mrmp.protocol.messages import LockGrantMessage, LockReleaseMessage, LockRequestMessage, StateMessage
from mrmp.robot.causal_pibt import ADD_CHILD, CONTRACTED, EXTENDED, MAX_CLAIM_FAILURES, REQUESTING, CausalRobot


def fleet(grid, starts, goals):
    robots = [CausalRobot(index, grid, starts, goal) for index, goal in enumerate(goals)]
    for robot in robots:  # everyone has heard everyone's state once
        for other in robots:
            if other is not robot:
                robot.receive(other.state_message(), now=0)
    return robots


def deliver(robots, sender, outgoing, now=0, log=None):
    """Deliver ``outgoing`` of robot ``sender`` and every answer, at once and in order (a perfect network)."""
    queue = [(sender, item) for item in outgoing]
    while queue:
        origin, item = queue.pop(0)
        recipients = item.recipients if item.recipients is not None else range(len(robots))
        for recipient in recipients:
            if recipient != origin:
                if log is not None:
                    log.append((origin, recipient, type(item.message).__name__))
                queue.extend((recipient, answer) for answer in robots[recipient].receive(item.message, now))


def activate(robots, index, now=0, log=None):
    deliver(robots, index, robots[index].activate(now), now, log)


def finish_move(robots, index, now=0):
    robot = robots[index]
    cell = robot.motion(now)
    assert cell is not None, "the safety layer should let the body move"
    deliver(robots, index, robot.arrived_at(cell, now), now)


def test_a_lone_robot_walks_to_its_goal_in_three_activations_per_cell():
    (robot,) = fleet(Grid(1, 3), [(0, 0)], [(0, 2)])
    for cell in [(0, 1), (0, 2)]:
        robot.activate(0)
        assert (robot.mode, robot.head) == (REQUESTING, cell)
        robot.activate(0)
        assert robot.mode == EXTENDED
        assert robot.motion(0) == cell
        robot.arrived_at(cell, 1)
        assert (robot.mode, robot.tail, robot.head) == (CONTRACTED, cell, None)
    assert robot.at_goal and robot.reached == 1 and robot.own_priority[0] == 0


def test_priority_inheritance_pushes_a_robot_off_its_goal_and_unlinks_on_extension():
    robots = fleet(Grid(1, 3), [(0, 0), (0, 1)], [(0, 2), (0, 1)])
    a, b = robots
    activate(robots, 0)
    assert (a.mode, a.head) == (REQUESTING, (0, 1))
    activate(robots, 1)  # b sits on its goal, but a, of higher priority, requests its cell
    assert b.parent == 0 and a.children == {1}
    assert b.inherited == a.inherited and (b.mode, b.head) == (REQUESTING, (0, 2))
    activate(robots, 0)
    assert a.mode == REQUESTING, "a waits: b still covers a's head"
    activate(robots, 1)
    assert b.mode == EXTENDED and b.parent == 1 and a.children == set()
    finish_move(robots, 1)
    activate(robots, 0)
    assert a.mode == EXTENDED
    finish_move(robots, 0)
    assert (a.tail, b.tail) == ((0, 1), (0, 2))


def test_a_child_with_no_way_out_backtracks_to_its_parent():
    robots = fleet(Grid(1, 2), [(0, 0), (0, 1)], [(0, 1), (0, 1)])
    a, b = robots
    activate(robots, 0)
    activate(robots, 1)  # b inherits a's priority, but its only neighbour is a's tail, taken by the tree
    assert b.parent == 0 and b.candidates == []
    assert (a.mode, a.head) == (CONTRACTED, None), "b wrote back: a is contracted again"
    assert {(0, 0), (0, 1)} <= a.visited and (0, 1) not in a.candidates


def test_locks_are_taken_in_index_order_and_a_locked_robot_waits_in_line():
    robots = fleet(Grid(1, 3), [(0, 0), (0, 2)], [(0, 2), (0, 0)])
    first = robots[1].activate(0)
    assert [(type(item.message).__name__, item.recipients) for item in first] == [("LockRequestMessage", (0,))]
    for answer in robots[0].receive(first[0].message, 0):  # robot 0 is now locked by robot 1
        assert isinstance(answer.message, LockGrantMessage)
        grant = answer.message
    assert robots[0].activate(0) == [], "robot 0 waits for its own lock"
    assert robots[0].session is not None
    log = []
    deliver(robots, 1, robots[1].receive(grant, 0), log=log)
    assert robots[1].session is None and robots[1].mode == REQUESTING
    assert robots[0].locked_by is None and robots[0].session is None, "robot 0 took its turn as soon as it was released"
    assert robots[0].mode == REQUESTING


def test_duplicates_late_and_foreign_lock_messages_are_harmless():
    robots = fleet(Grid(1, 3), [(0, 0), (0, 2)], [(0, 2), (0, 0)])
    a = robots[0]
    request = LockRequestMessage(1, 50, 7)
    (grant,) = a.receive(request, 0)
    (again,) = a.receive(request, 0)  # a copy: the same grant again
    assert replace(again.message, seq=grant.message.seq) == grant.message
    assert (again.message.locker, again.message.session) == (1, 7) and a.locked_by == (1, 7)
    release = LockReleaseMessage(1, 51, 7, ADD_CHILD)
    (_ack,) = a.receive(release, 0)
    assert a.children == {1} and a.locked_by is None and a.stats["written"] == 1
    (_ack_again,) = a.receive(release, 0)  # a copy of the release: acknowledged, not applied twice
    assert a.stats["written"] == 1 and a.dropped["duplicate_release"] == 1
    assert a.receive(request, 0) == [] and a.dropped["stale_lock_request"] == 1, "a late copy of the request locks nothing"
    assert a.locked_by is None
    a.receive(LockGrantMessage(1, 52, 0, 99, 0, (0, 2), None, True, 0, 1), 0)  # a grant for no activation of a's
    assert a.dropped["stale_grant"] == 1
    a.receive(StateMessage(1, 1, (0, 1), (0, 1)), 0)  # older than the state heard at the start
    assert a.dropped["stale_state"] == 1
    assert a.receive_datagram(encode(LockRequestMessage(1, 60, 8))[:-1], 0) == []
    assert a.dropped["truncated"] == 1
    assert a.receive(LockRequestMessage(9, 1, 1), 0) == [] and a.dropped["unknown_sender"] == 1


def test_a_release_that_overtakes_its_request_keeps_the_request_from_locking():
    robots = fleet(Grid(1, 3), [(0, 0), (0, 2)], [(0, 2), (0, 0)])
    a = robots[0]
    a.receive(LockReleaseMessage(1, 10, 3), 0)  # robot 1 abandoned activation 3 before its request arrived
    assert a.receive(LockRequestMessage(1, 9, 3), 0) == [] and a.locked_by is None


def test_an_activation_without_answers_is_abandoned_and_released_everywhere():
    robots = [CausalRobot(index, Grid(1, 3), [(0, 0), (0, 1)], goal, retry_interval=1, lock_timeout=5) for index, goal in enumerate([(0, 2), (0, 0)])]
    b = robots[1]
    b.receive(robots[0].state_message(), 0)
    (request,) = b.activate(0)
    assert b.expire(1)[0].message == LockRequestMessage(1, request.message.seq + 1, request.message.session)
    releases = b.expire(6)
    assert [type(item.message).__name__ for item in releases] == ["LockReleaseMessage"]
    assert b.stats["abandoned"] == 1 and b.mode == CONTRACTED
    assert b.expire(7)[0].message.session == request.message.session, "the release is resent until acknowledged"
    b.receive(robots[0].receive(releases[0].message, 7)[0].message, 7)
    assert b.session is None


def test_a_head_the_registries_keep_refusing_is_given_up_and_never_entered():
    """Robot 0 has not heard where robot 1 is: its plan extends into robot 1's cell, the safety layer refuses it."""
    robot = CausalRobot(0, Grid(1, 3), [(0, 0), (0, 1)], goal=(0, 2), retry_interval=1)
    robot.known.clear()  # stale knowledge: no robot known nearby, so no lock either
    robot.activate(0)
    robot.activate(0)
    assert (robot.mode, robot.head) == (EXTENDED, (0, 1))
    for now in range(1, 40):
        assert robot.motion(now) is None, "the body never enters a cell registered to another robot"
        robot.expire(now)
        if robot.mode != EXTENDED:
            break
    assert (robot.mode, robot.head, robot.tail) == (CONTRACTED, None, (0, 0))
    assert robot.stats["heads_given_up"] == 1 and robot.claim_failures == MAX_CLAIM_FAILURES
