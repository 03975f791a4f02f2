"""Turning (thesis section 3.3) and the discrepancy with the thesis's |h' - h|."""

import itertools

import pytest

from mrmp.core.heading import (
    HEADINGS,
    Heading,
    minimum_quarter_turns,
    minimum_right_turns,
    quarter_turns,
    right_turns,
    thesis_turn_count,
)


def test_thesis_constants():
    assert [int(h) for h in HEADINGS] == [1, 2, 3, 4]
    assert Heading.NORTH.delta == (1, 0)  # NORTH = x update
    assert Heading.EAST.delta == (0, 1)  # EAST = y update
    assert Heading.SOUTH.delta == (-1, 0)  # SOUTH = x decrement
    assert Heading.WEST.delta == (0, -1)  # WEST = y decrement


@pytest.mark.parametrize(
    ("start", "target", "turns"),
    [
        (Heading.NORTH, Heading.NORTH, 0),
        (Heading.NORTH, Heading.EAST, 1),
        (Heading.NORTH, Heading.SOUTH, 2),
        (Heading.NORTH, Heading.WEST, 3),
    ],
)
def test_target_not_below_start_agrees_with_thesis(start, target, turns):
    """When h' >= h the thesis's |h' - h| is right, and so is (h' - h) mod 4."""
    assert right_turns(start, target) == turns
    assert thesis_turn_count(start, target) == turns


def test_target_below_start_differs_from_thesis():
    """From EAST to NORTH the thesis's |1 - 2| = 1 right turn would face SOUTH; three are needed."""
    assert thesis_turn_count(Heading.EAST, Heading.NORTH) == 1
    assert right_turns(Heading.EAST, Heading.NORTH) == 3
    facing = Heading.EAST
    for _ in range(thesis_turn_count(Heading.EAST, Heading.NORTH)):
        facing = Heading((facing % 4) + 1)  # one right turn
    assert facing is Heading.SOUTH


@pytest.mark.parametrize("start", HEADINGS)
@pytest.mark.parametrize("target", HEADINGS)
def test_right_turns_really_reach_the_target(start, target):
    facing = start
    for _ in range(right_turns(start, target)):
        facing = Heading((facing % 4) + 1)
    assert facing is target
    assert 0 <= right_turns(start, target) <= 3


def test_between_and_parse():
    assert Heading.between((2, 2), (1, 2)) is Heading.SOUTH
    with pytest.raises(ValueError):
        Heading.between((0, 0), (1, 1))
    assert Heading.parse("west") is Heading.WEST and Heading.parse(2) is Heading.EAST
    with pytest.raises(ValueError):
        Heading.parse("up")


def test_minimum_right_turns_is_a_lower_bound():
    assert minimum_right_turns(Heading.NORTH, set()) == 0
    assert minimum_right_turns(Heading.NORTH, {Heading.NORTH, Heading.EAST}) == 1
    assert minimum_right_turns(Heading.WEST, {Heading.NORTH, Heading.EAST}) == 2


@pytest.mark.parametrize("current", HEADINGS)
def test_minimum_quarter_turns_is_the_fewest_over_every_order(current: Heading) -> None:
    """Brute force over every sequence of up to four quarter turns either way: the fewest that face each needed
    heading at some point equals the bound, for every set of headings a path may need."""
    sequences = [sequence for length in range(5) for sequence in itertools.product((1, -1), repeat=length)]
    for size in range(3):
        for needed in itertools.combinations(HEADINGS, size):
            fewest = min(len(sequence) for sequence in sequences if set(needed) <= set(_faced(current, sequence)))
            assert minimum_quarter_turns(current, set(needed)) == fewest, needed
    assert [quarter_turns(current, target) for target in HEADINGS].count(2) == 1


def _faced(current: Heading, sequence: tuple[int, ...]) -> list[Heading]:
    faced = [current]
    for step in sequence:
        faced.append(Heading((int(faced[-1]) - 1 + step) % 4 + 1))
    return faced
