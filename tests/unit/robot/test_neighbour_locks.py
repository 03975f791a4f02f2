"""The neighbour-lock state machine by itself: its transitions, refusals, timeouts, faulty messages and crashes."""

import pytest

from mrmp.protocol.messages import LockAckMessage, LockGrantMessage, LockReleaseMessage, LockRequestMessage
from mrmp.robot.neighbour_locks import (
    ACTIVATION_TRANSITIONS,
    LOCK_TRANSITIONS,
    ActivationEvent,
    ActivationState,
    LockEvent,
    LockProtocolError,
    LockState,
    NeighbourLocks,
)

RETRY, TIMEOUT = 1.0, 5.0


def grant_of(index):
    """A grant factory: the granting robot's state is its index, told in its tail."""
    return lambda locker, session: LockGrantMessage(index, 0, locker, session, 0, (0, index), None, True, 0, index)


def machines(count):
    return [NeighbourLocks(index, grant_of(index), retry_interval=RETRY, lock_timeout=TIMEOUT) for index in range(count)]


def only(outgoing):
    """The one message of ``outgoing``, with its recipients."""
    (item,) = outgoing
    return item.message, item.recipients


def request(locker, session, seq=1):
    return LockRequestMessage(locker, seq, session)


def deliver(fleet, origin, outgoing, write_backs=None):
    """Deliver ``outgoing`` of ``origin`` and every answer at once (a perfect network); a robot holding every lock
    releases at once with ``write_backs`` (its transition). Returns the messages delivered, as (type name, from, to)."""
    log, queue = [], [(origin, item) for item in outgoing]
    while queue:
        sender, item = queue.pop(0)
        for recipient in item.recipients:
            machine, message = fleet[recipient], item.message
            log.append((type(message).__name__, sender, recipient))
            if isinstance(message, LockRequestMessage):
                answers = machine.take_request(message)
            elif isinstance(message, LockGrantMessage):
                answers = machine.take_grant(message, now=0)
            elif isinstance(message, LockReleaseMessage):
                ack, _ = machine.take_release(message)
                answers = [ack, *machine.serve_line(now=0)]
            else:
                machine.take_ack(message)
                answers = []
            if machine.all_locked:
                answers += machine.release(write_backs or {}, now=0)
            queue.extend((recipient, answer) for answer in answers)
    return log


# -- every allowed transition, and the refusal of every other ----------------------------------------


def activation_in(state):
    """Robot 0 of a pair, its activation driven to ``state`` through the public calls; and robot 1."""
    locker, peer = machines(2)
    if state is ActivationState.IDLE:
        return locker, peer
    (ask,) = locker.begin([1], now=0)
    if state is ActivationState.ACQUIRING:
        return locker, peer
    (grant,) = peer.take_request(ask.message)
    locker.take_grant(grant.message, now=0)
    if state is ActivationState.HOLDING:
        return locker, peer
    locker.release({}, now=0)
    return locker, peer


def do_activation_event(event, locker, peer):
    """Make ``event`` happen to robot 0 through the public calls (the robot's calls, or messages from robot 1)."""
    session = locker.sessions
    if event is ActivationEvent.BEGIN:
        return locker.begin([1], now=0)
    if event is ActivationEvent.ALL_LOCKED:
        return locker.take_grant(grant_of(1)(0, session), now=0)
    if event is ActivationEvent.RELEASE:
        return locker.release({}, now=0)
    if event is ActivationEvent.ABANDON:
        return locker.expire(now=TIMEOUT)
    return locker.take_ack(LockAckMessage(1, 9, 0, session))


@pytest.mark.parametrize(
    ("state", "event", "after"),
    [(state, event, after) for state, moves in ACTIVATION_TRANSITIONS.items() for event, after in moves.items()],
    ids=lambda value: value.name,
)
def test_every_allowed_activation_transition(state, event, after):
    locker, peer = activation_in(state)
    assert locker.activation is state
    do_activation_event(event, locker, peer)
    assert locker.activation is after
    assert locker.idle == (after is ActivationState.IDLE) and locker.all_locked == (after is ActivationState.HOLDING)


CALLS_OF_THE_ROBOT = {ActivationEvent.BEGIN, ActivationEvent.RELEASE}


@pytest.mark.parametrize(
    ("state", "event"),
    [(state, event) for state in ActivationState for event in ActivationEvent if event not in ACTIVATION_TRANSITIONS[state]],
    ids=lambda value: value.name,
)
def test_every_other_activation_event_is_refused_or_leaves_the_state_alone(state, event):
    """The robot's own misuse (begin, release) raises; a message or a timer out of place changes nothing."""
    locker, peer = activation_in(state)
    if event in CALLS_OF_THE_ROBOT:
        with pytest.raises(LockProtocolError, match=f"robot 0's activation cannot {event.value} when {state.value}"):
            do_activation_event(event, locker, peer)
    else:
        do_activation_event(event, locker, peer)
    assert locker.activation is state


def lock_in(state):
    """Robot 1 of a trio, its lock driven to ``state``: free, taken by its own activation, or granted to robot 0."""
    robot = machines(3)[1]
    if state is LockState.HELD_BY_SELF:
        robot.begin([2], now=0)  # its own lock first (index order), then robot 2's
    elif state is LockState.HELD_BY_PEER:
        robot.take_request(request(0, 1))
    return robot


@pytest.mark.parametrize(
    ("state", "event", "after"),
    [(state, event, after) for state, moves in LOCK_TRANSITIONS.items() for event, after in moves.items()],
    ids=lambda value: value.name,
)
def test_every_allowed_lock_transition(state, event, after):
    robot = lock_in(state)
    assert robot.lock is state
    if event is LockEvent.TAKE_OWN:
        robot.begin([2], now=0)
        assert robot.holder == (1, 1)
    elif event is LockEvent.GIVE_BACK_OWN:
        robot.expire(now=TIMEOUT)  # abandoned: its own lock is given back
    elif event is LockEvent.GRANT:
        message, recipients = only(robot.take_request(request(2, 4)))
        assert recipients == (2,) and (message.locker, message.session) == (2, 4) and robot.holder == (2, 4)
    else:
        ack, of_holder = robot.take_release(LockReleaseMessage(0, 2, 1))
        assert of_holder and ack.recipients == (0,)
    assert robot.lock is after
    assert (robot.holder is None) == (after is LockState.FREE)


@pytest.mark.parametrize(
    ("state", "event"),
    [(state, event) for state in LockState for event in LockEvent if event not in LOCK_TRANSITIONS[state]],
    ids=lambda value: value.name,
)
def test_every_move_of_the_lock_outside_its_table_raises(state, event):
    robot = lock_in(state)
    holder = robot.holder
    with pytest.raises(LockProtocolError, match=f"robot 1's lock cannot {event.value} when {state.value}"):
        robot._move_lock(event, (2, 1))
    assert (robot.lock, robot.holder) == (state, holder)


def test_a_lock_taken_while_a_peer_holds_it_waits_in_line_instead():
    robot = lock_in(LockState.HELD_BY_PEER)
    assert robot.begin([2], now=0) == [], "robot 1's own turn waits for robot 0's release"
    assert (robot.lock, robot.holder, robot.activation) == (LockState.HELD_BY_PEER, (0, 1), ActivationState.ACQUIRING)
    assert robot.take_request(request(2, 3)) == [] and robot.stats["busy"] == 1


def test_the_tables_name_every_state():
    assert set(ACTIVATION_TRANSITIONS) == set(ActivationState)
    assert set(LOCK_TRANSITIONS) == set(LockState)
    assert {event for moves in ACTIVATION_TRANSITIONS.values() for event in moves} == set(ActivationEvent)
    assert {event for moves in LOCK_TRANSITIONS.values() for event in moves} == set(LockEvent)


# -- whole activations ------------------------------------------------------------------------------


def test_locks_are_taken_one_at_a_time_in_index_order_and_released_with_the_write_backs():
    fleet = machines(4)
    log = deliver(fleet, 2, fleet[2].begin([3, 0], now=0), write_backs={3: (0x04, ((0, 1),))})
    assert log == [
        ("LockRequestMessage", 2, 0),
        ("LockGrantMessage", 0, 2),
        ("LockRequestMessage", 2, 3),  # its own lock (index 2) was taken between the two, without a message
        ("LockGrantMessage", 3, 2),
        ("LockReleaseMessage", 2, 0),
        ("LockReleaseMessage", 2, 3),
        ("LockAckMessage", 0, 2),
        ("LockAckMessage", 3, 2),
    ]
    assert all(machine.lock is LockState.FREE and machine.idle for machine in fleet)


def test_the_release_carries_what_the_transition_wrote():
    locker, peer = machines(2)
    (ask,) = locker.begin([1], now=0)
    (grant,) = peer.take_request(ask.message)
    assert locker.take_grant(grant.message, now=0) == [] and locker.grants == [grant.message]
    release, recipients = only(locker.release({1: (0x08, ((3, 3),))}, now=0))
    assert recipients == (1,) and (release.session, release.operations, release.visited) == (1, 0x08, ((3, 3),))


def test_a_lone_activation_holds_its_own_lock_and_ends_at_once():
    (robot,) = machines(1)
    assert robot.begin([], now=0) == [] and robot.all_locked and robot.holder == (0, 1)
    assert robot.release({}, now=0) == []
    assert robot.idle and robot.lock is LockState.FREE and robot.session is None


def test_sessions_are_numbered_and_messages_go_out_unnumbered():
    locker, _ = machines(2)
    for number in (1, 2):
        message, _ = only(locker.begin([1], now=0))
        assert (message.session, message.seq) == (number, 0)
        locker.expire(now=100.0 * number)  # abandoned
        locker.take_ack(LockAckMessage(1, 0, 0, number))
        assert locker.idle


def test_the_line_is_first_come_and_keeps_each_lockers_newest_session():
    fleet = machines(4)
    robot = fleet[0]
    robot.take_request(request(1, 1))
    robot.take_request(request(3, 1))
    robot.take_request(request(2, 1))
    robot.take_request(request(3, 2))  # robot 3 abandoned session 1 and asks again: same place in line
    robot.take_release(LockReleaseMessage(1, 5, 1))
    message, recipients = only(robot.serve_line(now=0))
    assert recipients == (3,) and message.session == 2 and robot.holder == (3, 2)
    robot.take_release(LockReleaseMessage(3, 6, 2))
    assert only(robot.serve_line(now=0))[1] == (2,)


def test_a_robot_locked_by_a_peer_takes_its_own_turn_when_released():
    _, robot = machines(2)
    robot.take_request(request(0, 1))  # robot 0 holds robot 1's lock
    assert robot.begin([], now=0) == [] and robot.activation is ActivationState.ACQUIRING
    robot.take_release(LockReleaseMessage(0, 2, 1))
    assert robot.serve_line(now=1) == [] and robot.all_locked and robot.holder == (1, 1)


# -- timeouts ---------------------------------------------------------------------------------------


def test_a_request_is_resent_every_retry_interval_until_granted():
    locker, _ = machines(2)
    first, _ = only(locker.begin([1], now=0))
    assert locker.expire(now=0.5) == []
    again, recipients = only(locker.expire(now=1.0))
    assert again == first and recipients == (1,) and locker.stats["resent"] == 1
    assert locker.expire(now=1.5) == [] and len(locker.expire(now=2.0)) == 1


def test_an_activation_with_no_new_lock_for_the_timeout_is_abandoned_and_released_where_it_asked():
    fleet = machines(3)
    locker = fleet[0]
    (ask,) = locker.begin([1, 2], now=0)
    (grant,) = fleet[1].take_request(ask.message)
    locker.take_grant(grant.message, now=3)  # progress: the deadline counts from here
    assert locker.expire(now=7) and locker.activation is ActivationState.ACQUIRING, "a resent request, not abandoned"
    releases = locker.expire(now=8)
    assert sorted(item.recipients for item in releases) == [(1,), (2,)], "robot 2 was asked and may have granted"
    assert all(item.message.operations == 0 and item.message.visited == () for item in releases)
    assert locker.activation is ActivationState.RELEASING and locker.lock is LockState.FREE
    assert locker.stats["abandoned"] == 1


def test_releases_are_resent_until_every_one_is_acknowledged():
    fleet = machines(3)
    locker = fleet[0]
    (ask,) = locker.begin([1, 2], now=0)
    (grant,) = fleet[1].take_request(ask.message)
    locker.take_grant(grant.message, now=0)  # robot 2 is asked next, and never answers
    locker.expire(now=TIMEOUT)
    assert {item.recipients for item in locker.expire(now=TIMEOUT + RETRY)} == {(1,), (2,)}
    locker.take_ack(LockAckMessage(1, 1, 0, ask.message.session))
    (resent,) = locker.expire(now=TIMEOUT + 2 * RETRY)
    assert resent.recipients == (2,) and locker.stats["resent"] == 3
    locker.take_ack(LockAckMessage(2, 1, 0, ask.message.session))
    assert locker.idle and locker.expire(now=100) == []


def test_an_activation_waiting_in_line_for_its_own_lock_is_abandoned_too():
    _, robot, _ = machines(3)
    robot.take_request(request(0, 1))
    robot.begin([], now=0)
    assert robot.expire(now=TIMEOUT) == [] and robot.idle, "nobody was asked: over at once"
    assert robot.holder == (0, 1) and robot.stats["abandoned"] == 1
    robot.take_release(LockReleaseMessage(0, 2, 1))
    assert robot.serve_line(now=TIMEOUT + 1) == [] and robot.lock is LockState.FREE, "the abandoned turn is not taken"


def test_abandoning_gives_the_own_lock_to_the_next_in_line():
    _, robot, _ = machines(3)
    robot.begin([2], now=0)  # own lock held, robot 2 asked
    robot.take_request(request(0, 4))
    sent = robot.expire(now=TIMEOUT)
    assert [(type(item.message).__name__, item.recipients) for item in sent] == [
        ("LockGrantMessage", (0,)),
        ("LockReleaseMessage", (2,)),
    ]
    assert robot.holder == (0, 4)


# -- duplicated, reordered and stale messages -----------------------------------------------------


def test_a_copy_of_a_request_gets_the_same_grant_again():
    _, robot = machines(2)
    first = robot.take_request(request(0, 3))
    assert robot.take_request(request(0, 3, seq=2)) == first and robot.holder == (0, 3)
    assert robot.stats["busy"] == 0


def test_a_copy_of_a_release_is_acknowledged_and_not_taken_in_again():
    _, robot = machines(2)
    robot.take_request(request(0, 3))
    ack, of_holder = robot.take_release(LockReleaseMessage(0, 4, 3))
    again, of_holder_again = robot.take_release(LockReleaseMessage(0, 4, 3))
    assert of_holder and not of_holder_again and again == ack
    assert robot.dropped["duplicate_release"] == 1


def test_copies_of_grants_and_acks_are_dropped_and_counted():
    fleet = machines(3)
    locker = fleet[0]
    (ask,) = locker.begin([1, 2], now=0)
    (grant,) = fleet[1].take_request(ask.message)
    locker.take_grant(grant.message, now=0)
    assert locker.take_grant(grant.message, now=0) == [] and locker.dropped["stale_grant"] == 1
    (ask_2,) = locker.expire(now=1)  # resent to robot 2
    (grant_2,) = fleet[2].take_request(ask_2.message)
    locker.take_grant(grant_2.message, now=1)
    locker.release({}, now=1)
    ack = LockAckMessage(1, 5, 0, 1)
    locker.take_ack(ack)
    locker.take_ack(ack)
    assert locker.dropped["duplicate_ack"] == 1 and not locker.idle
    locker.take_ack(LockAckMessage(2, 5, 0, 1))
    locker.take_ack(ack)
    assert locker.idle and locker.dropped["stale_ack"] == 1


def test_a_release_that_overtakes_its_request_keeps_the_request_from_locking():
    _, robot = machines(2)
    ack, of_holder = robot.take_release(LockReleaseMessage(0, 9, 3))  # robot 0 abandoned session 3 early
    assert not of_holder and ack.recipients == (0,)
    assert robot.take_request(request(0, 3)) == [] and robot.lock is LockState.FREE
    assert robot.dropped["stale_lock_request"] == 1
    assert robot.take_request(request(0, 2)) == [], "an even older session"
    assert len(robot.take_request(request(0, 4))) == 1, "a newer session locks"


def test_a_grant_out_of_order_or_of_another_session_or_locker_is_dropped():
    fleet = machines(3)
    locker = fleet[0]
    locker.begin([1, 2], now=0)  # robot 1 is asked first
    for stray in (
        grant_of(2)(0, 1),  # robot 2 was not asked yet
        grant_of(1)(0, 7),  # another session
        grant_of(1)(2, 1),  # for another locker
    ):
        assert locker.take_grant(stray, now=0) == []
    assert locker.dropped["stale_grant"] == 3 and locker.session.position == 1


def test_a_late_grant_of_an_abandoned_session_is_dropped_and_its_lock_released():
    locker, peer = machines(2)
    (ask,) = locker.begin([1], now=0)
    (release,) = locker.expire(now=TIMEOUT)  # abandoned before the grant arrived
    (grant,) = peer.take_request(ask.message)  # the request arrives late
    assert locker.take_grant(grant.message, now=TIMEOUT) == [] and locker.dropped["stale_grant"] == 1
    ack, of_holder = peer.take_release(release.message)
    assert of_holder and peer.lock is LockState.FREE
    locker.take_ack(ack.message)
    assert locker.idle


def test_a_waiting_request_whose_session_was_released_meanwhile_is_skipped():
    fleet = machines(3)
    robot = fleet[0]
    robot.take_request(request(1, 1))
    robot.take_request(request(2, 1))  # in line
    robot.take_release(LockReleaseMessage(2, 3, 1))  # robot 2 abandoned its session 1
    robot.take_release(LockReleaseMessage(1, 3, 1))
    assert robot.serve_line(now=0) == [] and robot.lock is LockState.FREE


# -- crashes ----------------------------------------------------------------------------------------


def test_a_crashed_locker_leaves_its_locks_held_and_the_others_time_out():
    """No lease: robot 1 stays locked by robot 0, which crashed; robot 2, asking robot 1, abandons in time."""
    fleet = machines(3)
    crashed, held, other = fleet
    (ask,) = crashed.begin([1, 2], now=0)
    held.take_request(ask.message)  # granted; robot 0 crashes before it hears the grant
    assert held.begin([], now=1) == [], "robot 1's own activation waits in line"
    (asked_first,) = other.begin([0, 1], now=1)  # robot 2 asks robot 0 first: no answer ever
    assert asked_first.recipients == (0,)
    releases = other.expire(now=1 + TIMEOUT)
    assert other.stats["abandoned"] == 1 and {item.recipients for item in releases} == {(0,)}
    assert held.expire(now=1 + TIMEOUT) == [] and held.idle and held.stats["abandoned"] == 1, "its own turn gives up"
    held.expire(now=1000)
    assert held.holder == (0, 1) and held.lock is LockState.HELD_BY_PEER, "the lock has no lease: still held"
    assert held.take_request(request(2, 2)) == [] and held.stats["busy"] == 1


def test_a_restarted_peer_acknowledges_the_release_of_an_activation_it_granted_before_crashing():
    locker, peer = machines(2)
    (ask,) = locker.begin([1], now=0)
    peer.take_request(ask.message)  # granted, then the peer crashes: the grant is lost
    (release,) = locker.expire(now=TIMEOUT)
    assert locker.expire(now=TIMEOUT + RETRY)[0].recipients == (1,), "resent while unanswered"
    restarted = NeighbourLocks(1, grant_of(1), retry_interval=RETRY, lock_timeout=TIMEOUT)
    ack, of_holder = restarted.take_release(release.message)
    assert not of_holder and restarted.lock is LockState.FREE
    locker.take_ack(ack.message)
    assert locker.idle
    assert restarted.take_request(ask.message) == [], "the crashed session's late request locks nothing"
