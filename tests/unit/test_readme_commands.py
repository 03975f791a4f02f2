"""The README's commands run as written in a fresh shell after its set-up command.

Every command line of the README's ``sh`` blocks names the virtual environment's
programs (``.venv/bin/mrmp``, ``.venv/bin/python``, ``.venv/bin/pip``), so that
it works without activating anything; the slow test runs them, each in a fresh
``bash`` in a scratch folder that sees the repository's ``examples``, ``maps``,
``bench`` and ``.venv``, and fails on a command that is not found, is refused
(exit 2) or prints a traceback.
"""

from __future__ import annotations

import os
import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"

SET_UP = "python3 -m venv .venv && "
"""How both set-up commands begin: they create the environment the others use."""
PROGRAMS = (".venv/bin/mrmp ", ".venv/bin/python ", ".venv/bin/pip ")
NOT_RUN_HERE = {
    "One robot per computer": "needs three hosts (the documentation addresses 192.0.2.x)",
}
"""Sections whose commands are examples for other machines, with why they are not run here."""
TOO_LONG = (
    "bench/standard.yaml --out",
    "bench/generated.yaml --out",
    "out/standard --out",
    "bench/chapter5.py",
    "bench/messages_per_move.py",
    "bench/plan_execution.py",
    "bench/live_plan.py",
)
"""Commands left out of the run for their length (the standard matrix takes 12 minutes, chapter 5 more, the messages
per move up to 1000 robots several, the executions of plans for 200 robots minutes), by a fragment."""


@dataclass(frozen=True)
class Command:
    section: str
    line: int
    text: str


def readme_commands(text: str) -> list[Command]:
    """Every command line of the ``sh`` blocks, with its section (the last heading) and line number.

    >>> readme_commands("## A\\n```sh\\n# a comment\\n.venv/bin/mrmp run x.yaml   # note\\n```\\n")
    [Command(section='A', line=4, text='.venv/bin/mrmp run x.yaml')]
    """
    commands: list[Command] = []
    section, inside = "", False
    for number, line in enumerate(text.split("\n"), start=1):
        if line.startswith("#") and not inside:
            section = line.lstrip("#").strip()
        elif line.startswith("```"):
            inside = line.strip() == "```sh" if not inside else False
        elif inside and line.strip() and not line.lstrip().startswith("#"):
            commands.append(Command(section, number, re.sub(r"\s+#\s.*$", "", line).strip()))
    return commands


COMMANDS = readme_commands(README.read_text(encoding="utf-8"))


def test_every_command_names_the_environment_it_runs_in() -> None:
    set_up = [command for command in COMMANDS if command.text.startswith(SET_UP)]
    assert len(set_up) == 2, "exactly two set-up commands"
    wrong = [
        f"README.md:{command.line}: {command.text}"
        for command in COMMANDS
        if command not in set_up
        and command.section not in NOT_RUN_HERE
        and not command.text.startswith("export ")
        and not any(part.strip().startswith(PROGRAMS) for part in command.text.split("&&"))
    ]
    assert not wrong, "\n".join(wrong)


def _runnable() -> list[Command]:
    return [
        command
        for command in COMMANDS
        if not command.text.startswith(SET_UP)
        and command.section not in NOT_RUN_HERE
        and not any(fragment in command.text for fragment in TOO_LONG)
    ]


@pytest.fixture(scope="module")
def scratch(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("readme")
    for name in ("examples", "maps", "bench", ".venv"):
        (folder / name).symlink_to(ROOT / name)
    return folder


@pytest.mark.slow
@pytest.mark.parametrize("command", _runnable(), ids=lambda command: f"line{command.line}")
def test_the_command_runs_as_written(command: Command, scratch: Path) -> None:
    environment = {key: value for key, value in os.environ.items() if key not in ("VIRTUAL_ENV", "PYTHONPATH")}
    finished = subprocess.run(
        ["bash", "-c", command.text], cwd=scratch, capture_output=True, text=True, env=environment,
        stdin=subprocess.DEVNULL, check=False,
    )  # fmt: skip
    output = finished.stdout + finished.stderr
    assert finished.returncode in (0, 1), f"README.md:{command.line} exited {finished.returncode}:\n{output[-2000:]}"
    assert "Traceback" not in output, f"README.md:{command.line}:\n{output[-2000:]}"
