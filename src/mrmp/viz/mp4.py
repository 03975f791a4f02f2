"""MP4 video of a run: the GIF's frames (:mod:`mrmp.viz.raster`) encoded by ffmpeg with H.264.

Frames are drawn with Pillow and piped as raw RGB into ``ffmpeg -f rawvideo
... -c:v libx264 -pix_fmt yuv420p`` (preset ``veryfast``, tuned for
animation), the form every player reads. The frame
size is rounded up to even numbers (yuv420p needs them) by widening the
picture's margin. The last frame is held for ``hold_s`` seconds by repeating
it. The file is written to a temporary file beside the target and renamed
when ffmpeg succeeds.

ffmpeg must be installed (:func:`ffmpeg_path`); without it writing fails
with :class:`MissingProgram`, which names the program.

Examples
--------
>>> video_size(300, 221)
(300, 222)
>>> hold_frames(1.5, 10.0)
15
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
from pathlib import Path

from PIL import Image

from mrmp.core.errors import MrmpError
from mrmp.core.grid import Grid
from mrmp.core.result import RunResult
from mrmp.viz._atomic import replacing
from mrmp.viz.colouring import check_colouring
from mrmp.viz.layout import BACKGROUND, make_layout
from mrmp.viz.raster import FramePainter, Style, check_frame_options, frames_of_run

PIXEL_BUDGET = 400_000_000
"""Frames times pixels per frame drawn for one video before frames are sampled (drawing time)."""
MIN_FRAMES = 40
"""The budget never cuts a run below this many frames."""
FFMPEG = "ffmpeg"
"""The program that encodes the video, looked up on ``PATH``."""


class MissingProgram(MrmpError):
    """A program needed to write a file is not installed."""


def ffmpeg_path() -> str | None:
    """Where ffmpeg is on ``PATH``, or ``None`` when it is not installed."""
    return shutil.which(FFMPEG)


def video_size(width: int, height: int) -> tuple[int, int]:
    """The frame size for yuv420p: ``width`` and ``height`` rounded up to even numbers.

    >>> video_size(301, 220)
    (302, 220)
    """
    return (width + width % 2, height + height % 2)


def hold_frames(hold_s: float, fps: float) -> int:
    """Extra copies of the last frame that keep it on screen for ``hold_s`` seconds.

    >>> hold_frames(0.0, 10.0), hold_frames(0.25, 10.0)
    (0, 3)
    """
    return max(0, math.ceil(hold_s * fps - 1e-9))


def write_mp4(
    grid: Grid,
    result: RunResult,
    path: str | os.PathLike[str],
    *,
    frames_per_tick: int = 4,
    fps: float = 10.0,
    hold_s: float = 1.5,
    max_frames: int | None = None,
    show_messages: bool = False,
    colour_by: str | None = None,
    goal_lines: bool = False,
    speed: float = 1.0,
) -> Path:
    """Draw ``result`` on ``grid`` as an H.264 MP4 video at ``path``.

    Parameters
    ----------
    grid:
        The grid the run took place on.
    result:
        The run: robots' paths and headings (one per tick) and collisions.
    path:
        Where to write the video.
    frames_per_tick:
        Frames drawn per tick (1 shows only the ticks themselves).
    fps:
        Frames per second.
    hold_s:
        How long the last frame stays on screen at the end.
    max_frames:
        Most frames to draw (not counting the held last frame); by default a
        budget of pixels decides, never fewer than 40. A run that needs more
        gets fewer frames per tick, or frames spread evenly over it.
    show_messages:
        Draw each tick's messages as arrows from sender to recipient.
    colour_by, goal_lines, speed:
        As for :func:`mrmp.viz.gif.write_gif`: what robots' colours say,
        lines to goals, and how fast a live run plays (its real speed times
        ``speed``).

    Returns
    -------
    Path
        The path written (atomically).

    Raises
    ------
    ValueError
        If ``frames_per_tick``, ``fps`` or ``max_frames`` is not positive or
        ``hold_s`` is negative.
    MissingProgram
        If ffmpeg is not installed.
    MrmpError
        If ffmpeg fails (its last line of output is given).
    """
    check_frame_options(frames_per_tick, fps, max_frames)
    if not hold_s >= 0:
        raise ValueError(f"hold_s must not be negative, got {hold_s}")
    program = ffmpeg_path()
    if program is None:
        raise MissingProgram(f"cannot write '{os.fspath(path)}': {FFMPEG} is not installed (needed for .mp4)")
    style = Style(show_messages, check_colouring(colour_by, len(result.robots)), goal_lines, speed)
    layout = make_layout(grid, len(result.robots), colouring=style.colour_by, goal_lines=goal_lines)
    if max_frames is None:
        max_frames = max(MIN_FRAMES, PIXEL_BUDGET // (layout.width * layout.height))
    times, frame_seconds, painter = frames_of_run(grid, result, layout, frames_per_tick, max_frames, style, fps)
    rate = 1.0 / frame_seconds  # a live run capped to fewer frames plays them slower, at its real speed
    size = video_size(layout.width, layout.height)
    target = Path(path)
    with replacing(target) as temporary:
        _encode(program, painter, times, size, rate, hold_frames(hold_s, rate), temporary)
    return target


def _encode(
    program: str,
    painter: FramePainter,
    times: list[float],
    size: tuple[int, int],
    fps: float,
    hold: int,
    out: Path,
) -> None:
    """Pipe the frames at ``times`` (the last one ``hold`` more times) into ffmpeg, writing ``out``."""
    command = [
        program,
        "-hide_banner",
        "-loglevel",
        "error",
        "-y",
        "-f",
        "rawvideo",
        "-pix_fmt",
        "rgb24",
        "-s",
        f"{size[0]}x{size[1]}",
        "-r",
        f"{fps:g}",
        "-i",
        "-",
        "-an",
        "-c:v",
        "libx264",
        "-preset",
        "veryfast",
        "-tune",
        "animation",
        "-pix_fmt",
        "yuv420p",
        "-movflags",
        "+faststart",
        "-f",
        "mp4",
        str(out),
    ]
    process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    if process.stdin is None or process.stderr is None:  # not reached: both are pipes
        raise MrmpError(f"{FFMPEG} could not be started with pipes")
    broken = False
    try:
        last = b""
        for t in times:
            last = _padded(painter.frame(t), size).tobytes()
            process.stdin.write(last)
        for _ in range(hold):
            process.stdin.write(last)
    except BrokenPipeError:
        broken = True  # ffmpeg stopped early: its message says why
    except BaseException:
        process.kill()
        process.wait()
        raise
    finally:
        try:
            process.stdin.close()
        except BrokenPipeError:
            broken = True
    errors = process.stderr.read().decode("utf-8", "replace")
    status = process.wait()
    if status != 0 or broken:
        lines = [line for line in errors.splitlines() if line.strip()]
        reason = lines[-1] if lines else f"exit status {status}"
        raise MrmpError(f"{FFMPEG} could not write the video: {reason}")


def _padded(image: Image.Image, size: tuple[int, int]) -> Image.Image:
    """``image`` on a background of ``size`` (at most one pixel wider and taller), top-left aligned."""
    if image.size == size:
        return image
    canvas = Image.new("RGB", size, BACKGROUND)
    canvas.paste(image, (0, 0))
    return canvas
