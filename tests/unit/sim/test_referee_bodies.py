"""The referee's body rules: following, rotations and actions per body, agreement with brute force, broken variants caught."""

from __future__ import annotations

from itertools import pairwise

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mrmp.sim.referee as referee_module
from mrmp.core.body import BODY_TABLE, body_model
from mrmp.core.grid import Grid
from mrmp.core.heading import HEADINGS, Heading
from mrmp.core.result import COLLISION_KINDS
from mrmp.sim.referee import Referee, check_paths

N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST
OMNI, THESIS, TURNING = body_model("omni"), body_model("thesis"), body_model("turning")
GRID = Grid.from_rows(["....", ".@..", "....", "...."])  # blocked cell (2, 1)

# Fixture plans, each breaking exactly one body rule.
FOLLOW_PLAN = {"A": [(0, 1), (0, 2), (0, 3)], "B": [(0, 0), (0, 1), (0, 2)]}
"""B drives east right behind A, entering at each tick the cell A leaves: a train."""
FOLLOW_HEADINGS = {"A": [E], "B": [E]}
BLOCK = [(0, 0), (1, 0), (1, 1), (0, 1)]
ROTATION_PLAN = {name: [BLOCK[i], BLOCK[(i + 1) % 4]] for i, name in enumerate("ABCD")}
"""Four robots turn round the 2x2 block at the corner, each into the cell the next one leaves."""
ROTATION_HEADINGS = {"A": [N], "B": [E], "C": [S], "D": [W]}  # each faces the cell it enters
SIDESTEP_PLAN = {"A": [(0, 0), (0, 1)]}
"""A steps east while facing north (``x`` increases): a turning body cannot."""
SIDESTEP_HEADINGS = {"A": [N, N]}


def kinds(paths, headings=None, body=None, grid=GRID):
    return sorted((c.kind, c.tick, c.robots) for c in check_paths(grid, paths, headings, body))


def test_the_new_kinds_are_listed():
    assert {"follow", "rotation", "action"} <= set(COLLISION_KINDS)


@pytest.mark.parametrize("body", [None, OMNI])
def test_omni_allows_following_rotations_and_ignores_headings(body):
    assert kinds(FOLLOW_PLAN, FOLLOW_HEADINGS, body) == []
    assert kinds(ROTATION_PLAN, None, body) == []
    assert kinds(SIDESTEP_PLAN, SIDESTEP_HEADINGS, body) == []
    assert kinds({"A": [(0, 0), (0, 0)]}, {"A": [N, S]}, body) == []  # a half turn in place


def test_thesis_forbids_following_along_the_whole_train():
    assert kinds(FOLLOW_PLAN, body=THESIS) == [("follow", 1, ("B", "A")), ("follow", 2, ("B", "A"))]
    train = {f"r{i}": [(0, i), (1, i)] for i in range(3)}  # three abreast: nobody follows
    assert kinds(train, body=THESIS) == []
    column = {f"r{i}": [(i, 0), (i + 1, 0)] for i in range(3)}  # three in a column driving north together
    assert kinds(column, body=THESIS) == [("follow", 1, ("r0", "r1")), ("follow", 1, ("r1", "r2"))]


def test_a_one_cell_gap_is_not_following():
    """A thesis body may enter a cell left one tick earlier: its occupant has arrived elsewhere."""
    gapped = {"A": [(0, 2), (0, 3)], "B": [(0, 0), (0, 1), (0, 2)]}
    assert kinds(gapped, body=THESIS) == []
    assert kinds({"A": [(0, 1), (0, 2)], "B": [(0, 0), (0, 0), (0, 1)]}, body=THESIS) == []


def test_turning_allows_following_but_not_rotations():
    assert kinds(FOLLOW_PLAN, FOLLOW_HEADINGS, TURNING) == []
    assert kinds(ROTATION_PLAN, ROTATION_HEADINGS, TURNING) == [("rotation", 1, ("A", "B", "C", "D"))]


def test_a_rotation_is_reported_once_with_its_cycle_and_not_as_following():
    found = check_paths(GRID, ROTATION_PLAN, body=THESIS)
    assert [(c.kind, c.robots, c.cells) for c in found] == [("rotation", ("A", "B", "C", "D"), tuple(BLOCK))]


def test_the_cycle_starts_with_the_least_robot_and_a_train_behind_no_cycle_is_not_a_rotation():
    names = {"D": 0, "B": 1, "A": 2, "C": 3}
    plan = {name: [BLOCK[i], BLOCK[(i + 1) % 4]] for name, i in names.items()}
    found = check_paths(GRID, plan, body=TURNING)
    assert [(c.robots, c.cells) for c in found] == [(("D", "B", "A", "C"), tuple(BLOCK))]
    open_chain = {name: [BLOCK[i], BLOCK[i + 1]] for i, name in enumerate("ABC")}  # the fourth cell is free
    assert kinds(open_chain, body=TURNING) == []
    assert kinds(open_chain, body=THESIS) == [("follow", 1, ("A", "B")), ("follow", 1, ("B", "C"))]


def test_a_long_rotation_round_a_ring_is_found_without_recursion():
    """2 x 600 cells: 1200 robots round the border in one tick."""
    length = 600
    ring = [(0, y) for y in range(length)] + [(1, y) for y in reversed(range(length))]
    plan = {f"r{i}": [ring[i], ring[(i + 1) % len(ring)]] for i in range(len(ring))}
    found = check_paths(Grid(2, length), plan, body=TURNING)
    assert [(c.kind, len(c.robots)) for c in found] == [("rotation", len(ring))]
    assert kinds(plan, body=OMNI, grid=Grid(2, length)) == []


def test_entering_a_cell_whose_occupant_stays_is_a_vertex_collision_not_a_follow():
    plan = {"A": [(0, 1), (0, 1)], "B": [(0, 0), (0, 1)]}
    assert kinds(plan, body=THESIS) == [("vertex", 1, ("A", "B"))]


def test_a_swap_is_a_swap_for_every_body():
    plan = {"A": [(0, 0), (0, 1)], "B": [(0, 1), (0, 0)]}
    for body in (None, OMNI, THESIS, TURNING):
        assert kinds(plan, body=body) == [("swap", 1, ("A", "B"))]


def test_turning_actions():
    assert kinds(SIDESTEP_PLAN, SIDESTEP_HEADINGS, TURNING) == [("action", 1, ("A",))]
    assert kinds(SIDESTEP_PLAN, {"A": [E, E]}, TURNING) == []  # straight ahead
    assert kinds(SIDESTEP_PLAN, {"A": [E, N]}, TURNING) == [("action", 1, ("A",))]  # moved and turned
    assert kinds(SIDESTEP_PLAN, {"A": [N, E]}, TURNING) == [("action", 1, ("A",))]  # turned and moved
    still = {"A": [(0, 0), (0, 0), (0, 0)]}
    assert kinds(still, {"A": [N, E, N]}, TURNING) == []  # quarter turns, one per tick, either way
    assert kinds(still, {"A": [N, W, S]}, TURNING) == []
    assert kinds(still, {"A": [N, S]}, TURNING) == [("action", 1, ("A",))]  # a half turn in one tick


def test_thesis_actions():
    assert kinds(SIDESTEP_PLAN, SIDESTEP_HEADINGS, THESIS) == [("action", 1, ("A",))]  # moved east, faces north
    assert kinds(SIDESTEP_PLAN, {"A": [N, E]}, THESIS) == []  # right turn then the cell, one tick
    assert kinds(SIDESTEP_PLAN, {"A": [W, E]}, THESIS) == []  # two right turns
    assert kinds({"A": [(0, 0), (0, 0)]}, {"A": [N, S]}, THESIS) == []  # staying, it may turn as it likes


def test_actions_are_checked_only_with_both_heading_lists_and_a_jump_is_not_also_an_action():
    referee = Referee(GRID, ["A"], TURNING)
    assert referee.check_tick(1, [(0, 0)], [(0, 1)]) == []
    assert referee.check_tick(1, [(0, 0)], [(0, 1)], [N]) == []
    assert [c.kind for c in referee.check_tick(1, [(0, 0)], [(0, 1)], [N], [N])] == ["action"]
    assert [c.kind for c in referee.check_tick(1, [(0, 0)], [(0, 2)], [E], [E])] == ["jump"]
    with pytest.raises(ValueError, match="headings"):
        referee.check_tick(1, [(0, 0)], [(0, 1)], [N, N], [N])
    with pytest.raises(ValueError, match="headings"):
        referee.check_start([(0, 0)], [N, E])


def test_check_paths_pads_headings_and_may_outlast_the_paths():
    assert kinds({"A": [(0, 0), (1, 0)]}, {"A": [N]}, TURNING) == []  # the heading list is padded
    assert kinds({"A": [(0, 0), (1, 0)]}, {"A": [N, N, E, W]}, TURNING) == [("action", 3, ("A",))]
    with pytest.raises(ValueError, match="no headings for B"):
        check_paths(GRID, {"A": [(0, 0)], "B": [(1, 1)]}, {"A": [N]}, TURNING)


def test_the_referee_records_every_finding():
    referee = Referee(GRID, ["A", "B"], THESIS)
    referee.check_start([(0, 1), (0, 0)], [E, E])
    referee.check_tick(1, [(0, 1), (0, 0)], [(0, 2), (0, 1)], [E, E], [E, N])
    assert [(c.kind, c.robots) for c in referee.collisions] == [("follow", ("B", "A")), ("action", ("B",))]


# Agreement with an independent, quadratic brute force on random plans.


def brute_force(grid, paths, headings, body):
    """Every rule checked robot against robot and tick by tick, as the module docstring states them."""
    ids = list(paths)
    length = max(len(p) for p in list(paths.values()) + list(headings.values()))
    at = {r: list(paths[r]) + [paths[r][-1]] * (length - len(paths[r])) for r in ids}
    face = {r: list(headings[r]) + [headings[r][-1]] * (length - len(headings[r])) for r in ids}
    found = set()
    for t in range(1, length):
        if len({at[r][t - 1] for r in ids}) < len(ids):
            continue  # robots already sharing a cell: a vertex collision, reported a tick earlier
        moved = [r for r in ids if at[r][t] != at[r][t - 1]]
        enters = {r: [s for s in moved if s != r and at[s][t - 1] == at[r][t]] for r in moved}
        cycles = set()
        for r in moved:  # follow "enters the cell of" from r; a return to r closes a cycle
            seen, s = [r], r
            while enters.get(s) is not None and len(enters[s]) == 1:
                s = enters[s][0]
                if s == r:
                    if len(seen) >= 3 and not body.rotations:
                        cycles.add(frozenset(seen))
                    break
                if s in seen:
                    break
                seen.append(s)
        in_cycle = set().union(*cycles) if cycles else set()
        for members in cycles:
            found.add(("rotation", t, members))
        for r in moved:
            for s in enters[r]:
                swap = at[s][t] == at[r][t - 1]
                if not body.follows and not swap and r not in in_cycle:
                    found.add(("follow", t, frozenset((r, s))))
        if body.headed:
            for r in ids:
                (x0, y0), (x1, y1), h0, h1 = at[r][t - 1], at[r][t], face[r][t - 1], face[r][t]
                step = abs(x1 - x0) + abs(y1 - y0)
                if step == 0:
                    bad = body.turns_in_place and (h1 - h0) % 4 == 2
                elif step == 1:
                    direction = Heading.between((x0, y0), (x1, y1))
                    bad = (direction != h0 or h1 != h0) if body.turns_in_place else h1 != direction
                else:
                    bad = False
                if bad:
                    found.add(("action", t, frozenset((r,))))
    return found


def normalise(collisions):
    """The findings of the body rules, except at ticks after a vertex collision (the brute force skips those)."""
    crowded = {c.tick + 1 for c in collisions if c.kind == "vertex"}
    return {
        (c.kind, c.tick, frozenset(c.robots))
        for c in collisions
        if c.kind in ("follow", "rotation", "action") and c.tick not in crowded
    }


steps = st.sampled_from([(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)])
CELLS = [(x, y) for x in range(2) for y in range(3)]


@st.composite
def crowded_plans(draw):
    """Up to six robots on a 2x3 grid, moving at each tick at random, round a 2x2 block (a rotation) or in a row.

    A robot's headings are random, or (for thesis-like plans) the direction of each move.
    """
    count = draw(st.integers(1, 6))
    cells = draw(st.permutations(CELLS))[:count]
    paths = [[cell] for cell in cells]
    for _ in range(draw(st.integers(0, 5))):
        here = [path[-1] for path in paths]
        how = draw(st.sampled_from(["random", "rotate", "row"]))
        if how == "random":
            moves = [draw(steps) for _ in here]
            there = [(min(max(x + dx, 0), 1), min(max(y + dy, 0), 2)) for (x, y), (dx, dy) in zip(here, moves)]
        elif how == "rotate":
            offset, turn = draw(st.integers(0, 1)), draw(st.sampled_from([1, -1]))
            block = [(0, offset), (1, offset), (1, offset + 1), (0, offset + 1)]
            there = [block[(block.index(cell) + turn) % 4] if cell in block else cell for cell in here]
        else:
            dy = draw(st.sampled_from([1, -1]))
            there = [(x, y + dy) if 0 <= y + dy <= 2 else (x, y) for x, y in here]
        for path, cell in zip(paths, there):
            path.append(cell)
    headings = {}
    for index, path in enumerate(paths):
        if draw(st.booleans()):
            turns = [draw(st.sampled_from(HEADINGS))]
            for a, b in pairwise(path):
                turns.append(Heading.between(a, b) if a != b else turns[-1])
            headings[f"r{index}"] = turns
        else:
            headings[f"r{index}"] = draw(st.lists(st.sampled_from(HEADINGS), min_size=1, max_size=len(path) + 1))
    return {f"r{index}": path for index, path in enumerate(paths)}, headings


@settings(max_examples=500, derandomize=True, deadline=None)
@given(crowded_plans(), st.sampled_from(sorted(BODY_TABLE)))
def test_the_body_rules_agree_with_brute_force(plan, name):
    paths, headings = plan
    body = body_model(name)
    assert normalise(check_paths(Grid(2, 3), paths, headings, body)) == brute_force(Grid(2, 3), paths, headings, body)


@settings(max_examples=200, derandomize=True, deadline=None)
@given(crowded_plans())
def test_omni_is_exactly_the_referee_without_a_body(plan):
    paths, headings = plan
    length = max(len(path) for path in paths.values())
    headings = {robot: turns[:length] for robot, turns in headings.items()}  # heading lists may outlast the paths
    assert check_paths(Grid(2, 3), paths) == check_paths(Grid(2, 3), paths, headings, OMNI)


# Broken referees: each fixture plan is flagged by the real referee and passes one with the check removed.


class NoFollowCheck(Referee):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._no_follow = False


class NoRotationCheck(Referee):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._no_rotation = False


class NoActionCheck(Referee):
    def _check_actions(self, *args, **kwargs):
        return []


CASES = [
    (NoFollowCheck, FOLLOW_PLAN, FOLLOW_HEADINGS, THESIS, "follow"),
    (NoRotationCheck, ROTATION_PLAN, ROTATION_HEADINGS, TURNING, "rotation"),
    (NoActionCheck, SIDESTEP_PLAN, SIDESTEP_HEADINGS, TURNING, "action"),
]


@pytest.mark.parametrize(("broken", "plan", "headings", "body", "kind"), CASES)
def test_each_fixture_plan_is_flagged_and_would_pass_with_its_check_removed(monkeypatch, broken, plan, headings, body, kind):
    assert {c.kind for c in check_paths(GRID, plan, headings, body)} == {kind}
    monkeypatch.setattr(referee_module, "Referee", broken)
    assert check_paths(GRID, plan, headings, body) == []


RULES = [
    test_thesis_forbids_following_along_the_whole_train,
    test_turning_allows_following_but_not_rotations,
    test_a_rotation_is_reported_once_with_its_cycle_and_not_as_following,
    test_turning_actions,
    test_thesis_actions,
]


@pytest.mark.parametrize("broken", [case[0] for case in CASES])
def test_the_tests_above_catch_each_broken_referee(monkeypatch, broken):
    for rule in RULES:
        rule()  # all pass against the real referee
    monkeypatch.setattr(referee_module, "Referee", broken)
    failures = 0
    for rule in RULES:
        try:
            rule()
        except AssertionError:
            failures += 1
    assert failures > 0
