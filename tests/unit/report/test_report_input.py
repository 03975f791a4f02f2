"""Reading results.jsonl: typed records, a cut-short last line set aside, every other defect named by line."""

import json

import pytest
from report_fixtures import make_record, unfinished, write_jsonl

from mrmp.core.errors import InputError
from mrmp.experiments.matrix import BenchRun
from mrmp.experiments.records import base_record, execute_run
from mrmp.io.bench_results import append_record
from mrmp.io.report_input import FaultSetting, read_bench_results, record_from_dict


def problems_of(path):
    with pytest.raises(InputError) as caught:
        read_bench_results(path)
    return [str(problem) for problem in caught.value.problems]


def test_reads_a_folder_or_its_file_into_typed_records(tmp_path):
    lossy = {"loss": 0.2, "delay": [0, 3], "duplicate": 0.1, "reorder": 0.0}
    path = write_jsonl(
        tmp_path / "results.jsonl",
        [make_record(run_id="a"), make_record(run_id="b", faults=lossy, seed=7, soc_over_lb=2, bench="nightly", instance=3)],
    )
    for source in (tmp_path, path):
        results = read_bench_results(source)
        assert results.path == path and results.truncated_lines == 0 and results.replaced_records == 0
        first, second = results.records
        assert (first.run_id, first.status, first.map, first.agents, first.policy, first.success) == (
            "a", "done", "empty-8-8", 4, "pibt", True,
        )
        assert first.faults == FaultSetting() and first.faults.label == "none"
        assert second.faults == FaultSetting(loss=0.2, delay=(0, 3), duplicate=0.1)
        assert second.faults.label == "loss 0.2, delay 0..3, duplicate 0.1"
        assert second.soc_over_lb == 2.0 and isinstance(second.soc_over_lb, float)
        assert (second.seed, second.bench, second.instance, second.line) == (7, "nightly", 3, 2)


def test_a_cut_short_last_line_is_set_aside_and_counted(tmp_path):
    records = [make_record(run_id="a"), make_record(run_id="b")]
    cut = json.dumps(make_record(run_id="c"))[:57]
    results = read_bench_results(write_jsonl(tmp_path / "results.jsonl", records, tail=cut))
    assert [record.run_id for record in results.records] == ["a", "b"]
    assert results.truncated_lines == 1


def test_a_complete_last_line_without_newline_is_a_record(tmp_path):
    path = write_jsonl(tmp_path / "results.jsonl", [make_record(run_id="a")], tail=json.dumps(make_record(run_id="b")))
    results = read_bench_results(path)
    assert [record.run_id for record in results.records] == ["a", "b"] and results.truncated_lines == 0


def test_a_malformed_line_in_the_middle_is_an_error_naming_file_and_line(tmp_path):
    path = tmp_path / "results.jsonl"
    path.write_text(json.dumps(make_record(run_id="a")) + "\n{not json\n" + json.dumps(make_record(run_id="b")) + "\n")
    [problem] = problems_of(path)
    assert problem.startswith(f"{path}:2: not valid JSON")
    assert "\n" not in problem


def test_a_bad_last_line_that_ends_with_a_newline_is_not_truncation(tmp_path):
    path = write_jsonl(tmp_path / "results.jsonl", [make_record(run_id="a")], tail='{"format": "mrmp-be\n')
    [problem] = problems_of(path)
    assert problem.startswith(f"{path}:2: not valid JSON")


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        ({"format": "mrmp-bench-2"}, "format: expected 'mrmp-bench-1', got 'mrmp-bench-2'"),
        ({"agents": True}, "agents: expected a whole number, got True"),
        ({"agents": 0}, "agents: expected at least 1, got 0"),
        ({"status": "crashed"}, "status: expected one of done, timeout, error, got 'crashed'"),
        ({"success": None}, "success: null, but the run finished (status 'done')"),
        ({"wall_time_per_step_s": "fast"}, "wall_time_per_step_s: expected a number, got 'fast'"),
        ({"faults": {"loss": 2, "delay": [0, 0], "duplicate": 0, "reorder": 0}}, "faults.loss: expected a probability"),
        ({"faults": {"loss": 0, "delay": [3, 1], "duplicate": 0, "reorder": 0}}, "faults.delay: expected [low, high]"),
        ({"kind": "hybrid"}, "kind: expected one of decentralized, centralized, got 'hybrid'"),
        ({"instance": "one"}, "instance: expected a whole number, got 'one'"),
    ],
)
def test_a_wrong_field_is_named_with_its_line(tmp_path, change, reason):
    path = write_jsonl(tmp_path / "results.jsonl", [make_record(run_id="a"), make_record(run_id="b", **change)])
    [problem] = problems_of(path)
    assert problem.startswith(f"{path}:2: {reason}")


def test_a_missing_field_is_named(tmp_path):
    record = make_record()
    del record["policy"]
    [problem] = problems_of(write_jsonl(tmp_path / "results.jsonl", [record]))
    assert problem.endswith(":1: policy: missing")


def test_a_finished_run_needs_its_result_fields_an_unfinished_one_does_not(tmp_path):
    done = make_record(run_id="a")
    del done["steps"]
    timeout = {key: value for key, value in unfinished("timeout", run_id="b").items() if key != "steps"}
    with pytest.raises(ValueError, match="steps: missing"):
        record_from_dict(done)
    record = record_from_dict(timeout)
    assert record.status == "timeout" and record.steps is None and record.success is None


def test_an_error_run_needs_its_message(tmp_path):
    [problem] = problems_of(write_jsonl(tmp_path / "results.jsonl", [unfinished("error", None)]))
    assert "error: a run with status 'error' needs its one-line error message" in problem


def test_every_bad_line_is_listed_one_per_problem(tmp_path):
    path = tmp_path / "results.jsonl"
    path.write_text("[1]\n" + json.dumps(make_record()) + "\n42\n")
    assert problems_of(path) == [
        f"{path}:1: expected a JSON object (one run record), got a list",
        f"{path}:3: expected a JSON object (one run record), got a number",
    ]


def test_a_run_recorded_again_keeps_its_last_record(tmp_path):
    records = [
        unfinished("timeout", run_id="a"),
        make_record(run_id="b"),
        make_record(run_id="a", seed=0, success=False),
    ]
    results = read_bench_results(write_jsonl(tmp_path / "results.jsonl", records))
    assert [(record.run_id, record.status) for record in results.records] == [("b", "done"), ("a", "done")]
    assert results.replaced_records == 1


def test_a_folder_without_results_is_an_error(tmp_path):
    [problem] = problems_of(tmp_path)
    assert problem == f"{tmp_path}: no results.jsonl in this folder (is it the --out of mrmp bench?)"


def test_a_missing_file_is_an_error(tmp_path):
    [problem] = problems_of(tmp_path / "nowhere.jsonl")
    assert problem == f"{tmp_path / 'nowhere.jsonl'}: file not found"


def test_records_of_real_simulated_runs_are_read(tmp_path, simulated_records):
    results = read_bench_results(write_jsonl(tmp_path / "results.jsonl", simulated_records))
    assert len(results.records) == len(simulated_records) == 18
    assert all(record.finished and record.collisions == 0 for record in results.records)
    assert sum(record.lifelong for record in results.records) == 2


def test_records_appended_by_the_bench_writer_are_read(tmp_path):
    path = tmp_path / "results.jsonl"
    append_record(path, make_record(run_id="a"))
    append_record(path, unfinished("error", "planner crashed", run_id="b"))
    results = read_bench_results(tmp_path)
    assert [(record.run_id, record.status, record.error) for record in results.records] == [
        ("a", "done", None),
        ("b", "error", "planner crashed"),
    ]


def test_records_of_real_bench_runs_are_read_back_as_written(tmp_path):
    spec = (("density", 0.1), ("height", 12), ("kind", "random"), ("seed", 0), ("width", 12))
    one_shot = BenchRun("gen:random-12x12-p0.10-s0", 4, "pibt", generator=spec, instance=0, time_limit_s=20, bench="t")
    runs = [one_shot, one_shot.with_changes(policy="pp"), one_shot.with_changes(lifelong=True, max_ticks=30)]
    written = [execute_run(run) for run in runs]
    written.append(base_record(one_shot.with_changes(seed=1), "timeout", "killed"))
    written.append(base_record(one_shot.with_changes(seed=2), "error", "boom"))
    for record in written:
        append_record(tmp_path / "results.jsonl", record)
    results = read_bench_results(tmp_path)
    assert [record.run_id for record in results.records] == [record["run_id"] for record in written]
    for record, data in zip(results.records, written):
        for name in ("status", "error", "map", "agents", "policy", "kind", "seed", "lifelong", "success", "makespan",
                     "soc_over_lb", "throughput", "collisions", "messages_per_robot_move", "bench", "instance"):  # fmt: skip
            assert getattr(record, name) == data[name], name
    assert [record.kind for record in results.records[:2]] == ["decentralized", "centralized"]
    assert all(record.succeeded for record in results.records[:3])
    assert results.records[2].throughput > 0 and results.records[3].status == "timeout"


def test_a_planner_that_found_no_plan_is_a_finished_failure_without_measurements():
    planless = unfinished("done", run_id="p", policy="pp", kind="centralized")
    planless.update(success=False, stop_reason="no plan: failed", planning_time_s=0.2)
    record = record_from_dict(planless)
    assert (record.status, record.success, record.stop_reason, record.ticks) == ("done", False, "no plan: failed", None)
    planless["stop_reason"] = "deadlock"  # an executed run must carry its measurements
    with pytest.raises(ValueError, match="ticks: null, but the run finished"):
        record_from_dict(planless)
