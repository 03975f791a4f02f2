"""Choosing the animation format by the file's suffix."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from PIL import Image

from mrmp.core import Grid, RunResult
from mrmp.viz import write_animation


def test_gif_suffix_writes_a_gif(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    path = write_animation(grid, result, tmp_path / "run.GIF", frames_per_tick=1)
    with Image.open(path) as gif:
        assert gif.format == "GIF" and gif.n_frames == 7


def test_svg_suffix_writes_an_svg(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    path = write_animation(grid, result, str(tmp_path / "run.svg"))
    assert path == tmp_path / "run.svg"
    assert ET.parse(path).getroot().tag == "{http://www.w3.org/2000/svg}svg"


@pytest.mark.parametrize("name, shown", [("run.avi", "'.avi'"), ("run", "(none)"), ("run.gif.txt", "'.txt'")])
def test_unsupported_suffix_is_refused_in_one_line(
    swap: tuple[Grid, RunResult], tmp_path: Path, name: str, shown: str
) -> None:
    grid, result = swap
    with pytest.raises(ValueError) as caught:
        write_animation(grid, result, tmp_path / name)
    message = str(caught.value)
    assert "\n" not in message
    assert f"unsupported suffix {shown}" in message
    assert ".gif" in message and ".svg" in message and ".mp4" in message
    assert not (tmp_path / name).exists()
