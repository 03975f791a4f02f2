"""The task desk of live lifelong runs: the robot's side, the desk's side, their messages, and a whole fleet.

A lifelong live run takes its tasks from the desk (:mod:`mrmp.live.task_desk`);
what the desk counts must be what the robots' bodies did (the referee's
errand check, :func:`mrmp.live.referee.errands_not_visited`), and the fleet
must finish as many tasks as the simulator with the same brains.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mrmp.api import run as simulate
from mrmp.core.grid import Grid
from mrmp.core.tasks import TaskStream
from mrmp.io.lorr import lorr_scenario, read_lorr_problem
from mrmp.live.pibt_agent import PibtBrain, PibtTiming
from mrmp.live.task_desk import TaskDesk
from mrmp.live.transport import LiveFaults
from mrmp.live.virtual_time import VirtualOptions, run_virtual
from mrmp.protocol.codec import decode, encode
from mrmp.protocol.tasks import NO_TASK, TaskMessage, TaskReportMessage
from mrmp.protocol.wire import DecodeError
from mrmp.robot.task_taker import TaskTaker
from mrmp.sim.task_book import task_book

PROBLEM = Path(__file__).resolve().parents[3] / "examples" / "lorr" / "warehouse-small_24.json"
LINE = TaskStream(errands=(((0, 3),), ((0, 1), (0, 2))), reveal=2)
"""Two tasks on a 1x4 corridor."""


def lifelong(robots: int = 24, steps: int = 60):
    return lorr_scenario(read_lorr_problem(PROBLEM).with_team(robots), steps=steps)


# -- the robot's side ----------------------------------------------------------------------------


def test_a_robot_takes_a_task_only_when_free_and_never_a_finished_one_again() -> None:
    taker = TaskTaker(index=0, desk=1, retry=0.1)
    task_5 = TaskMessage(1, 1, task=5, done=0, errands=((0, 1),))
    assert taker.take(task_5) and taker.goal((0, 0)) == (0, 1)
    assert not taker.take(TaskMessage(1, 2, task=6, done=0, errands=((0, 3),)))  # busy with task 5
    assert taker.step_ended(4, (0, 1)) and not taker.busy and taker.goal((0, 1)) == (0, 1)
    assert not taker.take(task_5)  # a late copy of the task it finished
    assert taker.take(TaskMessage(1, 3, task=6, done=0, errands=((0, 3),))) and taker.goal((0, 1)) == (0, 3)


def test_an_errand_counts_once_per_step_however_often_the_robot_is_told() -> None:
    taker = TaskTaker(index=0, desk=1, retry=0.1)
    taker.take(TaskMessage(1, 1, task=0, done=0, errands=((0, 1), (0, 1))))
    assert taker.step_ended(3, (0, 1)) and not taker.step_ended(3, (0, 1))  # decided for good, then the step's end
    assert taker.done == 1 and taker.step_ended(4, (0, 1)) and taker.done == 2


def test_reports_repeat_until_acknowledged_and_a_free_robot_keeps_asking() -> None:
    taker = TaskTaker(index=3, desk=9, retry=0.1)
    assert [report.sender for report in taker.due(0.0, (0, 0), step=0)] == [3]
    assert taker.due(0.05, (0, 0), step=0) == [] and len(taker.due(0.1, (0, 0), step=0)) == 1  # free: asks again
    taker.take(TaskMessage(9, 1, task=2, done=0, errands=((0, 1), (0, 2))))
    assert len(taker.due(0.12, (0, 0), step=1)) == 1  # the change, at once
    assert taker.due(0.5, (0, 0), step=5) == []  # acknowledged by the task itself
    taker.step_ended(6, (0, 1))
    sent = [taker.due(t, (0, 1), step=7) for t in (0.6, 0.65, 0.7)]
    assert [len(reports) for reports in sent] == [1, 0, 1]  # again after the retry interval, while unacknowledged
    taker.take(TaskMessage(9, 2, task=2, done=1, errands=((0, 1), (0, 2))))
    assert taker.due(2.0, (0, 1), step=20) == []


# -- the desk's side -----------------------------------------------------------------------------


def test_the_desk_counts_each_errand_once_and_no_task_finished_after_the_last_step() -> None:
    desk = TaskDesk(LINE, Grid(1, 4), [(0, 0)], steps=5)
    [(_, first)] = desk.due(0.0)
    report = TaskReportMessage(0, 1, task=first.task, done=2, step=4, cell=(0, 2))
    answer = desk.take(report)
    assert desk.take(report) == TaskMessage(1, answer.seq + 1, answer.task, answer.done, answer.errands)  # idempotent
    assert desk.finished == 1 and len(desk.book.log.events) == 2
    desk.take(TaskReportMessage(0, 3, task=answer.task, done=1, step=6, cell=(0, 3)))  # after the last step
    assert desk.finished == 1 and desk.book.log.finished == 2


def test_the_desk_gives_the_first_tasks_as_the_simulators_task_book_does() -> None:
    scenario = lifelong()
    desk = TaskDesk(scenario.tasks, scenario.grid, [robot.start for robot in scenario.robots], steps=10)
    told = {robot: message.task for robot, message in desk.due(0.0)}
    book = task_book(scenario)
    book.update(0, [robot.start for robot in scenario.robots])
    assert told == {robot: task.task_id for robot, task in enumerate(book.task_of) if task is not None}
    assert len(told) == 24


@pytest.mark.parametrize(
    "message",
    [TaskMessage(24, 1, task=NO_TASK, done=0, errands=((0, 1),)), TaskMessage(24, 1, task=3, done=2, errands=((0, 1),))],
)
def test_malformed_task_messages_are_refused_by_the_codec(message: TaskMessage) -> None:
    with pytest.raises(DecodeError):
        decode(encode(message))


# -- a robot's brain -----------------------------------------------------------------------------


def test_a_lifelong_brain_heads_for_the_errand_the_desk_gave_it_and_nobody_else() -> None:
    scenario = lifelong(robots=4)
    brain = PibtBrain(scenario, 0, PibtTiming.for_body(0.4))
    errand = (scenario.robots[1].start[0], scenario.robots[1].start[1] + 1)
    brain.receive(TaskMessage(2, 1, task=0, done=0, errands=(errand,)), 0.0)  # a robot's index: not the desk's
    assert brain.dropped["unknown_sender"] == 1 and brain.tasks.task == NO_TASK
    brain.receive(TaskMessage(4, 1, task=0, done=0, errands=((-1, 0),)), 0.0)
    assert brain.dropped["off_map"] == 1
    brain.receive(TaskMessage(4, 2, task=0, done=0, errands=(errand,)), 0.0)  # before the fleet starts
    brain.start(0.0)
    brain.expire(0.0)
    assert brain.step == 1 and brain.robot.goal == brain.flat.index(errand)
    assert not brain.settled  # its steps are not over


# -- a whole fleet on the virtual clock ---------------------------------------------------------


@pytest.mark.slow
def test_a_virtual_lifelong_fleet_finishes_what_the_simulator_does_and_its_errands_are_real(tmp_path: Path) -> None:
    scenario = lifelong(steps=120)
    simulated = simulate(scenario).run
    result = run_virtual(scenario, VirtualOptions(results=tmp_path, time_scale=5, faults=LiveFaults(loss=0.1)))
    assert result.success and result.stop_reason == "time up" and not result.collisions
    assert result.network["tasks_errands_not_visited"] == 0
    errands, simulated_errands = len(result.tasks.events), len(simulated.tasks.events)
    assert simulated_errands >= 20 and abs(errands - simulated_errands) <= 0.1 * simulated_errands
    written = json.loads((tmp_path / "tasks.json").read_text())
    assert written["finished"] == result.tasks.finished and written["steps"] == 120


def test_the_errand_check_catches_robots_that_report_errands_they_never_reached(tmp_path, monkeypatch) -> None:
    def reached_wherever(self: TaskTaker, step: int, present: tuple[int, int]) -> bool:
        if step <= self._ended or not self.busy:
            return False
        self._ended, self.done, self.reached_at = step, self.done + 1, step
        self._changed = True
        return True

    monkeypatch.setattr(TaskTaker, "step_ended", reached_wherever)
    result = run_virtual(lifelong(robots=6, steps=20), VirtualOptions(results=tmp_path, time_scale=5))
    assert result.network["tasks_errands_not_visited"] > 0


# -- mrmp agent ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("lifelong", "arguments", "message"),
    [
        (True, [], "--task-desk: a lifelong robot takes its tasks from a task desk"),
        (True, ["--policy", "astar"], "--policy: astar does not take tasks live"),
        (False, ["--task-desk", "127.0.0.1:9009"], "--task-desk: a task desk serves a lifelong run"),
    ],
)
def test_mrmp_agent_refuses_a_robot_and_a_desk_that_do_not_go_together(
    tmp_path: Path, lifelong: bool, arguments: list[str], message: str
) -> None:
    from typer.testing import CliRunner

    from mrmp.cli import app

    scenario = tmp_path / "s.yaml"
    scenario.write_text(
        "map: {rows: ['....', '....']}\nrobots:\n  - {id: A, start: [0, 0], goal: [0, 0]}\n  - {id: B, start: [1, 3], goal: [1, 3]}\n"
        f"policy: {{name: pibt, body: turning}}\nlifelong: {str(lifelong).lower()}\nmax_ticks: 10\n"
    )
    result = CliRunner().invoke(app, ["agent", str(scenario), "--robot", "A", "--peer", "B=127.0.0.1:9002", *arguments])
    assert result.exit_code == 2 and message in result.output and "Traceback" not in result.output
