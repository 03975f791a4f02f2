"""The MP4 writer: ffmpeg-encoded frames of the thesis swap, and what happens without ffmpeg."""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
from pathlib import Path

import pytest
from PIL import Image

from mrmp.core import Grid, RunResult
from mrmp.core.errors import MrmpError
from mrmp.io import load_scenario
from mrmp.sim.simulator import simulate
from mrmp.viz import animation_problem, write_animation, write_mp4
from mrmp.viz.layout import make_layout, robot_colours
from mrmp.viz.mp4 import MissingProgram, hold_frames, video_size

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
needs_ffmpeg = pytest.mark.skipif(
    shutil.which("ffmpeg") is None or shutil.which("ffprobe") is None,
    reason="ffmpeg/ffprobe are not installed (apt-get install ffmpeg): the MP4 is not checked",
)


def probe(path: Path) -> dict[str, object]:
    """ffprobe's view of the first video stream, frames counted by decoding."""
    output = subprocess.run(
        [
            "ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
            "-show_entries", "stream=codec_name,pix_fmt,width,height,nb_read_frames,avg_frame_rate",
            "-of", "json", str(path),
        ],
        check=True, capture_output=True, text=True,
    ).stdout
    return json.loads(output)["streams"][0]


def decoded_frame(path: Path, index: int, out: Path) -> Image.Image:
    subprocess.run(
        ["ffmpeg", "-v", "error", "-y", "-i", str(path), "-vf", f"select=eq(n\\,{index})", "-vframes", "1", str(out)],
        check=True,
    )
    return Image.open(out).convert("RGB")


@needs_ffmpeg
def test_thesis_swap_mp4_has_every_frame_at_the_picture_size(tmp_path: Path) -> None:
    scenario = load_scenario(EXAMPLES / "thesis-swap.yaml")
    result = simulate(scenario)
    path = write_mp4(scenario.grid, result, tmp_path / "swap.mp4", frames_per_tick=4, fps=10, hold_s=1.0)
    layout = make_layout(scenario.grid, len(result.robots))
    stream = probe(path)
    assert stream["codec_name"] == "h264" and stream["pix_fmt"] == "yuv420p"
    assert (stream["width"], stream["height"]) == video_size(layout.width, layout.height)
    assert int(stream["nb_read_frames"]) == result.ticks * 4 + 1 + hold_frames(1.0, 10)
    assert stream["avg_frame_rate"] == "10/1"
    assert [p.name for p in tmp_path.iterdir()] == ["swap.mp4"], "no temporary file is left behind"


@needs_ffmpeg
def test_mp4_frames_show_the_robot_moving(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    path = write_animation(grid, result, tmp_path / "swap.MP4", frames_per_tick=1, hold_s=0)
    assert int(probe(path)["nb_read_frames"]) == 7
    layout = make_layout(grid, len(result.robots))
    blue = robot_colours(2)[0]
    first, last = decoded_frame(path, 0, tmp_path / "0.png"), decoded_frame(path, 6, tmp_path / "6.png")

    def near_blue(image: Image.Image, cell: tuple[int, int]) -> bool:
        x, y = layout.centre(cell)
        pixel = image.getpixel((round(x + layout.cell * 0.2), round(y)))  # beside the label, on the disc
        return all(abs(a - b) <= 30 for a, b in zip(pixel, blue))

    assert near_blue(first, (0, 2)) and not near_blue(first, (4, 2))
    assert near_blue(last, (4, 2)) and not near_blue(last, (0, 2))


def fake_ffmpeg(folder: Path, script: str) -> Path:
    folder.mkdir()
    program = folder / "ffmpeg"
    program.write_text("#!/bin/sh\n" + script)
    program.chmod(program.stat().st_mode | stat.S_IEXEC)
    return folder


def test_without_ffmpeg_writing_fails_naming_the_program(
    swap: tuple[Grid, RunResult], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    grid, result = swap
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    assert "ffmpeg is not installed" in (animation_problem(tmp_path / "run.mp4") or "")
    assert animation_problem(tmp_path / "run.gif") is None
    with pytest.raises(MissingProgram, match="ffmpeg is not installed"):
        write_mp4(grid, result, tmp_path / "run.mp4")
    assert not (tmp_path / "run.mp4").exists()


def test_a_failing_ffmpeg_leaves_the_old_file_and_no_temporary(
    swap: tuple[Grid, RunResult], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    grid, result = swap
    folder = fake_ffmpeg(tmp_path / "bin", "cat > /dev/null\necho 'Unknown encoder libx264' >&2\nexit 1\n")
    monkeypatch.setenv("PATH", str(folder) + os.pathsep + os.environ.get("PATH", ""))
    out = tmp_path / "out"
    out.mkdir()
    target = out / "run.mp4"
    target.write_bytes(b"previous video")
    with pytest.raises(MrmpError, match="Unknown encoder libx264"):
        write_mp4(grid, result, target)
    assert target.read_bytes() == b"previous video"
    assert [p.name for p in out.iterdir()] == ["run.mp4"]


@needs_ffmpeg
def test_mp4_frames_are_the_painted_frames(walled: tuple[Grid, RunResult], tmp_path: Path) -> None:
    """Obstacles, costly cells, goals, trails, headings and the collision flash: the GIF's picture, encoded."""
    from PIL import ImageChops, ImageStat

    from mrmp.viz.raster import FramePainter

    grid, result = walled
    path = write_mp4(grid, result, tmp_path / "walled.mp4", frames_per_tick=2, hold_s=0)
    painter = FramePainter(grid, result)
    painted = [painter.frame(index / 2) for index in range(result.ticks * 2 + 1)]

    def error(decoded: Image.Image, picture: Image.Image) -> float:
        cropped = decoded.crop((0, 0, *picture.size))
        return sum(ImageStat.Stat(ImageChops.difference(cropped, picture)).mean) / 3

    for index in (0, 3, 4, 6):  # 3 and 4: either side of the collision at tick 2
        decoded = decoded_frame(path, index, tmp_path / f"{index}.png")
        errors = {other: error(decoded, painted[other]) for other in range(len(painted))}
        assert errors[index] < 2.2, f"frame {index} differs from the painted one by {errors[index]:.2f} on average"
        assert min(errors, key=errors.__getitem__) == index, errors
