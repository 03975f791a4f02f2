"""Write a run's animation in the format its file name asks for.

``.gif`` and ``.svg`` need nothing beyond Pillow; ``.mp4`` needs ffmpeg
installed. :func:`animation_problem` says, before anything is run, whether a
path can be written.

Examples
--------
>>> from mrmp.core import Grid, RunResult
>>> write_animation(Grid(2, 2), RunResult("s", "p", 0, [], [], "done", 0, 0, 0.0), "run.avi")
Traceback (most recent call last):
...
ValueError: cannot write an animation to 'run.avi': unsupported suffix '.avi' (supported: .gif, .svg, .mp4)
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mrmp.core.grid import Grid
from mrmp.core.result import RunResult
from mrmp.viz.gif import write_gif
from mrmp.viz.mp4 import FFMPEG, MissingProgram, ffmpeg_path, write_mp4
from mrmp.viz.svg import write_svg

WRITERS: dict[str, Callable[..., Path]] = {".gif": write_gif, ".svg": write_svg, ".mp4": write_mp4}
"""The writer for each supported suffix (lower case)."""


def animation_problem(path: str | os.PathLike[str]) -> str | None:
    """Why an animation cannot be written to ``path`` (unsupported suffix, ffmpeg missing), or ``None``.

    >>> animation_problem("run.svg") is None
    True
    >>> animation_problem("run")
    'unsupported suffix (none); use .gif, .svg or .mp4'
    """
    suffix = Path(path).suffix
    if suffix.lower() not in WRITERS:
        shown = f"'{suffix}'" if suffix else "(none)"
        return f"unsupported suffix {shown}; use .gif, .svg or .mp4"
    if suffix.lower() == ".mp4" and ffmpeg_path() is None:
        return f"{FFMPEG} is not installed: it is needed to write .mp4 (install it, or use .gif or .svg)"
    return None


def write_animation(grid: Grid, result: RunResult, path: str | os.PathLike[str], **options: Any) -> Path:
    """Write ``result`` on ``grid`` as an animation, GIF, SVG or MP4 by ``path``'s suffix.

    Parameters
    ----------
    grid:
        The grid the run took place on.
    result:
        The run to draw.
    path:
        Where to write; the suffix (any case) chooses the format: ``.gif``,
        ``.svg`` or ``.mp4``.
    **options:
        Passed to :func:`~mrmp.viz.gif.write_gif`, :func:`~mrmp.viz.svg.write_svg`
        or :func:`~mrmp.viz.mp4.write_mp4` (all take ``show_messages``).

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    ValueError
        If the suffix is not one of the supported ones.
    MissingProgram
        If the suffix is ``.mp4`` and ffmpeg is not installed.
    """
    suffix = Path(path).suffix
    writer = WRITERS.get(suffix.lower())
    if writer is None:
        shown = f"'{suffix}'" if suffix else "(none)"
        supported = ", ".join(WRITERS)
        raise ValueError(
            f"cannot write an animation to '{os.fspath(path)}': unsupported suffix {shown} (supported: {supported})"
        )
    return writer(grid, result, path, **options)


__all__ = ["WRITERS", "MissingProgram", "animation_problem", "write_animation"]
