"""The live referee judges the actions of bodies that turn in place, as the lockstep referee does tick by tick."""

from __future__ import annotations

import json
import threading

import pytest

from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario, Timing
from mrmp.core.body import body_model
from mrmp.core.heading import Heading
from mrmp.io.live_files import TraceWriter
from mrmp.live.action_referee import TurningActions
from mrmp.live.body import OccupancyRecorder, SimulatedBody
from mrmp.live.process import run_referee

N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST


def judged(recorder: OccupancyRecorder, start: tuple[int, int], heading: Heading) -> list[str]:
    """The actions the live referee finds illegal in one body's recorded events, replayed in time order.

    A turn that ends when a move starts ended first (the body records them in that order).
    """
    actions = TurningActions(["A"], [start], [heading], start_time=0.0)
    events = [(t, 1, event, cell, None) for event, cell, t in recorder.events]
    events += [(t, 0, "heading", cell, facing) for cell, facing, t in recorder.headings]
    for t, _, event, cell, facing in sorted(events, key=lambda item: (item[0], item[1])):
        actions.feed(0, event, cell, t, facing)
    return [collision.kind for collision in actions.collisions()]


def test_a_turning_body_that_turns_then_drives_ahead_is_legal() -> None:
    recorder = OccupancyRecorder()
    body = SimulatedBody((0, 0), E, Grid(3, 3), Timing(1.0, 1.0), recorder=recorder, model=body_model("turning"))
    body.start_turn(N, now=0.0)
    assert not body.poll(0.5) and body.poll(1.0)
    body.start_move((1, 0), now=1.0)
    assert body.poll(2.0)
    assert recorder.headings == [((0, 0), N, 1.0)]
    assert judged(recorder, (0, 0), E) == []


def test_a_body_that_turns_as_part_of_its_move_is_caught() -> None:
    """The thesis's body turns right on the way into its next cell: a turning fleet driving it breaks the model."""
    recorder = OccupancyRecorder()
    body = SimulatedBody((0, 0), E, Grid(3, 3), Timing(1.0, 1.0), recorder=recorder)  # no model: the thesis's body
    body.start_move((1, 0), now=0.0)
    assert body.poll(10.0) and recorder.headings == []
    assert judged(recorder, (0, 0), E) == ["action"]


@pytest.mark.parametrize(
    ("events", "expected"),
    [
        ([("enter", (0, 1), 1.0, None), ("leave", (0, 0), 2.0, None), ("heading", (0, 1), 3.0, N)], []),
        ([("enter", (0, 1), 1.0, None), ("heading", (0, 1), 1.5, N), ("leave", (0, 0), 2.0, None)], ["action"]),
        ([("heading", (0, 0), 1.0, W)], ["action"]),  # a half turn in one action
        ([("enter", (1, 0), 1.0, None)], ["action"]),  # facing EAST, it drove NORTH
    ],
)
def test_moves_not_ahead_turns_during_moves_and_half_turns_are_actions_broken(events, expected) -> None:
    actions = TurningActions(["A"], [(0, 0)], [E], start_time=0.0)
    for event, cell, t, heading in events:
        actions.feed(0, event, cell, t, heading)
    assert [collision.kind for collision in actions.collisions()] == expected


def test_the_referee_process_judges_turning_traces_and_writes_the_verdict(tmp_path) -> None:
    robots = (RobotSpec("A", (0, 0), (1, 1), heading=E), RobotSpec("B", (2, 2), (2, 0), heading=W))
    scenario = Scenario(Grid(3, 3), robots, policy=PolicyOptions(name="pibt", body="turning", swap=False))
    a, b = (TraceWriter(tmp_path / f"trace-{index}.jsonl", index) for index in range(2))
    a.write("enter", (0, 1), 1.0)  # A drives ahead (EAST), then turns NORTH and drives on: legal
    a.write("leave", (0, 0), 2.0)
    a.write_heading((0, 1), N, 3.0)
    a.write("enter", (1, 1), 3.0)
    a.write("leave", (0, 1), 4.0)
    b.write("enter", (1, 2), 1.0)  # B faces WEST (-y) but drives to (1, 2), SOUTH (-x): not ahead
    b.write("leave", (2, 2), 2.0)
    for writer in (a, b):
        writer.close()
    reported: list[str] = []
    run_referee(scenario, tmp_path, 0.0, None, reported.append, threading.Event())
    verdict = json.loads((tmp_path / "referee.json").read_text())
    assert [(c["kind"], c["robots"], c["cells"]) for c in verdict["collisions"]] == [("action", ["B"], [[1, 2]])]
    assert reported == ["referee: tick 1000: action collision of B at (1, 2) (tick = milliseconds since the start)"]
