"""Causal-PIBT's transitions over a robot's state and views of its locked neighbours, without any message."""

import random

from mrmp.core.grid import Grid
from mrmp.protocol.messages import ADD_CHILD, CLEAR_PARENT, CONTRACT, REMOVE_CHILD, SET_VISITED, LockReleaseMessage
from mrmp.robot.causal_transitions import CausalTransitions
from mrmp.robot.causal_views import Mode, PeerView


def corridor(goal, length=4):
    return CausalTransitions(Grid(1, length), goal=goal, rng=random.Random(0))


def view(index, mode, tail, head=None, priority=(1, 0, 0), visited=()):
    return PeerView(index, mode, tail, head, priority, set(visited))


def test_a_requesting_robot_of_higher_priority_on_this_tail_is_inherited_from():
    transitions = corridor(goal=(0, 1))
    state = transitions.initial_state(1, (0, 1))  # on its goal: priority (0, 0, 1)
    parent = view(0, Mode.REQUESTING, (0, 0), head=(0, 1), priority=(1, 0, 0), visited={(0, 0), (0, 1)})
    transitions.act(state, {0: parent})
    assert state.parent == 0 and state.inherited == (1, 0, 0) and parent.operations == ADD_CHILD
    assert (state.mode, state.head) == (Mode.REQUESTING, (0, 2)), "the only cell the tree has not visited"
    assert transitions.stats["inherited"] == 1


def test_a_robot_with_no_candidate_left_backtracks_into_its_parent():
    transitions = corridor(goal=(0, 1), length=2)
    state = transitions.initial_state(1, (0, 1))
    parent = view(0, Mode.REQUESTING, (0, 0), head=(0, 1), visited={(0, 0), (0, 1)})
    transitions.act(state, {0: parent})
    assert state.candidates == [] and parent.operations == ADD_CHILD | SET_VISITED | CONTRACT
    assert parent.write_back() == (ADD_CHILD | SET_VISITED | CONTRACT, ((0, 0), (0, 1)))
    assert transitions.stats["backtracked"] == 1


def test_the_highest_of_the_robots_requesting_one_head_extends_and_the_others_contract():
    transitions = corridor(goal=(0, 3))
    state = transitions.initial_state(2, (0, 1))
    transitions.act(state, {})
    assert (state.mode, state.head) == (Mode.REQUESTING, (0, 2))
    lower = view(0, Mode.REQUESTING, (0, 3), head=(0, 2), priority=(1, 0, 0))
    transitions.act(state, {0: lower})  # own priority (1, 0, 2) is higher
    assert state.mode is Mode.EXTENDED and lower.operations == CONTRACT
    loser = transitions.initial_state(0, (0, 1))
    transitions.act(loser, {})
    higher = view(2, Mode.REQUESTING, (0, 3), head=(0, 2), priority=(1, 0, 2))
    transitions.act(loser, {2: higher})
    assert (loser.mode, loser.head) == (Mode.CONTRACTED, None) and higher.operations == 0


def test_a_covered_head_is_waited_for():
    transitions = corridor(goal=(0, 3))
    state = transitions.initial_state(0, (0, 1))
    transitions.act(state, {})
    transitions.act(state, {1: view(1, Mode.CONTRACTED, (0, 2))})
    assert (state.mode, state.head) == (Mode.REQUESTING, (0, 2))


def test_extending_cuts_the_links_to_parent_and_children():
    transitions = corridor(goal=(0, 3))
    state = transitions.initial_state(1, (0, 1))
    transitions.act(state, {})
    state.parent, state.children = 0, {2}
    parent, child = view(0, Mode.CONTRACTED, (0, 0)), view(2, Mode.CONTRACTED, (0, 3))
    transitions.act(state, {0: parent, 2: child})
    assert state.mode is Mode.EXTENDED and state.parent == 1 and state.children == set()
    assert (parent.operations, child.operations) == (REMOVE_CHILD, CLEAR_PARENT)


def test_a_release_writes_into_the_robot_what_its_locker_wrote():
    transitions = corridor(goal=(0, 3))
    state = transitions.initial_state(1, (0, 1))
    transitions.act(state, {})
    state.parent = 0
    transitions.apply_release(state, LockReleaseMessage(0, 1, 1, CLEAR_PARENT | ADD_CHILD | SET_VISITED | CONTRACT, ((0, 0),)))
    assert state.parent == 1 and state.children == {0} and state.visited == {(0, 0)}
    assert (0, 0) not in state.candidates and (state.mode, state.head) == (Mode.CONTRACTED, None)
    assert transitions.stats["written"] == 1


def test_the_body_arriving_on_the_goal_counts_a_goal_reached():
    transitions = corridor(goal=(0, 1))
    state = transitions.initial_state(0, (0, 0))
    transitions.act(state, {})
    transitions.act(state, {})
    transitions.act_extended(state)
    assert (state.tail, state.reached, state.away, state.own_priority) == ((0, 1), 1, 0, (0, -1, 0))
