"""The thesis's trade-places experiment over every pair of cells of the 5x5 grid, and the row swap.

The table is computed by the same function ``bench/thesis_pairs.py`` prints
(:func:`mrmp.experiments.trade_places.outcome_table`). The unguarded columns
follow from the thesis's rule alone and are pinned exactly. The guarded
columns depend on when the safety layer lets a robot enter a cell: in the
lockstep simulator a robot may follow into a cell its occupant leaves in the
same tick (the layer's handoff, ``docs/protocol.md``), so a guarded run makes
exactly the moves of the unguarded run wherever that one is collision-free
(checked pair by pair, path by path), and stops short where that one collides.
Their counts are pinned in ``GUARDED_OUTCOMES_WITH_FOLLOWING``; what must hold
whatever the layer does is checked separately.
"""

from collections import Counter
from pathlib import Path

import pytest

from mrmp.core.grid import Grid
from mrmp.experiments.trade_places import (
    COLUMNS,
    Column,
    outcome_table,
    table_markdown,
    trade_places_pairs,
    trade_places_scenario,
)
from mrmp.io import load_scenario
from mrmp.sim.simulator import LockstepSimulator, simulate

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

UNGUARDED_OUTCOMES = {
    Column("divert", guarded=False): Counter(success=268, livelock=16, collision=16),
    Column("wait", guarded=False): Counter(success=200, collision=100),
}
"""The thesis's rule as written: 16 row pairs livelock, 16 adjacent row pairs and every shared-line wait collide."""

GUARDED_OUTCOMES_WITH_FOLLOWING = {
    Column("divert", guarded=True): Counter(success=268, livelock=16, deadlock=16),
    Column("wait", guarded=True): Counter(success=200, deadlock=100),
}
"""Guarded counts under the lockstep model's following rule: the unguarded successes and livelocks, and a
deadlock where the unguarded run collides (the layer refuses the colliding move, and the rule repeats it).

Before the rule (a cell refused while its occupant stood on it, whatever it did in the tick) the divert
column was 260 successes and 40 livelocks: 44 runs took other paths and 8 went from success to livelock."""


@pytest.fixture(scope="module")
def table():
    return outcome_table(Grid(5, 5))


@pytest.mark.slow
def test_three_hundred_pairs_per_column(table):
    assert len(trade_places_pairs(Grid(5, 5))) == 300
    assert list(table) == list(COLUMNS)
    assert all(sum(counts.values()) == 300 for counts in table.values())


def test_unguarded_outcomes_are_the_rules_own(table):
    for column, expected in UNGUARDED_OUTCOMES.items():
        assert table[column] == expected, column.title


def test_guarded_outcomes_of_the_current_safety_layer(table):
    for column, expected in GUARDED_OUTCOMES_WITH_FOLLOWING.items():
        assert table[column] == expected, column.title


@pytest.mark.parametrize("resolve", ["divert", "wait"])
def test_guarded_runs_are_the_unguarded_runs_wherever_those_do_not_collide(resolve):
    """All 300 pairs: the safety layer grants every move the thesis's rule makes when that move is safe."""
    grid = Grid(5, 5)
    compared = 0
    for first, second in trade_places_pairs(grid):
        unguarded = simulate(trade_places_scenario(grid, first, second, resolve, guarded=False))
        if unguarded.collisions:
            continue
        guarded = simulate(trade_places_scenario(grid, first, second, resolve, guarded=True))
        pair = f"{resolve} {first}-{second}"
        assert [robot.path for robot in guarded.robots] == [robot.path for robot in unguarded.robots], pair
        assert [robot.headings for robot in guarded.robots] == [robot.headings for robot in unguarded.robots], pair
        assert guarded.stop_reason == unguarded.stop_reason and guarded.collisions == [], pair
        compared += 1
    assert compared == {"divert": 284, "wait": 200}[resolve]


def test_without_following_the_guarded_runs_differ():
    """The check above can fail: under the rule of live bodies (no following) the thesis's trade for A (0,0),
    B (0,3) livelocks guarded, where it succeeds unguarded."""
    scenario = trade_places_scenario(Grid(5, 5), (0, 0), (0, 3), "divert", guarded=True)
    assert simulate(scenario.with_changes(safety=False)).success
    assert LockstepSimulator(scenario).run().success
    assert LockstepSimulator(scenario, following=False).run().stop_reason == "livelock"


def test_guarded_never_collides_and_never_runs_out_of_ticks(table):
    for column in COLUMNS:
        if column.guarded:
            assert table[column]["collision"] == 0 and table[column]["tick limit"] == 0, column.title


def test_the_table_as_the_script_prints_it(table):
    lines = table_markdown(table).splitlines()
    assert lines[0] == "| outcome | divert, unguarded | divert, guarded | wait, unguarded | wait, guarded |"
    assert lines[3] == "| livelock | 16 | 16 | 0 | 0 |"
    assert lines[-1] == "| pairs | 300 | 300 | 300 | 300 |"


@pytest.mark.parametrize("safety", [True, False], ids=["guarded", "as-written"])
def test_row_swap_livelocks_in_a_two_tick_cycle(safety):
    """Trace of docs/thesis.md: each change of route to x + 1 hands the priority to the robot that diverted."""
    scenario = load_scenario(EXAMPLES / "thesis-swap-row.yaml").with_changes(safety=safety)
    simulator = LockstepSimulator(scenario, record_decisions=True)
    result = simulator.run()
    assert result.stop_reason == "livelock" and result.collisions == []
    a, b = (robot.path for robot in result.robots)
    assert a[:6] == [(2, 0), (2, 1), (3, 1), (2, 1), (3, 1), (2, 1)]
    assert b[:6] == [(2, 4), (2, 3), (2, 2), (3, 2), (2, 2), (3, 2)]
    reasons = [tuple(decision.reason for decision in tick) for tick in simulator.decisions[:5]]
    assert reasons == [
        ("clear", "clear"),
        ("divert", "priority"),
        ("priority", "divert"),
        ("divert", "priority"),
        ("priority", "divert"),
    ]


def test_column_swap_succeeds_where_the_row_swap_livelocks():
    column = LockstepSimulator(load_scenario(EXAMPLES / "thesis-swap.yaml")).run()
    row = LockstepSimulator(load_scenario(EXAMPLES / "thesis-swap-row.yaml")).run()
    assert column.success and not row.success
