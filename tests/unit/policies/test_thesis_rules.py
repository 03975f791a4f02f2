"""Each rule of thesis section 3.6 in isolation, and the choices recorded in docs/thesis.md."""

import pytest

from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.policies.base import PeerState, Situation
from mrmp.policies.priority import conflicting_peers, obstacle_found, outranks
from mrmp.policies.thesis import ThesisPolicy, change_of_route, update_coordinate_step


def peer(index, present, next_cell, arrived=False):
    return PeerState(index, present, next_cell, Heading.NORTH, arrived, seq=1, heard_at=0.0)


def situation(present, goal, peers=(), index=0, grid=None):
    return Situation(index, present, Heading.NORTH, goal, grid or Grid(5, 5), {p.index: p for p in peers})


# -- update coordinate method (3.1 item 4, 3.2 assumption 2) -----------------------


def test_update_coordinate_moves_x_first_then_y():
    cell, path = (0, 0), []
    while cell != (4, 4):
        cell = update_coordinate_step(cell, (4, 4))
        path.append(cell)
    assert path == [(1, 0), (2, 0), (3, 0), (4, 0), (4, 1), (4, 2), (4, 3), (4, 4)]


def test_update_coordinate_decrements_too():
    assert update_coordinate_step((4, 2), (0, 2)) == (3, 2)
    assert update_coordinate_step((0, 4), (0, 0)) == (0, 3)


# -- obstacle avoidance ------------------------------------------------------------


def test_obstacle_when_next_equals_other_present():
    assert obstacle_found((2, 2), peer(1, present=(2, 2), next_cell=(2, 1)))


def test_obstacle_when_next_equals_other_next():
    assert obstacle_found((2, 2), peer(1, present=(3, 2), next_cell=(2, 2)))


def test_no_obstacle_otherwise():
    assert not obstacle_found((2, 2), peer(1, present=(3, 2), next_cell=(3, 3)))
    assert conflicting_peers((2, 2), {1: peer(1, (3, 2), (3, 3))}) == []


# -- diversion (priority) ----------------------------------------------------------


@pytest.mark.parametrize(
    ("mine", "other", "i_win"),
    [
        ((3, 0), (1, 4), True),  # Xpresent > Xother: continue
        ((1, 4), (3, 0), False),  # Xpresent < Xother: change the route
        ((2, 3), (2, 1), True),  # equal x, Ypresent > Yother: continue
        ((2, 1), (2, 3), False),  # equal x, Ypresent < Yother: change the route
    ],
)
def test_priority_by_x_then_y(mine, other, i_win):
    assert outranks(mine, 0, other, 1) is i_win


def test_equal_present_breaks_tie_by_index():
    assert outranks((2, 2), 1, (2, 2), 0) and not outranks((2, 2), 0, (2, 2), 1)


# -- change of route, every branch of the pseudo-code --------------------------------


@pytest.mark.parametrize(
    ("present", "goal", "expected", "line"),
    [
        ((1, 0), (4, 4), (1, 1), "5: y differs from destination: step toward it"),
        ((1, 4), (4, 0), (1, 3), "5: step toward it, downward"),
        ((1, 2), (4, 2), (1, 3), "9: y at destination, below Ymax: Update Y (+1)"),
        ((1, 4), (4, 4), (1, 3), "12: y at destination and at Ymax: decrement"),
        ((2, 1), (2, 4), (3, 1), "18: x at destination, below Xmax: Update X (+1)"),
        ((4, 1), (4, 4), (3, 1), "21: x at destination and at Xmax: decrement"),
    ],
)
def test_change_of_route(present, goal, expected, line):
    assert change_of_route(present, goal, x_max=4, y_max=4) == expected, line


# -- the policy: who diverts, who continues ------------------------------------------


def test_lower_priority_diverts_higher_continues():
    policy = ThesisPolicy()
    a = policy.decide(situation((1, 2), (4, 2), [peer(1, (3, 2), (2, 2))], index=0), intended=(2, 2))
    b = policy.decide(situation((3, 2), (0, 2), [peer(0, (1, 2), (2, 2))], index=1), intended=(2, 2))
    assert (a.reason, a.next) == ("divert", (1, 3))
    assert (b.reason, b.next) == ("priority", (2, 2))


def test_with_n_robots_divert_if_any_conflicting_robot_outranks():
    policy = ThesisPolicy()
    peers = [peer(1, (1, 1), (2, 2)), peer(2, (3, 2), (2, 2))]  # one lower, one higher
    decision = policy.decide(situation((2, 3), (2, 0), peers), intended=(2, 2))
    assert decision.reason == "divert" and decision.conflicts == (1, 2)


def test_velocity_tuning_waits_instead_of_diverting():
    decision = ThesisPolicy(resolve="wait").decide(
        situation((1, 2), (4, 2), [peer(1, (3, 2), (2, 2))]), intended=(2, 2)
    )
    assert (decision.reason, decision.next) == ("wait", (1, 2))


def test_blocked_diversion_waits():
    """Choice: a diversion cell that another robot stands on or claims is not entered."""
    peers = [peer(1, (3, 2), (2, 2)), peer(2, (1, 3), (1, 3), arrived=True)]
    decision = ThesisPolicy().decide(situation((1, 2), (4, 2), peers), intended=(2, 2))
    assert (decision.reason, decision.next) == ("blocked", (1, 2))


def test_diversion_off_a_one_cell_wide_grid_waits():
    grid = Grid(5, 1)
    decision = ThesisPolicy().decide(
        situation((1, 0), (4, 0), [peer(1, (3, 0), (2, 0))], grid=grid), intended=(2, 0)
    )
    assert decision.reason == "blocked"


def test_static_obstacle_never_yields():
    """Choice: a static obstacle on Next is Obstacle Found, and the robot always changes route."""
    grid = Grid(5, 5, blocked=[(3, 0)])
    decision = ThesisPolicy().decide(situation((2, 0), (4, 4), grid=grid), intended=(3, 0))
    assert (decision.reason, decision.next) == ("divert", (2, 1))


def test_higher_priority_continues_even_into_a_parked_robot():
    """The thesis's weakness, reproduced: the referee (not the policy) reports the collision."""
    decision = ThesisPolicy().decide(
        situation((3, 2), (0, 2), [peer(1, (2, 2), (2, 2), arrived=True)]), intended=(2, 2)
    )
    assert (decision.reason, decision.next) == ("priority", (2, 2))


def test_arrived_robot_stays():
    policy = ThesisPolicy()
    here = situation((4, 2), (4, 2))
    assert policy.intend(here) == (4, 2)
    assert policy.decide(here, (4, 2)).reason == "arrived"
