"""bench/lorr.py refuses what it cannot run with one line, before building or running anything."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[3] / "bench" / "lorr.py"


def fake_start_kit(folder: Path) -> Path:
    """A folder shaped like a Start-Kit source tree, with a ``lifelong`` that is never run."""
    (folder / "default_planner").mkdir(parents=True)
    (folder / "CMakeLists.txt").write_text("project(lifelong)\n")
    return folder


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--start-kit", "{missing}"], "is not a Start-Kit source tree"),
        (["--start-kit", "{kit}", "--steps", "0"], "--steps: must be between 1 and"),
        (["--start-kit", "{kit}", "--plan-ms", "0"], "--plan-ms: must be between 1 and 60000"),
        (["--start-kit", "{kit}", "--sequencings", "local,chaos"], "--sequencings: expected some of driver, local"),
        (["--start-kit", "{kit}", "--guidances", "lanes"], "--guidances: expected some of none, crisscross"),
    ],
)
def test_bad_input_is_one_line_with_exit_code_2(arguments: list[str], message: str, tmp_path: Path) -> None:
    kit = fake_start_kit(tmp_path / "kit")
    filled = [argument.format(missing=tmp_path / "nowhere", kit=kit) for argument in arguments]
    run = subprocess.run([sys.executable, str(SCRIPT), *filled], capture_output=True, text=True, timeout=120)
    assert run.returncode == 2
    assert message in run.stderr and len(run.stderr.strip().splitlines()) == 1


def test_a_case_that_is_not_there_is_named(tmp_path: Path) -> None:
    kit = fake_start_kit(tmp_path / "kit")
    (kit / "build").mkdir()
    (kit / "build" / "lifelong").write_text("")
    run = subprocess.run(
        [sys.executable, str(SCRIPT), "--start-kit", str(kit), "--cases", "random.domain/none.json", "--out", str(tmp_path / "o")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert run.returncode == 2 and "none.json is not a file" in run.stderr
