"""A lifelong run live: one OS process per robot over UDP, the task desk a thread of the launcher, messages lost.

The desk's book must be what the bodies did (the referee's errand check) and
the fleet must reach about as many errands as the simulator's.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mrmp.api import run as simulate
from mrmp.core.progress import LiveProgress
from mrmp.io.lorr import lorr_scenario, read_lorr_problem
from mrmp.live.launcher import LiveOptions, run_live
from mrmp.live.transport import LiveFaults

PROBLEM = Path(__file__).resolve().parents[2] / "examples" / "lorr" / "warehouse-small_24.json"


@pytest.mark.slow
def test_a_lifelong_fleet_live_over_lossy_udp_reaches_real_errands(tmp_path: Path) -> None:
    scenario = lorr_scenario(read_lorr_problem(PROBLEM).with_team(8), steps=60)
    simulated = len(simulate(scenario).run.tasks.events)
    shown: list[LiveProgress] = []
    result = run_live(scenario, LiveOptions(time_scale=5, faults=LiveFaults(loss=0.2), results=tmp_path), on_progress=shown.append)
    assert result.stop_reason == "time up" and not result.collisions, (result.stop_reason, result.collisions)
    assert result.network["tasks_errands_not_visited"] == 0
    assert simulated >= 4 and len(result.tasks.events) >= simulated // 2
    written = json.loads((tmp_path / "tasks.json").read_text())
    assert shown and all(progress.tasks is not None for progress in shown)
    assert "tasks finished" in shown[-1].text()
    within = [event for event in written["events"] if event[0] <= 60]
    assert written["reports"] > 0 and within == [list(event) for event in result.tasks.events]
