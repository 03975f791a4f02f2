"""The benchmark runner: records on disk as runs end, resume, time limits, errors, the CLI, dask."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from mrmp.bench.runner import KILL_GRACE_S, run_bench, run_isolated
from mrmp.cli import app
from mrmp.experiments.bench_config import load_bench_config
from mrmp.experiments.matrix import BenchRun
from mrmp.io.bench_results import read_records

ROOT = Path(__file__).resolve().parents[3]
MAPS = ROOT / "maps"
TINY = ROOT / "bench" / "tiny.yaml"
SCHEMA_KEYS = (
    "format", "run_id", "status", "error", "map", "map_path", "scen", "generator", "agents", "policy", "kind",
    "seed", "faults", "lifelong", "max_ticks", "time_limit_s", "success", "stop_reason", "ticks", "makespan",
    "sum_of_costs", "lower_bound", "time_makespan_s", "messages", "network", "wall_time_s", "planning_time_s",
    "plan_bytes", "throughput", "collisions", "soc_over_lb", "robots_arrived", "goals_reached", "steps",
    "wall_time_per_step_s", "messages_per_robot_move",
)  # fmt: skip


def generated_run(policy="pibt", agents=4, **changes):
    spec = (("density", 0.1), ("height", 12), ("kind", "random"), ("seed", 0), ("width", 12))
    return BenchRun("gen:random-12x12-p0.10-s0", agents, policy, generator=spec, instance=0, **{"time_limit_s": 20, **changes})


def den520d_run(policy, agents, time_limit_s):
    return BenchRun("den520d", agents, policy, map_path=str(MAPS / "den520d.map"),
                    scen=str(MAPS / "den520d-random-1.scen"), time_limit_s=time_limit_s)  # fmt: skip


def test_tiny_bench_end_to_end_through_the_cli(tmp_path):
    result = CliRunner().invoke(app, ["bench", str(TINY), "--out", str(tmp_path), "--workers", "2"])
    assert result.exit_code == 0, result.output
    runs = load_bench_config(TINY).runs
    records = read_records(tmp_path / "results.jsonl")
    assert sorted(record["run_id"] for record in records) == sorted(run.run_id for run in runs)
    for record in records:
        assert all(key in record for key in SCHEMA_KEYS), set(SCHEMA_KEYS) - set(record)
        assert record["format"] == "mrmp-bench-1" and record["status"] == "done"
        # the referee's verdict
        assert record["collisions"] == 0 and record["success"] is True
        assert record["soc_over_lb"] >= 1.0 and record["robots_arrived"] == record["agents"]
        assert "robots" not in record
    kinds = {record["policy"]: record["kind"] for record in records}
    assert kinds == {"pibt": "decentralized", "astar": "decentralized", "pp": "centralized"}
    assert all(record["planning_time_s"] is not None for record in records if record["kind"] == "centralized")
    lines = (tmp_path / "results.csv").read_text().splitlines()
    assert len(lines) == 1 + len(runs) and lines[0].startswith("run_id,")
    for column in ("map", "policy", "success", "soc_over_lb"):
        assert column in result.output or column in lines[0]
    assert "tiny" in result.output and "100%" in result.output


def test_resume_skips_finished_runs(tmp_path):
    runs = [generated_run(policy, agents) for policy in ("pibt", "astar") for agents in (2, 4)]
    first = run_bench(runs[:2], tmp_path, workers=2, progress=False)
    assert first.ran == 2 and first.resumed == 0
    before = (tmp_path / "results.jsonl").read_bytes()
    # a marker: finished records are kept byte for byte and their runs are not executed again
    notes = []
    second = run_bench(runs, tmp_path, workers=2, progress=False, say=notes.append)
    assert notes == ["resumed: 2 of 4 runs already done"]
    assert second.ran == 2 and second.resumed == 2 and not second.interrupted
    after = (tmp_path / "results.jsonl").read_bytes()
    assert after.startswith(before)
    records = read_records(tmp_path / "results.jsonl")
    assert len(records) == 4 and len({record["run_id"] for record in records}) == 4
    third = run_bench(runs, tmp_path, workers=2, progress=False, say=notes.append)
    assert third.ran == 0 and len(read_records(tmp_path / "results.jsonl")) == 4
    assert len(third.records) == 4
    assert len((tmp_path / "results.csv").read_text().splitlines()) == 5


def test_a_line_cut_short_by_a_kill_is_dropped_and_its_run_redone(tmp_path):
    runs = [generated_run("pibt", 2), generated_run("pibt", 3)]
    run_bench(runs[:1], tmp_path, workers=1, progress=False)
    with open(tmp_path / "results.jsonl", "a") as stream:
        stream.write('{"run_id": "' + runs[1].run_id + '", "status": "do')
    outcome = run_bench(runs, tmp_path, workers=1, progress=False)
    assert outcome.ran == 1
    records = read_records(tmp_path / "results.jsonl")
    assert [record["run_id"] for record in records] == [run.run_id for run in runs]


@pytest.mark.slow
def test_interrupted_bench_stops_at_once_keeps_finished_records_and_resumes(tmp_path):
    config = tmp_path / "bench.yaml"
    config.write_text(
        f"maps:\n  - map: {MAPS / 'random-32-32-20.map'}\n    scen: [{MAPS / 'random-32-32-20-random-1.scen'}]\n"
        "    agents: [2, 3, 4]\n"
        f"  - map: {MAPS / 'den520d.map'}\n    scen: [{MAPS / 'den520d-random-1.scen'}]\n"
        "    agents: [300]\n"  # reactive A* needs far more than 3 s for these: killed at its time limit
        "agents: [1]\npolicies: [astar]\ntime_limit: 3\n"
    )
    out = tmp_path / "out"
    process = subprocess.Popen(
        [sys.executable, "-m", "mrmp", "bench", str(config), "--out", str(out), "--workers", "1"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(read_records(out / "results.jsonl")) < 3:
        time.sleep(0.05)
    time.sleep(0.3)
    process.send_signal(signal.SIGINT)
    interrupted = time.monotonic()
    _, errors = process.communicate(timeout=30)
    assert time.monotonic() - interrupted < 4, "the running run was not stopped"
    assert process.returncode == 130, errors
    kept = read_records(out / "results.jsonl")
    assert "interrupted: 3 of 4 runs are recorded" in errors
    assert [record["agents"] for record in kept] == [2, 3, 4] and all(r["status"] == "done" for r in kept)
    rerun = CliRunner().invoke(app, ["bench", str(config), "--out", str(out), "--workers", "1"])
    assert rerun.exit_code == 0, rerun.output
    assert "resumed: 3 of 4 runs already done" in rerun.output
    records = read_records(out / "results.jsonl")
    assert records[:3] == kept and len(records) == 4 and records[3]["status"] == "timeout"


def test_a_run_over_its_time_limit_is_killed_and_recorded_as_timeout():
    # reactive A* with the safety layer on den520d takes over 10 seconds for 200 robots (1 s for 40)
    run = den520d_run("astar", 200, time_limit_s=0.05)
    started = time.monotonic()
    record = run_isolated(run)
    assert record["status"] == "timeout" and record["error"].startswith("killed after")
    assert time.monotonic() - started < 60  # killed, not run to its end
    assert record["success"] is None and record["collisions"] is None and record["run_id"] == run.run_id


def test_a_planner_that_stops_at_its_limit_is_a_timeout():
    record = run_isolated(den520d_run("cbs", 60, time_limit_s=0.2))
    assert record["status"] == "timeout" and "cbs" in record["error"]
    assert record["sum_of_costs"] is None


def test_the_time_limit_counts_from_the_runs_readiness_not_its_start_up(tmp_path, monkeypatch):
    # every Python started from here first sleeps longer than the run's limit and grace: a slow start-up
    (tmp_path / "sitecustomize.py").write_text(f"import time\ntime.sleep({0.5 + KILL_GRACE_S + 1.0})\n")
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")]))
    record = run_isolated(generated_run("pp", 3, time_limit_s=0.5))
    assert record["status"] == "done", record["error"]


def test_a_run_whose_process_dies_before_it_is_ready_is_an_error(tmp_path, monkeypatch):
    (tmp_path / "sitecustomize.py").write_text("raise SystemExit('no interpreter today')\n")
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")]))
    record = run_isolated(generated_run("pp", 3))
    assert record["status"] == "error" and record["error"].endswith(": no interpreter today")


def test_a_run_that_fails_is_an_error_with_one_line():
    run = BenchRun("gone", 3, "pibt", map_path="/nonexistent/gone.map", scen="/nonexistent/gone.scen")
    record = run_isolated(run)
    assert record["status"] == "error" and "\n" not in record["error"] and "gone" in record["error"]
    assert record["success"] is None


def test_only_missing_runs_errors_again(tmp_path):
    good = generated_run("pibt", 2)
    bad = BenchRun("gone", 3, "pibt", map_path="/nonexistent/gone.map", scen="/nonexistent/gone.scen")
    run_bench([good, bad], tmp_path, workers=2, progress=False)
    assert run_bench([good, bad], tmp_path, progress=False).ran == 0
    again = run_bench([good, bad], tmp_path, retry_errors=True, progress=False)
    assert again.ran == 1 and len(read_records(tmp_path / "results.jsonl")) == 3
    statuses = {record["run_id"]: record["status"] for record in again.records}
    assert statuses == {good.run_id: "done", bad.run_id: "error"}


def test_cli_bad_config_exits_2_with_one_line(tmp_path):
    config = tmp_path / "bad.yaml"
    config.write_text("maps: []\nagents: [2]\npolicies: [pibt]\n")
    result = CliRunner().invoke(app, ["bench", str(config), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert f"error: {config}:1: maps: expected a non-empty list, got an empty list" in result.output
    assert not (tmp_path / "out").exists()
    result = CliRunner().invoke(app, ["bench", str(TINY), "--out", str(tmp_path / "out"), "--workers", "0"])
    assert result.exit_code == 2 and "--workers: must be at least 1" in result.output
    (tmp_path / "file").write_text("")
    result = CliRunner().invoke(app, ["bench", str(TINY), "--out", str(tmp_path / "file")])
    assert result.exit_code == 2 and "cannot create the output folder" in result.output


def test_dask_local_cluster_runs_the_same_records_and_resumes(tmp_path):
    distributed = pytest.importorskip("distributed")
    runs = [generated_run(policy, 3) for policy in ("pibt", "pp", "astar")]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster:
        first = run_bench(runs[:2], tmp_path, dask_address=cluster.scheduler_address, progress=False)
        assert first.ran == 2
        notes = []
        second = run_bench(runs, tmp_path, dask_address=cluster.scheduler_address, progress=False, say=notes.append)
    assert second.ran == 1 and notes == ["resumed: 2 of 3 runs already done"]
    records = read_records(tmp_path / "results.jsonl")
    assert sorted(record["run_id"] for record in records) == sorted(run.run_id for run in runs)
    assert all(record["status"] == "done" and record["collisions"] == 0 for record in records)


def _children(pid):
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                found.append(int(entry.name))
    return found


def test_a_worker_that_dies_stops_the_bench_with_a_note_and_no_false_record(tmp_path):
    import threading

    slow = den520d_run("astar", 200, time_limit_s=20)  # over 10 s: still running when its worker is killed
    notes, outcomes = [], []
    thread = threading.Thread(
        target=lambda: outcomes.append(run_bench([slow], tmp_path, workers=1, progress=False, say=notes.append))
    )
    thread.start()
    deadline = time.monotonic() + 20
    worker = None
    while worker is None and time.monotonic() < deadline:
        # the pool worker is the child of this process that has a run's process as its own child
        worker = next((pid for pid in _children(os.getpid()) if _children(pid)), None)
        time.sleep(0.05)
    assert worker is not None
    [run_process] = _children(worker)
    time.sleep(0.3)  # let the run's process start its work
    os.kill(worker, signal.SIGKILL)
    thread.join(timeout=30)
    [outcome] = outcomes
    assert outcome.failure is not None and outcome.ran == 0 and not outcome.interrupted
    assert notes and notes[0].startswith("stopped: BrokenProcessPool") and "run the same command again" in notes[0]
    assert read_records(tmp_path / "results.jsonl") == []
    # the run's own process ended with its worker
    deadline = time.monotonic() + 5
    while _running(run_process) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _running(run_process)


def _running(pid):
    """Whether ``pid`` exists and is not a zombie waiting to be reaped."""
    try:
        return (Path(f"/proc/{pid}") / "stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False
