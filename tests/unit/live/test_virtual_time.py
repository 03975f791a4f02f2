"""The live fleet on a virtual clock: the live drivers unchanged, one process, a simulated network and processors."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from mrmp.api import load
from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario, Timing
from mrmp.core.errors import InputError
from mrmp.live.transport import LiveFaults
from mrmp.live.virtual_time import ProcessingCosts, VirtualNetwork, VirtualOptions, run_virtual
from mrmp.sim.live_rounds import LiveRoundsSimulator
from mrmp.sim.synchronized_rounds import SynchronizedRoundsSimulator

ROOT = Path(__file__).resolve().parents[3]
CROSS = (
    RobotSpec("a", (0, 2), (4, 2)),
    RobotSpec("b", (4, 2), (0, 2)),
    RobotSpec("c", (2, 0), (2, 4)),
    RobotSpec("d", (2, 4), (2, 0)),
)


def crossing(**policy: object) -> Scenario:
    options = PolicyOptions(name="pibt", radius=8, **policy)  # type: ignore[arg-type]
    return Scenario(Grid(5, 5, [(2, 2)]), CROSS, timing=Timing(1.0, 0.5), policy=options, name="pibt-cross")


def distinct(cells) -> list:
    kept: list = []
    for cell in cells:
        if not kept or kept[-1] != tuple(cell):
            kept.append(tuple(cell))
    return kept


def believed_paths(results: Path, robots: int) -> list[list]:
    reports = [json.loads((results / f"agent-{index}.json").read_text()) for index in range(robots)]
    return [distinct(cell for _, cell in report["believed_path"]) for report in reports]


@pytest.mark.parametrize(("synchronizer", "simulator"), [("clock", None), ("local", SynchronizedRoundsSimulator)])
def test_a_virtual_fleet_moves_as_the_simulator_running_the_same_brain(tmp_path, synchronizer, simulator):
    """Perfect network, a radius that covers the map: the cells each robot enters are the simulator's, as for a live
    fleet of processes (``tests/network/test_live_pibt.py``)."""
    scenario = crossing(synchronizer=synchronizer)
    simulated = (simulator or (lambda s: LiveRoundsSimulator(s, step_ticks=4)))(scenario).run()
    virtual = run_virtual(scenario, VirtualOptions(results=tmp_path, time_scale=10))
    assert virtual.success and virtual.collisions == [], virtual.stop_reason
    assert believed_paths(tmp_path, len(CROSS)) == [distinct(robot.path) for robot in simulated.robots]


def test_the_same_seed_runs_the_same_fleet(tmp_path):
    faults = LiveFaults(loss=0.2, delay_max=0.01, duplicate=0.1)
    runs = [run_virtual(crossing(), VirtualOptions(results=tmp_path / str(run), time_scale=10, faults=faults, seed=4)) for run in range(2)]
    first, again = runs
    assert first.success and first.network["injected_lost"] > 0
    assert first.network == {**again.network} and first.time_makespan_s == again.time_makespan_s
    assert believed_paths(tmp_path / "0", 4) == believed_paths(tmp_path / "1", 4)


def test_a_slower_processor_makes_a_slower_fleet(tmp_path):
    """The processing costs are real: robots whose computers take far longer per turn and datagram arrive later."""
    scenario = crossing(synchronizer="local")  # steps end when the robots are done, not on a clock
    quick = run_virtual(scenario, VirtualOptions(results=tmp_path / "quick", time_scale=10, costs=ProcessingCosts(1e-6, 0)))
    slow_costs = ProcessingCosts(turn=1e-3, datagram=5e-3)
    slow = run_virtual(scenario, VirtualOptions(results=tmp_path / "slow", time_scale=10, costs=slow_costs))
    assert quick.success and slow.success
    assert slow.time_makespan_s > 1.2 * quick.time_makespan_s


def test_a_lossy_crowd_of_turning_robots_is_run_and_judged_as_live(tmp_path):
    """24 turning robots of ``causal-32`` ending their own steps over a network losing 20%: all arrive, no collision;
    every robot wrote its report and trace, and the referee judged them (its turns among them)."""
    scenario = load(ROOT / "examples" / "causal-32.yaml")
    policy = replace(scenario.policy, name="pibt", body="turning", synchronizer="local")
    scenario = scenario.with_changes(robots=scenario.robots[:24], policy=policy)
    result = run_virtual(scenario, VirtualOptions(results=tmp_path, time_scale=5, faults=LiveFaults(loss=0.2), seed=2))
    assert result.success and result.collisions == [] and result.body == "turning", result.stop_reason
    assert result.network["injected_lost"] > 0 and result.network["virtual_datagrams"] > result.network["datagrams_sent"]
    assert sum(robot.turns for robot in result.robots) > 0
    assert (tmp_path / "referee.json").exists() and len(list(tmp_path.glob("trace-*.jsonl"))) == 24


def test_over_multicast_a_message_for_several_peers_is_one_datagram_and_each_peer_misses_it_on_its_own(tmp_path):
    """The same lossy crossing over unicast and over a network where one datagram reaches several named peers: the
    messages are those a fleet needs either way; on the wire, multicast puts fewer datagrams than messages (a turn's
    messages for named peers go together)."""
    faults = LiveFaults(loss=0.2)
    runs = {
        multicast: run_virtual(crossing(), VirtualOptions(results=tmp_path / str(multicast), time_scale=10, faults=faults, multicast=multicast))
        for multicast in (False, True)
    }  # fmt: skip
    for run in runs.values():
        assert run.success and run.collisions == [], run.stop_reason
    unicast, multicast = runs[False].network, runs[True].network
    assert unicast["datagrams_sent"] == unicast["messages_sent"]
    assert multicast["datagrams_sent"] < 0.8 * multicast["messages_sent"]
    assert multicast["injected_lost"] > 0  # a fate per datagram and peer it reaches, a message for several peers
    assert multicast["datagrams_sent"] < multicast["injected_sent"] <= multicast["messages_sent"]  # reaching each


def test_a_body_the_policy_cannot_drive_live_is_refused(tmp_path):
    scenario = crossing().with_changes(policy=PolicyOptions(name="pibt", body="thesis"))
    with pytest.raises(InputError, match=r"policy\.body"):
        run_virtual(scenario, VirtualOptions(results=tmp_path))


def test_the_network_loses_and_duplicates_as_seeded():
    network = VirtualNetwork(2, LiveFaults(loss=0.5, duplicate=0.5), latency=0.0, seed=1)
    for number in range(1000):
        network.post(0, bytes([number % 256]), 1, at=0.0)
    arrived = len(list(network.take_due(0.0)))
    counts = network.counts[0]
    assert counts.sent == 1000 and 400 < counts.lost < 600 and arrived == 1000 - counts.lost + counts.duplicated


def test_ctrl_c_keeps_what_was_done(tmp_path, monkeypatch):
    """Interrupted, the run still writes every robot's report, the referee's verdict and its result."""
    from mrmp.live import virtual_time

    turn = virtual_time._VirtualFleet._turn
    turns = iter(range(10**9))

    def interrupted_later(self, index, robot):
        if next(turns) == 100:
            raise KeyboardInterrupt
        turn(self, index, robot)

    monkeypatch.setattr(virtual_time._VirtualFleet, "_turn", interrupted_later)
    result = run_virtual(crossing(), VirtualOptions(results=tmp_path, time_scale=10))
    assert result.stop_reason == "interrupted" and not result.success and result.collisions == []
    reports = [json.loads((tmp_path / f"agent-{index}.json").read_text()) for index in range(len(CROSS))]
    assert {report["stop_reason"] for report in reports} == {"interrupted"} and (tmp_path / "referee.json").exists()


def test_a_robot_arrives_when_its_body_enters_its_goal_for_the_last_time(tmp_path):
    """A live ``pibt`` brain decides a step before its body ends the move of the last one: the robot's arrival
    time is when its body entered its goal for good (its trace), whatever the brain had decided by then; a robot
    that starts on its goal and stays there arrives at once."""
    scenario = load(ROOT / "examples" / "causal-32.yaml")
    robots = (*scenario.robots[:23], RobotSpec("still", (15, 0), (15, 0)))
    scenario = scenario.with_changes(robots=robots, policy=replace(scenario.policy, name="pibt"))
    result = run_virtual(scenario, VirtualOptions(results=tmp_path, time_scale=5, faults=LiveFaults(loss=0.1), seed=1))
    assert result.success, result.stop_reason
    reports = [json.loads((tmp_path / f"agent-{index}.json").read_text()) for index in range(len(robots))]
    fleet_start = min(report["started_at"] for report in reports)
    for index, robot in enumerate(result.robots):
        lines = (tmp_path / f"trace-{index}.jsonl").read_text().splitlines()
        left = [event["t"] for event in map(json.loads, lines) if event.get("event") == "leave"]  # a move's end
        assert robot.time_s == pytest.approx(left[-1] - fleet_start if left else 0.0, abs=0.02), index


def test_a_live_robot_ranks_its_moves_by_its_guided_tables(tmp_path):
    """The live brain reads ``policy.guidance`` as the simulated one does (``tests/unit/sim/test_guidance.py``): on two
    rows whose lower one runs WEST, a turning robot going EAST along it leaves it only when guided."""
    from mrmp.core.heading import Heading

    robot = (RobotSpec("a", (1, 0), (1, 11), Heading.EAST),)
    rows = {}
    for guidance in ("none", "crisscross"):
        policy = PolicyOptions(name="pibt", body="turning", guidance=guidance)
        scenario = Scenario(Grid(2, 12), robot, timing=Timing(1.0, 0.5), policy=policy, name="lanes")
        result = run_virtual(scenario, VirtualOptions(results=tmp_path / guidance, time_scale=10))
        assert result.success and result.collisions == [], result.stop_reason
        rows[guidance] = {cell[0] for cell in believed_paths(tmp_path / guidance, 1)[0]}
    assert rows == {"none": {1}, "crisscross": {0, 1}}


def test_a_second_stop_signal_does_not_cut_the_writing_short(tmp_path, monkeypatch):
    """A real SIGTERM stops the run; another, while the reports are written, is left: every report, the referee's
    verdict and the result are still there (a shell's ``kill`` of a job reaches both it and what started it)."""
    import os
    import signal

    from mrmp.io.lifetime import interrupt_on_stop_signals
    from mrmp.live import virtual_time

    turn, finish = virtual_time._VirtualFleet._turn, virtual_time._VirtualFleet.finish
    turns = iter(range(10**9))

    def terminated_later(self, index, robot):
        if next(turns) == 100:
            os.kill(os.getpid(), signal.SIGTERM)
        turn(self, index, robot)

    def terminated_again(self):
        os.kill(os.getpid(), signal.SIGTERM)
        return finish(self)

    monkeypatch.setattr(virtual_time._VirtualFleet, "_turn", terminated_later)
    monkeypatch.setattr(virtual_time._VirtualFleet, "finish", terminated_again)
    saved = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        interrupt_on_stop_signals()  # as mrmp and bench/live_virtual.py have it
        result = run_virtual(crossing(), VirtualOptions(results=tmp_path, time_scale=10))
        assert signal.getsignal(signal.SIGTERM) is signal.default_int_handler  # restored on leaving
    finally:
        for signum, handler in saved.items():
            signal.signal(signum, handler)
    assert result.stop_reason == "interrupted" and result.collisions == []
    reports = [json.loads((tmp_path / f"agent-{index}.json").read_text()) for index in range(len(CROSS))]
    assert {report["stop_reason"] for report in reports} == {"interrupted"} and (tmp_path / "referee.json").exists()
