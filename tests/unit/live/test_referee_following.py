"""The referee following a run judges the traces as they grow: every collision is reported once, early or late."""

from __future__ import annotations

import json
import threading

from mrmp.core import Grid, RobotSpec, Scenario
from mrmp.io.live_files import TraceWriter
from mrmp.live.process import run_referee


def test_collisions_written_before_and_while_the_referee_follows_are_each_reported_once(tmp_path):
    robots = (RobotSpec("A", (0, 0), (0, 1)), RobotSpec("B", (0, 2), (0, 1)), RobotSpec("C", (0, 3), (0, 2)))
    scenario = Scenario(Grid(1, 4), robots)
    a, b, c = (TraceWriter(tmp_path / f"trace-{index}.jsonl", index) for index in range(3))
    a.write("enter", (0, 1), 1.0)
    b.write("enter", (0, 1), 1.5)  # B enters while A covers (0, 1): vertex
    done = tmp_path / "done"
    reported: list[str] = []
    first_seen = threading.Event()

    def report(text: str) -> None:
        reported.append(text)
        first_seen.set()

    stop = threading.Event()  # given: no signal handlers from a thread that is not the main one
    referee = threading.Thread(target=run_referee, args=(scenario, tmp_path, 0.0, done, report, stop))
    referee.start()
    assert first_seen.wait(30.0)
    c.write("enter", (0, 2), 2.0)  # later, C enters B's start cell, which B never left: vertex
    for writer in (a, b, c):
        writer.close()
    done.touch()
    referee.join(30.0)
    assert not referee.is_alive()
    verdict = json.loads((tmp_path / "referee.json").read_text())
    assert [(c["kind"], c["cells"]) for c in verdict["collisions"]] == [("vertex", [[0, 1]]), ("vertex", [[0, 2]])]
    assert reported == [
        "referee: tick 1500: vertex collision of A, B at (0, 1) (tick = milliseconds since the start)",
        "referee: tick 2000: vertex collision of B, C at (0, 2) (tick = milliseconds since the start)",
    ]


class SteppedClock:
    """A referee's clock that reads ``now`` and counts its readings (one per reading of the traces)."""

    def __init__(self, now: float) -> None:
        self.now = now
        self.readings = 0
        self.read = threading.Condition()

    def __call__(self) -> float:
        with self.read:
            self.readings += 1
            self.read.notify_all()
        return self.now

    def wait_for(self, readings: int) -> bool:
        with self.read:
            return self.read.wait_for(lambda: self.readings >= readings, timeout=30.0)


def test_a_collision_near_the_clock_waits_for_the_events_of_its_moment(tmp_path):
    """B is read entering the cell A covers; A's event of leaving it just before, written a little late, is not
    read yet. Within ``REFEREE_LAG`` of the clock nothing is reported, and the verdict has no collision.

    The broken variant (reporting whatever the traces say so far, as the referee once did) prints a vertex
    collision that the verdict then retracts."""
    robots = (RobotSpec("A", (0, 1), (0, 0)), RobotSpec("B", (0, 2), (0, 1)))
    scenario = Scenario(Grid(1, 3), robots)
    a, b = (TraceWriter(tmp_path / f"trace-{index}.jsonl", index) for index in range(2))
    b.write("enter", (0, 1), 11.9)  # A left (0, 1) at 11.8, not written yet
    clock = SteppedClock(12.0)
    done = tmp_path / "done"
    reported: list[str] = []
    stop = threading.Event()
    referee = threading.Thread(target=run_referee, args=(scenario, tmp_path, 0.0, done, reported.append, stop, clock))
    referee.start()
    assert clock.wait_for(3)  # every trace read twice at least
    a.write("enter", (0, 0), 11.7)
    a.write("leave", (0, 1), 11.8)
    for writer in (a, b):
        writer.close()
    done.touch()
    referee.join(30.0)
    assert not referee.is_alive()
    assert json.loads((tmp_path / "referee.json").read_text())["collisions"] == []
    assert reported == []
