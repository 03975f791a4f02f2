"""The README's standard benchmark table is what ``bench/compact_table.py`` prints from the data beside the report."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]


def _readme_table() -> list[str]:
    lines = (ROOT / "README.md").read_text(encoding="utf-8").split("\n")
    start = next(index for index, line in enumerate(lines) if line.startswith("| map | N | thesis |"))
    end = next(index for index in range(start, len(lines)) if not lines[index].startswith("|"))
    return lines[start:end]


def test_the_readme_table_is_the_standard_results_table() -> None:
    printed = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "compact_table.py"), str(ROOT / "docs" / "bench" / "standard")],
        capture_output=True, text=True, check=True,
    ).stdout.split("\n")  # fmt: skip
    assert printed[: len(_readme_table())] == _readme_table()
    assert printed[len(_readme_table())] == ""


def test_a_folder_without_results_is_a_one_line_error(tmp_path: Path) -> None:
    finished = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "compact_table.py"), str(tmp_path)], capture_output=True, text=True,
        check=False,
    )  # fmt: skip
    assert finished.returncode == 2 and finished.stderr.count("\n") == 1 and "no results.jsonl" in finished.stderr
