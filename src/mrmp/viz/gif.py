"""Animated GIF of a run, drawn with Pillow.

The picture, north up and east to the right: a warm-white grid with dark
obstacles and amber costly cells; each robot's goal as a hollow square in the
robot's colour; each robot as a disc with a pointed nose showing its heading
and, in big enough cells, its id; a fading trail of the cells it visited; a
caption band with the scenario, the tick and a progress bar; collision cells
flashed red at their tick (and faintly marked afterwards).

Motion between ticks is interpolated over ``frames_per_tick`` frames; a robot
that changes heading turns (rightwards, as the robots do) before it moves. The
last frame is held for ``hold_s`` seconds.

Large runs stay small and quick: past about 20 robots trails get shorter and
thinner, labels go away in small cells, and the number of frames is capped by
budgets of pixels and bytes (fewer frames per tick, then frames sampled evenly
over the run), so a run of hundreds of robots on a 64x64 grid still makes a GIF
of a few megabytes in a few seconds.

Examples
--------
>>> import tempfile, pathlib
>>> from PIL import Image
>>> from mrmp.core import Grid, Heading, RobotResult, RunResult
>>> robot = RobotResult("A", (0, 0), (0, 1), path=[(0, 0), (0, 1)], headings=[Heading.EAST, Heading.EAST])
>>> run = RunResult("demo", "thesis", 0, [robot], [], "arrived", 1, 1, 0.0)
>>> with tempfile.TemporaryDirectory() as folder:
...     written = write_gif(Grid(2, 2), run, pathlib.Path(folder) / "demo.gif", frames_per_tick=3)
...     with Image.open(written) as image:
...         print(image.n_frames, image.size)
4 (340, 309)
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from PIL import Image

from mrmp.core.grid import Grid
from mrmp.core.result import RunResult
from mrmp.viz._atomic import replacing
from mrmp.viz.colouring import HEADING_COLOURS, check_colouring, progress_ramp
from mrmp.viz.layout import (
    BACKGROUND,
    COLLISION,
    GRID_LINE,
    HEADER,
    HEADER_DIM,
    HEADER_TEXT,
    OBSTACLE,
    OBSTACLE_EDGE,
    RGB,
    ROBOT_EDGE,
    SUCCESS,
    Layout,
    is_live,
    make_layout,
    trim_idle,
)
from mrmp.viz.legend import AXIS_TEXT, GOAL_NEUTRAL, LEGEND_TEXT
from mrmp.viz.raster import Style, check_frame_options, frames_of_run

PIXEL_BUDGET = 90_000_000
"""Frames times pixels per frame that a GIF may hold before frames are sampled."""
BYTE_BUDGET = 7_500_000
"""Bytes a GIF is planned to hold before frames are sampled (a moving robot costs about half a byte a pixel of its cell)."""
SIZE_LIMIT = 9_500_000
"""A GIF written past this size (with the default frame cap) is drawn again with fewer frames."""
MIN_FRAMES = 40
"""The budgets never cut a run below this many frames."""
SIMULATED_FPS = 10.0
"""Frames per second of a simulated run's GIF."""
LIVE_FPS = 25.0
"""Frames per second of a live run's GIF, played at its real speed."""


def write_gif(
    grid: Grid,
    result: RunResult,
    path: str | os.PathLike[str],
    *,
    frames_per_tick: int = 4,
    fps: float | None = None,
    hold_s: float = 1.5,
    max_frames: int | None = None,
    show_messages: bool = False,
    colour_by: str | None = None,
    goal_lines: bool = False,
    speed: float = 1.0,
) -> Path:
    """Draw ``result`` on ``grid`` as a looping animated GIF at ``path``.

    Parameters
    ----------
    grid:
        The grid the run took place on.
    result:
        The run: robots' paths and headings (one per tick) and collisions.
    path:
        Where to write the GIF.
    frames_per_tick:
        Frames drawn per tick of a simulated run (1 shows only the ticks themselves).
    fps:
        Frames per second while playing: by default 10 for a simulated run
        and 25 for a live one, which plays at its real speed times ``speed``
        (:func:`mrmp.viz.raster.live_frame_times`).
    hold_s:
        How long the last frame stays on screen before the loop restarts.
    max_frames:
        Most frames to draw. By default budgets of pixels (drawing time) and
        of file size decide, never fewer than 40 frames, and a GIF that still
        comes out over 9.5 MB is drawn again with fewer. A run that needs more
        frames gets fewer per tick, or frames spread evenly over it.
    show_messages:
        Draw each tick's messages as arrows from sender to recipient (runs
        with a message log; see :func:`mrmp.viz.layout.message_arrows`).
    colour_by:
        What a robot's colour says: ``"robot"``, ``"progress"`` or
        ``"heading"`` (by default ``"robot"`` for a few robots, ``"progress"``
        for a crowd; see :mod:`mrmp.viz.colouring`).
    goal_lines:
        Draw a line from each robot to its goal.
    speed:
        A live run plays at ``speed`` times its real speed.

    Returns
    -------
    Path
        The path written (atomically: a temporary file in the same folder,
        then renamed).

    Raises
    ------
    ValueError
        If ``frames_per_tick``, ``fps``, ``max_frames`` or ``speed`` is not
        positive, or ``colour_by`` is unknown.
    """
    result = trim_idle(result)
    if fps is None:
        fps = LIVE_FPS if is_live(result) else SIMULATED_FPS
    check_frame_options(frames_per_tick, fps, max_frames)
    style = Style(show_messages, check_colouring(colour_by, len(result.robots)), goal_lines, speed)
    layout = make_layout(grid, len(result.robots), colouring=style.colour_by, goal_lines=goal_lines)
    max_frames_given = max_frames
    if max_frames is None:
        max_frames = _frame_cap(layout)
    times, frame_seconds, painter = frames_of_run(grid, result, layout, frames_per_tick, max_frames, style, fps)
    samples = sorted({0, len(times) // 3, (2 * len(times)) // 3, len(times) - 1})
    palette = _shared_palette([painter.frame(times[index]) for index in samples], painter.colours)
    frames = [painter.frame(t).quantize(palette=palette, dither=Image.Dither.NONE) for t in times]
    step_ms = max(20, 10 * round(100.0 * frame_seconds))  # GIF delays are whole hundredths of a second
    durations = [step_ms] * len(frames)
    durations[-1] = max(step_ms, round(hold_s * 1000.0))
    target = Path(path)
    with replacing(target) as temporary:
        _save(temporary, frames, durations)
        size = temporary.stat().st_size
        too_big = max_frames_given is None and len(times) > MIN_FRAMES and size > SIZE_LIMIT
        if too_big:
            temporary.unlink()  # nothing replaces the target: it is drawn again below
    if too_big:
        # The size estimate was too hopeful (a crowded run): draw fewer frames.
        fewer = max(MIN_FRAMES, int(len(times) * 0.85 * SIZE_LIMIT / size))
        return write_gif(
            grid,
            result,
            path,
            frames_per_tick=frames_per_tick,
            fps=fps,
            hold_s=hold_s,
            max_frames=fewer,
            show_messages=show_messages,
            colour_by=colour_by,
            goal_lines=goal_lines,
            speed=speed,
        )
    return target


def _save(target: Path, frames: Sequence[Image.Image], durations: Sequence[int]) -> None:
    """Write palette frames as a looping GIF; unchanged pixels become transparent (``optimize``)."""
    frames[0].save(
        target,  # the format is given: the temporary file's name says nothing
        format="GIF",
        save_all=True,
        append_images=list(frames[1:]),
        duration=list(durations),
        loop=0,
        disposal=1,
        optimize=True,
    )



def _frame_cap(layout: Layout) -> int:
    """Most frames that keep a GIF within :data:`PIXEL_BUDGET` and :data:`BYTE_BUDGET`."""
    by_pixels = PIXEL_BUDGET // (layout.width * layout.height)
    changed = 0.5 * layout.robots * layout.cell**2
    by_bytes = int(BYTE_BUDGET // (3000 + changed))
    return max(MIN_FRAMES, min(by_pixels, by_bytes))


def _shared_palette(images: Sequence[Image.Image], colours: Sequence[RGB]) -> Image.Image:
    """One 256-colour palette for every frame, so colours do not flicker between frames.

    Theme colours and robot colours are kept exactly; the remaining entries
    come from a median cut of the sample frames (anti-aliased edges, trails).
    """
    exact: list[RGB] = [
        BACKGROUND,
        GRID_LINE,
        OBSTACLE,
        OBSTACLE_EDGE,
        HEADER,
        HEADER_TEXT,
        HEADER_DIM,
        COLLISION,
        SUCCESS,
        ROBOT_EDGE,
        GOAL_NEUTRAL,
        AXIS_TEXT,
        LEGEND_TEXT,
        *progress_ramp(),
        *HEADING_COLOURS.values(),
    ]
    for colour in colours[:80]:
        if colour not in exact:
            exact.append(colour)
    sample = Image.new("RGB", (images[0].width, images[0].height * len(images)))
    for slot, image in enumerate(images):
        sample.paste(image, (0, image.height * slot))
    free = 255 - len(exact)  # one index stays free: Pillow uses it for unchanged pixels
    rest = sample.quantize(colors=free, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    rest_colours = rest.getpalette() or []
    entries = [channel for colour in exact for channel in colour] + rest_colours[: 3 * free]
    palette = Image.new("P", (1, 1))
    palette.putpalette(entries)
    return palette
