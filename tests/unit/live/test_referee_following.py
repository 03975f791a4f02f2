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
