"""Write a run's animation in the format its file name asks for.

Examples
--------
>>> from mrmp.core import Grid, RunResult
>>> write_animation(Grid(2, 2), RunResult("s", "p", 0, [], [], "done", 0, 0, 0.0), "run.mp4")
Traceback (most recent call last):
...
ValueError: cannot write an animation to 'run.mp4': unsupported suffix '.mp4' (supported: .gif, .svg)
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mrmp.core.grid import Grid
from mrmp.core.result import RunResult
from mrmp.viz.gif import write_gif
from mrmp.viz.svg import write_svg

WRITERS: dict[str, Callable[..., Path]] = {".gif": write_gif, ".svg": write_svg}
"""The writer for each supported suffix (lower case)."""


def write_animation(grid: Grid, result: RunResult, path: str | os.PathLike[str], **options: Any) -> Path:
    """Write ``result`` on ``grid`` as an animation, GIF or SVG by ``path``'s suffix.

    Parameters
    ----------
    grid:
        The grid the run took place on.
    result:
        The run to draw.
    path:
        Where to write; the suffix (any case) chooses the format: ``.gif`` or ``.svg``.
    **options:
        Passed to :func:`~mrmp.viz.gif.write_gif` or :func:`~mrmp.viz.svg.write_svg`.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    ValueError
        If the suffix is not one of the supported ones.
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
