"""Messages: recorded per tick by the lockstep simulator, kept in the JSON result, drawn as arrows."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

import pytest
from PIL import Image
from typer.testing import CliRunner

from mrmp.cli import app
from mrmp.core import Grid, RunResult
from mrmp.core.errors import InputError
from mrmp.core.scenario import PolicyOptions
from mrmp.io import load_scenario
from mrmp.io.results import read_result_json, result_from_dict, result_to_dict
from mrmp.sim.simulator import simulate
from mrmp.viz import write_gif, write_svg
from mrmp.viz.layout import make_layout, message_arrows, robot_colours

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def recorded() -> tuple[Grid, RunResult]:
    scenario = load_scenario(EXAMPLES / "thesis-swap.yaml")
    return scenario.grid, simulate(scenario, record_messages=True)


def test_the_log_has_one_entry_per_message_sent(recorded: tuple[Grid, RunResult]) -> None:
    _, result = recorded
    log = result.message_log
    assert log is not None and len(log) == result.ticks + 1 and log[0] == []
    by_sender = Counter(sender for entries in log for sender, _, _ in entries)
    assert by_sender == {robot.id: robot.messages_sent for robot in result.robots}
    assert {kind for entries in log for _, _, kind in entries} >= {"state", "claim", "reply"}
    assert all(sender != recipient for entries in log for sender, recipient, _ in entries)


def test_the_default_run_records_nothing_and_is_otherwise_the_same(recorded: tuple[Grid, RunResult]) -> None:
    _, with_log = recorded
    plain = simulate(load_scenario(EXAMPLES / "thesis-swap.yaml"))
    assert plain.message_log is None
    assert [r.path for r in plain.robots] == [r.path for r in with_log.robots]
    assert plain.messages == with_log.messages


def test_pibt_rounds_keep_no_log() -> None:
    scenario = load_scenario(EXAMPLES / "thesis-swap.yaml")
    result = simulate(scenario.with_changes(policy=PolicyOptions(name="pibt")), record_messages=True)
    assert result.success and result.message_log is None


def test_the_log_survives_json(recorded: tuple[Grid, RunResult]) -> None:
    _, result = recorded
    data = json.loads(json.dumps(result_to_dict(result)))
    assert data["message_log"][1][0] == list(result.message_log[1][0])
    assert result_from_dict(data) == result
    assert "message_log" not in result_to_dict(simulate(load_scenario(EXAMPLES / "thesis-swap.yaml")))


@pytest.mark.parametrize(
    "log, fragment",
    [({"message_log": "x"}, "message_log: expected a list of ticks"), ({"message_log": [[["A", 1, "state"]]]}, "message_log[0][0]")],
)
def test_a_bad_log_is_named(log: dict[str, object], fragment: str) -> None:
    with pytest.raises(InputError, match=fragment.replace("[", r"\[")):
        result_from_dict({"scenario": "s", "policy": "p", **log}, "run.json")


def test_arrows_merge_kinds_and_respect_the_limit(recorded: tuple[Grid, RunResult]) -> None:
    grid, result = recorded
    layout = make_layout(grid, 2)
    arrows = message_arrows(result, layout)
    kinds: dict[tuple[int, str, str], set[str]] = {}
    for tick, entries in enumerate(result.message_log):
        for sender, recipient, kind in entries:
            kinds.setdefault((tick, sender, recipient), set()).add(kind)
    ids = [robot.id for robot in result.robots]
    assert {(a.tick, ids[a.sender], ids[a.recipient]): set(a.kinds) for a in arrows} == kinds
    one_each = message_arrows(result, layout, limit=1)
    first_pairs = {tick: (entries[0][0], entries[0][1]) for tick, entries in enumerate(result.message_log) if entries}
    assert {a.tick: (ids[a.sender], ids[a.recipient]) for a in one_each} == first_pairs
    assert len(one_each) == len(first_pairs)


def test_svg_draws_one_arrow_per_pair_and_tick(recorded: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = recorded
    root = ET.parse(write_svg(grid, result, tmp_path / "m.svg", show_messages=True)).getroot()
    groups = root.findall(f".//{SVG}g[@class='message']")
    pairs = {(str(tick), s, r) for tick, entries in enumerate(result.message_log) for s, r, _ in entries}
    assert {(g.get("data-tick"), g.get("data-from"), g.get("data-to")) for g in groups} == pairs
    first = next(g for g in groups if "state" in g.get("data-kinds"))  # once the robots are within two cells
    assert first.find(f"{SVG}line") is not None
    assert first.find(f"{SVG}animate").get("calcMode") == "discrete"
    plain = ET.parse(write_svg(grid, result, tmp_path / "p.svg")).getroot()
    assert not plain.findall(f".//{SVG}g[@class='message']")


def test_gif_draws_the_arrows_between_the_robots(recorded: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = recorded
    layout = make_layout(grid, 2)
    arrow = message_arrows(result, layout)[0]  # tick 1, shown on the frame of tick 0
    x = (arrow.start[0] + arrow.end[0]) / 2
    y = (arrow.start[1] + arrow.end[1]) / 2
    colour = robot_colours(2)[arrow.sender]

    def first_frame(name: str, show: bool) -> tuple[int, int, int]:
        with Image.open(write_gif(grid, result, tmp_path / name, frames_per_tick=1, show_messages=show)) as gif:
            return gif.convert("RGB").getpixel((round(x), round(y)))

    shown, hidden = first_frame("m.gif", True), first_frame("p.gif", False)
    assert all(abs(a - b) <= 20 for a, b in zip(shown, colour)), (shown, colour)
    assert not all(abs(a - b) <= 20 for a, b in zip(hidden, colour))


def test_cli_records_messages_into_json_with_the_map_and_animates_them_later(tmp_path: Path) -> None:
    runner = CliRunner()
    saved = tmp_path / "run.json"
    done = runner.invoke(app, ["run", str(EXAMPLES / "thesis-swap.yaml"), "--show-messages", "--json", str(saved)])
    assert done.exit_code == 0, done.output
    result, grid = read_result_json(saved)
    assert grid is not None and (grid.x_size, grid.y_size) == (5, 5)
    assert result.message_log and sum(len(entries) for entries in result.message_log) == result.messages
    out = tmp_path / "again.svg"
    drawn = runner.invoke(app, ["animate", str(saved), "--out", str(out), "--show-messages"])
    assert drawn.exit_code == 0, drawn.output
    assert ET.parse(out).getroot().findall(f".//{SVG}g[@class='message']")


def test_cli_refuses_show_messages_where_none_are_recorded(tmp_path: Path) -> None:
    runner = CliRunner()
    swap = str(EXAMPLES / "thesis-swap.yaml")
    pibt = runner.invoke(app, ["run", swap, "--policy", "pibt", "--show-messages", "--animate", str(tmp_path / "a.svg")])
    assert pibt.exit_code == 2 and "pibt runs in synchronous rounds (mrmp.sim.rounds), which records no" in pibt.output
    causal = runner.invoke(app, ["run", swap, "--policy", "causal", "--show-messages", "--animate", str(tmp_path / "a.svg")])
    assert causal.exit_code == 2 and "causal runs asynchronously (mrmp.sim.asynchronous), which records no" in causal.output
    assert "success" not in pibt.output, "refused before the run"
    alone = runner.invoke(app, ["run", swap, "--show-messages"])
    assert alone.exit_code == 2 and "give --animate" in alone.output
    saved = tmp_path / "plain.json"
    assert runner.invoke(app, ["run", swap, "--json", str(saved)]).exit_code == 0
    missing = runner.invoke(app, ["animate", str(saved), "--out", str(tmp_path / "b.svg"), "--show-messages"])
    assert missing.exit_code == 2 and "no messages are recorded" in missing.output
    assert not (tmp_path / "a.svg").exists() and not (tmp_path / "b.svg").exists()


def test_over_the_limit_the_shortest_arrows_are_kept() -> None:
    from mrmp.core import RobotResult

    robots = [RobotResult(name, (0, y), (0, y), path=[(0, y), (0, y)]) for name, y in (("A", 0), ("B", 2), ("C", 6))]
    log = [[], [("A", "C", "state"), ("A", "B", "state"), ("C", "B", "state")]]
    run = RunResult("s", "p", 0, robots, [], "done", 1, 0, 0.0, message_log=log)
    layout = make_layout(Grid(1, 7), 3)
    assert [(a.sender, a.recipient) for a in message_arrows(run, layout)] == [(0, 2), (0, 1), (2, 1)]
    assert [(a.sender, a.recipient) for a in message_arrows(run, layout, limit=1)] == [(0, 1)]
    assert [(a.sender, a.recipient) for a in message_arrows(run, layout, limit=2)] == [(0, 1), (2, 1)]
