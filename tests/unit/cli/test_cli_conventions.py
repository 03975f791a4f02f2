"""``mrmp`` follows command-line conventions: --version, -h, listed choices, typed metavars, defaults, panels, completion."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import typer.main
from typer.testing import CliRunner

from mrmp.centralized.registry import PLANNER_NAMES
from mrmp.cli import app
from mrmp.core.options import RESOLUTIONS, SEARCH_NAMES
from mrmp.live.transport_table import TRANSPORTS
from mrmp.sim.policy_table import policy_names

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"
COMMANDS = ("run", "compare", "report", "animate", "export", "bench", "validate", "agent", "referee")
runner = CliRunner()


def invoke(*args: object, columns: int = 200):
    return runner.invoke(app, [str(arg) for arg in args], env={"COLUMNS": str(columns), "NO_COLOR": "1"})


def test_version_long_and_short() -> None:
    for flag in ("--version", "-V"):
        result = invoke(flag)
        assert result.exit_code == 0 and result.output.strip() == "mrmp 0.1.0"


@pytest.mark.parametrize("command", [(), *[(name,) for name in COMMANDS]])
def test_h_is_help_and_no_flag_shows_a_value_type(command: tuple[str, ...]) -> None:
    short, long = invoke(*command, "-h"), invoke(*command, "--help")
    assert short.exit_code == long.exit_code == 0 and short.output == long.output
    for python_type in ("<bool>", "<str>", "<list[str]>"):
        assert python_type not in long.output, (command, python_type)


def test_run_lists_the_choices_of_every_table() -> None:
    output = invoke("run", "-h").output
    for names in (policy_names(), PLANNER_NAMES, TRANSPORTS.names, RESOLUTIONS, ("default", *SEARCH_NAMES)):
        assert "[" + "|".join(names) + "]" in output.replace("\n", "").replace(" ", "").replace("│", ""), names


def test_run_groups_its_options_in_panels() -> None:
    output = invoke("run", "-h").output
    panels = ("Scenario", "Policy", "Network faults", "Output", "Central planner", "Live run (--live)")
    positions = [output.index(f"─ {panel}") for panel in panels]
    assert positions == sorted(positions)
    live = output[output.index("─ Live run"):]
    assert "--transport" in live and "--kill" in live and "--policy" not in live


@pytest.mark.parametrize("name", COMMANDS)
def test_defaults_are_shown_one_way(name: str) -> None:
    """A default is shown as ``[default: ...]``, never in the help sentence; an option with a value shows it."""
    command = typer.main.get_command(app).commands[name]  # type: ignore[attr-defined]
    for param in command.params:
        if param.param_type_name != "option" or param.hidden:
            continue
        assert "(default:" not in (param.help or "").lower(), f"mrmp {name} {param.opts[0]}: a default in the help text"
        if param.default is not None and not getattr(param, "is_flag", False) and not param.multiple:
            assert param.show_default is not False, f"mrmp {name} {param.opts[0]} hides its default"


def test_options_that_replace_a_scenario_value_say_so() -> None:
    command = typer.main.get_command(app).commands["run"]  # type: ignore[attr-defined]
    replacing = {"policy", "resolve", "heading_aware", "radius", "swap", "search", "max_ticks", "seed", "loss", "delay", "duplicate", "reorder"}
    for param in command.params:
        if param.name in replacing:
            assert str(param.show_default).startswith("the scenario's"), param.name


def test_paths_are_typed_as_paths() -> None:
    for name in ("run", "compare"):
        command = typer.main.get_command(app).commands[name]  # type: ignore[attr-defined]
        json_option = next(param for param in command.params if param.name == "json_path")
        assert json_option.type_descriptor.is_path and json_option.metavar == "PATH|-"
    out = invoke("run", EXAMPLES / "thesis-swap.yaml", "--json", "-")
    assert out.exit_code == 0 and '"stop_reason": "all arrived"' in out.stdout


def test_only_missing_says_what_its_name_says() -> None:
    output = " ".join(invoke("bench", "-h").output.replace("│", "").split())
    assert "--only-missing" in output and "as missing, and run it again" in output


def test_agent_takes_its_scenario_as_run_does_and_by_the_old_option() -> None:
    scenario = EXAMPLES / "thesis-swap.yaml"
    zenoh = ("--robot", "A", "--transport", "zenoh", "--listen", "tcp/127.0.0.1:7447?x=1")
    positional = invoke("agent", scenario, *zenoh)
    option = invoke("agent", "--scenario", scenario, *zenoh)
    assert positional.exit_code == option.exit_code == 2 and positional.output == option.output
    both = invoke("agent", scenario, "--scenario", scenario, "--robot", "A")
    assert both.exit_code == 2 and "give the scenario once" in both.output
    neither = invoke("agent", "--robot", "A")
    assert neither.exit_code == 2 and "SCENARIO: give the fleet's scenario file" in neither.output
    nobody = invoke("agent", scenario)
    assert nobody.exit_code == 2 and "--robot:" in nobody.output


def _event(robot: int, event: str, cell: tuple[int, int], t: float) -> str:
    return json.dumps({"robot": robot, "event": event, "cell": list(cell), "t": t}) + "\n"


def test_referee_by_hand_judges_the_traces_as_they_are(tmp_path: Path) -> None:
    # thesis-swap: A starts at (0, 2), B at (4, 2); B walks into A's cell 0.2 s after the first event
    (tmp_path / "trace-0.jsonl").write_text(_event(0, "enter", (0, 2), 100.1))
    (tmp_path / "trace-1.jsonl").write_text(
        "".join(_event(1, *step) for step in [("enter", (4, 2), 100.1), ("enter", (3, 2), 100.1), ("leave", (4, 2), 100.15),
                                              ("enter", (2, 2), 100.2), ("leave", (3, 2), 100.25), ("enter", (1, 2), 100.25),
                                              ("leave", (2, 2), 100.28), ("enter", (0, 2), 100.3)])
    )  # fmt: skip
    result = invoke("referee", EXAMPLES / "thesis-swap.yaml", "--results", tmp_path)
    assert result.exit_code == 1 and "1 collision;" in result.output
    verdict = json.loads((tmp_path / "referee.json").read_text())
    assert verdict["start_time"] == 100.1 and [c["tick"] for c in verdict["collisions"]] == [200]


def test_referee_of_a_missing_folder_is_bad_input(tmp_path: Path) -> None:
    result = invoke("referee", EXAMPLES / "thesis-swap.yaml", "--results", tmp_path / "nowhere")
    assert result.exit_code == 2 and "--results: no such folder" in result.output


@pytest.mark.slow
def test_shell_completion_completes_choices_from_the_tables() -> None:
    def complete(words: str) -> list[str]:
        env = {**os.environ, "_MRMP_COMPLETE": "complete_bash", "COMP_WORDS": words, "COMP_CWORD": str(len(words.split(" ")) - 1)}
        done = subprocess.run([sys.executable, "-m", "mrmp"], env=env, capture_output=True, text=True, check=False)
        return done.stdout.split()

    assert complete("mrmp run --policy ") == list(policy_names())
    assert complete("mrmp run --transport m") == ["multicast"]
    assert complete("mrmp run --planner ") == list(PLANNER_NAMES)
    # the shell named, not detected from the process's ancestors (typer's own switch for that): the test must not
    # depend on being started from a shell
    named = {**os.environ, "_TYPER_COMPLETE_TEST_DISABLE_SHELL_DETECTION": "1"}
    shown = subprocess.run(
        [sys.executable, "-m", "mrmp", "--show-completion", "bash"], env=named, capture_output=True, text=True, check=False
    )
    assert shown.returncode == 0 and "complete -o default -F _mrmp_completion mrmp" in shown.stdout


def test_animations_take_the_colouring_and_speed_the_api_takes(tmp_path: Path) -> None:
    drawn = tmp_path / "swap.svg"
    result = invoke("run", EXAMPLES / "thesis-swap.yaml", "--animate", drawn, "--colour-by", "heading", "--goal-lines")
    assert result.exit_code == 0 and "facing north" in drawn.read_text() and 'id="goal-lines"' in drawn.read_text()
    saved = tmp_path / "swap.json"
    assert invoke("run", EXAMPLES / "thesis-swap.yaml", "--json", saved).exit_code == 0
    again = tmp_path / "again.svg"
    assert invoke("animate", saved, "--out", again, "--colour-by", "heading").exit_code == 0
    assert "facing north" in again.read_text()
    for args, fragment in ((["--colour-by", "rainbow"], "--colour-by: unknown colouring 'rainbow'"), (["--speed", "0"], "--speed: must be positive")):
        refused = invoke("run", EXAMPLES / "thesis-swap.yaml", "--animate", tmp_path / "x.svg", *args)
        assert refused.exit_code == 2 and fragment in refused.output and not (tmp_path / "x.svg").exists()
