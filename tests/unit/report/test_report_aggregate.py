"""Aggregation of run records: exact figures on a hand-made benchmark."""

import pytest
from report_fixtures import make_record, unfinished

from mrmp.bench.aggregate import (
    GroupKey,
    headline_markdown,
    headline_table,
    notable_runs,
    overview,
    success_by_faults,
    summarize,
)
from mrmp.io.report_input import FaultSetting, record_from_dict

LOSSY = {"loss": 0.2, "delay": [0, 0], "duplicate": 0.0, "reorder": 0.0}


def hand_made():
    """Four configurations on map m1, one on m0 (listed last, sorted first)."""
    rows = [
        # pibt, no faults, N=4: two successes, a failure with a collision, a timeout
        make_record(run_id="a0", map="m1", seed=0, soc_over_lb=1.2, makespan=10, wall_time_per_step_s=0.004, messages_per_robot_move=2.0),
        make_record(run_id="a1", map="m1", seed=1, soc_over_lb=1.4, makespan=14, wall_time_per_step_s=0.006, messages_per_robot_move=4.0),
        make_record(
            run_id="a2", map="m1", seed=2, success=False, soc_over_lb=None, makespan=30, collisions=1,
            wall_time_per_step_s=0.008, messages_per_robot_move=6.0,
        ),
        unfinished("timeout", "time limit", run_id="a3", map="m1", seed=3),
        # pibt, 20 % loss, N=4: a success and an error
        make_record(run_id="b0", map="m1", faults=LOSSY, seed=0, soc_over_lb=1.5, makespan=12, wall_time_per_step_s=0.01),
        unfinished("error", "boom", run_id="b1", map="m1", faults=LOSSY, seed=1),
        # astar, no faults, N=8: nobody moved in one run (messages per move null)
        make_record(run_id="c0", map="m1", policy="astar", agents=8, seed=0, messages_per_robot_move=None, makespan=0, soc_over_lb=None),
        make_record(run_id="c1", map="m1", policy="astar", agents=8, seed=1, messages_per_robot_move=3.0, makespan=8, soc_over_lb=1.0),
        # pibt lifelong, N=4: throughput 0.5 and 0.7
        make_record(run_id="d0", map="m1", lifelong=True, seed=0, throughput=0.5),
        make_record(run_id="d1", map="m1", lifelong=True, seed=1, throughput=0.7),
        make_record(run_id="e0", map="m0", seed=5, soc_over_lb=1.1, makespan=7, wall_time_per_step_s=0.0005),
    ]
    return [record_from_dict(row, line) for line, row in enumerate(rows, start=1)]


def by_key(summaries):
    return {(s.key.map, s.key.policy, s.key.faults.label, s.key.agents, s.key.lifelong): s for s in summaries}


def test_groups_are_sorted_by_map_policy_faults_n():
    keys = [summary.key for summary in summarize(hand_made())]
    assert keys == [
        GroupKey("m0", "pibt", FaultSetting(), 4),
        GroupKey("m1", "astar", FaultSetting(), 8),
        GroupKey("m1", "pibt", FaultSetting(), 4),
        GroupKey("m1", "pibt", FaultSetting(), 4, lifelong=True),
        GroupKey("m1", "pibt", FaultSetting(loss=0.2), 4),
    ]


def test_figures_of_a_group_with_success_failure_and_timeout():
    group = by_key(summarize(hand_made()))[("m1", "pibt", "none", 4, False)]
    assert (group.runs, group.done, group.successes, group.timeouts, group.errors) == (4, 3, 2, 1, 0)
    assert group.success_rate == 0.5
    assert group.runs_with_collisions == 1
    assert group.seeds == (0, 1, 2, 3)
    assert group.mean_soc_over_lb == pytest.approx(1.3)  # successful runs only
    assert group.mean_makespan == pytest.approx(12.0)  # successful runs only
    assert group.mean_wall_time_per_step_s == pytest.approx(0.006)  # every finished run
    assert group.mean_messages_per_robot_move == pytest.approx(4.0)
    assert group.mean_throughput is None


def test_an_error_counts_as_a_failure_and_null_values_are_left_out_of_means():
    groups = by_key(summarize(hand_made()))
    lossy = groups[("m1", "pibt", "loss 0.2", 4, False)]
    assert (lossy.runs, lossy.successes, lossy.errors, lossy.success_rate) == (2, 1, 1, 0.5)
    assert lossy.mean_wall_time_per_step_s == pytest.approx(0.01)
    astar = groups[("m1", "astar", "none", 8, False)]
    assert astar.mean_messages_per_robot_move == pytest.approx(3.0)
    assert astar.mean_soc_over_lb == pytest.approx(1.0)
    assert astar.mean_makespan == pytest.approx(4.0)


def test_lifelong_runs_form_their_own_group_with_throughput():
    lifelong = by_key(summarize(hand_made()))[("m1", "pibt", "none", 4, True)]
    assert lifelong.runs == 2 and lifelong.mean_throughput == pytest.approx(0.6)


def test_success_by_faults_pools_n_and_leaves_out_lifelong_runs():
    pooled = [(row.map, row.policy, row.faults.label, row.runs, row.successes) for row in success_by_faults(summarize(hand_made()))]
    assert pooled == [
        ("m0", "pibt", "none", 1, 1),
        ("m1", "astar", "none", 2, 2),
        ("m1", "pibt", "none", 4, 2),
        ("m1", "pibt", "loss 0.2", 2, 1),
    ]


def test_overview_lists_every_dimension_and_status():
    facts = overview([*hand_made(), record_from_dict(make_record(run_id="z", policy="cbs", kind="centralized"))])
    assert facts.central_policies == ("cbs",)
    facts = overview(hand_made())
    assert facts.runs == 11 and facts.successes == 8 and facts.runs_with_collisions == 1
    assert facts.maps == ("m0", "m1") and facts.policies == ("astar", "pibt") and facts.agents == (4, 8)
    assert facts.seeds == (0, 1, 2, 3, 5)
    assert [faults.label for faults in facts.faults] == ["none", "loss 0.2"]
    assert facts.lifelong == (False, True)
    assert facts.statuses == (("done", 9), ("timeout", 1), ("error", 1))


def test_notable_runs_are_timeouts_errors_and_collisions():
    assert [record.run_id for record in notable_runs(hand_made())] == ["a2", "a3", "b1"]


def test_headline_table_cells():
    table = headline_table([s for s in summarize(hand_made()) if not s.key.lifelong])
    assert table.columns == ("map", "policy", "faults", "N", "runs", "success", "SoC/LB", "makespan", "ms/step", "msgs/move")
    assert table.rows[2] == ("m1", "pibt", "none", "4", "4", "50% (2/4)", "1.300", "12.0", "6.00", "4.00")
    assert table.rows[3] == ("m1", "pibt", "loss 0.2", "4", "2", "50% (1/2)", "1.500", "12.0", "10.0", "4.00")
    assert table.rows[0][8] == "0.500"


def test_headline_table_gets_lifelong_and_throughput_columns_when_needed():
    table = headline_table(summarize(hand_made()))
    assert table.columns[3] == "lifelong" and table.columns[-1] == "throughput"
    lifelong_row = table.rows[3]
    assert lifelong_row[3] == "yes" and lifelong_row[-1] == "0.600"
    assert table.rows[2][3] == "no" and table.rows[2][-1] == "-"


def test_headline_markdown_is_a_table_with_one_row_per_group():
    summaries = [s for s in summarize(hand_made()) if not s.key.lifelong]
    lines = headline_markdown(summaries).splitlines()
    assert len(lines) == 2 + len(summaries)
    assert lines[0] == "| map | policy | faults | N | runs | success | SoC/LB | makespan | ms/step | msgs/move |"
    assert lines[1] == "|---|---|---|---:|---:|---:|---:|---:|---:|---:|"
    assert lines[3] == "| m1 | astar | none | 8 | 2 | 100% (2/2) | 1.000 | 4.0 | 5.00 | 3.00 |"


def test_markdown_escapes_pipes():
    record = record_from_dict(make_record(map="a|b"))
    assert "| a\\|b | pibt |" in headline_markdown(summarize([record]))
