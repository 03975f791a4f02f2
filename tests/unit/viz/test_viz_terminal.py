"""The terminal view: the grid as text, the simulators' tick observers, and --watch in a real terminal."""

from __future__ import annotations

import io
import shlex
import shutil
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest
from rich.console import Console

from mrmp.centralized.registry import plan_with
from mrmp.core import Grid, Heading
from mrmp.core.scenario import PolicyOptions
from mrmp.experiments.execution import execute_in_simulator
from mrmp.io import load_scenario
from mrmp.sim.simulator import simulate
from mrmp.viz.terminal import TRAIL, TerminalView, legend_text, render_grid, scale_for, short_labels

ROOT = Path(__file__).resolve().parents[3]
SWAP = ROOT / "examples" / "thesis-swap.yaml"
N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST


def test_a_tiny_grid_exactly() -> None:
    grid = Grid.from_rows(["...@", ".@..", "...."])
    picture = render_grid(
        grid, ["A", "B", "r12"], [(0, 0), (2, 1), (1, 3)], [E, S, W], goals=[(2, 0), (0, 3), (1, 2)]
    )
    assert picture.plain.split("\n") == [
        "a◦B↓· ██",
        "· ██c◦C←",
        "A→· · b◦",
    ]


def test_robots_with_long_ids_get_letters_of_their_own_and_a_legend() -> None:
    ids = ["r3", "r13", "r23"]  # the same last character: once all drawn as "3"
    labels = short_labels(ids)
    assert labels == ["A", "B", "C"]
    picture = render_grid(Grid(1, 3), ids, [(0, 0), (0, 1), (0, 2)], [E, E, E], labels=labels)
    assert picture.plain == "A→B→C→"
    assert legend_text(ids, labels, 80, 3) == ["A r3  B r13  C r23"]
    many = [f"robot-{n}" for n in range(100)]
    lines = legend_text(many, short_labels(many), 60, 3)
    assert len(lines) == 3 and all(len(line) <= 60 for line in lines) and lines[-1].endswith("(100 robots)")


def test_trails_show_the_last_cells_left() -> None:
    picture = render_grid(Grid(1, 5), ["A"], [(0, 4)], [E], trails=[[(0, 1), (0, 2), (0, 3)]])
    assert picture.plain == "· • • • A→"
    styles = {span.style for span in picture.spans if picture.plain[span.start : span.end] == TRAIL}
    assert styles and all("dim" not in str(style) for style in styles)


def test_the_view_shows_a_legend_of_labels_for_long_ids() -> None:
    scenario = load_scenario(ROOT / "examples" / "warehouse-astar.yaml")
    console = Console(file=io.StringIO(), width=80, height=40, color_system=None)
    view = TerminalView(scenario, console, fps=1000)
    lines = view.picture().plain.split("\n")
    ids = [spec.id for spec in scenario.robots]
    assert lines[-1].startswith(f"A {ids[0]}  B {ids[1]}"), lines[-1]


def test_robots_are_coloured_and_goals_dim() -> None:
    picture = render_grid(Grid(1, 2), ["A", "B"], [(0, 0), (0, 1)], [N, N], colours=["red", "blue"])
    styles = [str(span.style) for span in picture.spans]
    assert styles == ["bold red", "bold blue"]


def test_a_big_grid_is_shrunk_to_the_room() -> None:
    grid = Grid.from_rows(["@@@@....", "@@@@....", "..@.....", "........"])
    picture = render_grid(grid, ["A", "B", "C"], [(0, 0), (0, 1), (3, 7)], [N, N, N], columns=8, lines=2)
    assert scale_for(grid, 8, 2) == 2
    assert picture.plain.split("\n") == ["████· C↑", "2×▒▒· · "]
    assert max(len(line) for line in picture.plain.split("\n")) <= 8


def test_mismatched_lengths_are_refused() -> None:
    with pytest.raises(ValueError, match="one entry per robot"):
        render_grid(Grid(2, 2), ["A"], [(0, 0), (1, 1)], [N])


def observed(run) -> list[tuple[int, list[tuple[int, int]]]]:
    seen: list[tuple[int, list[tuple[int, int]]]] = []
    result = run(lambda tick, cells: seen.append((tick, list(cells))))
    assert [tick for tick, _ in seen] == list(range(1, result.ticks + 1))
    for tick, cells in seen:
        assert cells == [robot.path[tick] for robot in result.robots]
    return seen


@pytest.mark.parametrize("policy", ["thesis", "astar", "pibt"])
def test_every_simulator_reports_every_tick(policy: str) -> None:
    scenario = load_scenario(SWAP)
    scenario = scenario.with_changes(policy=PolicyOptions(name=policy))
    assert observed(lambda on_tick: simulate(scenario, on_tick=on_tick))


def test_a_central_plan_reports_every_tick() -> None:
    scenario = load_scenario(SWAP)
    plan = plan_with("cbs", scenario, time_limit_s=10)
    assert observed(lambda on_tick: execute_in_simulator(scenario, plan, on_tick=on_tick))


def test_the_view_follows_the_run_and_paces_it() -> None:
    scenario = load_scenario(SWAP)
    console = Console(file=io.StringIO(), width=40, height=20, color_system=None)
    now = [0.0]
    waits: list[float] = []

    def sleep(seconds: float) -> None:
        waits.append(seconds)
        now[0] += seconds

    with TerminalView(scenario, console, fps=4, clock=lambda: now[0], sleep=sleep) as view:
        result = simulate(scenario, on_tick=view.on_tick)
    assert waits == [pytest.approx(0.25)] * result.ticks
    assert view.tick == result.ticks
    final = [line.rstrip() for line in view.picture().plain.split("\n")]
    assert final[0] == "thesis-swap · thesis · tick 6"
    assert final[1] == "· · A←• ·", "A arrived from the east, heading west; its trail behind it"
    assert final[2:5] == ["· · • • ·", "· · • • ·", "· · • · ·"], "the last three cells each robot left"
    assert final[5] == "· · B↓· ·"


def tmux() -> str:
    program = shutil.which("tmux")
    if program is None:
        pytest.skip("tmux is not installed (apt-get install tmux): --watch is not checked in a terminal")
    return program


def test_watch_draws_in_a_terminal_and_ends_with_the_summary() -> None:
    program = tmux()
    server = f"mrmp-watch-{uuid.uuid4().hex[:8]}"
    command = f"cd {shlex.quote(str(ROOT))} && {shlex.quote(sys.executable)} -m mrmp run examples/thesis-swap.yaml --watch --watch-fps 20; echo EXIT=$?; sleep 60"
    subprocess.run([program, "-L", server, "new-session", "-d", "-s", "watch", "-x", "100", "-y", "40", command], check=True)
    try:
        screen = ""
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            screen = subprocess.run(
                [program, "-L", server, "capture-pane", "-p", "-t", "watch"], capture_output=True, text=True
            ).stdout
            if "EXIT=" in screen:
                break
            time.sleep(0.2)
        lines = screen.splitlines()
        assert "EXIT=0" in screen, screen
        assert "thesis-swap · thesis · tick 6" in lines
        grid_top = lines.index("thesis-swap · thesis · tick 6") + 1
        assert [line.rstrip() for line in lines[grid_top : grid_top + 5]] == [
            "· · A←• ·",
            "· · • • ·",
            "· · • • ·",
            "· · • · ·",
            "· · B↓· ·",
        ]
        assert any(line.startswith("success (all arrived at tick 6)") for line in lines), screen
    finally:
        subprocess.run([program, "-L", server, "kill-server"], capture_output=True)
